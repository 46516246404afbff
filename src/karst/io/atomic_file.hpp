#pragma once
// Every output file is written to a temporary name beside its target and renamed over it, so a
// reader (or a crash) never sees a half-written file (style.md P8).
#include <filesystem>
#include <string_view>

namespace karst {

/// Writes `bytes` to `path` atomically and durably (fsync before the rename); throws
/// std::runtime_error naming the path and the operating system's reason on failure.
void write_file_atomically(const std::filesystem::path& path, std::string_view bytes);

}  // namespace karst
