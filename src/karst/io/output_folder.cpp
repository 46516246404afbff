#include "karst/io/output_folder.hpp"

#include "karst/io/atomic_file.hpp"
#include "karst/scene/scene_error.hpp"

#include <fmt/format.h>

#include <fstream>
#include <stdexcept>

namespace karst {

namespace fs = std::filesystem;

namespace {

/// A manifest line names a file of the folder itself, nothing above or below it.
bool plain_name(const std::string& name) {
    return !name.empty() && name != "." && name != ".." && name.find('/') == std::string::npos &&
           name.find('\0') == std::string::npos;
}

}  // namespace

OutputFolder::OutputFolder(fs::path dir, bool overwrite) : m_dir(std::move(dir)) {
    std::error_code ec;
    if (fs::exists(m_dir, ec) && !fs::is_directory(m_dir, ec))
        throw SceneError("--out", "a folder", fmt::format("a file at '{}'", m_dir.string()));
    fs::create_directories(m_dir, ec);
    if (ec)
        throw std::runtime_error(
            fmt::format("cannot create the folder '{}': {}", m_dir.string(), ec.message()));
    const fs::path manifest = m_dir / k_manifest;
    if (fs::exists(manifest)) {
        std::ifstream in(manifest);
        for (std::string name; std::getline(in, name);)
            if (plain_name(name)) {
                fs::remove(m_dir / name, ec);
                fs::remove(m_dir / (name + ".tmp"), ec);
            }
        fs::remove(manifest);
    } else if (!overwrite && !fs::is_empty(m_dir)) {
        size_t entries = 0;
        for ([[maybe_unused]] const auto& e : fs::directory_iterator(m_dir)) ++entries;
        throw SceneError(
            "--out",
            "an empty folder or one a karst run wrote (--overwrite writes into any "
            "folder, replacing only karst's own file names)",
            fmt::format("'{}' holding {} entries and no {}", m_dir.string(), entries, k_manifest));
    }
}

OutputFolder::OutputFolder(fs::path dir, Resume) : m_dir(std::move(dir)) {
    std::ifstream in(m_dir / k_manifest);
    if (!in)
        throw SceneError("--resume", "a folder a karst run wrote (with its manifest)",
                         fmt::format("no {} in '{}'", k_manifest, m_dir.string()));
    std::error_code ec;
    for (std::string name; std::getline(in, name);)
        if (plain_name(name)) {
            m_listed.insert(name);
            fs::remove(m_dir / (name + ".tmp"), ec);  // a killed run's unfinished write
        }
}

void OutputFolder::remove_if(const std::function<bool(const std::string&)>& pick) {
    std::error_code ec;
    for (const std::string& name : m_listed)
        if (pick(name)) fs::remove(m_dir / name, ec), fs::remove(m_dir / (name + ".tmp"), ec);
}

void OutputFolder::write(const std::string& name, std::string_view bytes) {
    if (m_listed.insert(name).second) {
        std::ofstream manifest(m_dir / k_manifest, std::ios::app);
        manifest << name << '\n';
        manifest.flush();
        if (!manifest)
            throw std::runtime_error(
                fmt::format("cannot write '{}'", (m_dir / k_manifest).string()));
    }
    write_file_atomically(m_dir / name, bytes);
}

}  // namespace karst
