// The implicit integrators' derivatives and input handling
// (integrators/implicit_impl.hpp):
// * every model's first_piola_differential dP = (dP/dF) : dF against central
//   differences of P at random F (as P is checked against psi);
// * the incremental potential's gradient against central differences of E,
//   and its Hessian-vector product against central differences of the
//   gradient, at random grid velocities, for every model (the plastic and
//   damage models at their current state: their elastic part; aniso-damage
//   with a fibre family), in 1D, 2D, 3D;
// * refused transfers and orders, unknown names;
// * pinned nodes stay at rest in the solve at a large step.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <random>
#include <string>

#include "core/errors.hpp"
#include "core/registry.hpp"
#include "models/registry.hpp"
#include "references/reference.hpp"
#include "setup.hpp"
#include "support/pinned.hpp"
#include "support/random_matrices.hpp"
#include "support/scenes.hpp"

namespace mpmtb {
namespace implicit_test {

using testing::RandomF;
using testing::RandomMatrix;

std::map<std::string, Real> Params(const std::string& model) {
  std::map<std::string, Real> v = {{"E", 1000}, {"nu", 0.3}, {"density", 10}};
  if (model == "damage" || model == "aniso-damage") v["sigma_crit"] = 10;
  // Stiff fibres, so that their stress and its derivative count in the checks.
  if (model == "aniso-damage") v["fiber_E"] = 2000, v["alpha"] = 2;
  return v;
}

template <int Dim>
void CheckModelDifferential() {
  std::mt19937 gen(7 + Dim);
  for (const auto& info : model_list()) {
    Parameters params("materials.test", Params(info.name));
    const auto model = make_model<Dim>(info.name, params);
    std::vector<Real> q(std::max(1, model->state_size()), 0);
    model->initial_state(q.data());
    // The damage models also at a damaged state (P degraded in tension only).
    const auto names = model->state_names();
    const auto damage = std::find(names.begin(), names.end(), "damage");
    for (int trial = 0; trial < 20; ++trial) {
      if (damage != names.end()) q[damage - names.begin()] = trial % 2 ? 0.6 : 0;
      // Trials 0 and 2: repeated singular values (the isotropic models' 0/0
      // limits), all equal and (3D) two of three.
      Mat<Dim> F = RandomF<Dim>(gen, 0.3, 0.3);
      if (trial == 0 || trial == 2) F = Real(1.1) * Mat<Dim>::Identity();
      if (trial == 2) F(Dim - 1, Dim - 1) = 0.95;
      const Mat<Dim> dF = RandomMatrix<Dim>(gen);
      const Real h = 1e-6;
      const Mat<Dim> fd =
          (model->first_piola(F + h * dF, q.data()) - model->first_piola(F - h * dF, q.data())) /
          (2 * h);
      const Mat<Dim> dP = model->first_piola_differential(F, dF, q.data());
      EXPECT_LE((dP - fd).norm(), 1e-6 * (1 + fd.norm()))
          << info.name << " " << Dim << "D trial " << trial << "\nF =\n"
          << F << "\ndP =\n"
          << dP << "\nfd =\n"
          << fd;
    }
  }
}

TEST(ImplicitModels, FirstPiolaDifferentialMatchesFiniteDifferences1D) {
  CheckModelDifferential<1>();
}
TEST(ImplicitModels, FirstPiolaDifferentialMatchesFiniteDifferences2D) {
  CheckModelDifferential<2>();
}
TEST(ImplicitModels, FirstPiolaDifferentialMatchesFiniteDifferences3D) {
  CheckModelDifferential<3>();
}

// A deformed, moving body next to a sticky and a slip wall, one pinned
// particle layer, so that the walls' ghosts, the masks and the pins all enter.
std::string SceneText(int dim, const std::string& model, const std::string& kernel,
                      const std::string& transfer) {
  std::string extra = Params(model).count("sigma_crit") ? "sigma_crit = 10.0\n" : "";
  if (model == "aniso-damage") extra += "fiber_E = 2000.0\nalpha = 2.0\n";
  return "[scene]\nname = \"implicit\"\ndim = " + std::to_string(dim) +
         "\ndims = [1, 2, 3]\n"
         "[domain]\nmin = [0.0, 0.0, 0.0]\nmax = [1.0, 1.0, 1.0]\n"
         "[grid]\ncells = 8\nppc = 2\n"
         "[method]\ntransfer = \"" +
         transfer + "\"\nkernel = \"" + kernel +
         "\"\n"
         "[time]\nt_end = 0.01\ndt = 1e-3\n"
         "[physics]\ngravity = [0.0, -9.81, 0.0]\n"
         "[boundary]\nx_min = \"sticky\"\ny_min = \"slip\"\n"
         "[materials.jelly]\nmodel = \"" +
         model + "\"\nE = 1000.0\nnu = 0.3\ndensity = 10.0\n" + extra +
         "[[bodies]]\nshape = \"box\"\nmin = [0.0, 0.0, 0.0]\nmax = [0.5, 0.5, 0.5]\n"
         "material = \"jelly\"\nvelocity = [0.3, -0.2, 0.1]\n" +
         (model != "aniso-damage" ? ""
          : dim == 1              ? "fiber = [1.0, 0.0, 0.0]\n"
          : dim == 2              ? "fiber = [1.0, 2.0, 0.0]\n"
                                  : "fiber = [1.0, 2.0, 0.5]\n") +
         "[[pins]]\nmin = [0.4, 0.4, 0.4]\nmax = [0.5, 0.5, 0.5]\n";
}

using V = std::vector<Real>;

template <int Dim>
void CheckObjective(const std::string& model, const std::string& kernel, Integrator integrator) {
  // The transfer only fills the grid the solve starts from (P2G, C_p = 0): APIC,
  // or FLIP (gradient-based, compiled with every kernel) where a reduced build
  // (MPMTB_COMBINATIONS=reduced) does not compile APIC with the kernel.
  const std::string transfer = compiled_combination("apic", kernel) ? "apic" : "flip";
  const Scene scene = testing::scene_from_toml(SceneText(Dim, model, kernel, transfer));
  State<Dim> s = build_state<Dim>(scene);
  std::mt19937 gen(3);
  std::uniform_real_distribution<Real> uni(-1, 1);
  for (std::size_t p = 0; p < s.particles.size(); ++p) {
    s.particles.F[p] = RandomF<Dim>(gen, 0.1, 0.5);
  }
  Parameters params = scene.transfer_params;
  auto stepper = make_stepper<Dim>(scene.transfer, scene.kernel, params);
  stepper->set_integrator(integrator);
  auto solve = make_implicit_solve<Dim>(scene.kernel, integrator, {});
  const Real dt = 2e-2;  // CFL ~ 2: the elastic part dominates the Hessian
  solve->setup(*stepper, s, dt);
  const std::vector<long>& nodes = solve->active_nodes();
  using Field = std::vector<Vec<Dim>>;
  Field u = solve->start(), d(u.size(), Vec<Dim>::Zero());
  for (const long i : nodes) {
    for (int a = 0; a < Dim; ++a) {
      u[i][a] += 0.2 * uni(gen);
      d[i][a] = uni(gen);
    }
  }
  Field g, gp, gm, Hd;
  solve->gradient(u, g);
  // The gradient is zero on the constrained components; its projection on d
  // against the central difference of E (the constrained parts of d do not
  // change E either).
  const Real h = 1e-6;
  auto shifted = [&](Real t) {
    Field w = u;
    for (const long i : nodes) w[i] += t * d[i];
    return w;
  };
  const Real dE = (solve->energy(shifted(h)) - solve->energy(shifted(-h))) / (2 * h);
  Real gd = 0, gnorm = 0;
  for (const long i : nodes) gd += g[i].dot(d[i]), gnorm += g[i].squaredNorm();
  EXPECT_NEAR(gd, dE, 1e-6 * (std::abs(dE) + std::sqrt(gnorm)))
      << model << " " << Dim << "D " << kernel;
  solve->gradient(shifted(h), gp);
  solve->gradient(shifted(-h), gm);
  solve->hessian_times(u, d, Hd, false);
  Real err = 0, norm = 0;
  for (const long i : nodes) {
    const Vec<Dim> fd = (gp[i] - gm[i]) / (2 * h);
    err += (Hd[i] - fd).squaredNorm();
    norm += fd.squaredNorm();
  }
  EXPECT_GT(norm, 0);
  EXPECT_LE(std::sqrt(err), 1e-5 * std::sqrt(norm)) << model << " " << Dim << "D " << kernel;
  // The projected product is symmetric positive semi-definite: d . H d >= 0.
  solve->hessian_times(u, d, Hd, true);
  Real dHd = 0;
  for (const long i : nodes) dHd += d[i].dot(Hd[i]);
  EXPECT_GE(dHd, 0);
}

TEST(ImplicitObjective, HessianVectorProductMatchesFiniteDifferencesOfTheGradient) {
  for (const auto& info : model_list()) {
    for (Integrator i : {Integrator::backward_euler, Integrator::newmark}) {
      CheckObjective<1>(info.name, "quadratic", i);
      CheckObjective<2>(info.name, "quadratic", i);
    }
  }
}

TEST(ImplicitObjective, HessianVectorProductEveryKernel3D) {
  for (const std::string kernel : {"linear", "quadratic", "cubic", "gimp"}) {
    CheckObjective<3>("neo-hookean", kernel, Integrator::backward_euler);
    CheckObjective<3>("fixed-corotated", kernel, Integrator::newmark);
  }
}

TEST(ImplicitInput, UnknownIntegratorNamesTheFieldAndTheAllowedValues) {
  try {
    parse_integrator("crank-nicolson");
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("method.integrator"), std::string::npos) << what;
    EXPECT_NE(what.find("crank-nicolson"), std::string::npos) << what;
    EXPECT_NE(what.find("explicit, backward-euler, newmark"), std::string::npos) << what;
  }
  EXPECT_THROW(testing::scene_from_toml(testing::free_body_toml(2, "pic", "quadratic"),
                                        {.integrator = "rk4"}),
               InputError);
}

TEST(ImplicitInput, NonGradientTransfersAndOtherOrdersAreRefused) {
  for (const std::string transfer : {"mls", "xpic"}) {
    Parameters params(transfer);
    auto stepper = make_stepper<2>(transfer, "quadratic", params);
    try {
      stepper->set_integrator(Integrator::backward_euler);
      FAIL() << transfer << " accepted";
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("method.integrator"), std::string::npos) << what;
      EXPECT_NE(what.find("allowed: pic, flip, apic"), std::string::npos) << what;
    }
    EXPECT_EQ(stepper->integrator(), Integrator::explicit_euler);  // left as it was
    EXPECT_EQ(stepper->implicit_stats(), nullptr);
    EXPECT_NO_THROW(stepper->set_integrator(Integrator::explicit_euler));
  }
  Parameters params("apic");
  auto stepper = make_stepper<2>("apic", "quadratic", params);
  stepper->set_update_order(UpdateOrder::usf);
  EXPECT_THROW(stepper->set_integrator(Integrator::newmark), InputError);
}

