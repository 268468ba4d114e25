// The damage length scale l0 (methods/models/damage.hpp, AnisoMPM, Wolper et
// al. 2020): d <- min(1, d + dt/eta <(1 - d) D~ - (d - l0^2 lap d)>), with
// lap d from the grid (methods/core/nonlocal.hpp), run through the step.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "core/registry.hpp"
#include "models/damage.hpp"
#include "setup.hpp"
#include "support/random_matrices.hpp"
#include "support/scenes.hpp"

namespace mpmtb {
namespace damage_length_test {

// The 2D pinned sheet struck by a ball (as in collider_test.cpp), damage with l0.
std::string sheet_toml(Real l0) {
  return "[scene]\nname = \"sheet\"\ndim = 2\n"
         "[domain]\nmin = [0.0, 0.0, 0.0]\nmax = [1.0, 1.0, 1.0]\n"
         "[grid]\ncells = 32\nppc = 2\n[method]\ntransfer = \"mls\"\nkernel = \"quadratic\"\n"
         "[time]\nt_end = 1.0\ndt = 2e-4\n[physics]\ngravity = [0.0, -9.81, 0.0]\n"
         "[materials.m]\nmodel = \"damage\"\nE = 2e4\nnu = 0.3\ndensity = 1000.0\n"
         "sigma_crit = 3e3\nl0 = " +
         std::to_string(l0) +
         "\n[[bodies]]\nshape = \"box\"\nmin = [0.4375, 0.25, 0.0]\nmax = [0.5625, 0.75, 0.0]\n"
         "material = \"m\"\n"
         "[[pins]]\nmin = [0.0, 0.74, 0.0]\nmax = [1.0, 1.0, 1.0]\n"
         "[[colliders]]\nshape = \"sphere\"\ncenter = [0.75, 0.45, 0.0]\nradius = 0.08\n"
         "velocity = [-1.0, 0.0, 0.0]\nwall = \"sticky\"\n";
}

std::vector<Real> damage_of(const State<2>& s) {
  std::vector<Real> d;
  for (std::size_t p = 0; p < s.particles.size(); ++p) d.push_back(s.particles.state_of(p)[0]);
  return d;
}

// With l0 = 2 dx, damage spreads through the Laplacian yet never decreases
// and never leaves [0, 1] at any particle in any step.
TEST(DamageLength, MonotoneAndBoundedWithLengthScale) {
  const Scene scene = testing::scene_from_toml(sheet_toml(2.0 / 32));
  State<2> s = build_state<2>(scene);
  Parameters params;
  auto st = make_stepper<2>("mls", "quadratic", params);
  std::vector<Real> d_old = damage_of(s);
  for (int i = 0; i < 1000; ++i) {
    st->step(s, 2e-4);
    const std::vector<Real> d = damage_of(s);
    for (std::size_t p = 0; p < d.size(); ++p) {
      ASSERT_GE(d[p], d_old[p]) << "particle " << p << " step " << i;
      ASSERT_LE(d[p], 1) << "particle " << p << " step " << i;
    }
    d_old = d;
  }
  int damaged = 0;
  for (Real d : d_old) damaged += d >= 0.5;
  EXPECT_GT(damaged, 10) << "the ball must damage the sheet";
}

// l0 = 0 is the local model: the step asks for no Laplacian, and running the
// stages without the nonlocal hook gives the same state bit for bit.
TEST(DamageLength, ZeroLengthIsTheLocalModelBitForBit) {
  const Scene scene = testing::scene_from_toml(sheet_toml(0));
  State<2> a = build_state<2>(scene), b = build_state<2>(scene);
  EXPECT_FALSE(a.materials[0]->laplacian_request().active());
  Parameters params;
  auto sa = make_stepper<2>("mls", "quadratic", params);
  auto sb = make_stepper<2>("mls", "quadratic", params);
  for (int i = 0; i < 1000; ++i) {
    sa->step(a, 2e-4);
    sb->particles_to_grid(b, 2e-4);  // the stages without nonlocal_update
    sb->update_grid(b, 2e-4);
    sb->grid_to_particles(b, 2e-4);
    sb->constitutive_update(b, 2e-4);
    b.time += 2e-4;
  }
  EXPECT_EQ(a.particles.state, b.particles.state);
  EXPECT_EQ(a.particles.x, b.particles.x);
  EXPECT_EQ(a.particles.F, b.particles.F);
  Real d_max = 0;
  for (Real d : damage_of(a)) d_max = std::max(d_max, d);
  EXPECT_GT(d_max, 0.5) << "the comparison must include damage";
}

// ... and the update of one particle is the local law written out here,
// d + dt/eta max(0, (1 - d) zeta <sigma_max/sigma_crit - 1> - d), bit for bit
// (the Laplacian slots are ignored when l0 = 0).
TEST(DamageLength, ZeroLengthUpdateIsTheLocalLaw) {
  const Real sigma_crit = 5, zeta = 2, eta = 1e-3, dt = 2e-4;
  Parameters p("materials.test", {{"E", 250},
                                  {"nu", 0.3},
                                  {"density", 7},
                                  {"sigma_crit", sigma_crit},
                                  {"zeta", zeta},
                                  {"eta", eta},
                                  {"l0", 0}});
  const Damage<3> m(p);
  std::mt19937 gen(7);
  std::uniform_real_distribution<Real> unit(0, 1);
  int grew = 0;
  for (int trial = 0; trial < 200; ++trial) {
    Mat<3> F = Mat<3>::Identity() + 0.2 * testing::RandomMatrix<3>(gen);
    if (F.determinant() < 0.3) continue;
    const Real d0 = unit(gen);
    Real q[4] = {d0, 0, 123.0 * unit(gen), 456.0};  // junk Laplacian slots
    const Real excess = m.max_principal_stress(F) - sigma_crit;
    const Real D = excess > 0 ? zeta * excess / sigma_crit : 0;
    const Real rate = std::max(Real(0), (1 - d0) * D - d0);
    const Real expected = rate > 0 ? std::min(Real(1), d0 + dt / eta * rate) : d0;
    m.project(F, q, dt);
    EXPECT_EQ(q[0], expected) << "trial " << trial;
    grew += q[0] > d0;
  }
  EXPECT_GT(grew, 10);
}

// A 1D bar pulled apart from a weak middle segment: only the weak segment
// reaches its critical stress (the strong part's is 60 times the peak stress
// rho c v), so with l0 = 0 damage stays inside it; with l0 > 0 it spreads
// into the strong part over a distance of order l0 (the steady tail of
// d = l0^2 d'' is exp(-|x| / l0), above 10 % out to 2.3 l0 on each side).
Real damage_zone_width(Real l0_cells) {
  const int cells = 64;
  const Real dx = 1.0 / cells, l0 = l0_cells * dx;
  const std::string damage =
      "model = \"damage\"\nE = 1e4\nnu = 0.0\ndensity = 1000.0\nl0 = " + std::to_string(l0) + "\n";
  const std::string toml =
      "[scene]\nname = \"bar\"\ndim = 1\n[domain]\nmin = [0.0, 0.0, 0.0]\nmax = [1.0, 1.0, 1.0]\n"
      "[grid]\ncells = 64\nppc = 2\n[method]\ntransfer = \"flip\"\nkernel = \"quadratic\"\n"
      "[time]\nt_end = 0.03\ndt = 2e-4\n"
      "[materials.weak]\n" +
      damage + "sigma_crit = 40.0\n[materials.strong]\n" + damage +
      "sigma_crit = 1e4\n"
      "[[bodies]]\nshape = \"box\"\nmin = [0.484375, 0, 0]\nmax = [0.515625, 0, 0]\n"
      "material = \"weak\"\n"
      "[[bodies]]\nshape = \"box\"\nmin = [0.25, 0, 0]\nmax = [0.484375, 0, 0]\n"
      "material = \"strong\"\nvelocity = [-0.05, 0, 0]\n"
      "[[bodies]]\nshape = \"box\"\nmin = [0.515625, 0, 0]\nmax = [0.75, 0, 0]\n"
      "material = \"strong\"\nvelocity = [0.05, 0, 0]\n";
  const Scene scene = testing::scene_from_toml(toml);
  State<1> s = build_state<1>(scene);
  Parameters params;
  auto st = make_stepper<1>("flip", "quadratic", params);
  for (int i = 0; i < 150; ++i) st->step(s, 2e-4);
  Real width = 0, d_max = 0;
  for (std::size_t p = 0; p < s.particles.size(); ++p) {
    const Real d = s.particles.state_of(p)[0];
    d_max = std::max(d_max, d);
    if (d >= 0.1) width += s.particles.V0[p];  // V0 = dx / ppc in 1D
  }
  EXPECT_GT(d_max, 0.5) << "the weak segment must break (l0 = " << l0_cells << " cells)";
  return width / dx;
}

TEST(DamageLength, DamageZoneWidensWithLengthScale) {
  const Real weak_cells = 2;
  const Real w0 = damage_zone_width(0), w1 = damage_zone_width(1), w2 = damage_zone_width(2),
             w4 = damage_zone_width(4);
  EXPECT_LE(w0, weak_cells + 1e-9) << "local damage stays where the stress is critical";
  EXPECT_LT(w0, w1);
  EXPECT_LT(w1, w2);
  EXPECT_LT(w2, w4);
  // The zone grows by a distance of order l0 (at least l0 in all).
  EXPECT_GE(w2 - w0, 2.0);
  EXPECT_GE(w4 - w0, 4.0);
  std::cout << "damage zone width in cells for l0 = 0, 1, 2, 4 cells: " << w0 << " " << w1 << " "
            << w2 << " " << w4 << "\n";
}

}  // namespace damage_length_test
}  // namespace mpmtb
