#include "karst/scene/read_json.hpp"

#include "karst/scene/scene_error.hpp"

#include <fmt/format.h>

#include <string_view>
#include <unordered_set>
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
        // A literal with a non-zero digit before its exponent that reads as 0 underflowed.
        const std::string_view mantissa = std::string_view(s).substr(0, s.find_first_of("eE"));
        if (x == 0 && mantissa.find_first_of("123456789") != std::string_view::npos)
            throw SceneError(pending_path(), "a number a double can hold (0 or |x| > 4.9e-324)", s);
        return value(), dom_.number_float(x, s);
    }
    bool string(json::string_t& s) { return value(), dom_.string(s); }
    bool binary(json::binary_t& b) { return value(), dom_.binary(b); }
    bool start_object(std::size_t n) { return open(false), dom_.start_object(n); }
    bool key(json::string_t& k) {
        Level& l = levels_.back();
        l.key = json_pointer_token(k);
        if (!l.keys.insert(k).second)
            throw SceneError(pending_path(), "each key once in an object",
                             "it a second time (the first would be ignored)");
        return dom_.key(k);
    }
    bool end_object() { return levels_.pop_back(), dom_.end_object(); }
    bool start_array(std::size_t n) { return open(true), dom_.start_array(n); }
    bool end_array() { return levels_.pop_back(), dom_.end_array(); }

    bool parse_error(std::size_t byte, const std::string& token, const json::exception& e) {
        if (e.id == 406)  // a number out of the range of a double
            throw SceneError(pending_path(), "a number a double can hold (|x| < 1.8e308)", token);
        // nlohmann's text without its "[json.exception.parse_error.101] " tag.
        std::string what = e.what();
        if (what.size() > 0 && what[0] == '[') what.erase(0, what.find("] ") + 2);
        throw SceneError(pending_path(), "valid JSON",
                         fmt::format("a syntax error (byte {}, near {}): {}", byte,
                                     pending_path().empty() ? "/" : pending_path(), what));
    }

private:
    struct Level {
        bool array = false;
        std::size_t next_index = 0;
        std::string key;                       ///< the last key read, as a pointer token
        std::unordered_set<std::string> keys;  ///< every key read in this object
        std::string path;                      ///< of this array or object
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
        levels_.push_back({array, 0, "", {}, path});
    }

    nlohmann::detail::json_sax_dom_parser<json> dom_;
    std::vector<Level> levels_;
};

}  // namespace

std::string utf8_prefix(const std::string& text, size_t bytes) {
    size_t end = std::min(text.size(), bytes);
    // Back off from continuation bytes (10xxxxxx) to the first byte of their character.
    while (end < text.size() && end > 0 && (static_cast<unsigned char>(text[end]) & 0xC0) == 0x80)
        --end;
    return text.substr(0, end);
}

std::string json_pointer_token(const std::string& key) {
    constexpr size_t k_longest = 64;
    const std::string kept = utf8_prefix(key, k_longest);
    std::string out;
    for (size_t i = 0; i < kept.size(); ++i) {
        const unsigned char c = static_cast<unsigned char>(kept[i]);
        if (c == '~')
            out += "~0";
        else if (c == '/')
            out += "~1";
        else if (c < 0x20 || c == 0x7f)
            out += fmt::format("\\u{:04x}", c);
        else
            out += char(c);
    }
    if (key.size() > k_longest) out += fmt::format("... ({} bytes)", key.size());
    return out;
}

json read_scene_json(const std::string& text) {
    if (const size_t nul = text.find('\0'); nul != std::string::npos)
        throw SceneError("", "JSON text", fmt::format("a NUL byte at byte {}", nul));
    json doc;
    PathTrackingBuilder builder(doc);
    json::sax_parse(text, &builder);
    return doc;
}

}  // namespace karst
