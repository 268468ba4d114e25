// Runs that never lose work and refuse what cannot run (issue 17): the
// checkpoint archive keeps every bit and refuses what does not fit the scene;
// --out, the scene's dimensions, non-finite values and memory requests too
// large are refused up front with the field named (exit 2, nothing written).
// The stop / resume round trips themselves run end to end (tests/e2e_resume.sh).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>

#include "archive.hpp"
#include "checkpoint.hpp"
#include "core/errors.hpp"
#include "scene.hpp"
#include "setup.hpp"
#include "support/cli.hpp"

namespace mpmtb {
namespace run_limits_test {

using testing::run_cli;
using testing::scratch_path;

constexpr int kInvalid = 2;

// A small 3D state from the pinned block with every field set to values whose
// bits a text round trip would lose (and a denormal, a negative zero).
State<3> odd_state() {
  State<3> s = build_state<3>(load_scene("pinned_block", {.cells = 12}));
  auto& P = s.particles;
  for (std::size_t p = 0; p < P.size(); ++p) {
    P.x[p] += Vec<3>::Constant(std::nextafter(Real(1) / 3, Real(1)) * 1e-3);
    P.v[p] = Vec<3>(std::numeric_limits<Real>::denorm_min(), -0.0, Real(p) / 7);
    P.C[p].setConstant(Real(1) / 9);
    P.F[p](0, 1) = std::sqrt(Real(2)) * 1e-7;
  }
  P.use_transfer_state(3);
  for (std::size_t k = 0; k < P.transfer_state.size(); ++k) P.transfer_state[k] = Real(k) / 11;
  for (auto& q : P.state) q = Real(2) / 3;
  s.collider_impulse = Vec3(1.0 / 3, -2.0 / 7, 5e-300);
  s.pin_impulse = Vec3(0.1, 0.2, 0.3);
  s.collider_work = 1.0 / 13;
  s.time = 0.1 + 0.2;
  s.step = 1234567;
  return s;
}

template <class T>
bool same_bits(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() &&
         (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

TEST(Checkpoint, StateRoundTripKeepsEveryBit) {
  const State<3> a = odd_state();
  ArchiveWriter w;
  save_state(w, a);
  State<3> b = build_state<3>(load_scene("pinned_block", {.cells = 12}));
  ArchiveReader r(w.bytes(), "test");
  restore_state(r, b);
  const auto& P = a.particles;
  const auto& Q = b.particles;
  EXPECT_TRUE(same_bits(P.x, Q.x));
  EXPECT_TRUE(same_bits(P.v, Q.v));
  EXPECT_TRUE(same_bits(P.C, Q.C));
  EXPECT_TRUE(same_bits(P.F, Q.F));
  EXPECT_TRUE(same_bits(P.m, Q.m));
  EXPECT_TRUE(same_bits(P.V0, Q.V0));
  EXPECT_TRUE(same_bits(P.state, Q.state));
  EXPECT_EQ(Q.transfer_state_size, 3);
  EXPECT_TRUE(same_bits(P.transfer_state, Q.transfer_state));
  EXPECT_EQ(P.pinned, Q.pinned);
  EXPECT_EQ(std::memcmp(a.collider_impulse.data(), b.collider_impulse.data(), sizeof(Vec3)), 0);
  EXPECT_EQ(std::memcmp(a.pin_impulse.data(), b.pin_impulse.data(), sizeof(Vec3)), 0);
  EXPECT_EQ(a.collider_work, b.collider_work);
  EXPECT_EQ(a.time, b.time);
  EXPECT_EQ(a.step, b.step);
}

TEST(Checkpoint, RefusesAnotherSceneNamingTheField) {
  ArchiveWriter w;
  save_state(w, odd_state());
  State<3> other = build_state<3>(load_scene("pinned_block", {.cells = 16}));
  ArchiveReader r(w.bytes(), "ck");
  try {
    restore_state(r, other);
    FAIL() << "a checkpoint of another particle count was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("particle count"), std::string::npos) << e.what();
  }
}

TEST(Checkpoint, RefusesATruncatedOrForeignFile) {
  ArchiveWriter w;
  save_state(w, odd_state());
  const std::string cut = w.bytes().substr(0, w.bytes().size() / 2);
  State<3> s = build_state<3>(load_scene("pinned_block", {.cells = 12}));
  ArchiveReader r(cut, "ck");
  EXPECT_THROW(restore_state(r, s), InputError);
  EXPECT_THROW(ArchiveReader("step,t\n", "series.csv"), InputError);
}

// `mpmtb run ARGS --out DIR`: exit 2, one line naming `parts`, nothing written.
void expect_refused(const std::string& args, std::initializer_list<std::string> parts) {
  const auto out = scratch_path("refused_out");
  const testing::CliResult r = run_cli("run " + args + " --out " + out.string());
  SCOPED_TRACE(args);
  EXPECT_EQ(r.status, kInvalid) << r.err;
  EXPECT_EQ(r.err.rfind("mpmtb: invalid input: ", 0), 0u) << r.err;
  for (const auto& p : parts) EXPECT_NE(r.err.find(p), std::string::npos) << "lacks " << p;
  EXPECT_FALSE(std::filesystem::exists(out)) << "nothing may be written";
}

TEST(RunChecks, OutNamingAnExistingFileIsRefused) {
  const auto file = scratch_path("a_file");
  std::ofstream(file) << "not a folder\n";
  for (const auto& out : {file, file / "sub"}) {
    const testing::CliResult r = run_cli("run bar --cells 8 --t-end 0.1 --out " + out.string());
    EXPECT_EQ(r.status, kInvalid) << r.err;
    EXPECT_NE(r.err.find("--out"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("is an existing file, not a folder"), std::string::npos) << r.err;
  }
  std::filesystem::remove(file);
}

TEST(RunChecks, DimensionOutsideTheScenesOwnIsRefused) {
  // disks declares dim = 2 and no dims; the pinned block dim = 3.
  expect_refused("disks --dim 1", {"scene.dim = 1", "disks", "allowed: 2"});
  expect_refused("pinned_block --dim 2", {"scene.dim = 2", "pinned_block", "allowed: 3"});
  expect_refused("disks --set scene.dim=3", {"scene.dim = 3", "allowed: 2"});
}

TEST(RunChecks, NonFiniteValuesSayTheyMustBeFinite) {
  expect_refused("bar --set time.t_end=inf", {"time.t_end", "must be finite"});
  expect_refused("bar --cfl inf", {"time.cfl", "must be finite"});
}

TEST(RunChecks, MemoryBeyondTheLimitIsRefusedWithBothFigures) {
  // 200,000 cells per axis in 3D: far beyond any machine's MemAvailable.
  expect_refused("pinned_block --cells 200000", {"needs about", "MemAvailable", "--max-memory"});
  // A small run under a smaller explicit limit: refused the same way.
  expect_refused("bar --cells 8 --max-memory 1K",
                 {"needs about", "1 KiB is the limit set by --max-memory"});
  expect_refused("bar --cells 8 --max-memory lots", {"--max-memory 'lots'", "K, M, G or T"});
}

TEST(RunChecks, ResumeWithoutACheckpointIsRefused) {
  const auto dir = scratch_path("no_checkpoint");
  std::filesystem::create_directories(dir);
  const testing::CliResult r = run_cli("run --resume " + dir.string());
  EXPECT_EQ(r.status, kInvalid) << r.err;
  EXPECT_NE(r.err.find("no checkpoint"), std::string::npos) << r.err;
  const testing::CliResult both = run_cli("run bar --resume " + dir.string());
  EXPECT_EQ(both.status, kInvalid) << both.err;
  std::filesystem::remove_all(dir);
}

}  // namespace run_limits_test
}  // namespace mpmtb
