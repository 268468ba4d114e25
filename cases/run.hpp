// Runs one scene to its end time, watching for instability, and writes
// DIR/series.csv and DIR/summary.json (the output contract in DESIGN.md).
#pragma once

#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>

#include "scene.hpp"
#include "timing.hpp"
#include "vtk/frame_options.hpp"

namespace mpmtb {

class ArchiveReader;

struct RunOptions {
  int threads = 0;              // 0: OpenMP's default
  FrameOptions frames = {};     // ParaView frames (off by default)
  bool progress = false;        // draw a progress line on stderr (see Progress::wanted)
  std::string label = {};       // names the run on the progress line
  double wall_limit = 0;        // stop cleanly after this many wall seconds (0: none)
  double checkpoint_every = 0;  // simulated time between checkpoints (0: none)
  // Bytes the run may use instead of the machine's MemAvailable (0: MemAvailable).
  double max_memory = 0;
  // A checkpoint to continue (its meta record already read): the run goes on
  // from its state into the same folder.
  ArchiveReader* resume = nullptr;
  // After a stable run, time its stepping again (summary `timing`; timing.hpp).
  TimingOptions timing = {};
};

struct RunOutcome {
  std::string status;  // ok | unstable | invalid | interrupted
  std::string reason;
  nlohmann::json summary;
  int stop_exit = -1;  // interrupted: the exit status its stop asks for (130, 143, 124)
};

// Runs `scene` and writes its files under `out_dir`. Throws InputError when
// the scene cannot be set up (the caller reports it as invalid).
RunOutcome run_scene(const Scene& scene, const std::filesystem::path& out_dir,
                     const RunOptions& options = {});

// Writes a summary with status `invalid` and the reason (nothing else is run).
RunOutcome write_invalid(const std::filesystem::path& out_dir, const std::string& reason,
                         const nlohmann::json& context);

nlohmann::json toml_to_json(const toml::node& node);
// JSON text of a summary, with invalid UTF-8 replaced rather than thrown on.
std::string dump_json(const nlohmann::json& j);

}  // namespace mpmtb
