#pragma once
// The one table of scene keys (style.md P8). It drives validation (validate.cpp), the generated
// docs/scene_format.md (`karst schema`), and nothing else holds a key name, a range or a default.
#include <nlohmann/json.hpp>

#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace karst {

enum class ValueType {
    String,
    Number,
    Integer,
    Bool,
    Vec3,         ///< array of three numbers
    Enum,         ///< string from `options`
    Object,       ///< nested keys listed under this pointer
    ObjectArray,  ///< array of objects whose keys are listed under pointer + "/[]"
    Shape,        ///< a geometry object (keys listed under "shape" and "shape:<type>")
    ShapeArray,   ///< non-empty array of geometry objects
    Table,        ///< non-empty array of [time, value] rows, times (s) increasing from 0 on
};

/// Closed or open numeric interval for Number and Integer keys, and for every component of Vec3.
struct Range {
    double lo = -std::numeric_limits<double>::infinity();
    double hi = std::numeric_limits<double>::infinity();
    bool lo_open = false;
    bool hi_open = false;
    bool contains(double v) const;
    std::string describe() const;
};

struct KeySpec {
    std::string pointer;  ///< "/fluid/viscosity"; "[]" stands for any array index; "shape:box/min"
    ValueType type;
    std::string unit;  ///< SI unit, "" for dimensionless
    Range range;       ///< numbers only
    std::optional<nlohmann::json>
        value;              ///< default; none with `required` means the key must be given
    bool required = false;  ///< true: no default, must be present; false and no value: optional
    std::string doc;
    std::vector<std::string> options;  ///< Enum only
};

/// Every key a scene may hold, in documentation order.
const std::vector<KeySpec>& scene_schema();

/// The Markdown reference generated from the table (committed as docs/scene_format.md).
std::string scene_schema_markdown();

/// Human-readable type name used in error messages and docs.
std::string describe_type(const KeySpec& spec);

}  // namespace karst
