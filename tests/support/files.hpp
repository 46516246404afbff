#pragma once
// Small helpers the tests share: reading a file whole, a temporary folder, the exit code of a
// command, and the SceneError a bad scene raises.
#include "karst/scene/scene.hpp"
#include "karst/scene/scene_error.hpp"
#include "karst/sim/model.hpp"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
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

/// A fresh folder karst_test_<name> in the temporary directory, removed at the end.
struct TempDir {
    std::filesystem::path path;
    explicit TempDir(const std::string& name)
        : path(std::filesystem::temp_directory_path() / ("karst_test_" + name)) {
        std::filesystem::remove_all(path);
        std::filesystem::create_directories(path);
    }
    ~TempDir() { std::filesystem::remove_all(path); }
};

/// Runs a shell command with stdout discarded; its exit code (128 + signal when killed), and what
/// it printed on stderr in `err` when given.
inline int exit_code_of(const std::string& command, std::string* err = nullptr) {
    // One file per test process: CTest runs tests side by side.
    const std::filesystem::path log = std::filesystem::temp_directory_path() /
                                      ("karst_test_stderr_" + std::to_string(getpid()) + ".txt");
    const int status = std::system((command + " 2>" + log.string() + " >/dev/null").c_str());
    if (err) *err = read_text(log);
    std::filesystem::remove(log);
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
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
