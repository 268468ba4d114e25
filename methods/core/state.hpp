// Everything a step reads and writes: particles, grid, materials, boundary.
#pragma once

#include <functional>
#include <memory>
#include <span>
#include <vector>

#include "boundary/colliders.hpp"
#include "boundary/walls.hpp"
#include "core/grid.hpp"
#include "core/particles.hpp"
#include "models/model.hpp"

namespace mpmtb {

template <int Dim>
struct State {
  Particles<Dim> particles;
  Grid<Dim> grid;
  std::vector<std::unique_ptr<ConstitutiveModel<Dim>>> materials;
  std::vector<std::vector<int>> material_particles;  // particle ids of each material
  Walls<Dim> walls;
  Colliders<Dim> colliders;
  // Momentum given to the material so far by the colliders and by the pinned
  // nodes (their reaction), for the momentum balance.
  Vec3 collider_impulse = Vec3::Zero();
  Vec3 pin_impulse = Vec3::Zero();
  Real collider_work = 0;  // work the colliders did on the material
  Vec<Dim> gravity = Vec<Dim>::Zero();
  // Optional body force per unit mass b(x_p, p, t) (manufactured solutions).
  std::function<Vec<Dim>(const Particles<Dim>&, int p, Real t)> body_force;
  Real time = 0;
  long step = 0;

  // Groups particle ids by material; call after the particles are seeded.
  void index_materials() {
    material_particles.assign(materials.size(), {});
    for (std::size_t p = 0; p < particles.size(); ++p) {
      material_particles[particles.material[p]].push_back(static_cast<int>(p));
    }
  }
  // Largest wave speed over the materials in their current state (snow
  // hardening raises it), for the CFL time step.
  Real max_wave_speed() const {
    Real c = 0;
    for (std::size_t k = 0; k < materials.size(); ++k) {
      const std::span<const int> ids = k < material_particles.size()
                                           ? std::span<const int>(material_particles[k])
                                           : std::span<const int>();
      c = std::max(c, materials[k]->max_wave_speed(particles, ids));
    }
    return c;
  }
};

}  // namespace mpmtb
