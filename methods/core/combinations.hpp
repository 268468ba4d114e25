// Which transfer x kernel combinations this build compiles: the CMake option
// MPMTB_COMBINATIONS (all, the default, or reduced, which defines
// MPMTB_REDUCED_COMBINATIONS). SolverInstances (core/solver_impl.hpp) compiles
// the solvers of these combinations, for every dimension; the registry
// (core/registry.cpp) resolves names only to them and refuses the others.
#pragma once

// The default build includes nothing here: the transfers' translation units
// then see exactly what they saw before the option, and GCC emits the same code
// for them (checked function by function with objdump -d; with the registries
// included here, register allocation moved in some functions).
#ifdef MPMTB_REDUCED_COMBINATIONS
#include <type_traits>

#include "kernels/all.hpp"
#include "transfers/all.hpp"
#endif

namespace mpmtb {

#ifdef MPMTB_REDUCED_COMBINATIONS
inline constexpr bool kReducedCombinations = true;

// The reduced set is for the sanitizer tree (scripts/sanitize.sh), where
// compiling the solvers dominates the stage: every code path once, not every
// product of them.
// * Every transfer with the quadratic B-spline (which all of them support):
//   each transfer's own math runs.
// * Every kernel with two transfers, one of each scatter form of the solver
//   (folds_force, core/solver_impl.hpp): FLIP keeps v_old, so its force is
//   scattered apart from the momentum; MLS-MPM folds the force into the
//   momentum and, being affine, runs the kernel's own branch of D_p
//   (transfers/affine.hpp: constant for the B-splines, the gradient form for
//   the hat, per particle for uGIMP and cpGIMP). CPDI refuses the affine
//   transfers (full D_p), so PIC folds for it.
// The transfer-independent stages are compiled for every kernel with both
// scatter forms anyway (core/solver_stages_*d.cpp); this set runs both.
template <class Kernel>
using FoldingPartner =
    std::conditional_t<MlsTransfer::template supports<Kernel>, MlsTransfer, PicTransfer>;

// True when the solvers of (Transfer, Kernel) are compiled in this build.
template <class Transfer, class Kernel>
inline constexpr bool kCompiled = Transfer::template supports<Kernel> &&
                                  (std::is_same_v<Kernel, QuadraticKernel> ||
                                   std::is_same_v<Transfer, FlipTransfer> ||
                                   std::is_same_v<Transfer, FoldingPartner<Kernel>>);
#else
inline constexpr bool kReducedCombinations = false;
// The default build: every combination the transfer supports.
template <class Transfer, class Kernel>
inline constexpr bool kCompiled = Transfer::template supports<Kernel>;
#endif

}  // namespace mpmtb
