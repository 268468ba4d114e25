// Optional per-particle hooks of a transfer policy, called generically by the base
// solver (and by the tests that compare its two paths): a policy that needs the
// particle's stencil at the start of P2G or G2P (e.g. the affine transfers with a
// kernel whose D_p differs per particle, transfers/affine.hpp) declares
//   Source prepare(P, p, tauV, stencil)   beside, or instead of, Source prepare(P, p, tauV)
//   Gather begin_gather(stencil)          returning its own Gather type.
// Policies without them (or whose own Source/Gather types hide a base's) are called
// as before. On the fast path (core/tensor_transfer.hpp) a policy turns the
// stencil sums into its Gather with
//   Gather gather_from(sums)                     or, with TensorTerms::nodal,
//   void gather_from(sums, Gather&)              after the stencil's velocity rows
//                                                were copied to Gather::v_data().
// A policy may keep values per particle from P2G to the G2P of the same step
// (PolyPIC's modes: the particles have not moved in between), declaring
//   struct Kept;                                        one per particle, held by the solver
//   Source prepare(P, p, tauV, stencil, Kept*)          P2G writes it
//   Gather begin_gather(stencil, x_p, const Kept*)      G2P begins from it (null:
//                                                       nothing kept this step)
//   void finish_rows(rows, stencil, P, p, dt)    G2P's finish straight from the
//                                                stencil sums in registers
//                                                (TensorTransfer::Partial), declared
//                                                with `using FinishRows = ThisPolicy;`.
#pragma once

#include <concepts>
#include <type_traits>

#include "core/particles.hpp"
#include "core/stencil.hpp"
#include "core/tensor_transfer.hpp"

namespace mpmtb {

template <class Policy, int Dim, class Kernel>
auto prepare_source(const Policy& policy, const Particles<Dim>& P, int p, const Mat<Dim>& tauV,
                    const Stencil<Dim, Kernel>& st) {
  if constexpr (!requires { policy.prepare(P, p, tauV); }) {
    return policy.prepare(P, p, tauV, st);  // only the stencil-aware form (PolyPIC)
  } else if constexpr (requires {
                         {
                           policy.prepare(P, p, tauV, st)
                           } -> std::same_as<decltype(policy.prepare(P, p, tauV))>;
                       }) {
    return policy.prepare(P, p, tauV, st);
  } else {
    return policy.prepare(P, p, tauV);
  }
}

// Whether the policy keeps values from P2G to G2P (Policy::Kept), and their type
// (an empty one where it keeps none).
// (A policy that keeps nothing in some dimensions declares Kept as NothingKept there.)
struct NothingKept {};
template <class Policy>
constexpr bool keeps_from_p2g = [] {
  if constexpr (requires { typename Policy::Kept; }) {
    return !std::is_same_v<typename Policy::Kept, NothingKept>;
  } else {
    return false;
  }
}();
template <class Policy>
struct KeptType {
  using type = NothingKept;
};
template <class Policy>
requires keeps_from_p2g<Policy>
struct KeptType<Policy> {
  using type = typename Policy::Kept;
};
template <class Policy>
using KeptOf = typename KeptType<Policy>::type;

// prepare_source, recording what the policy keeps for G2P into *kept.
template <class Policy, int Dim, class Kernel>
MPMTB_INLINE inline auto prepare_source(const Policy& policy, const Particles<Dim>& P, int p,
                                        const Mat<Dim>& tauV, const Stencil<Dim, Kernel>& st,
                                        KeptOf<Policy>* kept) {
  if constexpr (keeps_from_p2g<Policy>) {
    return policy.prepare(P, p, tauV, st, kept);
  } else {
    return prepare_source(policy, P, p, tauV, st);
  }
}

template <class Policy, int Dim, class Kernel>
typename Policy::Gather begin_gather(const Policy& policy, const Stencil<Dim, Kernel>& st) {
  if constexpr (requires {
                  { policy.begin_gather(st) } -> std::same_as<typename Policy::Gather>;
                }) {
    return policy.begin_gather(st);
  } else {
    return {};
  }
}

// With TensorTerms::nodal: the stencil sums and the stencil's rows into a
// Gather begun at the same stencil (begin_gather), in place. (The solver calls
// this on its own Gather: returned from tensor_gather, PolyPIC's Gather, a
// stencil's rows and modes, was copied whole, three copies of 2 KB per particle.)
template <class Policy, int Dim, class Kernel>
MPMTB_INLINE inline void tensor_gather_into(const Policy& policy, const Stencil<Dim, Kernel>& st,
                                            const GridGeometry<Dim>& g, const Real* rows,
                                            typename Policy::Gather& gather) {
  constexpr TensorTerms terms = Policy::gather_terms;
  static_assert(terms.nodal);
  policy.gather_from(
      TensorTransfer<Dim, Kernel>::template gather<terms>(st, g, rows, gather.v_data()), gather);
}

// G2P on the fast path: the policy's Gather from the packed velocity rows
// (VelocityRows) around the particle.
template <class Policy, int Dim, class Kernel>
MPMTB_INLINE inline typename Policy::Gather tensor_gather(const Policy& policy,
                                                          const Stencil<Dim, Kernel>& st,
                                                          const GridGeometry<Dim>& g,
                                                          const Real* rows) {
  constexpr TensorTerms terms = Policy::gather_terms;
  using Sums = TensorTransfer<Dim, Kernel>;
  if constexpr (terms.nodal) {
    typename Policy::Gather gather = begin_gather(policy, st);
    tensor_gather_into(policy, st, g, rows, gather);
    return gather;
  } else {
    return policy.gather_from(Sums::template gather<terms>(st, g, rows));
  }
}

// True when Policy itself (not only a base class) finishes from the rows.
template <class Policy>
using FinishRowsOf = typename Policy::FinishRows;
template <class Policy>
constexpr bool has_finish_rows() {
  return names_itself<FinishRowsOf, Policy>();
}

}  // namespace mpmtb
