#pragma once
// The output folder of a run: per-frame fluid files, the static boundary, run.pvd, log.csv and
// stats.json. Each file is written atomically; run.pvd and log.csv are rewritten after every
// frame, so the folder is complete and consistent whenever a run stops.
#include "karst/scene/scene.hpp"
#include "karst/sim/model.hpp"
#include "karst/sim/state.hpp"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <vector>

namespace karst {

/// One row of log.csv.
struct FrameLog {
    Real time = 0;               ///< s
    Real dt = 0;                 ///< last step, s
    Index steps = 0;             ///< steps so far
    Index particles = 0;         ///< fluid particles now
    Real density_error = 0;      ///< largest PCISPH density error since the last frame (fraction)
    Real mipps = 0;              ///< million particle-steps per second since the last frame
};

class FrameWriter {
public:
    /// Creates `dir` and removes frame files a previous run left there.
    FrameWriter(std::filesystem::path dir, const OutputSettings& settings);
    void write_boundary(const WallParticles& walls);
    void write_frame(const FluidParticles& fluid, const FrameLog& log);
    void write_stats(const nlohmann::json& stats) const;
    int frames() const { return int(m_log.size()); }
    const std::filesystem::path& dir() const { return m_dir; }

private:
    std::filesystem::path m_dir;
    OutputSettings m_settings;
    bool m_has_boundary = false;
    std::vector<FrameLog> m_log;
};

}  // namespace karst
