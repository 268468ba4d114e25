// ModelBase's own paths for a model that writes out less than the built-in ones:
// a St. Venant-Kirchhoff model with psi, P and tau but no dP gets the central
// difference of P as its first_piola_differential (the implicit integrators'
// Hessian), which must match the exact differential of P, and its stresses
// through the batch loop (no tau_given_log) must be V0 P F^T.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "core/lanes.hpp"
#include "core/particles.hpp"
#include "core/state.hpp"
#include "models/model.hpp"
#include "models/registry.hpp"
#include "support/random_matrices.hpp"

namespace mpmtb {
namespace model_base_test {

// St. Venant-Kirchhoff (Bonet & Wood 2008, sec. 6.4.1): E = (F^T F - I)/2,
//   S = lambda tr(E) I + 2 mu E,  P = F S,  psi = lambda/2 tr(E)^2 + mu E : E.
template <int Dim>
class StVenantKirchhoff final : public ModelBase<Dim, StVenantKirchhoff<Dim>> {
 public:
  static constexpr Real mu = 3, lambda = 5;
  std::string_view name() const override { return "st-venant-kirchhoff (test)"; }
  Real density() const override { return 1; }
  Real wave_speed() const override { return std::sqrt(lambda + 2 * mu); }

  static Mat<Dim> green(const Mat<Dim>& F) {
    return Real(0.5) * (F.transpose() * F - Mat<Dim>::Identity());
  }
  Real psi(const Mat<Dim>& F, const Real*) const {
    const Mat<Dim> E = green(F);
    return Real(0.5) * lambda * E.trace() * E.trace() + mu * E.cwiseProduct(E).sum();
  }
  Mat<Dim> P(const Mat<Dim>& F, const Real*) const {
    const Mat<Dim> E = green(F);
    return F * (lambda * E.trace() * Mat<Dim>::Identity() + 2 * mu * E);
  }
  Mat<Dim> tau(const Mat<Dim>& F, const Real* q) const { return P(F, q) * F.transpose(); }
  // No dP: ModelBase differentiates P numerically.
};

// The exact differential: dP = dF S + F dS, dS = lambda tr(dE) I + 2 mu dE,
// dE = (dF^T F + F^T dF) / 2.
template <int Dim>
Mat<Dim> exact_dP(const Mat<Dim>& F, const Mat<Dim>& dF) {
  using Model = StVenantKirchhoff<Dim>;
  const Mat<Dim> E = Model::green(F), I = Mat<Dim>::Identity();
  const Mat<Dim> dE = Real(0.5) * (dF.transpose() * F + F.transpose() * dF);
  const Mat<Dim> S = Model::lambda * E.trace() * I + 2 * Model::mu * E;
  const Mat<Dim> dS = Model::lambda * dE.trace() * I + 2 * Model::mu * dE;
  return dF * S + F * dS;
}

template <int Dim>
void expect_fallback_matches_exact_differential() {
  const StVenantKirchhoff<Dim> model;
  std::mt19937 gen(11 + Dim);
  for (int trial = 0; trial < 50; ++trial) {
    const Mat<Dim> F = Mat<Dim>::Identity() + Real(0.4) * testing::RandomMatrix<Dim>(gen);
    const Mat<Dim> dF = testing::RandomMatrix<Dim>(gen);
    const Mat<Dim> exact = exact_dP<Dim>(F, dF);
    const Mat<Dim> fallback = model.first_piola_differential(F, dF, nullptr);
    // A central difference with h = 1e-6 relative: O(h^2) truncation and
    // round-off of eps / h, about 1e-10 of |dP|.
    EXPECT_LE((fallback - exact).norm(), 1e-8 * exact.norm()) << "trial " << trial;
  }
  EXPECT_EQ(model.first_piola_differential(Mat<Dim>::Identity(), Mat<Dim>::Zero(), nullptr),
            Mat<Dim>::Zero());
}

TEST(ModelBase, FiniteDifferenceDifferentialOfAModelWithoutDP2D) {
  expect_fallback_matches_exact_differential<2>();
}
TEST(ModelBase, FiniteDifferenceDifferentialOfAModelWithoutDP3D) {
  expect_fallback_matches_exact_differential<3>();
}

TEST(ModelBase, StressPassOfAModelWithoutLogIsV0PFTransposed) {
  const StVenantKirchhoff<3> model;
  std::mt19937 gen(5);
  Particles<3> P;
  std::vector<int> ids;
  for (int p = 0; p < 100; ++p) {
    P.add(Vec<3>::Zero(), Vec<3>::Zero(), 1, Real(1) + p, 0);
    P.F[p] += Real(0.3) * testing::RandomMatrix<3>(gen);
    ids.push_back(p);
  }
  std::vector<Mat<3>> tauV(P.size());
  model.kirchhoff_times_volume(P, ids, tauV);
  for (int p = 0; p < 100; ++p) {
    const Mat<3> expected = P.V0[p] * model.first_piola(P.F[p], nullptr) * P.F[p].transpose();
    EXPECT_LE((tauV[p] - expected).norm(), 1e-13 * expected.norm()) << "particle " << p;
  }
}

// A run of P2G across materials (State::kirchhoff_times_volume_of): each
// particle gets its own material's stress, the bits of that material's pass,
// in the run's order. Three materials, the particles' materials mixed along the
// run (and one material absent from it).
TEST(ModelBase, RunAcrossMaterialsGivesEachParticleItsMaterialsStress) {
  State<3> s;
  const auto add_model = [&](const std::string& name, std::map<std::string, Real> values) {
    Parameters p("materials." + name, values);
    s.materials.push_back(make_model<3>(name, p));
  };
  add_model("neo-hookean", {{"E", 1e4}, {"nu", 0.3}, {"density", 1}});
  add_model("damage", {{"E", 2e4}, {"nu", 0.25}, {"density", 2}, {"sigma_crit", 50}});
  add_model("fixed-corotated", {{"E", 3e4}, {"nu", 0.2}, {"density", 3}});
  add_model("linear-elastic", {{"E", 5e3}, {"nu", 0.3}, {"density", 1}});
  std::mt19937 gen(11);
  const int n = 90;
  for (const auto& m : s.materials)
    s.particles.state_size = std::max(s.particles.state_size, m->state_size());
  for (int p = 0; p < n; ++p) {
    const int material = p % 7 < 3 ? 0 : (p % 7 < 5 ? 1 : 2);  // never the fourth
    s.particles.add(Vec<3>::Zero(), Vec<3>::Zero(), 1, Real(1) + p, material);
    s.particles.F[p] = testing::RandomF<3>(gen);
    s.materials[material]->initial_state(s.particles.state_of(p));
  }
  s.index_materials();
  std::vector<Mat<3>> pass(n);
  for (std::size_t m = 0; m < s.materials.size(); ++m)
    s.materials[m]->kirchhoff_times_volume(s.particles, s.material_particles[m], pass);
  std::vector<int> run(n);
  for (int k = 0; k < n; ++k) run[k] = (k * 37) % n;  // a permutation: 37 and 90 coprime
  std::vector<Mat<3>> out(n, Mat<3>::Constant(std::nan("")));
  s.kirchhoff_times_volume_of(run, out.data());
  for (int k = 0; k < n; ++k) {
    EXPECT_TRUE(out[k] == pass[run[k]])
        << "particle " << run[k] << " (material " << s.particles.material[run[k]] << ")";
  }
  // Another material's stress differs (the test tells the materials apart).
  for (const int p : {3, 5}) {
    Mat<3> other;
    s.materials[0]->kirchhoff_times_volume_of(s.particles, std::span<const int>(&p, 1), &other);
    EXPECT_FALSE(other == pass[p]) << "particle " << p;
  }
}

// The stress batches' determinant over a register of particles
// (core/lanes.hpp) is each particle's F.determinant(), bit for bit: their
// logarithms are those of the per-particle formulas.
template <int Dim>
void expect_lane_determinants_are_eigens() {
  std::mt19937 gen(Dim);
  std::vector<Mat<Dim>> F(kLanes + 3);
  std::vector<int> ids(F.size());
  for (std::size_t p = 0; p < F.size(); ++p) {
    F[p] = testing::RandomF<Dim>(gen, Real(0.5));
    ids[p] = static_cast<int>(F.size() - 1 - p);
  }
  Lanes packs[Dim][Dim];
  load_lanes<Dim>(F, ids.data(), kLanes - 1, packs);  // the last lane: the identity
  const Lanes det = determinant_of<Dim>(packs);
  for (int l = 0; l < kLanes - 1; ++l) EXPECT_EQ(det[l], F[ids[l]].determinant()) << "lane " << l;
  EXPECT_EQ(det[kLanes - 1], Real(1));
}

TEST(ModelBase, LaneDeterminantsAreEigens) {
  expect_lane_determinants_are_eigens<1>();
  expect_lane_determinants_are_eigens<2>();
  expect_lane_determinants_are_eigens<3>();
}

// Matrices and vectors into registers and back (core/lanes.hpp), whole
// registers (3D: rows of 8 Reals and transposes) and partly filled ones (lane
// by lane): lane l holds particle ids[l]'s values, and the store returns them.
template <int Dim>
void expect_lanes_hold_each_particle() {
  std::mt19937 gen(10 + Dim);
  std::uniform_real_distribution<Real> value(-1, 1);
  std::vector<Mat<Dim>> F(3 * kLanes);
  std::vector<Vec<Dim>> v(F.size());
  std::vector<int> ids(F.size());
  for (std::size_t p = 0; p < F.size(); ++p) {
    F[p] = testing::RandomF<Dim>(gen, Real(0.5));
    for (int a = 0; a < Dim; ++a) v[p][a] = value(gen);
    ids[p] = static_cast<int>((7 * p + 3) % F.size());  // out of order
  }
  for (const int lanes : {kLanes, kLanes - 1}) {
    Lanes packs[Dim][Dim];
    load_lanes<Dim>(F, ids.data(), lanes, packs);
    for (int l = 0; l < kLanes; ++l) {
      for (int i = 0; i < Dim; ++i) {
        for (int j = 0; j < Dim; ++j) {
          const Real expected = l < lanes ? F[ids[l]](i, j) : Real(i == j);
          EXPECT_EQ(packs[i][j][l], expected) << lanes << " lanes, lane " << l;
        }
      }
    }
    std::vector<Mat<Dim>> back(kLanes, Mat<Dim>::Constant(-7));
    store_lanes<Dim>(packs, lanes, [&](int l) -> Mat<Dim>& { return back[l]; });
    for (int l = 0; l < kLanes; ++l) {
      EXPECT_EQ(back[l], l < lanes ? F[ids[l]] : Mat<Dim>::Constant(-7)) << "lane " << l;
    }
  }
  Lanes components[Dim];
  load_vector_lanes<Dim>(&v[5], components);
  for (int l = 0; l < kLanes; ++l) {
    for (int a = 0; a < Dim; ++a) EXPECT_EQ(components[a][l], v[5 + l][a]) << "lane " << l;
  }
}

TEST(ModelBase, LanesHoldEachParticlesValues) {
  expect_lanes_hold_each_particle<1>();
  expect_lanes_hold_each_particle<2>();
  expect_lanes_hold_each_particle<3>();
}

// A model's state records into registers by transposes (load_record_lanes,
// where the register is whole multiples of 8 lanes): lane l of entry e holds
// record ids[l]'s value e, for records longer than the 4 it reads and ids out
// of order, the last record at the very end of its array.
TEST(ModelBase, RecordLanesHoldEachParticlesRecord) {
  if constexpr (!kRecordTransposes) {
    GTEST_SKIP() << "no record transposes for " << kLanes << " lanes";
  } else {
    constexpr long kStride = 5;
    const int n = 3 * kLanes;
    std::vector<Real> records((n - 1) * kStride + 4);  // the last record: 4 Reals
    for (std::size_t i = 0; i < records.size(); ++i) records[i] = Real(0.5) + Real(i);
    std::vector<int> ids(kLanes);
    for (int l = 0; l < kLanes; ++l) ids[l] = (7 * l + (l == 0 ? n - 1 : 3)) % n;
    ASSERT_EQ(ids[0], n - 1);
    Lanes entries[4];
    load_record_lanes(records.data(), kStride, ids.data(), entries);
    for (int l = 0; l < kLanes; ++l) {
      for (int e = 0; e < 4; ++e) {
        EXPECT_EQ(entries[e][l], records[ids[l] * kStride + e]) << "lane " << l << ", entry " << e;
      }
    }
  }
}

}  // namespace model_base_test
}  // namespace mpmtb
