// Re-running a recorded run: summary.json keeps the fully resolved scene tree
// (`config`, after every override), so `mpmtb run --config DIR/summary.json`
// rebuilds exactly that scene; the same thread count gives identical output.
#pragma once

#include <nlohmann/json.hpp>

#include <filesystem>
#include <optional>

#include "scene.hpp"

namespace mpmtb {

// The summary's JSON. Throws InputError when it is missing or unreadable.
nlohmann::json read_summary(const std::filesystem::path& summary);

// The scene recorded in a summary (its `config`), with further overrides applied.
// Integers stay integers and floating-point numbers round-trip exactly.
Scene load_recorded_scene(const nlohmann::json& summary, const std::string& source,
                          const Overrides& o = {});

// The thread count the run used, when recorded.
std::optional<int> recorded_threads(const nlohmann::json& summary);

toml::table json_to_toml(const nlohmann::json& object);

}  // namespace mpmtb
