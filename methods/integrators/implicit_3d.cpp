// The implicit step in 3D, for every kernel (integrators/implicit_impl.hpp).
#include "integrators/implicit_impl.hpp"

namespace mpmtb {
template std::unique_ptr<ImplicitSolve<3>> make_implicit_solve<3>(std::string_view, Integrator,
                                                                  const ImplicitOptions&);
}  // namespace mpmtb
