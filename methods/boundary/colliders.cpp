#include "boundary/colliders.hpp"

#include <algorithm>
#include <cmath>

namespace mpmtb {
namespace {

// v with the sphere's condition applied; n is the outward unit normal.
template <int Dim>
Vec<Dim> collide(const SphereCollider& c, const Vec<Dim>& v, const Vec<Dim>& n) {
  const Vec<Dim> vc = head<Dim>(c.velocity);
  if (c.wall == Wall::sticky) return vc;
  Vec<Dim> rel = v - vc;
  const Real normal = rel.dot(n);
  if (c.wall == Wall::slip || normal < 0) rel -= normal * n;
  return vc + rel;
}

}  // namespace

template <int Dim>
void Colliders<Dim>::apply(Grid<Dim>& grid, Real t, Vec3& total_impulse, Real& work) const {
  const auto& geo = grid.geo;
  constexpr int pad = GridGeometry<Dim>::pad;
  for (const auto& c : spheres) {
    if (c.wall == Wall::free) continue;
    const Vec<Dim> center = head<Dim>(c.center(t));
    // Only the nodes of the sphere's bounding box within the grid's active box,
    // outside which every node is massless (Grid::active). (The pinned block's
    // ball, above the block until it strikes, swept some 1,500 empty nodes a step.)
    std::array<int, Dim> lo{}, hi{};
    bool inside_grid = true;
    for (int a = 0; a < Dim; ++a) {
      lo[a] =
          std::max(grid.active.lo[a],
                   static_cast<int>(std::floor((center[a] - c.radius - geo.lo[a]) / geo.dx)) + pad);
      hi[a] =
          std::min(grid.active.hi[a],
                   static_cast<int>(std::ceil((center[a] + c.radius - geo.lo[a]) / geo.dx)) + pad);
      inside_grid = inside_grid && lo[a] <= hi[a];
    }
    if (!inside_grid) continue;
    Vec3 impulse = Vec3::Zero();
    std::array<int, Dim> idx = lo;
    for (bool more = true; more;) {
      long node = 0;
      Vec<Dim> x;
      for (int a = 0; a < Dim; ++a) {
        node += idx[a] * geo.strides()[a];
        x[a] = geo.coordinate(a, idx[a]);
      }
      const Vec<Dim> r = x - center;
      const Real dist = r.norm();
      if (grid.m[node] > 0 && dist <= c.radius) {
        const Vec<Dim> n = dist > 0 ? Vec<Dim>(r / dist) : Vec<Dim>::Unit(Dim - 1);
        const Vec<Dim> before = grid.v[node];
        grid.v[node] = collide<Dim>(c, before, n);
        impulse += to3<Dim>(grid.m[node] * (grid.v[node] - before));
      }
      // Next multi-index in the box, last axis fastest.
      int a = Dim - 1;
      for (; a >= 0; --a) {
        if (++idx[a] <= hi[a]) break;
        idx[a] = lo[a];
      }
      more = a >= 0;
    }
    total_impulse += impulse;
    work += impulse.dot(c.velocity);
  }
}

template <int Dim>
Real Colliders<Dim>::max_penetration(const std::vector<Vec<Dim>>& x, Real t) const {
  Real depth = 0;
  for (const auto& c : spheres) {
    const Vec<Dim> center = head<Dim>(c.center(t));
    for (const auto& xp : x) depth = std::max(depth, c.radius - (xp - center).norm());
  }
  return depth;
}

template struct Colliders<1>;
template struct Colliders<2>;
template struct Colliders<3>;

}  // namespace mpmtb
