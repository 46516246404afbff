#pragma once
// Small helpers the tests share: reading a file whole, and the SceneError a bad scene raises.
#include "karst/scene/scene.hpp"
#include "karst/scene/scene_error.hpp"
#include "karst/sim/model.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

namespace karst::test {

/// The whole file (empty if it cannot be read).
inline std::string read_text(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

/// Loads `json` (scene + model) and returns the SceneError it must raise; a failure if accepted.
inline SceneError refuse_scene(const std::string& json) {
    try {
        build_model(parse_scene(json));
    } catch (const SceneError& e) {
        return e;
    }
    ADD_FAILURE() << "scene accepted: " << json;
    return SceneError("", "", "");
}

}  // namespace karst::test
