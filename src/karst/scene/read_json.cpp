#include "karst/scene/read_json.hpp"

#include "karst/scene/scene_error.hpp"

#include <fmt/format.h>

#include <vector>

namespace karst {

namespace {

using json = nlohmann::json;

/// nlohmann's DOM builder, with the JSON path of the value being read kept alongside, so that
/// a nesting or number error can say where it is.
class PathTrackingBuilder {
public:
    explicit PathTrackingBuilder(json& root) : dom_(root, true) {}

    bool null() { return value(), dom_.null(); }
    bool boolean(bool b) { return value(), dom_.boolean(b); }
    bool number_integer(json::number_integer_t n) { return value(), dom_.number_integer(n); }
    bool number_unsigned(json::number_unsigned_t n) { return value(), dom_.number_unsigned(n); }
    bool number_float(json::number_float_t x, const json::string_t& s) {
        return value(), dom_.number_float(x, s);
    }
    bool string(json::string_t& s) { return value(), dom_.string(s); }
    bool binary(json::binary_t& b) { return value(), dom_.binary(b); }
    bool start_object(std::size_t n) { return open(false), dom_.start_object(n); }
    bool key(json::string_t& k) {
        levels_.back().key = k;
        return dom_.key(k);
    }
    bool end_object() { return levels_.pop_back(), dom_.end_object(); }
    bool start_array(std::size_t n) { return open(true), dom_.start_array(n); }
    bool end_array() { return levels_.pop_back(), dom_.end_array(); }

    bool parse_error(std::size_t byte, const std::string& token, const json::exception& e) {
        if (e.id == 406)  // a number out of the range of a double
            throw SceneError(pending_path(), "a number a double can hold (|x| < 1.8e308)", token);
        throw SceneError(pending_path(), "valid JSON",
                         fmt::format("a syntax error at byte {}: {}", byte, e.what()));
    }

private:
    struct Level {
        bool array = false;
        std::size_t next_index = 0;
        std::string key;
        std::string path;  ///< of this array or object
    };

    /// The path the next value gets (its key or index in the innermost open value).
    std::string pending_path() const {
        if (levels_.empty()) return "";
        const Level& l = levels_.back();
        return l.path + "/" + (l.array ? std::to_string(l.next_index) : l.key);
    }

    void value() {
        if (!levels_.empty() && levels_.back().array) ++levels_.back().next_index;
    }

    void open(bool array) {
        const std::string path = pending_path();
        if (int(levels_.size()) >= k_max_json_depth)
            throw SceneError(path, fmt::format("values nested at most {} deep", k_max_json_depth),
                             "a deeper array or object");
        value();
        levels_.push_back({array, 0, "", path});
    }

    nlohmann::detail::json_sax_dom_parser<json> dom_;
    std::vector<Level> levels_;
};

}  // namespace

json read_scene_json(const std::string& text) {
    json doc;
    PathTrackingBuilder builder(doc);
    json::sax_parse(text, &builder);
    return doc;
}

}  // namespace karst
