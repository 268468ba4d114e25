// Every class of bad input, through the program itself: one line on stderr that
// names the scene (file), the field and what is allowed; exit status 2 (invalid,
// distinct from 1 = internal error and 3 = unstable); nothing written, except
// in a sweep, where a refused run leaves only an `invalid` summary.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "core/registry.hpp"
#include "support/cli.hpp"
#include "support/scenes.hpp"

namespace mpmtb {
namespace input_test {

using testing::run_cli;
using testing::scratch_path;

constexpr int kInvalid = 2;

// A scene file on disk: the free body of the unit tests with `extra` appended
// and every line in `drop` removed.
std::filesystem::path scene_file(const std::string& name, const std::string& extra = "",
                                 const std::vector<std::string>& drop = {}) {
  std::string text = testing::free_body_toml(2, "mls", "quadratic", extra);
  for (const auto& line : drop) {
    const auto at = text.find(line);
    EXPECT_NE(at, std::string::npos) << line;
    if (at != std::string::npos) text.erase(at, line.size());
  }
  const auto path = scratch_path(name + ".toml");
  std::ofstream(path) << text;
  return path;
}

// Runs `mpmtb run ARGS --out DIR` and checks the contract; `parts` must all
// appear in the message (the file or scene, the field, the allowed values).
void expect_invalid(const std::string& args, std::initializer_list<std::string> parts) {
  const auto out = scratch_path("invalid_out");
  const testing::CliResult r = run_cli("run " + args + " --out " + out.string());
  SCOPED_TRACE(args);
  EXPECT_EQ(r.status, kInvalid) << r.err;
  EXPECT_EQ(r.err.rfind("mpmtb: invalid input: ", 0), 0u) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "one line:\n" << r.err;
  for (const auto& p : parts) EXPECT_NE(r.err.find(p), std::string::npos) << "lacks " << p;
  EXPECT_FALSE(std::filesystem::exists(out)) << "nothing may be written for invalid input";
}

TEST(BadInput, UnknownKeys) {
  expect_invalid("bar --set grid.celss=3", {"scene 'bar'", "grid.celss", "unknown field", "cells"});
  const auto file = scene_file("unknown_table", "[gird]\ncells = 3\n");
  expect_invalid(file.string(), {file.string(), "gird", "unknown field", "grid"});
  expect_invalid("bar --set materials.bar.G=3", {"materials.bar", "unknown parameter 'G'", "E"});
}

TEST(BadInput, WrongTypes) {
  expect_invalid("bar --set grid.cells=many", {"scene 'bar'", "grid.cells", "expected an integer"});
  expect_invalid("bar --set grid.cells=2.5", {"grid.cells", "expected an integer in [1,"});
  expect_invalid("bar --set materials.bar.E=[1]", {"materials.bar.E", "expected a number"});
  expect_invalid("bar --set domain.max=3", {"domain.max", "array of 1 to 3 numbers"});
  expect_invalid("bar --set method.kernel=2", {"method.kernel", "expected a string"});
  expect_invalid("bar --set grid=3", {"grid", "expected a table"});
}

TEST(BadInput, MissingRequiredFields) {
  const auto file = scene_file("missing", "", {"t_end = 0.01\n"});
  expect_invalid(file.string(), {file.string(), "time.t_end", "missing required field"});
  const auto no_e = scene_file("missing_e", "", {"E = 1000.0\n"});
  expect_invalid(no_e.string(), {no_e.string(), "materials.jelly", "missing", "'E'", "> 0"});
}

TEST(BadInput, YoungsModulusMustBePositive) {
  expect_invalid("bar --set materials.bar.E=0", {"scene 'bar'", "materials.bar.E = 0", "> 0"});
  expect_invalid("bar --set materials.bar.E=-5", {"materials.bar.E = -5", "> 0"});
}

TEST(BadInput, PoissonRatioMustLieInTheOpenInterval) {
  for (const char* nu : {"0.5", "-1", "0.7", "nan"}) {
    expect_invalid(std::string("bar --set materials.bar.nu=") + nu,
                   {"materials.bar.nu", "in (-1, 0.5)"});
  }
}

TEST(BadInput, DensityMustBePositive) {
  expect_invalid("bar --set materials.bar.density=0", {"materials.bar.density = 0", "> 0"});
  expect_invalid("bar --set materials.bar.density=inf", {"materials.bar.density", "> 0"});
}

TEST(BadInput, CellsAndParticlesPerCellAtLeastOne) {
  expect_invalid("bar --cells 0", {"scene 'bar'", "grid.cells = 0", "[1, 1048576]"});
  expect_invalid("bar --ppc 0", {"grid.ppc = 0", "[1, 16]"});
  expect_invalid("bar --ppc 17", {"grid.ppc = 17", "[1, 16]"});
}

TEST(BadInput, BodiesOutsideTheDomain) {
  expect_invalid("disks --set bodies.1.center=[0.9,0.8]",
                 {"scene 'disks'", "bodies[1]", "outside the domain along axis 0"});
}

// Bodies may touch (half-open boxes, open spheres) but not overlap.
TEST(BadInput, OverlappingBodies) {
  expect_invalid("disks --set bodies.1.center=[0.5,0.3]",
                 {"scene 'disks'", "bodies[0] and bodies[1] overlap", "may touch but not overlap"});
  const auto touching =
      scene_file("touching",
                 "[[bodies]]\nshape = \"box\"\nmin = [0.62, 0.35, 0.3]\nmax = [0.8, 0.6, 0.7]\n"
                 "material = \"jelly\"\n");
  const auto out = scratch_path("touching_out");
  const auto r = run_cli("run " + touching.string() + " --t-end 0.001 --out " + out.string());
  EXPECT_EQ(r.status, 0) << "boxes sharing a face are allowed: " << r.err;
}

TEST(BadInput, TimeStepAndCflMustBePositive) {
  expect_invalid("bar --cfl 0", {"scene 'bar'", "time.cfl = 0", "> 0"});
  expect_invalid("bar --cfl -0.5", {"time.cfl = -0.5", "> 0"});
  expect_invalid("bar --dt 0", {"time.dt = 0", "> 0"});
  expect_invalid("bar --dt -1e-3", {"time.dt = -0.001", "> 0"});
  expect_invalid("bar --t-end 0", {"time.t_end = 0", "> 0"});
  expect_invalid("bar --set time.dt=1e-3", {"time", "exactly one of 'dt'", "'cfl'"});
}

TEST(BadInput, UnknownMethodNames) {
  expect_invalid("bar --transfer nope", {"method.transfer", "'nope'", "pic, flip, apic, mls"});
  expect_invalid("bar --kernel quartic",
                 {"method.kernel", "'quartic'", "linear, quadratic, cubic"});
  expect_invalid("bar --model rubber", {"materials.bar.model", "'rubber'", "neo-hookean"});
  expect_invalid("bar --set boundary.x_max=glue", {"boundary.x_max", "'glue'", "sticky, slip"});
  expect_invalid("bar --set reference.kind=exact", {"reference.kind", "'exact'", "vibrating-bar"});
}

TEST(BadInput, BadSetSyntax) {
  expect_invalid("bar --set grid.cells", {"scene 'bar'", "--set 'grid.cells'", "key.path=value"});
  expect_invalid("bar --set =3", {"--set '=3'", "key.path=value"});
  expect_invalid("bar --set grid.cells=", {"--set 'grid.cells='", "key.path=value"});
  expect_invalid("bar --set grid..cells=3", {"--set 'grid..cells=3'", "empty key"});
  expect_invalid("bar --set bodies.7.min=[1]", {"'7' is not an index of an array of 1"});
  expect_invalid("bar --set scene.name.x=1", {"--set 'scene.name.x=1'", "cannot assign inside"});
  expect_invalid("bar --set \"$(printf 'grid.cells=\\377')\"", {"--set", "not valid UTF-8"});
}

TEST(BadInput, MalformedToml) {
  const auto path = scratch_path("malformed.toml");
  std::ofstream(path) << "[scene]\nname = \"x\"\n[grid\ncells = 3\n";
  expect_invalid(path.string(), {path.string() + ":3:", "malformed TOML"});
}

TEST(BadInput, SceneFileThatDoesNotExist) {
  expect_invalid("/nonexistent/scene.toml",
                 {"'/nonexistent/scene.toml'", "no such file or built-in scene", "built-in: bar"});
}

TEST(BadInput, BadCommandLineValues) {
  expect_invalid("bar --threads x", {"command line", "--threads"});
  expect_invalid("bar --dim 4", {"command line", "--dim"});
  expect_invalid("bar --cells many", {"command line", "--cells"});
}

// A sweep records refused runs: only an `invalid` summary each, no series.
TEST(BadInput, SweepWritesOnlyInvalidSummaries) {
  const auto out = scratch_path("invalid_sweep");
  const auto r = run_cli("run bar --transfer all --set materials.bar.E=0 --out " + out.string());
  EXPECT_EQ(r.status, kInvalid) << r.err;
  int runs = 0;
  for (const auto& dir : std::filesystem::directory_iterator(out)) {
    if (!dir.is_directory()) continue;
    ++runs;
    EXPECT_FALSE(std::filesystem::exists(dir.path() / "series.csv")) << dir.path();
    const auto j = testing::read_json(dir.path() / "summary.json");
    EXPECT_EQ(j["status"], "invalid");
    EXPECT_NE(j["reason"].get<std::string>().find("materials.bar.E = 0"), std::string::npos);
  }
  EXPECT_EQ(runs, static_cast<int>(transfer_list().size())) << "one folder per transfer";
  EXPECT_NE(testing::read_text(out / "runs.csv").find(",invalid,"), std::string::npos);
  std::filesystem::remove_all(out);
}

}  // namespace input_test
}  // namespace mpmtb
