// Compiles flip for every dimension and kernel.
#include "transfers/flip.hpp"

#include "core/solver_impl.hpp"

template struct mpmtb::SolverInstances<mpmtb::FlipTransfer>;
