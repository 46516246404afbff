#pragma once
// Runs a scene in-process, without output, for physics tests.
#include "karst/scene/scene.hpp"
#include "karst/sim/model.hpp"
#include "karst/sim/state.hpp"
#include "karst/sim/step.hpp"
#include "karst/sph/integrate.hpp"

#include <functional>
#include <limits>

namespace karst::test {

struct Simulation {
    Model model;
    State state;
    StepProfile profile;
    Real max_density_error = 0;

    explicit Simulation(const std::string& scene_json)
        : model(build_model(parse_scene(scene_json))), state(make_initial_state(model)) {}

    /// One step of the length a run takes (the CFL or fixed step, landing on Biot calls).
    StepReport advance() {
        const StepReport r =
            step(model, state,
                 next_step_length(model, state, std::numeric_limits<Real>::infinity()), profile);
        max_density_error = std::max(max_density_error, r.max_density_error);
        return r;
    }
    /// Steps until `t`, calling `each` after every step.
    void run_until(Real t, const std::function<void()>& each = {}) {
        while (state.time < t) {
            advance();
            if (each) each();
        }
    }
};

}  // namespace karst::test
