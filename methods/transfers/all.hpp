// The transfer registry: every scheme listed here is compiled for every kernel
// and dimension and joins the conformance tests and suites.
// Adding a transfer: its .hpp and .cpp + one entry here.
#pragma once

#include "core/type_list.hpp"
#include "transfers/apic.hpp"
#include "transfers/asflip.hpp"
#include "transfers/flip.hpp"
#include "transfers/mls.hpp"
#include "transfers/pic.hpp"
#include "transfers/polypic.hpp"
#include "transfers/tpic.hpp"
#include "transfers/xpic.hpp"

namespace mpmtb {

using AllTransfers = TypeList<PicTransfer, FlipTransfer, ApicTransfer, MlsTransfer, TpicTransfer,
                              PolypicTransfer, XpicTransfer, AflipTransfer, AsflipTransfer>;

}  // namespace mpmtb
