// Compiles asflip for every dimension and kernel.
#include "transfers/asflip.hpp"

#include "core/solver_impl.hpp"

template struct mpmtb::SolverInstances<mpmtb::AflipTransfer>;
template struct mpmtb::SolverInstances<mpmtb::AsflipTransfer>;
