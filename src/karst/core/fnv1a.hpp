#pragma once
// FNV-1a, the 64-bit hash that fingerprints scenes, checkpoints and written meshes.
#include <cstdint>
#include <string_view>

namespace karst {

inline std::uint64_t fnv1a(std::string_view bytes) {
    std::uint64_t hash = 14695981039346656037ull;
    for (const unsigned char c : bytes) hash = (hash ^ c) * 1099511628211ull;
    return hash;
}

}  // namespace karst
