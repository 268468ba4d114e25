#include "boundary/walls.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>

#include "core/errors.hpp"

namespace mpmtb {

const std::vector<std::string>& wall_names() {
  static const std::vector<std::string> names = {"free", "sticky", "slip", "separate"};
  return names;
}

std::string_view wall_name(Wall w) {
  return wall_names()[static_cast<int>(w)];
}

Wall parse_wall(std::string_view name, const std::string& field) {
  const auto& names = wall_names();
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (names[i] == name) return static_cast<Wall>(i);
  }
  throw InputError(
      fmt::format("{}: unknown wall '{}'; allowed: {}", field, name, fmt::join(names, ", ")));
}

namespace {

// R v: the mirror map of a sticky (odd) or slip (normal odd, tangential even) wall.
template <int Dim>
Vec<Dim> reflected(Wall w, int axis, const Vec<Dim>& v) {
  if (w == Wall::sticky) return -v;
  Vec<Dim> r = v;
  r[axis] = -v[axis];
  return r;
}

// Calls fn(wall, axis, outward, face_node, one_step_outward) for every node on
// every face that has a wall; with a box, only on the faces whose nodes, ghosts
// or mirrors (pad layers either side) it meets.
template <int Dim, class Fn>
void for_each_face_node(const Walls<Dim>& walls, const GridGeometry<Dim>& geo,
                        const NodeBox<Dim>* box, Fn&& fn) {
  constexpr int pad = GridGeometry<Dim>::pad;
  for (int axis = 0; axis < Dim; ++axis) {
    const long stride = geo.strides()[axis];
    const long block = stride * geo.nodes(axis);
    const long outer = geo.node_count() / block;
    for (int side = 0; side < 2; ++side) {
      const Wall w = walls.face[2 * axis + side];
      if (w == Wall::free) continue;
      const int outward = side == 0 ? -1 : 1;
      const int face_index = side == 0 ? pad : pad + geo.cells[axis];
      if (box && (box->lo[axis] > face_index + pad || box->hi[axis] < face_index - pad)) continue;
      for (long o = 0; o < outer; ++o) {
        for (long s = 0; s < stride; ++s) {
          fn(w, axis, outward, o * block + face_index * stride + s, outward * stride);
        }
      }
    }
  }
}

// Ghost layers k = 1..pad whose mirror lies inside the domain (not beyond the
// opposite face of a domain thinner than the kernel).
template <int Dim>
int mirrored_layers(const GridGeometry<Dim>& geo, int axis) {
  return std::min(GridGeometry<Dim>::pad, geo.cells[axis]);
}

}  // namespace

template <int Dim>
void Walls<Dim>::fold(Grid<Dim>& grid) const {
  const NodeBox<Dim>* every_face = nullptr;
  for_each_face_node(*this, grid.geo, every_face, [&](Wall w, int axis, int, long face, long out) {
    if (w == Wall::separate) return;
    for (int k = 1; k <= mirrored_layers(grid.geo, axis); ++k) {
      const long ghost = face + k * out, mirror = face - k * out;
      if (grid.m[ghost] <= 0) continue;
      grid.m[mirror] += grid.m[ghost];
      grid.p[mirror] += reflected<Dim>(w, axis, grid.p[ghost]);
      grid.f[mirror] += reflected<Dim>(w, axis, grid.f[ghost]);
    }
  });
}

template <int Dim>
void Walls<Dim>::apply(Grid<Dim>& grid) const {
  constexpr int pad = GridGeometry<Dim>::pad;
  // Only on the faces the active box meets: outside it every velocity is zero,
  // and the condition on a face it does not meet changed only the sign of zeros,
  // on nodes no particle reads (perf: the pinned block's floor, far below it,
  // cost 2 % of its step).
  const NodeBox<Dim>* box = &grid.active;
  for_each_face_node(*this, grid.geo, box, [&](Wall w, int axis, int outward, long face, long out) {
    // Also on face nodes without mass: at a corner they are another face's ghosts,
    // mirrored before this face's condition was applied to their mirrors.
    apply_wall<Dim>(w, axis, outward, grid.v[face]);
    const int mirrored = w == Wall::separate ? 0 : mirrored_layers(grid.geo, axis);
    for (int k = 1; k <= pad; ++k) {
      const long ghost = face + k * out, mirror = face - k * out;
      // Mirrored ghosts are set even where no particle reaches them: with a kernel
      // whose support is narrower than its stencil (uGIMP: 1 + l cells over 3 nodes)
      // they still enter the interpolation at points on the face, and corner ghosts
      // then follow from the faces' passes in turn. Particles never read them
      // (w_ip = 0 wherever m_i = 0), so particle results do not change.
      if (grid.m[ghost] <= 0 && k > mirrored) continue;
      if (k <= mirrored) {
        grid.v[ghost] = reflected<Dim>(w, axis, grid.v[mirror]);
      } else {
        apply_wall<Dim>(w, axis, outward, grid.v[ghost]);
      }
    }
  });
}

template struct Walls<1>;
template struct Walls<2>;
template struct Walls<3>;

}  // namespace mpmtb
