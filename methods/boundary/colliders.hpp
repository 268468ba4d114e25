// Kinematic colliders: rigid bodies on prescribed paths that act on grid
// velocities (Stomakhin et al. 2013, sec. 8, "collision objects"). A node
// inside the body gets the body's velocity (sticky), loses the normal part of
// its velocity relative to the body (slip), or loses it only while moving
// into the body (separate). The impulse each one gives the material is summed
// so that the momentum balance can be checked.
#pragma once

#include <vector>

#include "boundary/walls.hpp"
#include "core/grid.hpp"

namespace mpmtb {

// A sphere (a disk in 2D) whose centre moves as c(t) = start + velocity t.
struct SphereCollider {
  Vec3 start = Vec3::Zero();
  Vec3 velocity = Vec3::Zero();
  Real radius = 0;
  Wall wall = Wall::sticky;  // sticky, slip or separate

  Vec3 center(Real t) const { return start + t * velocity; }
};

template <int Dim>
struct Colliders {
  std::vector<SphereCollider> spheres;

  bool empty() const { return spheres.empty(); }
  // Applies every collider at time t to the nodes with mass. Adds the impulse
  // given to the material, sum m_i (v_after - v_before), and the work done on
  // it, the impulse times the collider's velocity.
  void apply(Grid<Dim>& grid, Real t, Vec3& impulse, Real& work) const;
  // Deepest penetration of a particle into any collider at time t (>= 0).
  Real max_penetration(const std::vector<Vec<Dim>>& x, Real t) const;
};

}  // namespace mpmtb
