// A minimal compile-time list of types, used by the registries.
#pragma once

#include <utility>

namespace mpmtb {

template <class... Ts>
struct TypeList {
  static constexpr std::size_t size = sizeof...(Ts);
  // Calls f.template operator()<T>() for every T in order.
  template <class F>
  static void for_each(F&& f) {
    (f.template operator()<Ts>(), ...);
  }
};

}  // namespace mpmtb
