// What built this program: the semantic version (CMake's project(VERSION)), the
// git revision and the flags that decide its floating-point results. Every
// summary.json carries it (`version`), and `mpmtb --version` prints it.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

namespace mpmtb {

struct BuildInfo {
  std::string version;       // semantic version, e.g. 0.2.0
  std::string git_revision;  // short hash built, "-dirty.<diff>" with edits, or "unknown"
  std::string build_type;    // Release, Debug, ...
  std::string compiler;      // id and version, e.g. GNU 12.2.0
  std::string precision;     // the field type: double or float
  std::string march;         // the -march value, empty for the compiler's default
  bool target_fma = false;   // the target instruction set has fused multiply-add
  std::string fp_contract;   // -ffp-contract: "off" means no FMA the source does not spell
};

const BuildInfo& build_info();

// The `version` object of summary.json.
nlohmann::json version_json();

// `mpmtb --version`: one line of version and revision, then the flags.
std::string version_text();

}  // namespace mpmtb
