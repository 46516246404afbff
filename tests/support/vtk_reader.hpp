#pragma once
// Reads back the VTK XML files karst writes (appended binary, raw or zlib blocks), following
// VTK's own reading rules (vtkXMLDataParser), so tests can check a frame holds exactly what was
// written. Arrays are returned as doubles by name; the positions as "Points".
#include <zlib.h>

#include <cstdint>
#include <cstring>
#include <map>
#include <regex>
#include <stdexcept>
#include <string>
#include <vector>

namespace karst::test {

struct VtkArrays {
    bool compressed = false;
    std::map<std::string, std::vector<double>> arrays;
};

inline VtkArrays read_vtk_xml(const std::string& file) {
    const std::string marker = "<AppendedData encoding=\"raw\">\n   _";
    const size_t at = file.find(marker);
    if (at == std::string::npos) throw std::runtime_error("no appended data");
    const size_t data = at + marker.size();
    const std::string head = file.substr(0, at);
    VtkArrays out;
    out.compressed = head.find("compressor=\"vtkZLibDataCompressor\"") != std::string::npos;
    auto word = [&](size_t pos) {
        std::uint64_t v;
        std::memcpy(&v, file.data() + pos, sizeof v);
        return v;
    };
    const std::regex element(R"(<DataArray ([^>]*)/>)"), attribute(R"((\w+)="([^"]*)\")");
    for (auto e = std::sregex_iterator(head.begin(), head.end(), element);
         e != std::sregex_iterator(); ++e) {
        std::map<std::string, std::string> attr;
        const std::string text = (*e)[1];
        for (auto a = std::sregex_iterator(text.begin(), text.end(), attribute);
             a != std::sregex_iterator(); ++a)
            attr[(*a)[1]] = (*a)[2];
        size_t pos = data + std::stoull(attr.at("offset"));
        std::string bytes;
        if (out.compressed) {
            const std::uint64_t blocks = word(pos), block = word(pos + 8), last = word(pos + 16);
            size_t in = pos + 24 + 8 * blocks;
            for (std::uint64_t b = 0; b < blocks; ++b) {
                const std::uint64_t packed = word(pos + 24 + 8 * b);
                uLongf size = (b + 1 == blocks && last) ? last : block;
                std::string chunk(size, '\0');
                if (uncompress(reinterpret_cast<Bytef*>(chunk.data()), &size,
                               reinterpret_cast<const Bytef*>(file.data() + in), packed) != Z_OK)
                    throw std::runtime_error("bad zlib block");
                bytes += chunk.substr(0, size);
                in += packed;
            }
        } else {
            bytes = file.substr(pos + 8, word(pos));
        }
        const std::string type = attr.at("type");
        std::vector<double> values;
        auto decode = [&](auto sample) {
            using T = decltype(sample);
            for (size_t i = 0; i + sizeof(T) <= bytes.size(); i += sizeof(T)) {
                T v;
                std::memcpy(&v, bytes.data() + i, sizeof v);
                values.push_back(double(v));
            }
        };
        if (type == "Float32")
            decode(float{});
        else if (type == "Int64")
            decode(std::int64_t{});
        else if (type == "Int32")
            decode(std::int32_t{});
        else if (type == "UInt8")
            decode(std::uint8_t{});
        else
            throw std::runtime_error("unexpected type " + type);
        out.arrays[attr.count("Name") ? attr["Name"] : "Points"] = std::move(values);
    }
    return out;
}

}  // namespace karst::test
