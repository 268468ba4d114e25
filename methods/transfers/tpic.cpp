// Compiles tpic for every dimension and kernel.
#include "transfers/tpic.hpp"

#include "core/solver_impl.hpp"

template struct mpmtb::SolverInstances<mpmtb::TpicTransfer>;
