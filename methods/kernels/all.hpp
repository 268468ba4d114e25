// The kernel registry: every kernel listed here is compiled into every transfer
// and joins the conformance tests. Adding a kernel: its header + one entry here.
#pragma once

#include "core/type_list.hpp"
#include "kernels/cubic.hpp"
#include "kernels/gimp.hpp"
#include "kernels/linear.hpp"
#include "kernels/quadratic.hpp"

namespace mpmtb {

using AllKernels = TypeList<LinearKernel, QuadraticKernel, CubicKernel, GimpKernel>;

}  // namespace mpmtb
