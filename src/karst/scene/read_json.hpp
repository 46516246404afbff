#pragma once
// Scene text to a JSON document, refusing what the validator could not walk safely or what would
// silently change the scene: values nested deeper than k_max_json_depth, numbers a double cannot
// hold (1e309, or 1e-400, which would read as 0), a key given twice in one object (the last
// would win) and a NUL byte (the parser would stop there), each named by its JSON path.
#include <nlohmann/json.hpp>

#include <string>

namespace karst {

inline constexpr int k_max_json_depth = 64;

/// Throws SceneError naming the path of the first value refused, or the line and column of a
/// syntax error.
nlohmann::json read_scene_json(const std::string& text);

/// A key as a JSON pointer token for messages (RFC 6901: '~' as ~0, '/' as ~1), with control
/// characters written as \u00XX and a key longer than 64 bytes cut, so no message echoes
/// terminal escapes or a megabyte of key.
std::string json_pointer_token(const std::string& key);

/// The longest start of `text` of at most `bytes` bytes that ends on a whole UTF-8 character.
std::string utf8_prefix(const std::string& text, size_t bytes);

}  // namespace karst
