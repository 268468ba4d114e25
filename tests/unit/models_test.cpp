// Conformance of every registered constitutive model (REFERENCE.md, "Constitutive
// models"), in 1, 2 and 3 dimensions, through the interface the solver uses:
// P = dpsi/dF, tau = P F^T, rest state, rotations, objectivity, small-strain
// limit, the energy budget through the return map, and input checks. A new
// model joins by its registry line; the tables below list the documented
// exceptions and model-specific parameters.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <numeric>
#include <ostream>
#include <random>
#include <regex>
#include <set>
#include <span>
#include <string>
#include <vector>

#include "core/errors.hpp"
#include "core/particles.hpp"
#include "models/fixed_corotated.hpp"
#include "models/registry.hpp"
#include "support/finite_difference.hpp"
#include "support/random_matrices.hpp"

namespace mpmtb {
namespace models_test {

using testing::FiniteDifferenceP;
using testing::RandomF;
using testing::RandomMatrix;
using testing::RandomRotation;

constexpr Real kE = 250, kNu = 0.3, kRho = 7;
// Lame constants derived here, independently of the code under test.
constexpr Real kMu = kE / (2 * (1 + kNu));
constexpr Real kLambda = kE * kNu / ((1 + kNu) * (1 - 2 * kNu));

// Models that are not frame indifferent by design (documented in their headers).
const std::set<std::string> kNotFrameIndifferent = {"linear-elastic"};
// Parameters without a default that a model needs beyond E, nu, density.
const std::map<std::string, std::map<std::string, Real>> kRequired = {
    {"damage", {{"sigma_crit", 10}}}, {"aniso-damage", {{"sigma_crit", 10}}}};
// Values every model must reject (naming the key), then model-specific ones.
const std::vector<std::pair<std::string, Real>> kInvalidElastic = {
    {"E", 0},    {"E", -5},  {"E", std::nan("")}, {"nu", 0.5},
    {"nu", 0.7}, {"nu", -1}, {"density", 0},      {"density", -1}};
const std::map<std::string, std::vector<std::pair<std::string, Real>>> kInvalid = {
    {"snow", {{"theta_c", 0}, {"theta_c", -0.1}, {"theta_c", 1}, {"theta_s", 0}, {"xi", -1}}},
    {"sand",
     {{"friction_angle", 0},
      {"friction_angle", 90},
      {"friction_angle", -5},
      {"h1", -1},
      {"h2", 0},
      {"h3", 30},
      {"h3", -1},
      {"h1", 1000}}},
    {"damage", {{"sigma_crit", 0}, {"zeta", 0}, {"eta", 0}, {"k", 1}, {"k", -0.1}}},
    {"aniso-damage",
     {{"sigma_crit", 0},
      {"alpha", -1},
      {"fiber_E", -1},
      {"fiber_k", 1.5},
      {"fiber_k", -0.1},
      {"l0", -1},
      {"alpha_l", -1}}}};

std::map<std::string, Real> ValidParams(const std::string& model) {
  std::map<std::string, Real> v = {{"E", kE}, {"nu", kNu}, {"density", kRho}};
  if (auto it = kRequired.find(model); it != kRequired.end())
    v.insert(it->second.begin(), it->second.end());
  return v;
}

template <int Dim>
std::unique_ptr<ConstitutiveModel<Dim>> Make(const std::string& model) {
  Parameters p("materials.test", ValidParams(model));
  return make_model<Dim>(model, p);
}

// Particles of one material with the given F, V0 = 1 + p, initial state.
template <int Dim>
Particles<Dim> MakeParticles(const ConstitutiveModel<Dim>& m, const std::vector<Mat<Dim>>& Fs) {
  Particles<Dim> P;
  P.state_size = m.state_size();
  for (std::size_t p = 0; p < Fs.size(); ++p) {
    P.add(Vec<Dim>::Zero(), Vec<Dim>::Zero(), 1, Real(1 + p), 0);
    P.F[p] = Fs[p];
    if (P.state_size) m.initial_state(P.state_of(p));
  }
  return P;
}

std::vector<int> Ids(std::size_t n) {
  std::vector<int> ids(n);
  std::iota(ids.begin(), ids.end(), 0);
  return ids;
}

struct Case {
  std::string model;
  int dim;
};

void PrintTo(const Case& c, std::ostream* os) {
  *os << c.model << " in " << c.dim << "D";
}

std::vector<Case> AllCases() {
  std::vector<Case> cases;
  for (const auto& info : model_list())
    for (int dim = 1; dim <= 3; ++dim) cases.push_back({info.name, dim});
  return cases;
}

class ModelConformance : public ::testing::TestWithParam<Case> {
 protected:
  // Calls body(model) with the case's model built in the case's dimension
  // (body is a generic lambda taking const ConstitutiveModel<Dim>&).
  template <class Body>
  void ForDim(Body&& body) {
    const Case& c = GetParam();
    if (c.dim == 1) body(*Make<1>(c.model));
    if (c.dim == 2) body(*Make<2>(c.model));
    if (c.dim == 3) body(*Make<3>(c.model));
  }
  bool frame_indifferent() const { return !kNotFrameIndifferent.count(GetParam().model); }
  std::mt19937 gen_{1234};
};

TEST_P(ModelConformance, StressIsEnergyGradient) {
  ForDim([&]<int Dim>(const ConstitutiveModel<Dim>& m) {
    std::vector<Mat<Dim>> Fs;
    for (int s = 0; s < 20; ++s) Fs.push_back(RandomF<Dim>(gen_));
    // Fresh state, then the state after a return map from a larger deformation.
    Particles<Dim> P = MakeParticles(m, Fs);
    for (int pass = 0; pass < 2; ++pass) {
      for (std::size_t p = 0; p < Fs.size(); ++p) {
        const Mat<Dim> F = P.F[p], Pk = m.first_piola(F, P.state_of(p));
        const Mat<Dim> P_fd = FiniteDifferenceP(m, F, P.state_of(p));
        // The floor 1e-9 E covers the O(h^2) truncation error where P = 0 (a
        // plastic state projected to a stress-free one, e.g. sand's cone tip).
        EXPECT_LT((Pk - P_fd).norm(), 1e-6 * Pk.norm() + 1e-9 * kE) << "pass " << pass << " F =\n"
                                                                    << F;
      }
      for (auto& F : P.F) F = F * RandomF<Dim>(gen_, 0.2);
      m.return_map(P, Ids(P.size()), 1e-3);
    }
  });
}

TEST_P(ModelConformance, BatchesMatchPerParticleFormulas) {
  ForDim([&]<int Dim>(const ConstitutiveModel<Dim>& m) {
    std::vector<Mat<Dim>> Fs;
    for (int s = 0; s < 10; ++s) Fs.push_back(RandomF<Dim>(gen_));
    const Particles<Dim> P = MakeParticles(m, Fs);
    std::vector<Mat<Dim>> tauV(P.size());
    m.kirchhoff_times_volume(P, Ids(P.size()), tauV);
    Real energy = 0;
    for (std::size_t p = 0; p < P.size(); ++p) {
      const Mat<Dim> expected = P.V0[p] * m.first_piola(P.F[p], P.state_of(p)) * P.F[p].transpose();
      EXPECT_LT((tauV[p] - expected).norm(), 1e-12 * (expected.norm() + kE)) << "p = " << p;
      energy += P.V0[p] * m.energy_density(P.F[p], P.state_of(p));
    }
    EXPECT_NEAR(m.strain_energy(P, Ids(P.size())), energy, 1e-12 * (std::abs(energy) + kE));
    EXPECT_EQ(m.dissipated_energy(P, Ids(P.size())), 0.0)
        << "nothing dissipated before a return map";
  });
}

// P2G's runs (kirchhoff_times_volume_of: any particles in any order, a few at a
// time, core/solver_impl.hpp) give each particle the stress pass's bits: a
// particle's stress does not depend on the batch that computes it. States away
// from the initial one (a return map after a larger deformation).
TEST_P(ModelConformance, RunsGiveEachParticleThePassBits) {
  ForDim([&]<int Dim>(const ConstitutiveModel<Dim>& m) {
    std::vector<Mat<Dim>> Fs;
    for (int s = 0; s < 150; ++s) Fs.push_back(RandomF<Dim>(gen_, 0.3));
    Particles<Dim> P = MakeParticles(m, Fs);
    m.return_map(P, Ids(P.size()), 1e-3);
    std::vector<Mat<Dim>> tauV(P.size());
    m.kirchhoff_times_volume(P, Ids(P.size()), tauV);
    std::vector<int> order = Ids(P.size());
    std::shuffle(order.begin(), order.end(), gen_);
    // Runs of 1, of fewer and more than a batch of logarithms (64), and the rest.
    std::size_t first = 0;
    for (const std::size_t length :
         {std::size_t{1}, std::size_t{37}, std::size_t{100}, order.size()}) {
      const std::size_t count = std::min(length, order.size() - first);
      std::vector<Mat<Dim>> out(count, Mat<Dim>::Constant(std::nan("")));
      m.kirchhoff_times_volume_of(P, std::span<const int>(&order[first], count), out.data());
      for (std::size_t k = 0; k < count; ++k) {
        const int p = order[first + k];
        EXPECT_TRUE(out[k] == tauV[p]) << "particle " << p << " in a run of " << count << ":\n"
                                       << out[k] << "\npass:\n"
                                       << tauV[p];
      }
      first += count;
    }
    EXPECT_EQ(first, order.size());
  });
}

// Stresses and energies scale with E: "zero" means below 1e-12 E.
TEST_P(ModelConformance, RestStateIsStressFreeAndStaysPut) {
  ForDim([&]<int Dim>(const ConstitutiveModel<Dim>& m) {
    EXPECT_EQ(m.name(), GetParam().model);
    EXPECT_DOUBLE_EQ(m.density(), kRho);
    EXPECT_NEAR(m.wave_speed(), std::sqrt((kLambda + 2 * kMu) / kRho), 1e-12);
    EXPECT_EQ(static_cast<int>(m.state_names().size()), m.state_size());
    const Mat<Dim> I = Mat<Dim>::Identity();
    Particles<Dim> P = MakeParticles(m, {I, I});
    const Real* q = P.state_of(0);
    EXPECT_LT(std::abs(m.energy_density(I, q)), 1e-12 * kE);
    EXPECT_LT(m.first_piola(I, q).norm(), 1e-12 * kE);
    std::vector<Mat<Dim>> tauV(2);
    m.kirchhoff_times_volume(P, Ids(2), tauV);
    EXPECT_LT(tauV[1].norm(), 1e-12 * kE);
    m.return_map(P, Ids(2), 1e-3);
    EXPECT_EQ(P.F[0], I) << "the return map moved the rest state";
    EXPECT_EQ(m.dissipated_energy(P, Ids(2)), 0.0);
    // Guards against a model that returns zero everywhere.
    EXPECT_GT(m.first_piola(Real(1.1) * I, q).norm(), 1e-2 * kE);
    EXPECT_GT(m.energy_density(Real(1.1) * I, q), 1e-4 * kE);
  });
}

TEST_P(ModelConformance, RotationsAreStressFreeExceptForLinearElastic) {
  ForDim([&]<int Dim>(const ConstitutiveModel<Dim>& m) {
    const Particles<Dim> P = MakeParticles(m, {Mat<Dim>::Identity()});
    const Real* q = P.state_of(0);
    if (frame_indifferent()) {
      for (int s = 0; s < 10; ++s) {
        const Mat<Dim> R = RandomRotation<Dim>(gen_);
        EXPECT_LT(std::abs(m.energy_density(R, q)), 1e-12 * kE) << "R =\n" << R;
        EXPECT_LT(m.first_piola(R, q).norm(), 1e-12 * kE) << "R =\n" << R;
      }
    } else if constexpr (Dim >= 2) {
      // The documented exception: a quarter turn is far from stress-free
      // (eps = (R + R^T)/2 - I = -I in its plane).
      Mat<Dim> R = Mat<Dim>::Identity();
      R.template topLeftCorner<2, 2>() << 0, -1, 1, 0;
      EXPECT_GT(m.energy_density(R, q), 0.1 * kE);
      EXPECT_GT(m.first_piola(R, q).norm(), 0.1 * kE);
    }
  });
}

TEST_P(ModelConformance, FrameIndifference) {
  if (GetParam().dim == 1) GTEST_SKIP() << "the only rotation in 1D is the identity";
  if (!frame_indifferent()) GTEST_SKIP() << "documented exception (not frame indifferent)";
  ForDim([&]<int Dim>(const ConstitutiveModel<Dim>& m) {
    const Particles<Dim> P = MakeParticles(m, {Mat<Dim>::Identity()});
    const Real* q = P.state_of(0);
    for (int s = 0; s < 20; ++s) {
      const Mat<Dim> F = RandomF<Dim>(gen_), R = RandomRotation<Dim>(gen_);
      const Real psi = m.energy_density(F, q);
      EXPECT_NEAR(m.energy_density(R * F, q), psi, 1e-12 * (std::abs(psi) + kE));
      const Mat<Dim> RP = R * m.first_piola(F, q);  // P(R F) = R P(F)
      EXPECT_LT((m.first_piola(R * F, q) - RP).norm(), 1e-12 * (RP.norm() + kE));
    }
  });
}

// At F = I + eps H (H not symmetric), P = 2 mu e + lambda tr(e) I + O(eps^2), e = sym(eps H).
TEST_P(ModelConformance, SmallStrainLimitIsLinearElastic) {
  ForDim([&]<int Dim>(const ConstitutiveModel<Dim>& m) {
    const Particles<Dim> P = MakeParticles(m, {Mat<Dim>::Identity()});
    const Real eps = 1e-6;
    for (int s = 0; s < 10; ++s) {
      const Mat<Dim> H = eps * RandomMatrix<Dim>(gen_);
      const Mat<Dim> e = Real(0.5) * (H + H.transpose());
      const Mat<Dim> sigma = kLambda * e.trace() * Mat<Dim>::Identity() + 2 * kMu * e;
      const Mat<Dim> Pk = m.first_piola(Mat<Dim>::Identity() + H, P.state_of(0));
      EXPECT_LT((Pk - sigma).norm(), 1e-4 * sigma.norm()) << "P - sigma =\n" << Pk - sigma;
    }
  });
}

// The return map changes no velocity: what it takes from the strain energy must
// appear as dissipated energy, so kinetic + strain + gravity + dissipated is kept.
TEST_P(ModelConformance, ReturnMapKeepsTheEnergyBudget) {
  ForDim([&]<int Dim>(const ConstitutiveModel<Dim>& m) {
    std::vector<Mat<Dim>> Fs;
    for (int s = 0; s < 20; ++s) Fs.push_back(RandomF<Dim>(gen_, 0.6));
    Particles<Dim> P = MakeParticles(m, Fs);
    const auto ids = Ids(P.size());
    for (int pass = 0; pass < 3; ++pass) {
      const Real before = m.strain_energy(P, ids) + m.dissipated_energy(P, ids);
      m.return_map(P, ids, 1e-3);
      const Real after = m.strain_energy(P, ids) + m.dissipated_energy(P, ids);
      EXPECT_NEAR(after, before, 1e-12 * (std::abs(before) + kE)) << "pass " << pass;
      for (auto& F : P.F) F = F * RandomF<Dim>(gen_, 0.2);
    }
  });
}

void ExpectRejected(const std::string& model, std::map<std::string, Real> values,
                    const std::string& key) {
  SCOPED_TRACE(model + ": expected rejection naming '" + key + "'");
  Parameters p("materials.test", std::move(values));
  try {
    make_model<2>(model, p);
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_TRUE(std::regex_search(e.what(), std::regex("\\b" + key + "\\b")))
        << "message: " << e.what();
  }
}

// Out-of-range, missing and unknown parameters (independent of the dimension).
TEST(ModelParameters, InvalidParametersAreRejectedByName) {
  for (const auto& info : model_list()) {
    const std::string& model = info.name;
    auto with = [&](const std::string& key, Real value) {
      auto v = ValidParams(model);
      v[key] = value;
      return v;
    };
    for (const auto& [key, value] : kInvalidElastic) ExpectRejected(model, with(key, value), key);
    if (auto it = kInvalid.find(model); it != kInvalid.end()) {
      for (const auto& [key, value] : it->second) ExpectRejected(model, with(key, value), key);
    }
    for (const auto& [key, value] : ValidParams(model)) {
      auto missing = ValidParams(model);
      missing.erase(key);
      ExpectRejected(model, missing, key);
    }
    ExpectRejected(model, with("youngs_modulus", 3), "youngs_modulus");
  }
}

std::string CaseName(const ::testing::TestParamInfo<Case>& info) {
  std::string name = info.param.model;
  std::replace(name.begin(), name.end(), '-', '_');
  return name + "_" + std::to_string(info.param.dim) + "d";
}

INSTANTIATE_TEST_SUITE_P(Registered, ModelConformance, ::testing::ValuesIn(AllCases()), CaseName);

// The tables above name registered models only (a renamed model would skip its checks).
TEST(ModelRegistry, ExceptionTablesNameRegisteredModels) {
  std::set<std::string> names;
  for (const auto& info : model_list()) names.insert(info.name);
  for (const auto& name : kNotFrameIndifferent) EXPECT_TRUE(names.count(name)) << name;
  for (const auto& [name, v] : kRequired) EXPECT_TRUE(names.count(name)) << name;
  for (const auto& [name, v] : kInvalid) EXPECT_TRUE(names.count(name)) << name;
  for (const char* name : {"neo-hookean", "linear-elastic", "fixed-corotated", "snow"})
    EXPECT_TRUE(names.count(name)) << name << " is not registered";
}

// Fixed-corotated is invertible: finite energy and stress, P = dpsi/dF, for J <= 0.
TEST(FixedCorotatedModel, DefinedForInvertedAndDegenerateF) {
  Parameters params("materials.test", ValidParams("fixed-corotated"));
  const FixedCorotated<3> m(params);
  std::mt19937 gen(99);
  Mat<3> reflect = Mat<3>::Identity();
  reflect(2, 2) = -1;
  for (int s = 0; s < 20; ++s) {
    const Mat<3> F = RandomF<3>(gen) * reflect;  // det F < 0
    const Mat<3> Pk = m.P(F, nullptr), P_fd = FiniteDifferenceP<3>(m, F, nullptr);
    EXPECT_LT((Pk - P_fd).norm(), 1e-6 * Pk.norm()) << "F =\n" << F;
    EXPECT_LT((m.tau(F, nullptr) - Pk * F.transpose()).norm(), 1e-12 * (Pk.norm() + kE));
  }
  // A flattened element (J = 0) pushes back towards positive volume: P : cof(F) < 0.
  const Mat<3> flat = Vec<3>(1, 1, 0).asDiagonal();
  const Mat<3> P0 = m.P(flat, nullptr);
  EXPECT_TRUE(P0.allFinite());
  EXPECT_LT((P0.array() * cofactor<3>(flat).array()).sum(), 0);
}

// psi's two forms (fixed_corotated.hpp): mu |F - R|^2 + lambda/2 (J - 1)^2 with
// R from the polar decomposition, and mu sum (sigma_i - 1)^2 + lambda/2
// (prod sigma_i - 1)^2 from the signed singular values (the snow return map's).
// They agree to round-off, for inverted F too (sigma_d < 0).
template <int Dim>
void ExpectPsiFormsAgree() {
  std::mt19937 gen(7 + Dim);
  const Real mu = 40, lambda = 60;
  Mat<Dim> reflect = Mat<Dim>::Identity();
  reflect(Dim - 1, Dim - 1) = -1;
  for (int s = 0; s < 40; ++s) {
    const Mat<Dim> F = s % 2 ? Mat<Dim>(RandomF<Dim>(gen, 0.5) * reflect) : RandomF<Dim>(gen, 0.5);
    const Real by_polar = fixed_corotated_psi<Dim>(F, mu, lambda);
    const Real by_sigma = fixed_corotated_psi_of_sigma<Dim>(signed_svd<Dim>(F).sigma, mu, lambda);
    EXPECT_NEAR(by_sigma, by_polar, 1e-12 * (1 + std::abs(by_polar))) << "F =\n" << F;
  }
}
TEST(FixedCorotatedModel, EnergyOfSingularValuesIsTheEnergyOfF) {
  ExpectPsiFormsAgree<2>();
  ExpectPsiFormsAgree<3>();
}

}  // namespace models_test
}  // namespace mpmtb
