// G2P's failure detection (Solver::gather_particles): per particle det F_p,
// |v_p|^2 and whether x_p lies in the domain box, reduced to the StepReport's J
// range, largest squared speed, first non-finite particle and first particle
// outside the box.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/lanes.hpp"
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
    long p = first;
    const long end = first + count;
    if constexpr (kTransposes<Dim>) p = add_in_lanes(P, p, end);
    Real J_lo = J_min_, J_hi = J_max_, v2_hi = v2_max_;
    for (; p < end; ++p) {
      const Real J = P.F[p].determinant();
      J_lo = std::min(J_lo, J);
      J_hi = std::max(J_hi, J);
      const Real v2 = P.v[p].squaredNorm();
      v2_hi = std::max(v2_hi, v2);
      classify(P, p, J, v2);
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
  // Non-finite or outside the box: the first such particle of each kind.
  MPMTB_INLINE void classify(const Particles<Dim>& P, long p, Real J, Real v2) {
    // The box test first: only a non-finite or escaped position fails it.
    const bool inside = ((P.x[p].array() >= lo_.array()) && (P.x[p].array() <= hi_.array())).all();
    if (!std::isfinite(J) || !std::isfinite(v2) || (!inside && !P.x[p].allFinite())) {
      non_finite_ = std::min(non_finite_, p);
    } else if (!inside) {
      outside_ = std::min(outside_, p);
    }
  }
  // The whole registers of particles from p on (core/lanes.hpp): det F in
  // Eigen's cofactor order and |v|^2 in squaredNorm's order, so each lane holds
  // its particle's own values; min and max are exact, so their order does not
  // matter. A register with a particle non-finite or outside is classified
  // particle by particle. Returns the first particle left (3D block, 1 thread,
  // perf: the check was 3.7 % of the step particle by particle).
  long add_in_lanes(const Particles<Dim>& P, long p, long end) {
    const auto splat = [](Real r) MPMTB_INLINE_LAMBDA { return Lanes{} + r; };
    Lanes J_lo = splat(J_min_), J_hi = splat(J_max_), v2_hi = splat(v2_max_);
    for (; p + kLanes <= end; p += kLanes) {
      int ids[kLanes];
      for (int l = 0; l < kLanes; ++l) ids[l] = static_cast<int>(p + l);
      Lanes F[Dim][Dim], v[Dim], x[Dim];
      load_lanes<Dim>(P.F, ids, kLanes, F);
      load_vector_lanes<Dim>(&P.v[p], v);
      load_vector_lanes<Dim>(&P.x[p], x);
      const Lanes J = determinant_of<Dim>(F);
      Lanes v2 = v[0] * v[0];
      for (int a = 1; a < Dim; ++a) v2 = v2 + v[a] * v[a];
      // std::min and std::max lane by lane: a NaN is never taken.
      J_lo = J < J_lo ? J : J_lo;
      J_hi = J_hi < J ? J : J_hi;
      v2_hi = v2_hi < v2 ? v2 : v2_hi;
      auto fine = (J - J == 0) & (v2 - v2 == 0);  // finite: inf - inf and NaN fail
      for (int a = 0; a < Dim; ++a) fine &= (x[a] >= splat(lo_[a])) & (x[a] <= splat(hi_[a]));
      if (!all_lanes(fine)) {
        for (int l = 0; l < kLanes; ++l) classify(P, p + l, J[l], v2[l]);
      }
    }
    for (int l = 0; l < kLanes; ++l) {
      J_min_ = std::min(J_min_, J_lo[l]);
      J_max_ = std::max(J_max_, J_hi[l]);
      v2_max_ = std::max(v2_max_, v2_hi[l]);
    }
    return p;
  }

  Vec<Dim> lo_, hi_;
  Real J_min_ = std::numeric_limits<Real>::infinity(), J_max_ = -J_min_, v2_max_ = 0;
  long non_finite_, outside_;
};

}  // namespace mpmtb
