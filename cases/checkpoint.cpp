#include "checkpoint.hpp"

#include <fmt/format.h>

#include "core/errors.hpp"

namespace mpmtb {

template <int Dim>
void save_state(ArchiveWriter& a, const State<Dim>& s) {
  const Particles<Dim>& P = s.particles;
  a.put("dim", Dim);
  a.put("real_bytes", static_cast<int>(sizeof(Real)));
  a.put("particles", static_cast<std::uint64_t>(P.size()));
  a.put_vector("x", P.x);
  a.put_vector("v", P.v);
  a.put_vector("C", P.C);
  a.put_vector("F", P.F);
  a.put_vector("m", P.m);
  a.put_vector("V0", P.V0);
  a.put_vector("material", P.material);
  a.put_vector("pinned", P.pinned);
  a.put("state_size", P.state_size);
  a.put_vector("state", P.state);
  a.put("transfer_state_size", P.transfer_state_size);
  a.put_vector("transfer_state", P.transfer_state);
  a.put("collider_impulse", s.collider_impulse);
  a.put("pin_impulse", s.pin_impulse);
  a.put("collider_work", s.collider_work);
  a.put("time", s.time);
  a.put("step", s.step);
}

template <int Dim>
void restore_state(ArchiveReader& a, State<Dim>& s) {
  Particles<Dim>& P = s.particles;
  auto expect = [&](const char* what, auto found, auto wanted) {
    if (found != wanted) {
      throw InputError(fmt::format(
          "{}: {} is {} in the checkpoint but {} for the scene it records (a checkpoint of "
          "another build or scene)",
          a.source(), what, found, wanted));
    }
  };
  int dim = 0, real_bytes = 0;
  std::uint64_t count = 0;
  a.get("dim", dim);
  expect("dim", dim, Dim);
  a.get("real_bytes", real_bytes);
  expect("the size of a Real", real_bytes, static_cast<int>(sizeof(Real)));
  a.get("particles", count);
  expect("the particle count", count, static_cast<std::uint64_t>(P.size()));
  const std::vector<int> seeded_material = P.material;
  a.get_vector("x", P.x);
  a.get_vector("v", P.v);
  a.get_vector("C", P.C);
  a.get_vector("F", P.F);
  a.get_vector("m", P.m);
  a.get_vector("V0", P.V0);
  a.get_vector("material", P.material);
  a.get_vector("pinned", P.pinned);
  int state_size = 0;
  a.get("state_size", state_size);
  expect("the per-model state size", state_size, P.state_size);
  a.get_vector("state", P.state);
  a.get("transfer_state_size", P.transfer_state_size);
  a.get_vector("transfer_state", P.transfer_state);
  for (const auto* field : {&P.x, &P.v})
    expect("a position or velocity count", field->size(), count);
  expect("F's count", P.F.size(), count);
  expect("the per-model state length", P.state.size(), count * P.state_size);
  expect("the per-transfer state length", P.transfer_state.size(), count * P.transfer_state_size);
  // The material index lists (State::material_particles) were built from the
  // seeded materials; they are valid only if the checkpoint agrees.
  if (P.material != seeded_material) {
    throw InputError(
        fmt::format("{}: the particles' materials differ from the scene's seeding", a.source()));
  }
  a.get("collider_impulse", s.collider_impulse);
  a.get("pin_impulse", s.pin_impulse);
  a.get("collider_work", s.collider_work);
  a.get("time", s.time);
  a.get("step", s.step);
}

nlohmann::json read_checkpoint_meta(ArchiveReader& a) {
  try {
    return nlohmann::json::parse(a.get_string("meta"));
  } catch (const nlohmann::json::exception& e) {
    throw InputError(fmt::format("{}: the meta record is not JSON: {}", a.source(), e.what()));
  }
}

template void save_state<1>(ArchiveWriter&, const State<1>&);
template void save_state<2>(ArchiveWriter&, const State<2>&);
template void save_state<3>(ArchiveWriter&, const State<3>&);
template void restore_state<1>(ArchiveReader&, State<1>&);
template void restore_state<2>(ArchiveReader&, State<2>&);
template void restore_state<3>(ArchiveReader&, State<3>&);

}  // namespace mpmtb
