#pragma once
// Checkpoints (issue 15): the physical State and the run loop's record, written atomically into
// the output folder as checkpoint_<steps>.kcp, so that `karst run SCENE --resume DIR` continues
// bit-identically. Solvers, factorisations and neighbour lists are not saved: they are rebuilt
// from the state. The pore-flow pairs are saved (they are built when the porous topology changes,
// not every step, so rebuilding them at another time would change the round-off).
#include "karst/sim/run_record.hpp"
#include "karst/sim/state.hpp"

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace karst {

/// Bumped whenever the layout changes: a checkpoint of another layout is refused.
inline constexpr std::uint32_t k_checkpoint_format = 9;

/// What a checkpoint must match to be resumed.
struct CheckpointKey {
    std::uint64_t scene = 0;  ///< Scene::fingerprint
    Real fps = 0;             ///< frames per second the run writes
};

/// The checkpoint file: header (format, karst version, key), the state and the record, checksum.
std::string checkpoint_bytes(const CheckpointKey& key, const State& state, const RunRecord& record);

/// Reads `file` into state and record; throws SceneError at "--resume" naming the file and what
/// is wrong (not a checkpoint, another format, version, scene or frame rate, damaged).
void read_checkpoint(const std::filesystem::path& file, const CheckpointKey& key, State& state,
                     RunRecord& record);

/// checkpoint_<steps, 12 digits>.kcp: names sort in step order.
std::string checkpoint_name(Index steps);

/// The checkpoint files in `dir`, oldest first.
std::vector<std::string> checkpoint_names(const std::filesystem::path& dir);

}  // namespace karst
