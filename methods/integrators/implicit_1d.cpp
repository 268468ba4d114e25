// The implicit step in 1D, for every kernel (integrators/implicit_impl.hpp).
#include "integrators/implicit_impl.hpp"

namespace mpmtb {
template std::unique_ptr<ImplicitSolve<1>> make_implicit_solve<1>(std::string_view, Integrator,
                                                                  const ImplicitOptions&);
}  // namespace mpmtb
