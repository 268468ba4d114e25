// G2P's failure detection (Solver::gather_particles): per particle det F_p,
// |v_p|^2 and whether x_p lies in the domain box, reduced to the StepReport's J
// range, largest squared speed, first non-finite particle and first particle
// outside the box.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/particles.hpp"
#include "core/types.hpp"

namespace mpmtb {

template <int Dim>
class ParticleCheck {
 public:
  // For the particles 0 .. n - 1 in the closed box [lo, hi] (GridGeometry::contains).
  ParticleCheck(const Vec<Dim>& lo, const Vec<Dim>& hi, long n)
      : lo_(lo), hi_(hi), non_finite_(n), outside_(n) {}

  // The particles first .. first + count - 1, after the transfer has finished
  // them: G2P calls it once per chunk of particles, a loop of its own. (Fused
  // into the transfer's loop, one particle behind it, the check's values
  // competed for registers with the transfer's: the 3D block at 1 thread ran
  // 1.5-2.5 % faster with this loop, 15 interleaved rounds.)
  [[gnu::noinline]] void add(const Particles<Dim>& P, long first, long count) {
    Real J_lo = J_min_, J_hi = J_max_, v2_hi = v2_max_;
    for (long p = first; p < first + count; ++p) {
      const Real J = P.F[p].determinant();
      J_lo = std::min(J_lo, J);
      J_hi = std::max(J_hi, J);
      const Real v2 = P.v[p].squaredNorm();
      v2_hi = std::max(v2_hi, v2);
      // The box test first: only a non-finite or escaped position fails it.
      const bool inside =
          ((P.x[p].array() >= lo_.array()) && (P.x[p].array() <= hi_.array())).all();
      if (!std::isfinite(J) || !std::isfinite(v2) || (!inside && !P.x[p].allFinite())) {
        non_finite_ = std::min(non_finite_, p);
      } else if (!inside) {
        outside_ = std::min(outside_, p);
      }
    }
    J_min_ = J_lo, J_max_ = J_hi, v2_max_ = v2_hi;
  }

  // Over the particles added (a NaN never taken): +inf, -inf and 0 when none was.
  Real J_min() const { return J_min_; }
  Real J_max() const { return J_max_; }
  Real v2_max() const { return v2_max_; }
  // The first particle non-finite (or outside the box), n when none is.
  long first_non_finite() const { return non_finite_; }
  long first_outside() const { return outside_; }

 private:
  Vec<Dim> lo_, hi_;
  Real J_min_ = std::numeric_limits<Real>::infinity(), J_max_ = -J_min_, v2_max_ = 0;
  long non_finite_, outside_;
};

}  // namespace mpmtb
