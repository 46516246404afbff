#pragma once
// What the run loop (sim/run.cpp) carries from step to step besides the State: the frame
// cadence, the figures stats.json reports and the warnings already given. A checkpoint holds it
// with the State, so a resumed run reports as if it had never stopped.
#include "karst/io/frame_writer.hpp"
#include "karst/sim/energy.hpp"
#include "karst/sim/state.hpp"
#include "karst/sim/step_profile.hpp"

namespace karst {

/// The conserved totals (docs/method.md §4.7-4.8): water is the fluid's mass less its solute and
/// the water it already gave (drained), plus the pore water; grains are the solute plus the porous
/// particles' solid mass. All in kg.
struct MassTotals {
    Real water = 0, solute = 0, absorbed = 0, grains = 0;
};
MassTotals mass_totals(const State& state);

struct RunRecord {
    int next_frame = 1;  ///< number of the next frame to write
    Real max_density_error = 0, frame_density_error = 0;
    Index frames_over_tolerance = 0;  ///< frames whose steps ended above the solve's tolerance
    double particle_steps = 0, frame_particle_steps = 0, frame_step_seconds = 0;
    double wall_seconds = 0;  ///< wall time of the run before it was resumed, s
    bool energy_warned = false, removed_warned = false, biot_warned = false,
         porous_removed_warned = false;
    MassTotals initial;
    EnergyAccount energy;
    StepProfile profile;
    FrameHistory frames;
};

}  // namespace karst
