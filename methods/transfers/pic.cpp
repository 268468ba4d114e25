// Compiles pic for every dimension and kernel.
#include "transfers/pic.hpp"

#include "core/solver_impl.hpp"

template struct mpmtb::SolverInstances<mpmtb::PicTransfer>;
