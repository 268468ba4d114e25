#include "core/diagnostics.hpp"

#include <algorithm>
#include <limits>

namespace mpmtb {

template <int Dim>
Diagnostics measure(const State<Dim>& s, const Stepper<Dim>& stepper) {
  const Particles<Dim>& P = s.particles;
  Diagnostics d;
  d.J_min = std::numeric_limits<Real>::infinity();
  d.J_max = -d.J_min;
  Vec3 mx = Vec3::Zero();
  for (std::size_t p = 0; p < P.size(); ++p) {
    const Vec3 x = to3<Dim>(P.x[p]);
    const Vec3 mv = P.m[p] * to3<Dim>(P.v[p]);
    const Real J = s.materials[P.material[p]]->total_J(P.F[p], P.state_of(p));
    d.mass += P.m[p];
    d.kinetic += Real(0.5) * P.m[p] * P.v[p].squaredNorm();
    d.gravity -= P.m[p] * s.gravity.dot(P.x[p]);
    d.momentum += mv;
    d.angular_momentum += x.cross(mv);
    d.volume += P.V0[p] * J;
    d.J_min = std::min(d.J_min, J);
    d.J_max = std::max(d.J_max, J);
    mx += P.m[p] * x;
  }
  for (std::size_t m = 0; m < s.materials.size(); ++m) {
    d.strain += s.materials[m]->strain_energy(P, s.material_particles[m]);
    d.dissipated += s.materials[m]->dissipated_energy(P, s.material_particles[m]);
  }
  d.angular_momentum += stepper.affine_angular_momentum(s);
  d.total = d.kinetic + d.strain + d.gravity + d.dissipated;
  if (d.mass > 0) {
    d.center_of_mass = mx / d.mass;
    d.center_of_mass_velocity = d.momentum / d.mass;
  }
  if (P.size() == 0) d.J_min = d.J_max = 1;
  return d;
}

template <int Dim>
GridDiagnostics measure_grid(const Grid<Dim>& g) {
  GridDiagnostics d;
  for (std::size_t i = 0; i < g.size(); ++i) {
    if (g.m[i] <= 0) continue;
    const Vec3 p = to3<Dim>(g.p[i]);
    d.mass += g.m[i];
    d.momentum += p;
    d.angular_momentum += to3<Dim>(g.geo.position(static_cast<long>(i))).cross(p);
    d.kinetic += Real(0.5) * g.m[i] * g.v[i].squaredNorm();
  }
  return d;
}

#define MPMTB_INSTANTIATE(D)                                           \
  template Diagnostics measure<D>(const State<D>&, const Stepper<D>&); \
  template GridDiagnostics measure_grid<D>(const Grid<D>&);
MPMTB_INSTANTIATE(1)
MPMTB_INSTANTIATE(2)
MPMTB_INSTANTIATE(3)
#undef MPMTB_INSTANTIATE

}  // namespace mpmtb
