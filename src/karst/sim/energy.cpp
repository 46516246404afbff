#include "karst/sim/energy.hpp"

#include "karst/core/parallel.hpp"
#include "karst/rigid/fragment_motion.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace karst {

Energy mechanical_energy(const Model& model, const State& state) {
    const Vec3 g = model.scene.gravity;
    const FluidParticles& f = state.fluid;
    const PorousParticles& p = state.porous.particles;
    Energy e;
    e.kinetic = deterministic_sum(f.size(), Real(0),
                                  [&](Index i) { return 0.5 * f.mass[i] * f.v[i].squaredNorm(); });
    e.potential =
        deterministic_sum(f.size(), Real(0), [&](Index i) { return -f.mass[i] * g.dot(f.x[i]); });
    // An anchored fragment's particles move only as its quasi-static Biot displacement says
    // (their velocity spreads a call's u over dt_B, for the fluid's sake): no inertia, no
    // kinetic energy. Free fragments carry theirs.
    const std::vector<Fragment>& fragments = state.porous.fragments;
    e.kinetic += deterministic_sum(p.size(), Real(0), [&](Index i) {
        if (fragments[p.fragment[i]].anchored) return Real(0);
        return 0.5 * (p.solid_mass[i] + p.absorbed_mass[i]) * p.v[i].squaredNorm();
    });
    e.potential += deterministic_sum(p.size(), Real(0), [&](Index i) {
        return -(p.solid_mass[i] + p.absorbed_mass[i]) * g.dot(p.x[i]);
    });
    e.contact = contact_energy(model, state);
    return e;
}

std::pair<Real, Real> fluid_speed_p99_and_max(const FluidParticles& f) {
    if (f.size() == 0) return {0, 0};
    std::vector<Real> speed(f.size());
    for (Index i = 0; i < f.size(); ++i) speed[i] = f.v[i].norm();
    const auto p99 = speed.begin() + std::min<Index>(f.size() - 1, Index(0.99 * f.size()));
    std::nth_element(speed.begin(), p99, speed.end());
    const Real fast = *p99;
    return {fast, *std::max_element(p99, speed.end())};
}

void EnergyAccount::add(const Energy& e) {
    m_released = std::max(m_released, m_start.total() - e.potential);
    m_largest_gain = std::max(m_largest_gain, e.total() - m_lowest);
    m_largest_rise = std::max(m_largest_rise, e.total() - m_start.total());
    const Real gain = e.total() - m_lowest;
    // With nothing released yet, a gain above round-off (and above 1 mJ, since the potential's
    // origin is arbitrary and energies that the account leaves out, such as surface tension's,
    // may move a little) is more than any share of it.
    // A gain within the sum's round-off is no gain, whatever was released (a solid at rest
    // whose deformation keeps its centre of mass moves it by 1e-15 of its potential energy).
    const Real magnitude =
        std::abs(m_start.kinetic) + std::abs(m_start.potential) + std::abs(m_start.contact);
    const Real round_off = 1e-6 * magnitude + 1e-3;
    if (m_released > 0 && gain > 1e-9 * magnitude)
        m_worst_ratio = std::max(m_worst_ratio, gain / m_released);
    else if (m_released <= 0 && gain > round_off)
        m_worst_ratio = std::numeric_limits<Real>::infinity();
    m_lowest = std::min(m_lowest, e.total());
}

}  // namespace karst
