// Compiles polypic for every dimension and kernel.
#include "transfers/polypic.hpp"

#include "core/solver_impl.hpp"

template struct mpmtb::SolverInstances<mpmtb::PolypicTransfer>;
