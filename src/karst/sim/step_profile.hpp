#pragma once
// Seconds spent in each named stage of the step (style.md P2), accumulated over a run.
#include <array>
#include <string_view>

namespace karst {

enum class Stage {
    Neighbours,
    Density,
    SoluteDiffusion,
    NonPressureForces,
    PressureSolve,
    FluidReactions,
    PoreFlow,
    Integrate,
    Fragments,
    Dissolution,
    Structure,
    Fracture,
    Count
};

inline constexpr std::array<std::string_view, size_t(Stage::Count)> k_stage_names{
    "neighbours",     "density",         "solute_diffusion", "non_pressure_forces",
    "pressure_solve", "fluid_reactions", "pore_flow",        "integrate",
    "fragments",      "dissolution",     "structure",        "fracture"};

struct StepProfile {
    std::array<double, size_t(Stage::Count)> seconds{};
    double& operator[](Stage s) { return seconds[size_t(s)]; }
    double total() const {
        double t = 0;
        for (double s : seconds) t += s;
        return t;
    }
};

}  // namespace karst
