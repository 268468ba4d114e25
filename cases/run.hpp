// Runs one scene to its end time, watching for instability, and writes
// DIR/series.csv and DIR/summary.json (the output contract in DESIGN.md).
#pragma once

#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>

#include "scene.hpp"
#include "vtk/frame_options.hpp"

namespace mpmtb {

struct RunOptions {
  int threads = 0;           // 0: OpenMP's default
  FrameOptions frames = {};  // ParaView frames (off by default)
  bool progress = false;     // draw a progress line on stderr (see Progress::wanted)
  std::string label = {};    // names the run on the progress line
};

struct RunOutcome {
  std::string status;  // ok | unstable | invalid
  std::string reason;
  nlohmann::json summary;
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
