// The transfer-independent stages in 1D, for every kernel (core/solver_stages.hpp).
#include "core/solver_stages_impl.hpp"

template void mpmtb::instantiate_solver_stages<1>();
