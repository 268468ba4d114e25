// The transfer registry: every scheme listed here is compiled for every kernel
// and dimension and joins the conformance tests and suites.
// Adding a transfer: its .hpp and .cpp + one entry here.
#pragma once

#include "core/type_list.hpp"
#include "transfers/mls.hpp"

namespace mpmtb {

using AllTransfers = TypeList<MlsTransfer>;

}  // namespace mpmtb
