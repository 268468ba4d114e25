// Compiles apic for every dimension and kernel.
#include "transfers/apic.hpp"

#include "core/solver_impl.hpp"

template struct mpmtb::SolverInstances<mpmtb::ApicTransfer>;
