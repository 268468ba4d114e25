#include "core/registry.hpp"

#include <fmt/format.h>

#include "core/combinations.hpp"
#include "core/errors.hpp"
#include "core/solver.hpp"
#include "kernels/all.hpp"
#include "transfers/all.hpp"

namespace mpmtb {
namespace {

template <class List>
std::vector<VariantInfo> infos() {
  std::vector<VariantInfo> out;
  List::for_each([&]<class T>() {
    out.push_back({std::string(T::name), std::string(T::description), std::string(T::bibtex)});
  });
  return out;
}

std::string joined_names(const std::vector<VariantInfo>& list) {
  std::string s;
  for (const auto& v : list) s += (s.empty() ? "" : ", ") + v.name;
  return s;
}

void require_known(std::string_view transfer, std::string_view kernel) {
  bool t_ok = false, k_ok = false;
  AllTransfers::for_each([&]<class T>() { t_ok |= T::name == transfer; });
  AllKernels::for_each([&]<class K>() { k_ok |= K::name == kernel; });
  if (!t_ok) {
    throw InputError(fmt::format("method.transfer: unknown transfer '{}'; allowed: {}", transfer,
                                 joined_names(transfer_list())));
  }
  if (!k_ok) {
    throw InputError(fmt::format("method.kernel: unknown kernel '{}'; allowed: {}", kernel,
                                 joined_names(kernel_list())));
  }
}

}  // namespace

std::vector<VariantInfo> transfer_list() {
  std::vector<VariantInfo> out = infos<AllTransfers>();
  std::size_t i = 0;
  AllTransfers::for_each([&]<class T>() {
    out[i].affine = T::affine_momentum;
    if constexpr (requires { T::positions_follow_momentum; })
      out[i].positions_follow_momentum = T::positions_follow_momentum;
    out[i++].conserves_angular_momentum = T::conserves_angular_momentum;
  });
  return out;
}
std::vector<VariantInfo> kernel_list() {
  return infos<AllKernels>();
}

std::string unsupported_reason(std::string_view transfer, std::string_view kernel) {
  require_known(transfer, kernel);
  std::string reason;
  AllTransfers::for_each([&]<class T>() {
    if (T::name != transfer) return;
    AllKernels::for_each([&]<class K>() {
      if (K::name != kernel) return;
      if constexpr (!T::template supports<K>) {
        reason = fmt::format("transfer '{}' with kernel '{}' is refused: {}", T::name, K::name,
                             T::unsupported_reason);
      }
    });
  });
  return reason;
}

bool compiled_combination(std::string_view transfer, std::string_view kernel) {
  require_known(transfer, kernel);
  bool compiled = false;
  AllTransfers::for_each([&]<class T>() {
    AllKernels::for_each([&]<class K>() {
      compiled |= kCompiled<T, K> && T::name == transfer && K::name == kernel;
    });
  });
  return compiled;
}

template <int Dim>
std::unique_ptr<Stepper<Dim>> make_stepper(std::string_view transfer, std::string_view kernel,
                                           Parameters& transfer_params) {
  if (auto reason = unsupported_reason(transfer, kernel); !reason.empty()) {
    throw InputError(reason);
  }
  if (!compiled_combination(transfer, kernel)) {
    std::vector<VariantInfo> compiled = kernel_list();
    std::erase_if(compiled,
                  [&](const VariantInfo& k) { return !compiled_combination(transfer, k.name); });
    throw InputError(
        fmt::format("method.kernel: transfer '{}' with kernel '{}' is not compiled in this build "
                    "(MPMTB_COMBINATIONS=reduced); kernels compiled for '{}': {}",
                    transfer, kernel, transfer, joined_names(compiled)));
  }
  std::unique_ptr<Stepper<Dim>> stepper;
  AllTransfers::for_each([&]<class T>() {
    if (T::name != transfer) return;
    AllKernels::for_each([&]<class K>() {
      if constexpr (kCompiled<T, K>) {
        if (K::name == kernel) stepper = make_solver<Dim, K, T>(transfer_params);
      }
    });
  });
  return stepper;
}

template <int Dim>
long clamped_domains(std::string_view kernel, const std::vector<Mat<Dim>>& F, Real l0) {
  long count = -1;
  AllKernels::for_each([&]<class K>() {
    if constexpr (requires { K::template domain_clamped<Dim>(l0, F[0]); }) {
      if (K::name != kernel) return;
      count = 0;
      for (const auto& Fp : F) count += K::template domain_clamped<Dim>(l0, Fp);
    }
  });
  return count;
}

template long clamped_domains<1>(std::string_view, const std::vector<Mat<1>>&, Real);
template long clamped_domains<2>(std::string_view, const std::vector<Mat<2>>&, Real);
template long clamped_domains<3>(std::string_view, const std::vector<Mat<3>>&, Real);

template std::unique_ptr<Stepper<1>> make_stepper<1>(std::string_view, std::string_view,
                                                     Parameters&);
template std::unique_ptr<Stepper<2>> make_stepper<2>(std::string_view, std::string_view,
                                                     Parameters&);
template std::unique_ptr<Stepper<3>> make_stepper<3>(std::string_view, std::string_view,
                                                     Parameters&);

}  // namespace mpmtb
