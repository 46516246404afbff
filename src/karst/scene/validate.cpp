#include "karst/scene/validate.hpp"

#include "karst/scene/read_json.hpp"
#include "karst/scene/scene_error.hpp"
#include "karst/scene/schema.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <map>

namespace karst {

namespace {

using json = nlohmann::json;

/// Children of each pattern in the schema: "/fluid" -> {"/fluid/viscosity", ...}.
const std::map<std::string, std::vector<const KeySpec*>>& children_by_parent() {
    static const auto table = [] {
        std::map<std::string, std::vector<const KeySpec*>> t;
        for (const KeySpec& s : scene_schema()) {
            const auto slash = s.pointer.rfind('/');
            t[s.pointer.substr(0, slash)].push_back(&s);
        }
        return t;
    }();
    return table;
}

std::string leaf_name(const std::string& pointer) {
    return pointer.substr(pointer.rfind('/') + 1);
}

/// A short description of a JSON value for error messages.
std::string describe_value(const json& v) {
    std::string d = v.dump();
    if (d.size() > 60) d = d.substr(0, 57) + "...";
    switch (v.type()) {
        case json::value_t::string:
            return "string " + d;
        case json::value_t::boolean:
            return "boolean " + d;
        case json::value_t::array:
            return "array " + d;
        case json::value_t::object:
            return "object " + d;
        case json::value_t::null:
            return "null";
        default:
            return d;
    }
}

size_t edit_distance(const std::string& a, const std::string& b) {
    std::vector<size_t> prev(b.size() + 1), cur(b.size() + 1);
    for (size_t j = 0; j <= b.size(); ++j) prev[j] = j;
    for (size_t i = 1; i <= a.size(); ++i) {
        cur[0] = i;
        for (size_t j = 1; j <= b.size(); ++j)
            cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (a[i - 1] != b[j - 1])});
        std::swap(prev, cur);
    }
    return prev[b.size()];
}

class Validator {
public:
    void object(json& obj, const std::vector<const KeySpec*>& keys, const std::string& path) {
        if (!obj.is_object()) throw SceneError(path, "an object", describe_value(obj));
        for (auto it = obj.begin(); it != obj.end(); ++it) {
            const bool known = std::any_of(keys.begin(), keys.end(), [&](const KeySpec* k) {
                return leaf_name(k->pointer) == it.key();
            });
            if (!known) unknown_key(it.key(), keys, path);
        }
        for (const KeySpec* k : keys) {
            const std::string name = leaf_name(k->pointer);
            const std::string child_path = path + "/" + name;
            if (!obj.contains(name)) {
                if (k->required)
                    throw SceneError(child_path, "a " + describe_type(*k) + " (required)",
                                     "nothing");
                if (!k->value) continue;  // optional, no default: absence has a meaning
                obj[name] = *k->value;
            }
            value(obj[name], *k, child_path);
        }
    }

private:
    [[noreturn]] void unknown_key(const std::string& name, const std::vector<const KeySpec*>& keys,
                                  const std::string& path) {
        std::string best;
        size_t best_d = 3;  // suggest only close matches
        std::string allowed;
        for (const KeySpec* k : keys) {
            const std::string cand = leaf_name(k->pointer);
            allowed += (allowed.empty() ? "" : ", ") + cand;
            const size_t d = edit_distance(name, cand);
            if (d < best_d) best_d = d, best = cand;
        }
        std::string expected = best.empty() ? "one of the keys " + allowed
                                            : "a known key (did you mean \"" + best + "\"?)";
        std::string shown = json(name).dump();  // quoted, control characters escaped
        if (shown.size() > 70) shown = utf8_prefix(shown, 67) + "...";
        throw SceneError(path + "/" + json_pointer_token(name), expected, "unknown key " + shown);
    }

    void number(const json& v, const KeySpec& k, const std::string& path, bool integer) {
        const std::string range = k.range.describe();
        const std::string unit = k.unit.empty() ? "" : " " + k.unit;
        const std::string expected =
            (integer ? "an integer" : "a number") + (range.empty() ? "" : " in " + range) + unit;
        if (integer ? !v.is_number_integer() : !v.is_number())
            throw SceneError(path, expected, describe_value(v));
        if (!k.range.contains(v.get<double>())) throw SceneError(path, expected, v.dump());
    }

