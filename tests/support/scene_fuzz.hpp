// The property both fuzzers check (tests/unit/scene_fuzz_test.cpp, a seeded
// random search under GoogleTest, and tests/fuzz/scene_fuzz.cpp, libFuzzer):
// any scene text with any `--set` assignments is either accepted, and then
// its resolved tree prints as TOML and JSON, or rejected with an InputError
// whose message starts with the scene's name. Anything else (another
// exception, a crash, a sanitizer report, a hang) is a defect.
#pragma once

#include <sstream>
#include <string>
#include <vector>

#include "core/errors.hpp"
#include "run.hpp"
#include "scene.hpp"

namespace mpmtb::testing {

struct FuzzVerdict {
  bool accepted = false;
  std::string message;  // the InputError's message when rejected
};

inline FuzzVerdict check_scene_input(const std::string& text, const std::vector<std::string>& set) {
  const std::string source = "fuzz.toml";
  FuzzVerdict v;
  try {
    const Scene s = scene_from_text(text, source, Overrides{.set = set});
    std::ostringstream toml_text;
    toml_text << s.resolved;
    (void)dump_json(toml_to_json(s.resolved));
    v.accepted = true;
  } catch (const InputError& e) {
    v.message = e.what();
    if (v.message.rfind(source + ":", 0) != 0) {
      throw std::logic_error("an InputError that does not name the scene: " + v.message);
    }
  }
  return v;
}

// libFuzzer's input: the scene text, then optionally a line "%%" followed by
// one `--set` assignment per line.
inline FuzzVerdict check_scene_bytes(const std::string& bytes) {
  const auto split = bytes.find("\n%%\n");
  std::vector<std::string> set;
  if (split != std::string::npos) {
    std::istringstream rest(bytes.substr(split + 4));
    for (std::string line; std::getline(rest, line);) set.push_back(line);
  }
  return check_scene_input(bytes.substr(0, split), set);
}

}  // namespace mpmtb::testing
