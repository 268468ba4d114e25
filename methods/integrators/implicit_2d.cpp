// The implicit step in 2D, for every kernel (integrators/implicit_impl.hpp).
#include "integrators/implicit_impl.hpp"

namespace mpmtb {
template std::unique_ptr<ImplicitSolve<2>> make_implicit_solve<2>(std::string_view, Integrator,
                                                                  const ImplicitOptions&);
}  // namespace mpmtb
