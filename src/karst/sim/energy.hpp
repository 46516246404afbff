#pragma once
// The mechanical energy account (issue 11): kinetic and potential energy of the fluid and the
// porous particles (which carry their fragments' mass: grains and pore water), and the elastic
// energy of the fragments' contact springs. A closed system may lose energy to viscosity and
// inelastic impacts, never gain it; the account says when it did.
#include "karst/sim/model.hpp"
#include "karst/sim/state.hpp"

namespace karst {

struct Energy {
    Real kinetic = 0;    ///< sum 1/2 m |v|^2, J
    Real potential = 0;  ///< sum -m g.x (zero at the origin), J
    Real contact = 0;    ///< the touching contact springs, sum 1/2 s k_c (rest - r)^2, J
    Real total() const { return kinetic + potential + contact; }
};

/// Kinetic and potential energy of the fluid (true mass m) and the porous particles
/// (grains + pore water, moving with their fragment's rigid velocity), and the contact springs'
/// energy (rigid/fragment_motion.hpp). Thread-count independent.
Energy mechanical_energy(const Model& model, const State& state);

/// The 99th percentile and the maximum of the fluid particles' speeds, m/s.
std::pair<Real, Real> fluid_speed_p99_and_max(const FluidParticles& fluid);

/// Follows the energy frame by frame. `released` is what the motion has had to spend: the
/// initial kinetic and contact energy plus the largest drop of potential energy so far. A rise of
/// the total over its lowest value so far is energy the numerics made.
class EnergyAccount {
public:
    EnergyAccount() = default;
    explicit EnergyAccount(const Energy& start) : m_start(start), m_lowest(start.total()) {}
    void add(const Energy& e);
    Real released() const { return m_released; }
    /// Largest rise of the total above its running minimum, J.
    Real largest_gain() const { return m_largest_gain; }
    /// Largest rise of the total above its start, J.
    Real largest_rise_over_start() const { return m_largest_rise; }
    /// True once a rise exceeded `fraction` of the energy released by then (while nothing was
    /// released, once a rise exceeded round-off and 1 mJ).
    bool gained_more_than(Real fraction) const { return m_worst_ratio > fraction; }
    Real worst_ratio() const { return m_worst_ratio; }

    /// The account's fields for a checkpoint (io/binary_archive.hpp).
    template <class Archive>
    friend void fields(Archive& ar, EnergyAccount& a) {
        ar(a.m_start.kinetic, a.m_start.potential, a.m_start.contact, a.m_lowest, a.m_released,
           a.m_largest_gain, a.m_largest_rise, a.m_worst_ratio);
    }

private:
    Energy m_start;
    Real m_lowest = 0, m_released = 0, m_largest_gain = 0, m_largest_rise = 0, m_worst_ratio = 0;
};

}  // namespace karst
