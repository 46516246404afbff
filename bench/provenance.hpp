#pragma once
// Where a benchmark row was measured: the date (UTC), the commit ("-dirty" with uncommitted
// changes) and the machine (cores, CPU model). Every row in bench/results starts with them, so
// figures from different commits and machines are never compared unknowingly.
#include <fmt/format.h>

#include <array>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

namespace karst::bench {

/// First line printed by a shell command, or "unknown".
inline std::string first_line_of(const std::string& command) {
    std::string out;
    if (FILE* pipe = popen(command.c_str(), "r")) {
        std::array<char, 256> buffer{};
        if (fgets(buffer.data(), int(buffer.size()), pipe)) out = buffer.data();
        pclose(pipe);
    }
    while (!out.empty() && (out.back() == '\n' || out.back() == '\r')) out.pop_back();
    return out.empty() ? "unknown" : out;
}

inline std::string cpu_model() {
    std::ifstream in("/proc/cpuinfo");
    for (std::string line; std::getline(in, line);)
        if (line.rfind("model name", 0) == 0) return line.substr(line.find(':') + 2);
    return "unknown";
}

/// "date,commit,cores,cpu," for the CSV header and for a row measured now in `source_dir`.
inline constexpr const char* k_provenance_columns = "date,commit,cores,cpu,";
inline std::string provenance_fields(const std::string& source_dir) {
    const std::string git = "git -C '" + source_dir + "' ";
    std::string commit = first_line_of(git + "rev-parse --short=10 HEAD 2>/dev/null");
    if (first_line_of(git + "status --porcelain --untracked-files=no 2>/dev/null") != "unknown")
        commit += "-dirty";
    std::array<char, 32> date{};
    const std::time_t now = std::time(nullptr);
    std::strftime(date.data(), date.size(), "%Y-%m-%dT%H:%MZ", std::gmtime(&now));
    std::string cpu = cpu_model();
    for (char& c : cpu)
        if (c == ',') c = ' ';
    return fmt::format("{},{},{},{},", date.data(), commit, std::thread::hardware_concurrency(),
                       cpu);
}

/// `file` opened for appending, with `header` (provenance columns first) written when it is new.
inline std::ofstream open_results(const std::filesystem::path& file, const std::string& header) {
    std::filesystem::create_directories(file.parent_path());
    const bool fresh = !std::filesystem::exists(file);
    std::ofstream csv(file, std::ios::app);
    if (fresh) csv << k_provenance_columns << header << "\n";
    return csv;
}

}  // namespace karst::bench
