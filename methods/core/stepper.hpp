// The common step interface: one compiled combination of dimension, kernel and
// transfer scheme. The stages follow the textbook pipeline:
//   P2G (mass, momentum, internal force) -> grid update (divide by mass, gravity,
//   walls, pinned nodes, colliders) -> G2P (v, C, F, x) -> constitutive return map.
// One virtual call per stage; everything inside is monomorphic.
#pragma once

#include <string_view>

#include "core/state.hpp"

namespace mpmtb {

// What G2P saw, for instability detection at negligible cost.
struct StepReport {
  Real J_min = 1, J_max = 1;
  Real v_max = 0;        // max |v_p|, for the CFL time step
  long non_finite = -1;  // a particle with NaN/Inf position, velocity or F (-1: none)
  long outside = -1;     // a particle that left the domain box (-1: none)
};

template <int Dim>
class Stepper {
 public:
  virtual ~Stepper() = default;
  virtual std::string_view transfer_name() const = 0;
  virtual std::string_view kernel_name() const = 0;

  // One explicit step of size dt (symplectic Euler).
  StepReport step(State<Dim>& s, Real dt) {
    particles_to_grid(s, dt);
    update_grid(s, dt);
    StepReport r = grid_to_particles(s, dt);
    nonlocal_update(s);
    constitutive_update(s, dt);
    s.time += dt;
    ++s.step;
    return r;
  }

  // The stages, public so that tests can check each transfer direction.
  virtual void particles_to_grid(State<Dim>& s, Real dt) = 0;
  virtual void update_grid(State<Dim>& s, Real dt) = 0;
  virtual StepReport grid_to_particles(State<Dim>& s, Real dt) = 0;
  // Grid Laplacians that nonlocal models ask for (core/nonlocal.hpp).
  virtual void nonlocal_update(State<Dim>& /*s*/) {}
  void constitutive_update(State<Dim>& s, Real dt) {
    for (std::size_t m = 0; m < s.materials.size(); ++m) {
      s.materials[m]->return_map(s.particles, s.material_particles[m], dt);
    }
  }

  // Angular momentum carried by the affine matrices, sum_p m_p eps : (C_p D_p)
  // (Jiang et al. 2015, sec. 5.3); zero for transfers without affine momentum.
  virtual Vec3 affine_angular_momentum(const State<Dim>& s) const = 0;
};

}  // namespace mpmtb
