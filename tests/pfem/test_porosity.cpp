// Dynamic porosity (M23) and Kozeny-Carman permeability (M24), docs/method.md §5.4.
#include "karst/pfem/porosity.hpp"

#include <gtest/gtest.h>

namespace karst {
namespace {

TEST(Porosity, RestStateGivesPhi0AndK0) {
    for (Real phi0 : {0.05, 0.2, 0.4}) {
        const Real phi = dynamic_porosity(phi0, 0, 0, 3e10);
        EXPECT_DOUBLE_EQ(phi, phi0);
        EXPECT_DOUBLE_EQ(kozeny_carman_permeability(1e-12, phi0, phi), 1e-12);
    }
}

TEST(Porosity, PaperEquation9IsRecoveredWithoutPressure) {
    const Real k0 = 2e-13, phi0 = 0.25;
    for (Real ev : {-0.05, -0.01, 0.002, 0.03}) {
        const Real k = kozeny_carman_permeability(k0, phi0, dynamic_porosity(phi0, ev, 0, 3e10));
        const Real paper = k0 * std::pow(1 + ev / phi0, 3) / (1 + ev);
        EXPECT_NEAR(k / paper, 1, 1e-12) << "eps_v " << ev;
    }
}

TEST(Porosity, SolidVolumeIsConservedUnderStrainAndPressure) {
    // M23 is exact: the solid volume (1 - phi) V changes only by the grain compression dp/K_s.
    const Real phi0 = 0.3, Ks = 1e9;
    for (Real ev : {-0.02, 0.01})
        for (Real dp : {0.0, 1e6, -5e5}) {
            const Real phi = dynamic_porosity(phi0, ev, dp, Ks);
            EXPECT_NEAR((1 - phi) * (1 + ev), (1 - phi0) * (1 - dp / Ks), 1e-14);
        }
    // Compaction closes pores, so permeability falls; dilation opens them.
    EXPECT_LT(kozeny_carman_permeability(1, phi0, dynamic_porosity(phi0, -0.02, 0, Ks)), 1);
    EXPECT_GT(kozeny_carman_permeability(1, phi0, dynamic_porosity(phi0, 0.02, 0, Ks)), 1);
}

}  // namespace
}  // namespace karst
