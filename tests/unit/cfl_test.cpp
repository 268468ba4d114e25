// The adaptive time step follows the current stiffness: snow hardening
// mu = mu0 exp(xi (1 - J_P)), lambda likewise (Stomakhin et al. 2013), raises
// the P-wave speed to c0 sqrt(exp(xi (1 - J_P))), so the CFL step must shrink.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "run.hpp"
#include "setup.hpp"
#include "support/scenes.hpp"

namespace mpmtb {
namespace cfl_test {

constexpr Real kE = 1000, kNu = 0.3, kRho = 1000, kXi = 10;
// P-wave speed of the unhardened material, from E, nu, rho directly.
const Real kC0 = std::sqrt(kE * (1 - kNu) / ((1 + kNu) * (1 - 2 * kNu)) / kRho);

std::string two_materials_toml() {
  return "[scene]\nname = \"two\"\ndim = 2\n[domain]\nmin = [0.0, 0.0, 0.0]\n"
         "max = [1.0, 1.0, 1.0]\n[grid]\ncells = 16\nppc = 2\n"
         "[method]\ntransfer = \"flip\"\nkernel = \"quadratic\"\n[time]\nt_end = 0.1\ncfl = 0.3\n"
         "[materials.snow]\nmodel = \"snow\"\nE = 1000.0\nnu = 0.3\ndensity = 1000.0\nxi = 10.0\n"
         "[materials.soft]\nmodel = \"neo-hookean\"\nE = 10.0\nnu = 0.3\ndensity = 1000.0\n"
         "[[bodies]]\nshape = \"box\"\nmin = [0.2, 0.2, 0]\nmax = [0.4, 0.4, 0]\n"
         "material = \"snow\"\n"
         "[[bodies]]\nshape = \"box\"\nmin = [0.6, 0.6, 0]\nmax = [0.8, 0.8, 0]\n"
         "material = \"soft\"\n";
}

TEST(CflWaveSpeed, FollowsSnowHardening) {
  State<2> s = build_state<2>(testing::scene_from_toml(two_materials_toml()));
  EXPECT_NEAR(s.max_wave_speed(), kC0, 1e-12 * kC0) << "at rest J_P = 1: no hardening";
  // Compress one snow particle plastically: the fastest wave is its own.
  const int p = s.material_particles[0][3];
  s.particles.state_of(p)[0] = 0.95;  // J_P
  const Real hardened = kC0 * std::sqrt(std::exp(kXi * (1 - 0.95)));
  EXPECT_NEAR(s.max_wave_speed(), hardened, 1e-12 * hardened);
  // Plastic dilation (J_P > 1) softens; the other particles still set c0.
  s.particles.state_of(p)[0] = 1.05;
  EXPECT_NEAR(s.max_wave_speed(), kC0, 1e-12 * kC0);
}

// Snow disks colliding with an adaptive step: the collision compresses them
// plastically, the wave speed the step used exceeds c0, and every step obeys
// dt <= cfl dx / c_max (dt = cfl dx / (c + max|v|) with the current c).
TEST(CflWaveSpeed, AdaptiveStepShrinksWhenSnowHardens) {
  const Scene scene = load_scene("disks", {.transfer = "flip",
                                           .model = "snow",
                                           .cfl = 0.3,
                                           .t_end = 2.0,
                                           .set = {"materials.elastic.xi=10.0"}});
  const auto dir = std::filesystem::temp_directory_path() / "mpmtb_cfl_snow";
  const RunOutcome r = run_scene(scene, dir, {.threads = 1});
  ASSERT_EQ(r.status, "ok") << r.reason;
  const Real c_max = r.summary["wave_speed_max"], dt_min = r.summary["dt_min"];
  const Real dx = scene.dx();
  EXPECT_GT(c_max, 1.1 * kC0) << "the collision must harden the snow";
  EXPECT_LE(dt_min, 0.3 * dx / c_max * (1 + 1e-12));
  // At the start dt = cfl dx / (c0 + |v|); the hardened material needs a much smaller one.
  EXPECT_LT(dt_min, 0.5 * Real(r.summary["dt_max"])) << "the step must shrink as the snow hardens";
}

}  // namespace cfl_test
}  // namespace mpmtb
