// PolyPIC (Fu, Guo, Gast, Jiang & Teran 2017): its per-particle modes, the
// exactness of the round trip for fields in their span, and the energy it keeps.
// Conservation of mass, momentum and angular momentum: the conformance tests
// (transfer_test.cpp), which it joins through the registry.
#include <gtest/gtest.h>

#include <array>
#include <cstring>
#include <fstream>
#include <random>
#include <sstream>
#include <vector>

#include "core/diagnostics.hpp"
#include "kernels/all.hpp"
#include "run.hpp"
#include "setup.hpp"
#include "support/cli.hpp"
#include "support/combinations.hpp"
#include "support/scenes.hpp"
#include "transfers/polypic.hpp"

namespace mpmtb {
namespace polypic_test {

// The 1D modes of a stencil: e_0 = 1, e_1 = u (B-splines have zero first
// moment), orthogonal under the weights; the norms are the weighted sums.
template <class Kernel>
void check_modes(Real x, Real dx) {
  const GridGeometry<1> geo(Vec<1>::Zero(), dx, {8});
  const Stencil<1, Kernel> st(Vec<1>(x), geo);
  PolyModes<1, Kernel::support> modes;
  modes.build(st, dx);
  constexpr int S = Kernel::support;
  for (int k = 0; k < S; ++k) {
    EXPECT_EQ(modes.e(0, 0, k), 1);
    EXPECT_NEAR(modes.e(0, 1, k), st.d(0, k) / dx, 1e-14);
  }
  for (int n = 0; n < S; ++n) {
    if (modes.norm(0, n) == 0) continue;
    Real nn = 0;
    for (int k = 0; k < S; ++k) nn += st.w(0, k) * modes.e(0, n, k) * modes.e(0, n, k);
    EXPECT_NEAR(modes.norm(0, n), nn, 1e-14);
    for (int m = 0; m < n; ++m) {
      Real dot = 0;
      for (int k = 0; k < S; ++k) dot += st.w(0, k) * modes.e(0, n, k) * modes.e(0, m, k);
      EXPECT_LE(std::abs(dot), 1e-15) << Kernel::name << " modes " << n << ", " << m;
    }
  }
}

TEST(PolypicModes, OrthogonalUnderTheWeights) {
  for (const Real x : {2.3, 2.61, 3.05, 4.999}) {
    check_modes<LinearKernel>(x * 0.1, 0.1);
    check_modes<QuadraticKernel>(x * 0.1, 0.1);
    check_modes<CubicKernel>(x * 0.1, 0.1);
  }
}

// Three nodes per axis (quadratic B-spline, uGIMP): the closed-form modes
// (PolyModes::build_three) are Gram-Schmidt's to round-off (the quadratic mode
// is unique up to its scale on three nodes), drop where it drops (a particle
// half-way between nodes), and stay orthonormal under the weights where an end
// weight is tiny (an offset of 1e-6 to 1e-14 cells from half-way), where
// Gram-Schmidt's cancellation is worst.
template <class Kernel>
void check_closed_form_modes() {
  constexpr int S = Kernel::support;
  static_assert(S == 3);
  const Real dx = 0.1;
  const GridGeometry<1> geo(Vec<1>::Zero(), dx, {16});
  std::vector<Real> xs = {0.35, 0.3, 0.45 - 1e-9, 0.35 + 1e-7};
  std::mt19937 gen(23);
  std::uniform_real_distribution<Real> inside(0.3, 0.4);
  for (int i = 0; i < 200; ++i) xs.push_back(inside(gen));
  for (const Real tiny : {1e-6, 1e-10, 1e-14}) {
    xs.push_back(0.35 + tiny * dx), xs.push_back(0.35 - tiny * dx);
  }
  int dropped = 0, kept = 0;
  for (const Real x : xs) {
    const Stencil<1, Kernel> st(Vec<1>(x), geo);
    PolyModes<1, S> closed, gs;
    closed.build(st, dx);
    gs.build_by_gram_schmidt(st.wk, st.dk, dx);
    for (int n = 0; n < S; ++n) {
      EXPECT_EQ(closed.norm(0, n) == 0, gs.norm(0, n) == 0) << "x " << x << ", mode " << n;
      EXPECT_NEAR(closed.norm(0, n), gs.norm(0, n), 1e-13) << "x " << x << ", mode " << n;
    }
    EXPECT_NEAR(closed.root_norm(0), gs.root_norm(0), 1e-13) << "x " << x;
    (closed.norm(0, 2) == 0 ? dropped : kept) += 1;
    for (int n = 0; n < S; ++n) {
      for (int k = 0; k < S; ++k) {
        // Gram-Schmidt's own error grows as an end weight shrinks.
        const Real w_end = std::min(st.w(0, 0), st.w(0, 2));
        const Real tolerance = 1e-13 / std::sqrt(std::max(w_end, Real(1e-8)));
        EXPECT_NEAR(closed.wunit(0, n, k), gs.wunit(0, n, k), tolerance)
            << Kernel::name << " x " << x << ", mode " << n << ", node " << k;
      }
      // Orthonormal under the weights: sum_k w_k unit_n unit_m = delta_nm.
      for (int m = 0; m <= n; ++m) {
        if (closed.norm(0, n) == 0 || closed.norm(0, m) == 0) continue;
        Real dot = 0;
        for (int k = 0; k < S; ++k) dot += closed.wunit(0, n, k) * closed.unit(0, m, k);
        EXPECT_NEAR(dot, n == m ? 1 : 0, 1e-14) << "x " << x << ", modes " << n << ", " << m;
      }
    }
  }
  EXPECT_GT(kept, 100);
  if (std::is_same_v<Kernel, QuadraticKernel>) {
    EXPECT_GE(dropped, 1);  // half-way
  }
}

TEST(PolypicModes, ClosedFormOnThreeNodesIsGramSchmidts) {
  check_closed_form_modes<QuadraticKernel>();
  check_closed_form_modes<GimpKernel>();
}

// G particles' modes from one build, their axes side by side in the lanes
// (PolyModes::keep_group, the pass before P2G: pairs, in 3D in a register twice
// as wide as one particle's, and fours in 2D), are each particle's own build,
// bit for bit: also where a mode is dropped (a particle on a node, or half-way
// between two with the quadratic B-spline), in some of them or all.
template <int Dim, class Kernel, int G>
void check_group_build() {
  constexpr int S = Kernel::support;
  using Modes = PolyModes<Dim, S>;
  const Real dx = 0.1;
  std::array<int, Dim> cells;
  cells.fill(8);
  const GridGeometry<Dim> geo(Vec<Dim>::Zero(), dx, cells);
  std::mt19937 gen(7 + Dim + G);
  std::uniform_real_distribution<Real> inside(0.25, 0.55);
  const auto bits = [](const typename Modes::Kept& k) {
    std::array<unsigned char, sizeof k> b;
    std::memcpy(b.data(), &k, sizeof k);
    return b;
  };
  for (int trial = 0; trial < 40; ++trial) {
    std::array<Vec<Dim>, G> x;
    for (auto& xg : x)
      for (int a = 0; a < Dim; ++a) xg[a] = inside(gen);
    if (trial % 4 == 1) x[0] = Vec<Dim>::Constant(0.3);       // on a node
    if (trial % 4 == 2) x[G - 1] = Vec<Dim>::Constant(0.35);  // half-way
    if (trial % 4 == 3) x[0] = x[G - 1];
    std::vector<Stencil<Dim, Kernel>> st;
    for (const auto& xg : x) st.emplace_back(xg, geo);
    std::array<typename Modes::Kept, G> together, alone;
    std::memset(together.data(), 0xff, sizeof together);
    std::memset(alone.data(), 0, sizeof alone);
    const Stencil<Dim, Kernel>* stencils[G];
    typename Modes::Kept* kept[G];
    for (int g = 0; g < G; ++g) stencils[g] = &st[g], kept[g] = &together[g];
    Modes::template keep_group<G, Kernel>(stencils, dx, kept);
    for (int g = 0; g < G; ++g) {
      Modes own;
      own.build(st[g], dx);
      own.keep(alone[g]);
      EXPECT_EQ(bits(together[g]), bits(alone[g]))
          << Dim << "D " << Kernel::name << ", " << G << " together, particle " << g << ", trial "
          << trial;
    }
  }
}

TEST(PolypicModes, GroupBuildIsEachParticlesOwn) {
  check_group_build<1, QuadraticKernel, 2>();
  check_group_build<1, CubicKernel, 2>();
  check_group_build<2, QuadraticKernel, 2>();
  check_group_build<2, CubicKernel, 2>();
  check_group_build<2, CpGimpKernel, 2>();
  check_group_build<2, QuadraticKernel, 4>();
  check_group_build<2, CubicKernel, 4>();
  check_group_build<2, CpGimpKernel, 4>();
  check_group_build<3, QuadraticKernel, 2>();
  check_group_build<3, CubicKernel, 2>();
  check_group_build<3, CpGimpKernel, 2>();
}

// The weighted transforms give the same bits whatever the rows' width: rows of 2
// and 4 values (two nodes per register where two fit: the paired path with
// AVX-512 or AVX) against rows of 8 (never paired: one node per register or
// more), holding the same values in their first lanes.
template <int Dim, class Kernel, int N>
void check_paired_transforms() {
  std::array<int, Dim> cells;
  cells.fill(8);
  const Real dx = 0.1;
  const GridGeometry<Dim> geo(Vec<Dim>::Zero(), dx, cells);
  Vec<Dim> x;
  for (int a = 0; a < Dim; ++a) x[a] = (3.27 + 0.21 * a) * dx;
  const Stencil<Dim, Kernel> st(x, geo);
  PolyModes<Dim, Kernel::support> modes;
  modes.build(st, dx);
  constexpr int count = PolyModes<Dim, Kernel::support>::count;
  Row<N> in[count], out[count], back[count];
  Row<8> wide_in[count], wide_out[count], wide_back[count];
  std::mt19937 rng(11);
  std::uniform_real_distribution<Real> u(-1, 1);
  for (int j = 0; j < count; ++j) {
    Real values[8] = {};
    for (int l = 0; l < N; ++l) values[l] = u(rng);
    in[j] = Row<N>::load(values);
    wide_in[j] = Row<8>::load(values);
  }
  modes.to_nodes(in, out);
  modes.to_modes(out, back);
  modes.to_nodes(wide_in, wide_out);
  modes.to_modes(wide_out, wide_back);
  for (int j = 0; j < count; ++j) {
    Real a[8], b[8];
    out[j].store(a);
    wide_out[j].store(b);
    EXPECT_EQ(0, std::memcmp(a, b, N * sizeof(Real))) << Kernel::name << " to_nodes " << j;
    back[j].store(a);
    wide_back[j].store(b);
    EXPECT_EQ(0, std::memcmp(a, b, N * sizeof(Real))) << Kernel::name << " to_modes " << j;
  }
}

TEST(PolypicModes, PairedTransformsAreTheSameBits) {
  AllKernels::for_each([&]<class K>() {
    if constexpr (!kernel_full_inertia<K>) {
      check_paired_transforms<1, K, 2>();
      check_paired_transforms<2, K, 2>();
      check_paired_transforms<2, K, 4>();
      check_paired_transforms<3, K, 4>();
    }
  });
}

// Fewer weighted nodes than modes: the hat at a node has one (the linear mode
// vanishes there), the quadratic B-spline half-way between nodes two (the
// quadratic mode is constant on them). Those modes are dropped, not divided by 0.
TEST(PolypicModes, DegenerateModesAreDropped) {
  const GridGeometry<1> geo(Vec<1>::Zero(), 0.25, {8});
  const Stencil<1, LinearKernel> hat(Vec<1>(0.75), geo);
  PolyModes<1, 2> m2;
  m2.build(hat, 0.25);
  EXPECT_GT(m2.norm(0, 0), 0);
  EXPECT_EQ(m2.norm(0, 1), 0);
  const Stencil<1, QuadraticKernel> quad(Vec<1>(0.625), geo);
  PolyModes<1, 3> m3;
  m3.build(quad, 0.25);
  EXPECT_GT(m3.norm(0, 1), 0);
  EXPECT_EQ(m3.norm(0, 2), 0);
}

// A velocity field of degree <= support - 1 along every axis (here: affine,
// quadratic and the full tensor product x_0^2 x_1^2 ...) lies, on each stencil,
// in the span of the particle's modes. G2P from the nodal values v(x_i) sets the
// coefficients (a projection, exact for such a field); P2G then rebuilds
// v_i = sum_p m_p w_ip v_p(x_i) / m_i = v(x_i) at every node with mass, and a
// second G2P returns the same coefficients. Returns the nodal error; the
// coefficient drift goes to `drift`.
template <int Dim>
Real polynomial_round_trip(const std::string& transfer, const std::string& kernel, Real& drift) {
  const Scene scene = testing::scene_from_toml(testing::free_body_toml(Dim, transfer, kernel), {});
  State<Dim> s = build_state<Dim>(scene);
  Parameters params = scene.transfer_params;
  auto st = make_stepper<Dim>(transfer, kernel, params);
  auto field = [](const Vec<Dim>& x) {
    Vec<Dim> v;
    Real tensor = 0.8;
    for (int a = 0; a < Dim; ++a) tensor *= x[a] * x[a];
    for (int i = 0; i < Dim; ++i) {
      v[i] = 0.3 - 0.1 * i + tensor * (1 - i);
      for (int j = 0; j < Dim; ++j)
        v[i] += (0.7 * (i + 1) - 0.4 * j) * x[j] + 0.5 * (j + 1 - i) * x[j] * x[j];
    }
    return v;
  };
  Grid<Dim>& g = s.grid;
  auto& P = s.particles;
  st->particles_to_grid(s, 0);
  st->update_grid(s, 0);
  for (long i = 0; i < g.geo.node_count(); ++i) g.v[i] = field(g.geo.position(i));
  st->grid_to_particles(s, 0);
  const auto v1 = P.v;
  const auto C1 = P.C;
  const auto q1 = P.transfer_state;
  st->particles_to_grid(s, 0);
  st->update_grid(s, 0);
  Real err = 0, scale = 0;
  for (long i = 0; i < g.geo.node_count(); ++i) {
    if (g.m[i] <= 0) continue;
    const Vec<Dim> exact = field(g.geo.position(i));
    err = std::max(err, (g.v[i] - exact).norm());
    scale = std::max(scale, exact.norm());
  }
  st->grid_to_particles(s, 0);
  drift = 0;
  for (std::size_t p = 0; p < P.size(); ++p) {
    drift = std::max(drift, (P.v[p] - v1[p]).norm() / v1[p].norm());
    drift = std::max(drift, (P.C[p] - C1[p]).norm() / C1[p].norm());
  }
  Real qmax = 0, qdiff = 0;
  for (std::size_t k = 0; k < q1.size(); ++k) {
    qmax = std::max(qmax, std::abs(q1[k]));
    qdiff = std::max(qdiff, std::abs(P.transfer_state[k] - q1[k]));
  }
  if (qmax > 0) drift = std::max(drift, qdiff / qmax);
  return err / scale;
}

TEST(Polypic, PolynomialFieldRoundTripIsExact) {
  std::string left_out;
  for (const char* kernel : {"quadratic", "cubic"}) {
    if (!compiled_combination("polypic", kernel) || !compiled_combination("apic", kernel)) {
      left_out += std::string(left_out.empty() ? "" : ", ") + kernel;
      continue;
    }
    for (int dim : {1, 2, 3}) {
      testing::with_dim(dim, [&]<int Dim>() {
        Real drift = 0;
        EXPECT_LE(polynomial_round_trip<Dim>("polypic", kernel, drift), 1e-12)
            << Dim << "D " << kernel;
        EXPECT_LE(drift, 1e-11) << Dim << "D " << kernel;
        // APIC keeps only the affine part: the test field is beyond it.
        EXPECT_GT(polynomial_round_trip<Dim>("apic", kernel, drift), 1e-4) << Dim << "D";
      });
    }
  }
  if (!left_out.empty()) {
    GTEST_SKIP()
        << "not compiled in this build (MPMTB_COMBINATIONS=reduced): polypic and apic with "
        << left_out << " (the other kernels ran)";
  }
}

// G2P begins from the modes P2G kept at the same positions (PolypicPolicy::Kept,
// 1D and 2D): the same particle results, bit for bit, as G2P building them
// again (a fresh stepper, which kept nothing, on a copy of the grid). Where the
// particles moved between the two (by dx/7 here), the kept modes are those of
// another stencil and must not be used: again the same as built.
template <int Dim>
void expect_kept_modes_are_the_built_ones(const std::string& kernel, bool move) {
  const Scene scene = testing::scene_from_toml(testing::free_body_toml(Dim, "polypic", kernel));
  State<Dim> a = build_state<Dim>(scene), b = build_state<Dim>(scene);
  Parameters pa = scene.transfer_params, pb = scene.transfer_params, pc = pb;
  auto sa = make_stepper<Dim>("polypic", kernel, pa);
  auto sb = make_stepper<Dim>("polypic", kernel, pb);
  auto fresh = make_stepper<Dim>("polypic", kernel, pc);
  const Real dt = 1e-3;
  for (int step = 0; step < 3; ++step) {
    for (auto [s, stepper] : {std::pair{&a, sa.get()}, std::pair{&b, sb.get()}}) {
      stepper->particles_to_grid(*s, dt);
      stepper->update_grid(*s, dt);
      if (move) {
        for (auto& x : s->particles.x) x += Vec<Dim>::Constant(s->grid.geo.dx / 7);
      }
    }
    sa->grid_to_particles(a, dt);     // from its scatter's modes, where it may
    fresh->grid_to_particles(b, dt);  // built again: no scatter of its own
    for (std::size_t p = 0; p < a.particles.size(); ++p) {
      ASSERT_EQ(a.particles.v[p], b.particles.v[p]) << "step " << step << ", particle " << p;
      ASSERT_EQ(a.particles.C[p], b.particles.C[p]) << "step " << step << ", particle " << p;
      ASSERT_EQ(a.particles.x[p], b.particles.x[p]) << "step " << step << ", particle " << p;
    }
    ASSERT_EQ(a.particles.transfer_state, b.particles.transfer_state) << "step " << step;
  }
}

TEST(Polypic, ModesKeptFromTheScatterAreTheBuiltOnes) {
  for (const char* kernel : {"quadratic", "cubic"}) {
    if (!compiled_combination("polypic", kernel)) continue;
    for (const bool move : {false, true}) {
      expect_kept_modes_are_the_built_ones<1>(kernel, move);
      expect_kept_modes_are_the_built_ones<2>(kernel, move);
      expect_kept_modes_are_the_built_ones<3>(kernel, move);
    }
  }
}

// Energy kept, (kinetic + strain) at the end over the start, on the colliding
// disks (Sulsky et al. 1994). PolyPIC's P2G/G2P round trip loses less than
// APIC's (the modes beyond the affine ones survive), so it keeps at least as
// much. The scene's full 3.5 s (3500 steps of 416 particles: about 3 s for
// PolyPIC in Release on one core).
Real energy_kept(const std::string& transfer) {
  const Scene scene = load_scene("disks", {.transfer = transfer});
  const auto dir = std::filesystem::temp_directory_path() / ("mpmtb_polypic_disks_" + transfer);
  RunOptions options;
  options.threads = 1;
  const RunOutcome r = run_scene(scene, dir, options);
  EXPECT_EQ(r.status, "ok") << r.reason;
  return testing::series_ratio(dir / "series.csv", {"kinetic", "strain"});
}

TEST(Polypic, KeepsAtLeastApicsEnergyOnTheDisks) {
  const Real apic = energy_kept("apic"), polypic = energy_kept("polypic");
  EXPECT_GE(polypic, apic);
  EXPECT_LE(polypic, 1.0 + 1e-3) << "no energy gain";
  RecordProperty("apic", std::to_string(apic));
  RecordProperty("polypic", std::to_string(polypic));
}

}  // namespace polypic_test
}  // namespace mpmtb
