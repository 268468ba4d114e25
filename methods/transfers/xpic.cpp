// Compiles xpic for every dimension and kernel.
#include "transfers/xpic.hpp"

#include "core/solver_impl.hpp"

template struct mpmtb::SolverInstances<mpmtb::XpicTransfer>;
