// Jacobi-preconditioned conjugate gradients on the implicit step's grid
// velocities (integrators/implicit_impl.hpp): the unknowns are the Dim-vectors of
// the active nodes, the operator is matrix-free (a Hessian-vector product), the
// preconditioner the inverse of its diagonal (Saad 2003, "Iterative Methods for
// Sparse Linear Systems", alg. 9.1).
#pragma once

#include <cmath>
#include <vector>

#include "core/types.hpp"

namespace mpmtb {

// sum over the nodes of a_i . b_i.
template <int Dim>
Real node_dot(const std::vector<long>& nodes, const std::vector<Vec<Dim>>& a,
              const std::vector<Vec<Dim>>& b) {
  Real s = 0;
  for (const long i : nodes) s += a[i].dot(b[i]);
  return s;
}

// Solves H x = b to |r| <= tol in at most max_iterations; apply(q, Hq) is the
// operator, inv_diag its diagonal's inverse. x starts at zero. Returns the
// iterations; stops early where H is not positive definite along a direction
// (which the per-particle projection rules out).
template <int Dim, class Apply>
long preconditioned_cg(const std::vector<long>& nodes, const std::vector<Vec<Dim>>& inv_diag,
                       const std::vector<Vec<Dim>>& b, std::vector<Vec<Dim>>& x, Real tol,
                       long max_iterations, Apply&& apply) {
  using V = std::vector<Vec<Dim>>;
  const std::size_t N = b.size();
  x.assign(N, Vec<Dim>::Zero());
  V r = b, z(N, Vec<Dim>::Zero()), q, Aq;
  for (const long i : nodes) z[i] = inv_diag[i].cwiseProduct(r[i]);
  q = z;
  Real rz = node_dot<Dim>(nodes, r, z);
  long k = 0;
  for (; k < max_iterations && std::sqrt(node_dot<Dim>(nodes, r, r)) > tol; ++k) {
    apply(q, Aq);
    const Real qAq = node_dot<Dim>(nodes, q, Aq);
    if (!(qAq > 0)) break;
    const Real alpha = rz / qAq;
    for (const long i : nodes) {
      x[i] += alpha * q[i];
      r[i] -= alpha * Aq[i];
      z[i] = inv_diag[i].cwiseProduct(r[i]);
    }
    const Real rz_new = node_dot<Dim>(nodes, r, z);
    const Real beta = rz_new / rz;
    rz = rz_new;
    for (const long i : nodes) q[i] = z[i] + beta * q[i];
  }
  return k;
}

}  // namespace mpmtb