// A hanging block pinned along its top at CFL ~ 6: the pinned particles'
// nodes are held exactly, the rest falls and swings, and the pins' reaction
// closes the momentum balance: p(t) = p(0) + M g t + pin impulse.
TEST(ImplicitPins, PinnedNodesHoldAtLargeSteps) {
  const std::string text =
      "[scene]\nname = \"hang\"\ndim = 2\n"
      "[domain]\nmin = [0.0, 0.0, 0.0]\nmax = [1.0, 1.0, 1.0]\n"
      "[grid]\ncells = 16\nppc = 2\n"
      "[method]\ntransfer = \"apic\"\nkernel = \"quadratic\"\n"
      "[time]\nt_end = 0.5\ndt = 0.01\n"
      "[physics]\ngravity = [0.0, -9.81, 0.0]\n"
      "[materials.jelly]\nmodel = \"neo-hookean\"\nE = 1e4\nnu = 0.3\ndensity = 10.0\n"
      "[[bodies]]\nshape = \"box\"\nmin = [0.25, 0.25, 0.0]\nmax = [0.75, 0.75, 1.0]\n"
      "material = \"jelly\"\n"
      "[[pins]]\nmin = [0.0, 0.7, 0.0]\nmax = [1.0, 1.0, 1.0]\n";
  for (Integrator integrator : {Integrator::backward_euler, Integrator::newmark}) {
    const Scene scene = testing::scene_from_toml(text);
    State<2> s = build_state<2>(scene);
    Parameters params = scene.transfer_params;
    auto stepper = make_stepper<2>(scene.transfer, scene.kernel, params);
    stepper->set_integrator(integrator);
    const Real c = s.max_wave_speed(), dt = 0.01;
    EXPECT_GT(dt * c / s.grid.geo.dx, 5);  // far beyond the explicit limit
    const std::vector<Vec<2>> x0 = testing::pinned_positions(s.particles);
    ASSERT_FALSE(x0.empty());
    const Diagnostics d0 = measure(s, *stepper);
    for (int n = 0; n < 50; ++n) {
      const StepReport r = stepper->step(s, dt);
      ASSERT_LT(r.non_finite, 0);
      ASSERT_TRUE(stepper->implicit_stats()->converged) << "step " << n;
    }
    EXPECT_EQ(testing::largest_pinned_displacement(s.particles, x0), 0)
        << integrator_name(integrator);
    const Diagnostics d = measure(s, *stepper);
    const Vec3 expected = d0.momentum + d0.mass * s.time * Vec3(0, -9.81, 0) + s.pin_impulse;
    const Real scale = d0.mass * 9.81 * s.time;
    EXPECT_LE((d.momentum - expected).norm(), 1e-6 * scale)
        << integrator_name(integrator) << ": p = " << d.momentum.transpose() << ", expected "
        << expected.transpose();
  }
}

}  // namespace implicit_test
}  // namespace mpmtb
