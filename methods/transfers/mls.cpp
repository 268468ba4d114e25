// Compiles MLS-MPM for every dimension and kernel.
#include "transfers/mls.hpp"

#include "core/solver_impl.hpp"

template struct mpmtb::SolverInstances<mpmtb::MlsTransfer>;
