#pragma once
// Scene text to a JSON document, refusing what the validator could not walk safely: values nested
// deeper than k_max_json_depth, and numbers a double cannot hold (1e309), both named by their
// JSON path (issue 15: no recursion without a depth limit, every number error with its path).
#include <nlohmann/json.hpp>

#include <string>

namespace karst {

inline constexpr int k_max_json_depth = 64;

/// Throws SceneError naming the path of the first value that is too deep or out of range, or
/// the byte of a syntax error.
nlohmann::json read_scene_json(const std::string& text);

}  // namespace karst
