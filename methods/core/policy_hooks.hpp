// Optional per-particle hooks of a transfer policy, called generically by the base
// solver (and by the tests that compare its two paths): a policy that needs the
// particle's stencil at the start of P2G or G2P (e.g. the affine transfers with a
// kernel whose D_p differs per particle, transfers/affine.hpp) declares
//   Source prepare(P, p, tauV, stencil)   beside, or instead of, Source prepare(P, p, tauV)
//   Gather begin_gather(stencil)          returning its own Gather type.
// Policies without them (or whose own Source/Gather types hide a base's) are called
// as before.
#pragma once

#include <concepts>

#include "core/particles.hpp"
#include "core/stencil.hpp"

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

}  // namespace mpmtb