    /// Rows [time, value]: times at least 0 and strictly increasing, values in the key's range.
    void time_table(const json& v, const KeySpec& k, const std::string& path) {
        if (!v.is_array() || v.empty())
            throw SceneError(path, "a non-empty array of [time, value] rows", describe_value(v));
        KeySpec time = k;
        time.unit = "s", time.range = Range{0, 1e12};
        for (size_t i = 0; i < v.size(); ++i) {
            const std::string row = fmt::format("{}/{}", path, i);
            if (!v[i].is_array() || v[i].size() != 2)
                throw SceneError(row, "a [time, value] row", describe_value(v[i]));
            number(v[i][0], time, row + "/0", false);
            number(v[i][1], k, row + "/1", false);
            if (i > 0 && v[i][0].get<double>() <= v[i - 1][0].get<double>())
                throw SceneError(
                    row + "/0",
                    fmt::format("a time after the previous row's {} s", v[i - 1][0].get<double>()),
                    v[i][0].dump());
        }
    }

    void shape(json& v, const std::string& path) {
        if (!v.is_object()) throw SceneError(path, "a shape object", describe_value(v));
        const auto& table = children_by_parent();
        const KeySpec* type_key = table.at("shape").front();
        if (!v.contains("type")) {
            // A misspelt "type" is named as the unknown key it is.
            for (auto it = v.begin(); it != v.end(); ++it)
                if (edit_distance(it.key(), "type") < 3) unknown_key(it.key(), {type_key}, path);
            throw SceneError(path + "/type", describe_type(*type_key) + " (required)", "nothing");
        }
        value(v["type"], *type_key, path + "/type");
        std::vector<const KeySpec*> keys = table.at("shape");
        const auto& specific = table.at("shape:" + v["type"].get<std::string>());
        keys.insert(keys.end(), specific.begin(), specific.end());
        object(v, keys, path);
    }

    void value(json& v, const KeySpec& k, const std::string& path) {
        const auto& table = children_by_parent();
        switch (k.type) {
            case ValueType::String:
                if (!v.is_string() || v.get<std::string>().empty())
                    throw SceneError(path, "a non-empty string", describe_value(v));
                break;
            case ValueType::Number:
                number(v, k, path, false);
                break;
            case ValueType::Integer:
                number(v, k, path, true);
                break;
            case ValueType::Bool:
                if (!v.is_boolean()) throw SceneError(path, "true or false", describe_value(v));
                break;
            case ValueType::Vec3:
                if (!v.is_array() || v.size() != 3)
                    throw SceneError(path, "an array of 3 numbers" + unit_suffix(k),
                                     describe_value(v));
                for (size_t i = 0; i < 3; ++i)
                    number(v[i], k, fmt::format("{}/{}", path, i), false);
                break;
            case ValueType::Enum: {
                const bool ok = v.is_string() && std::find(k.options.begin(), k.options.end(),
                                                           v.get<std::string>()) != k.options.end();
                if (!ok) throw SceneError(path, describe_type(k), describe_value(v));
                break;
            }
            case ValueType::Object:
                object(v, table.at(k.pointer), path);
                break;
            case ValueType::ObjectArray:
                if (!v.is_array()) throw SceneError(path, "an array of objects", describe_value(v));
                for (size_t i = 0; i < v.size(); ++i)
                    object(v[i], table.at(k.pointer + "/[]"), fmt::format("{}/{}", path, i));
                break;
            case ValueType::Shape:
                shape(v, path);
                break;
            case ValueType::Table:
                time_table(v, k, path);
                break;
            case ValueType::ShapeArray:
                if (!v.is_array() || v.empty())
                    throw SceneError(path, "a non-empty array of shapes", describe_value(v));
                for (size_t i = 0; i < v.size(); ++i) shape(v[i], fmt::format("{}/{}", path, i));
                break;
        }
    }

    static std::string unit_suffix(const KeySpec& k) {
        return k.unit.empty() ? "" : " (" + k.unit + ")";
    }
};

}  // namespace

void validate_scene_document(json& doc) {
    Validator().object(doc, children_by_parent().at(""), "");
}

}  // namespace karst
