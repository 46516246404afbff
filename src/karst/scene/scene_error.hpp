#pragma once
// The one error type for bad input (style.md P8): it names the JSON path, what was expected and
// what was found. The CLI catches it in one place and exits with code 2.
#include <stdexcept>
#include <string>

namespace karst {

struct SceneError : std::runtime_error {
    SceneError(std::string path_, std::string expected_, std::string found_)
        : std::runtime_error("scene error at " + (path_.empty() ? std::string("/") : path_) +
                             ": expected " + expected_ + ", found " + found_),
          path(std::move(path_)),
          expected(std::move(expected_)),
          found(std::move(found_)) {}
    std::string path;  ///< JSON pointer of the offending value, e.g. /fluid_blocks/0/shape/radius
    std::string expected;  ///< what the schema allows
    std::string found;     ///< what the scene holds
};

}  // namespace karst
