// P2G's block colouring (core/particle_blocks.hpp): the blocks of one colour
// scatter in parallel without locks, which is race-free only if no two blocks
// of a colour reach a common grid node. Checked here through the stencils
// themselves (every node a particle's stencil visits, zero weights included:
// the scatter adds to those too), for kernels of span 2, 3 and 4 nodes (the
// blocks are span - 1 or span cells wide), in 2D and 3D, on clustered and
// spread-out particles; and that every particle sits in exactly one block.
#include <gtest/gtest.h>

#include <array>
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

}  // namespace particle_blocks_test
}  // namespace mpmtb
