// Boundary conditions on the faces of the domain box, applied to grid velocities.
// The face lies on a grid node layer. Sticky and slip walls tie each ghost node
// beyond the face to its mirror node inside, v_ghost = R v_mirror (sticky:
// R = -I; slip: the normal component odd, the tangential ones even), so that
// the B-spline interpolant sum_i w_ip v_i itself satisfies the condition on
// the face. The constraint is imposed in the Galerkin sense: fold() adds the
// ghost's mass, momentum and force, mapped by R, to its mirror before the
// velocities are solved (the mirror's equation becomes m_m + m_g, p_m + R p_g,
// f_m + R f_g), and apply() then sets the ghosts from their mirrors.
// Merely zeroing the ghosts leaves v(face) = v_1 / 8 for the quadratic B-spline,
// and copying mirrors without folding loses the ghosts' inertia: either way
// the vibrating bar's period error is O(dx) (1.2 % and 0.64 % at 16 cells),
// against 0.1 % (O(dx^2)) with the folded constraint.
#pragma once

#include <array>
#include <string>
#include <string_view>
#include <vector>

#include "core/grid.hpp"

namespace mpmtb {

enum class Wall {
  free,      // open: nothing is imposed
  sticky,    // v = 0 (no-slip, Dirichlet)
  slip,      // the normal component is removed, tangential kept
  separate,  // slip while pressing into the wall; free when moving away from it
};

std::string_view wall_name(Wall w);
// Parses a wall name; throws InputError naming `field` and the allowed names.
Wall parse_wall(std::string_view name, const std::string& field);
const std::vector<std::string>& wall_names();

// Face numbering: 2 * axis + side, side 0 the lower face, 1 the upper.
template <int Dim>
struct Walls {
  std::array<Wall, 2 * Dim> face{};  // all free by default

  // Before the velocity solve: folds ghost m, p, f onto mirror nodes.
  void fold(Grid<Dim>& grid) const;
  // Whether a wall on `axis` has its face, ghost or mirror layers (the face's
  // node -+ GridGeometry::pad) within `margin` nodes of the nodes first..last.
  bool near(const GridGeometry<Dim>& geo, int axis, int first, int last, int margin) const {
    constexpr int pad = GridGeometry<Dim>::pad;
    for (int side = 0; side < 2; ++side) {
      if (face[2 * axis + side] == Wall::free) continue;
      const int f = side == 0 ? pad : pad + geo.cells[axis];
      if (first - margin <= f + pad && last + margin >= f - pad) return true;
    }
    return false;
  }
  // Whether fold() can change the grid: a ghost layer meets the active box
  // (outside it no node has mass; fold() acts only on ghosts with mass).
  bool may_fold(const Grid<Dim>& grid) const {
    for (int a = 0; a < Dim; ++a) {
      if (near(grid.geo, a, grid.active.lo[a], grid.active.hi[a], 0)) return true;
    }
    return false;
  }
  // After it: the face nodes' condition, and ghosts from their mirrors.
  void apply(Grid<Dim>& grid) const;
};

// v with the wall's condition applied, for outward unit normal `n` (axis-aligned).
template <int Dim>
inline void apply_wall(Wall w, int axis, Real outward, Vec<Dim>& v) {
  switch (w) {
    case Wall::free:
      return;
    case Wall::sticky:
      v.setZero();
      return;
    case Wall::slip:
      v[axis] = 0;
      return;
    case Wall::separate:
      if (v[axis] * outward > 0) v[axis] = 0;
      return;
  }
}

}  // namespace mpmtb
