#include "setup.hpp"

#include <fmt/format.h>

#include <cmath>

#include "core/errors.hpp"
#include "models/registry.hpp"

namespace mpmtb {
namespace {

template <int Dim>
Vec<Dim> rigid_velocity(const BodySpec& b, const Vec3& x) {
  const Vec3 r = x - b.rotation_center();
  Vec3 v = b.velocity + b.stretch_rate.cwiseProduct(r);
  if constexpr (Dim == 2) {
    v += Vec3(-b.angular_velocity[2] * r[1], b.angular_velocity[2] * r[0], 0);
  } else if constexpr (Dim == 3) {
    v += b.angular_velocity.cross(r);
  }
  return head<Dim>(v);
}

template <int Dim>
bool pinned_at(const Scene& scene, const Vec3& x) {
  for (const auto& pin : scene.pins) {
    bool inside = true;
    for (int a = 0; a < Dim; ++a) inside = inside && x[a] >= pin.min[a] && x[a] <= pin.max[a];
    if (inside) return true;
  }
  return false;
}

// Bodies may not overlap: a lattice point inside two of them would silently
// take the first one's material and velocity (cases/README.md).
[[noreturn]] void throw_overlap(const Scene& scene, const BodySpec& a, const BodySpec& b,
                                const Vec3& x) {
  const auto index = [&](const BodySpec& body) { return &body - scene.bodies.data(); };
  throw InputError(fmt::format(
      "bodies[{}] and bodies[{}] overlap at ({:.6g}, {:.6g}, {:.6g}); bodies may touch but not "
      "overlap",
      index(a), index(b), x[0], x[1], x[2]));
}

// Seeds the lattice points inside the bodies; returns each particle's body.
template <int Dim>
std::vector<const BodySpec*> seed_particles(const Scene& scene, State<Dim>& s) {
  std::vector<const BodySpec*> body_of;
  const GridGeometry<Dim>& geo = s.grid.geo;
  const int ppc = scene.ppc;
  const Real h = geo.dx / ppc;  // lattice spacing
  const Real volume = std::pow(h, Dim);
  std::array<long, Dim> n{};
  long total = 1;
  for (int a = 0; a < Dim; ++a) total *= n[a] = static_cast<long>(geo.cells[a]) * ppc;
  for (long k = 0; k < total; ++k) {
    Vec3 x = Vec3::Zero();
    long rest = k;
    for (int a = Dim - 1; a >= 0; --a) {
      x[a] = geo.lo[a] + (static_cast<Real>(rest % n[a]) + Real(0.5)) * h;
      rest /= n[a];
    }
    const BodySpec* owner = nullptr;
    for (const auto& body : scene.bodies) {
      if (!body.contains(x, Dim)) continue;
      if (owner) throw_overlap(scene, *owner, body, x);
      owner = &body;
    }
    if (owner) {
      const Real rho = s.materials[owner->material]->density();
      s.particles.add(head<Dim>(x), rigid_velocity<Dim>(*owner, x), rho * volume, volume,
                      owner->material, pinned_at<Dim>(scene, x));
      body_of.push_back(owner);
    }
  }
  if (s.particles.size() == 0) throw InputError("bodies: no particle lies inside any body");
  return body_of;
}

}  // namespace

template <int Dim>
GridGeometry<Dim> scene_grid(const Scene& scene) {
  const Real dx = scene.dx();
  std::array<int, Dim> cells{};
  for (int a = 0; a < Dim; ++a) {
    const Real extent = scene.domain_max[a] - scene.domain_min[a];
    cells[a] = std::max(1, static_cast<int>(std::ceil(extent / dx - 1e-9)));
  }
  GridGeometry<Dim> geo(head<Dim>(scene.domain_min), dx, cells);
  geo.l = Real(1) / (2 * scene.ppc);  // particle half-width in cells (uGIMP)
  return geo;
}

template <int Dim>
State<Dim> build_state(const Scene& scene) {
  State<Dim> s;
  s.grid = Grid<Dim>(scene_grid<Dim>(scene));
  int state_size = 0;
  for (const auto& m : scene.materials) {
    Parameters params = m.params;
    s.materials.push_back(make_model<Dim>(m.model, params));
    state_size = std::max(state_size, s.materials.back()->state_size());
  }
  s.particles.state_size = state_size;
  for (int a = 0; a < Dim; ++a) {
    s.walls.face[2 * a] = parse_wall(scene.walls[2 * a], "boundary");
    s.walls.face[2 * a + 1] = parse_wall(scene.walls[2 * a + 1], "boundary");
  }
  s.gravity = head<Dim>(scene.gravity);
  s.colliders.spheres = scene.colliders;
  const std::vector<const BodySpec*> body_of = seed_particles(scene, s);
  for (std::size_t p = 0; p < s.particles.size(); ++p) {
    const auto& model = *s.materials[s.particles.material[p]];
    model.initial_state(s.particles.state_of(p));
    if (!body_of[p]->fibers.empty()) {  // read_scene checked that the model takes them
      std::vector<Vec<Dim>> a0;
      for (const Vec3& a : body_of[p]->fibers) a0.push_back(head<Dim>(a).normalized());
      model.set_fibers(s.particles.state_of(p), a0);
    }
  }
  s.index_materials();
  return s;
}

template GridGeometry<1> scene_grid<1>(const Scene&);
template GridGeometry<2> scene_grid<2>(const Scene&);
template GridGeometry<3> scene_grid<3>(const Scene&);
template State<1> build_state<1>(const Scene&);
template State<2> build_state<2>(const Scene&);
template State<3> build_state<3>(const Scene&);

double max_wave_speed(const Scene& s) {
  switch (s.dim) {
    case 1:
      return build_state<1>(s).max_wave_speed();
    case 2:
      return build_state<2>(s).max_wave_speed();
    default:
      return build_state<3>(s).max_wave_speed();
  }
}

}  // namespace mpmtb
