// P2G's block colouring (core/particle_blocks.hpp): the blocks of one colour
// scatter in parallel without locks, which is race-free only if no two blocks
// of a colour reach a common grid node. Checked here through the stencils
// themselves (every node a particle's stencil visits, zero weights included:
// the scatter adds to those too), for kernels of span 2, 3 and 4 nodes (the
// blocks are span - 1 or span cells wide), in 2D and 3D, on clustered and
// spread-out particles; and that every particle sits in exactly one block.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include "core/grid.hpp"
#include "core/particle_blocks.hpp"
#include "core/stencil.hpp"
#include "kernels/all.hpp"

namespace mpmtb {
namespace particle_blocks_test {

// Particles uniformly in [lo, hi]^Dim (cell units) on a grid of n cells per axis.
template <int Dim>
std::vector<Vec<Dim>> RandomPositions(std::mt19937& gen, int count, Real lo, Real hi) {
  std::uniform_real_distribution<Real> u(lo, hi);
  std::vector<Vec<Dim>> x(count);
  for (auto& xp : x) {
    for (int a = 0; a < Dim; ++a) xp[a] = u(gen);
  }
  return x;
}

template <int Dim, class Kernel>
void ExpectBlocksOfAColourShareNoNode(int cells, Real lo, Real hi, unsigned seed) {
  const GridGeometry<Dim> geo(Vec<Dim>::Zero(), Real(1), [&] {
    std::array<int, Dim> n{};
    n.fill(cells);
    return n;
  }());
  std::mt19937 gen(seed);
  const std::vector<Vec<Dim>> x = RandomPositions<Dim>(gen, 3000, lo, hi);
  ParticleBlocks<Dim, Kernel> blocks;
  NodeBox<Dim> box;
  blocks.bin(x, geo, box);

  std::vector<int> seen(x.size(), 0);
  std::map<std::pair<int, long>, int> owner;  // (colour, node) -> the block that reached it
  int block = 0, colours_with_blocks = 0, last_colour = -1;
  blocks.for_each_block([&](int colour, std::span<const int> ids) {
    ++block;
    if (!ids.empty() && colour != last_colour) ++colours_with_blocks, last_colour = colour;
    for (const int p : ids) {
      ++seen[p];
      const Stencil<Dim, Kernel> st(x[p], Mat<Dim>::Identity(), geo);
      st.for_each_node(geo, [&](long node, Real, const Vec<Dim>&, const Vec<Dim>&) {
        const auto [it, fresh] = owner.emplace(std::pair{colour, node}, block);
        EXPECT_TRUE(fresh || it->second == block)
            << Kernel::name << ": node " << node << " reached by two blocks of colour " << colour;
      });
    }
  });
  for (std::size_t p = 0; p < x.size(); ++p) EXPECT_EQ(seen[p], 1) << "particle " << p;
  // The spread-out particles fill several blocks of every colour: the check
  // above compares blocks, not one block with itself.
  EXPECT_EQ(colours_with_blocks, 1 << (Dim >= 2 ? 2 : 1)) << Kernel::name;
}

template <int Dim>
void ExpectColouringForEveryKernel() {
  for (unsigned seed = 1; seed <= 3; ++seed) {
    // Spread over most of the grid, and clustered in a few cells (few blocks).
    ExpectBlocksOfAColourShareNoNode<Dim, LinearKernel>(24, 0.5, 23.5, seed);
    ExpectBlocksOfAColourShareNoNode<Dim, QuadraticKernel>(24, 0.5, 23.5, seed);
    ExpectBlocksOfAColourShareNoNode<Dim, CubicKernel>(24, 1, 23, seed);
    ExpectBlocksOfAColourShareNoNode<Dim, GimpKernel>(24, 0.5, 23.5, seed);
    ExpectBlocksOfAColourShareNoNode<Dim, CpGimpKernel>(24, 0.5, 23.5, seed);
    ExpectBlocksOfAColourShareNoNode<Dim, QuadraticKernel>(24, 10, 15, seed);
    ExpectBlocksOfAColourShareNoNode<Dim, CubicKernel>(24, 10, 15, seed);
  }
}

TEST(ParticleBlocks, BlocksOfOneColourNeverShareANode2D) {
  ExpectColouringForEveryKernel<2>();
}
TEST(ParticleBlocks, BlocksOfOneColourNeverShareANode3D) {
  ExpectColouringForEveryKernel<3>();
}

// The active box that bin() sets: every node a stencil visits (zero weights
// included) lies in it, and it reaches pad nodes beyond them only along an axis
// with a wall within reach, whose ghosts fold onto mirrors that the grid update
// must sweep. Elsewhere those nodes hold no mass, and sweeping them in every
// grid pass cost the pinned block (4 cells thick) twice the nodes per row.
template <int Dim, class Kernel>
void ExpectBoxHoldsTheStencilsPaddedOnlyNearWalls(Real lo, Real hi, const Mat<Dim>& F) {
  constexpr int cells = 24, pad = GridGeometry<Dim>::pad;
  const GridGeometry<Dim> geo(Vec<Dim>::Zero(), Real(1), [&] {
    std::array<int, Dim> n{};
    n.fill(cells);
    return n;
  }());
  std::mt19937 gen(7);
  const std::vector<Vec<Dim>> x = RandomPositions<Dim>(gen, 500, lo, hi);
  // The hull of the stencils' nodes, per axis.
  std::array<int, Dim> first{}, last{};
  first.fill(std::numeric_limits<int>::max());
  last.fill(std::numeric_limits<int>::min());
  for (const auto& xp : x) {
    Stencil<Dim, Kernel>(xp, F, geo)
        .for_each_node(geo, [&](long node, Real, const Vec<Dim>&, const Vec<Dim>&) {
          for (int a = 0; a < Dim; ++a) {
            const int i = static_cast<int>((node / geo.strides()[a]) % geo.nodes(a));
            first[a] = std::min(first[a], i), last[a] = std::max(last[a], i);
          }
        });
  }
  ParticleBlocks<Dim, Kernel> blocks;
  NodeBox<Dim> box;
  // No walls: the box is the stencils' hull (CPDI's box may start one node
  // past the first node binned: its span, not its support).
  Walls<Dim> walls;
  blocks.bin(x, geo, box, &walls);
  constexpr int later = stencil_span<Dim, Kernel>() - Kernel::support;  // CPDI: 1
  for (int a = 0; a < Dim; ++a) {
    EXPECT_LE(box.lo[a], first[a]) << Kernel::name << " axis " << a;
    EXPECT_GE(box.lo[a], first[a] - later) << Kernel::name << " axis " << a;
    EXPECT_GE(box.hi[a], last[a]) << Kernel::name << " axis " << a;
    EXPECT_LE(box.hi[a], last[a] + later) << Kernel::name << " axis " << a;
  }
  // A sticky wall at x = 0, within reach of particles from x = lo <= 1 cell,
  // and a slip wall at the top of y, beyond reach (hi < cells - 2 pad - 3).
  walls.face[0] = Wall::sticky;
  walls.face[3] = Wall::slip;
  NodeBox<Dim> near_wall;
  blocks.bin(x, geo, near_wall, &walls);
  EXPECT_EQ(near_wall.lo[0], std::max(0, box.lo[0] - pad)) << Kernel::name;
  EXPECT_EQ(near_wall.hi[0], box.hi[0] + pad) << Kernel::name;
  for (int a = 1; a < Dim; ++a) {
    EXPECT_EQ(near_wall.lo[a], box.lo[a]) << Kernel::name << " axis " << a;
    EXPECT_EQ(near_wall.hi[a], box.hi[a]) << Kernel::name << " axis " << a;
  }
  // Without walls given (the nonlocal pass's and the implicit solver's boxes):
  // the pad along every axis.
  NodeBox<Dim> padded;
  blocks.bin(x, geo, padded);
  for (int a = 0; a < Dim; ++a) {
    EXPECT_EQ(padded.lo[a], std::max(0, box.lo[a] - pad)) << Kernel::name << " axis " << a;
    EXPECT_EQ(padded.hi[a], box.hi[a] + pad) << Kernel::name << " axis " << a;
  }
}

template <int Dim>
void ExpectActiveBoxForEveryKernel() {
  const Mat<Dim> I = Mat<Dim>::Identity();
  Mat<Dim> sheared = I;
  sheared(0, Dim - 1) = Real(0.4);  // CPDI's box follows F
  ExpectBoxHoldsTheStencilsPaddedOnlyNearWalls<Dim, LinearKernel>(0.5, 12, I);
  ExpectBoxHoldsTheStencilsPaddedOnlyNearWalls<Dim, QuadraticKernel>(0.5, 12, I);
  ExpectBoxHoldsTheStencilsPaddedOnlyNearWalls<Dim, CubicKernel>(1, 12, I);
  ExpectBoxHoldsTheStencilsPaddedOnlyNearWalls<Dim, GimpKernel>(0.5, 12, I);
  ExpectBoxHoldsTheStencilsPaddedOnlyNearWalls<Dim, CpGimpKernel>(0.5, 12, I);
  ExpectBoxHoldsTheStencilsPaddedOnlyNearWalls<Dim, CpdiKernel>(1, 12, I);
  ExpectBoxHoldsTheStencilsPaddedOnlyNearWalls<Dim, CpdiKernel>(1, 12, sheared);
}

TEST(ParticleBlocks, ActiveBoxHoldsTheStencilsPaddedOnlyNearWalls2D) {
  ExpectActiveBoxForEveryKernel<2>();
}
TEST(ParticleBlocks, ActiveBoxHoldsTheStencilsPaddedOnlyNearWalls3D) {
  ExpectActiveBoxForEveryKernel<3>();
}

}  // namespace particle_blocks_test
}  // namespace mpmtb
