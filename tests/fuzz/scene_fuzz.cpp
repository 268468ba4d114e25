// libFuzzer target for the scene parser and `--set` overrides (scripts/fuzz.sh).
// Input: scene TOML, then optionally a line "%%" and one assignment per line.
// An accepted or rejected (InputError) input returns; any other exception
// escapes and aborts, which libFuzzer reports as a crash with the input.
#include <cstddef>
#include <cstdint>
#include <string>

#include "support/scene_fuzz.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  mpmtb::testing::check_scene_bytes(std::string(reinterpret_cast<const char*>(data), size));
  return 0;
}
