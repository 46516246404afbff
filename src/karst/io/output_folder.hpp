#pragma once
// The folder a run writes into, claimed so that a run can only hurt its own files (issue 15):
// every file it writes is listed in manifest.txt before it is written; a later run into the same
// folder deletes exactly the files listed there, and a non-empty folder without a manifest (a
// folder karst did not write, or `--out .`) is refused unless the user says --overwrite.
#include <filesystem>
#include <functional>
#include <set>
#include <string>
#include <string_view>

namespace karst {

class OutputFolder {
public:
    /// Creates `dir`, or clears the files an earlier run listed in its manifest; throws
    /// SceneError (at "--out") for a non-empty folder without one unless `overwrite`.
    OutputFolder(std::filesystem::path dir, bool overwrite);
    /// Continues the run whose manifest is in `dir` (a resumed run): nothing is removed. Throws
    /// SceneError (at "--resume") when `dir` has no manifest.
    struct Resume {};
    OutputFolder(std::filesystem::path dir, Resume);
    /// Writes `name` (a plain file name) atomically, listing it in the manifest first.
    void write(const std::string& name, std::string_view bytes);
    /// Removes the listed files (of this run or the one it continues) whose name `pick` selects.
    void remove_if(const std::function<bool(const std::string&)>& pick);
    const std::filesystem::path& dir() const { return m_dir; }

    static constexpr const char* k_manifest = "manifest.txt";

private:
    std::filesystem::path m_dir;
    std::set<std::string> m_listed;
};

}  // namespace karst
