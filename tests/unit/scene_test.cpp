// Bad input is rejected with a message that names the field and what is
// allowed; the command line exits non-zero and writes nothing.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "core/errors.hpp"
#include "support/cli.hpp"
#include "support/scenes.hpp"

namespace mpmtb {
namespace scene_test {

// Expects read_scene to throw an InputError whose message contains every `part`.
void expect_rejected(const std::string& toml, std::initializer_list<std::string> parts,
                     const Overrides& o = {}) {
  try {
    testing::scene_from_toml(toml, o);
    ADD_FAILURE() << "accepted:\n" << toml;
  } catch (const InputError& e) {
    for (const auto& p : parts)
      EXPECT_NE(std::string(e.what()).find(p), std::string::npos)
          << "message '" << e.what() << "' lacks '" << p << "'";
  }
}

std::string body(const std::string& extra = "") {
  return testing::free_body_toml(2, "mls", "quadratic", extra);
}

TEST(Scene, ValidSceneIsRead) {
  const Scene s = testing::scene_from_toml(body());
  EXPECT_EQ(s.dim, 2);
  EXPECT_EQ(s.materials.size(), 1u);
  EXPECT_DOUBLE_EQ(s.dx(), 1.0 / 16);
}

TEST(Scene, UnknownNamesListTheAllowedOnes) {
  expect_rejected(body(), {"method.transfer", "'nope'", "mls"}, {.transfer = "nope"});
  expect_rejected(body(), {"method.kernel", "'quartic'", "quadratic", "cubic"},
                  {.kernel = "quartic"});
  expect_rejected(body(), {"materials.jelly.model", "'rubber'", "neo-hookean"},
                  {.model = "rubber"});
  expect_rejected(body("[boundary]\nx_min = \"glue\"\n"), {"boundary.x_min", "sticky", "slip"});
}

TEST(Scene, OutOfRangeParametersNameTheField) {
  expect_rejected(body(), {"materials.jelly.E", "> 0"}, {.set = {"materials.jelly.E=-1"}});
  expect_rejected(body(), {"materials.jelly.nu", "0.5"}, {.set = {"materials.jelly.nu=0.5"}});
  expect_rejected(body(), {"materials.jelly.density"}, {.set = {"materials.jelly.density=0"}});
  expect_rejected(body(), {"grid.cells"}, {.cells = 0});
  expect_rejected(body(), {"grid.ppc"}, {.set = {"grid.ppc=0"}});
  expect_rejected(body(), {"time.cfl"}, {.cfl = -0.5});
  expect_rejected(body(), {"scene.dim", "[1, 3]"}, {.set = {"scene.dim=4"}});
  expect_rejected(body(), {"scene.dim = 3", "allowed: 2"}, {.dim = 3, .set = {"scene.dims=[2]"}});
}

std::string without(std::string text, const std::string& line) {
  const auto at = text.find(line);
  EXPECT_NE(at, std::string::npos);
  return text.erase(at, line.size());
}

TEST(Scene, MissingAndUnknownFields) {
  expect_rejected(without(body(), "E = 1000.0\n"), {"materials.jelly", "missing", "'E'"});
  expect_rejected(without(body(), "t_end = 0.01\n"), {"time.t_end", "missing"});
  expect_rejected(without(body(), "material = \"jelly\"\n"), {"bodies[0].material", "missing"});
  expect_rejected(body(), {"grid.celss", "unknown field", "cells"}, {.set = {"grid.celss=3"}});
  expect_rejected(body(), {"materials.jelly", "unknown parameter 'G'", "E"},
                  {.set = {"materials.jelly.G=3"}});
  expect_rejected(body(), {"bodies[0]", "unknown material 'steel'", "jelly"},
                  {.set = {"bodies.0.material=steel"}});
}

TEST(Scene, MalformedTomlGivesTheLine) {
  try {
    parse_scene_text("[scene]\nname = \"x\"\ndim = \n", "broken.toml");
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("broken.toml:3"), std::string::npos) << e.what();
  }
}

TEST(Scene, BadSetSyntaxIsRejected) {
  expect_rejected(body(), {"--set", "key.path=value"}, {.set = {"grid.cells"}});
  expect_rejected(body(), {"--set", "empty key"}, {.set = {"grid..cells=3"}});
  expect_rejected(body(), {"--set", "not an index"}, {.set = {"bodies.7.radius=1"}});
}

TEST(Scene, BodiesOutsideTheDomainAreRejected) {
  expect_rejected(body(), {"bodies[0]", "outside the domain"},
                  {.set = {"bodies.0.max=[1.5,0.6,0.7]"}});
}

TEST(Scene, TimeNeedsExactlyOneOfDtAndCfl) {
  expect_rejected(body(), {"time", "exactly one"}, {.set = {"time.cfl=0.5"}});
}

TEST(Scene, SetReachesEveryField) {
  const Scene s = testing::scene_from_toml(
      body(),
      {.set = {"materials.jelly.E=2500", "bodies.0.velocity=[1, 2]", "physics.gravity=[0,-9.81]"}});
  EXPECT_EQ(s.materials[0].params.values().at("E"), 2500);
  EXPECT_EQ(s.bodies[0].velocity[1], 2);
  EXPECT_EQ(s.gravity[1], -9.81);
}

// The program itself: exit status 2, the field named on stderr, no files
// (tests/unit/input_test.cpp goes through every class of bad input).
using Cli = testing::CliResult;
using testing::run_cli;

TEST(Cli, BadInputExitsWithStatusTwoAndNamesTheField) {
  const auto out =
      std::filesystem::temp_directory_path() / ("mpmtb_cli_out_" + std::to_string(::getpid()));
  std::filesystem::remove_all(out);
  const std::string o = " --out " + out.string();
  Cli c = run_cli("run bar --kernel quartic" + o);
  EXPECT_EQ(c.status, 2);
  EXPECT_NE(c.err.find("method.kernel"), std::string::npos) << c.err;
  c = run_cli("run bar --set materials.bar.nu=0.7" + o);
  EXPECT_EQ(c.status, 2);
  EXPECT_NE(c.err.find("materials.bar.nu"), std::string::npos) << c.err;
  c = run_cli("run no-such-scene" + o);
  EXPECT_EQ(c.status, 2);
  EXPECT_NE(c.err.find("built-in: bar"), std::string::npos) << c.err;
  c = run_cli("run bar --transfer flip --set flip.alpha=2" + o);
  EXPECT_EQ(c.status, 2);
  EXPECT_NE(c.err.find("flip.alpha"), std::string::npos) << c.err;
  EXPECT_FALSE(std::filesystem::exists(out)) << "nothing may be written for invalid input";
}

TEST(Cli, MalformedSceneFileNamesTheFileAndLine) {
  const auto path = std::filesystem::temp_directory_path() / "mpmtb_bad_scene.toml";
  std::ofstream(path) << "[scene]\nname = \"x\"\n[grid\ncells = 3\n";
  const Cli c = run_cli("run " + path.string() + " --out /tmp/mpmtb_never");
  EXPECT_EQ(c.status, 2);
  EXPECT_NE(c.err.find("mpmtb_bad_scene.toml:3"), std::string::npos) << c.err;
}

}  // namespace scene_test
}  // namespace mpmtb
