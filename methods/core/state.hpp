// Everything a step reads and writes: particles, grid, materials, boundary.
#pragma once

#include <algorithm>
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
  // out[k] = V0_p tau_p for the particles p = ids[k], each from its material's
  // model, serially (a run of P2G's scatter: core/solver_impl.hpp).
  void kirchhoff_times_volume_of(std::span<const int> ids, Mat<Dim>* out) const {
    if (ids.empty()) return;
    if (materials.size() == 1) {  // (the scan below read each particle's material)
      materials[0]->kirchhoff_times_volume_of(particles, ids, out);
      return;
    }
    const std::vector<int>& material = particles.material;
    const int first = material[ids[0]];
    if (std::all_of(ids.begin(), ids.end(), [&](int p) { return material[p] == first; })) {
      materials[first]->kirchhoff_times_volume_of(particles, ids, out);
      return;
    }
    // A run across materials (rare: where bodies meet): each material's
    // particles of the run together.
    std::vector<int> own, place;
    std::vector<Mat<Dim>> own_out;
    for (std::size_t m = 0; m < materials.size(); ++m) {
      own.clear(), place.clear();
      for (std::size_t k = 0; k < ids.size(); ++k) {
        if (material[ids[k]] == static_cast<int>(m)) own.push_back(ids[k]), place.push_back(k);
      }
      if (own.empty()) continue;
      own_out.resize(own.size());
      materials[m]->kirchhoff_times_volume_of(particles, own, own_out.data());
      for (std::size_t i = 0; i < own.size(); ++i) out[place[i]] = own_out[i];
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
