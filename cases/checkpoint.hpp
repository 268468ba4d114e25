// Checkpoints: the complete state of a run, written atomically to
// DIR/checkpoint/state.bin so that `mpmtb run --resume DIR` continues it and
// writes what an uninterrupted run would, byte for byte, at the same thread
// count. One file, in this order: `meta` (JSON: the resolved scene and the
// run's options, so the scene is rebuilt exactly), the State's evolving part
// (save_state), the run's monitors, the reference's accumulators and the
// frame ledger. What the scene alone decides (grid, materials, walls, collider
// paths, pinned nodes) is rebuilt from `meta`, not stored.
#pragma once

#include <nlohmann/json.hpp>

#include <filesystem>

#include "archive.hpp"
#include "core/state.hpp"

namespace mpmtb {

inline std::filesystem::path checkpoint_file(const std::filesystem::path& run_dir) {
  return run_dir / "checkpoint" / "state.bin";
}

// Every particle field (in particle order: the engine bins particles through an
// index array and never reorders them, so the order is that of the seeding),
// per-model and per-transfer state, time, step and the collider and pin ledgers.
template <int Dim>
void save_state(ArchiveWriter& a, const State<Dim>& s);
// Overwrites those fields of `s`, a state built from the same scene. Throws
// InputError when the particle count or a state size does not match it.
template <int Dim>
void restore_state(ArchiveReader& a, State<Dim>& s);

// The meta record of a checkpoint (the first field), for `--resume`.
nlohmann::json read_checkpoint_meta(ArchiveReader& a);

}  // namespace mpmtb
