// `mpmtb describe SCENE`: the scene's effective parameters after overrides,
// defaults included and marked, then the scene tree itself.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <iostream>

#include "boundary/walls.hpp"
#include "commands.hpp"
#include "core/registry.hpp"
#include "models/registry.hpp"
#include "setup.hpp"

namespace mpmtb {
namespace {

std::string vec(const Vec3& v, int dim) {
  std::vector<std::string> c;
  for (int a = 0; a < dim; ++a) c.push_back(fmt::format("{:g}", v[a]));
  return fmt::format("[{}]", fmt::join(c, ", "));
}

// "(default)" when the scene tree does not set the dotted key.
std::string mark(const Scene& s, const std::string& key) {
  return s.resolved.at_path(key) ? "" : "  (default)";
}

void print_parameters(const std::string& title, const Parameters& p) {
  for (const auto& [key, r] : p.read()) {
    fmt::print("  {:<28} {:<12g} {}{}\n", title + "." + key, r.value, r.range,
               r.defaulted ? "  (default)" : "");
  }
}

template <int Dim>
void describe_dim(const Scene& s) {
  fmt::print("  {:<28} {}{}\n", "dim", s.dim,
             fmt::format("  (supports {})", fmt::join(s.dims, ", ")));
  fmt::print("  {:<28} {} .. {}\n", "domain", vec(s.domain_min, Dim), vec(s.domain_max, Dim));
  const auto geo = scene_grid<Dim>(s);
  fmt::print("  {:<28} {}{}\n", "grid.cells", s.cells, "  (along grid.length)");
  fmt::print("  {:<28} {:g}{}  -> dx = {:g}, {} cells\n", "grid.length", s.length,
             mark(s, "grid.length"), s.dx(), fmt::join(geo.cells, " x "));
  fmt::print("  {:<28} {}{}\n", "grid.ppc", s.ppc, mark(s, "grid.ppc"));
  fmt::print("  {:<28} {}\n", "method.transfer", s.transfer);
  fmt::print("  {:<28} {}\n", "method.kernel", s.kernel);
  Parameters transfer = s.transfer_params;
  {
    auto stepper = make_stepper<Dim>(s.transfer, s.kernel, transfer);
    stepper->set_update_order(s.update_order);
    stepper->set_integrator(s.integrator, s.implicit);
  }
  fmt::print("  {:<28} {}{}\n", "method.update_order", update_order_name(s.update_order),
             mark(s, "method.update_order"));
  fmt::print("  {:<28} {}{}\n", "method.integrator", integrator_name(s.integrator),
             mark(s, "method.integrator"));
  print_parameters(s.transfer, transfer);
  fmt::print("  {:<28} {:g}\n", "time.t_end", s.t_end);
  if (s.dt) fmt::print("  {:<28} {:g}  (fixed step)\n", "time.dt", *s.dt);
  if (s.cfl) fmt::print("  {:<28} {:g}  (dt = cfl dx / (c_p + max|v|))\n", "time.cfl", *s.cfl);
  fmt::print("  {:<28} {:g}{}\n", "time.output_interval", s.output_interval,
             mark(s, "time.output_interval"));
  fmt::print("  {:<28} {}{}\n", "physics.gravity", vec(s.gravity, Dim), mark(s, "physics.gravity"));
  static const char* faces[] = {"x_min", "x_max", "y_min", "y_max", "z_min", "z_max"};
  for (int f = 0; f < 2 * Dim; ++f) {
    const std::string key = std::string("boundary.") + faces[f];
    fmt::print("  {:<28} {}{}\n", key, s.walls[f],
               s.resolved.at_path(key) ? "" : "  (boundary.default)");
  }
  fmt::print("  {:<28} {:g}{}\n", "checks.energy_limit", s.energy_limit,
             mark(s, "checks.energy_limit"));
  for (const auto& m : s.materials) {
    fmt::print("  {:<28} {}\n", "materials." + m.name + ".model", m.model);
    Parameters params = m.params;
    make_model<Dim>(m.model, params);
    print_parameters("materials." + m.name, params);
  }
  for (std::size_t b = 0; b < s.bodies.size(); ++b) {
    const auto& body = s.bodies[b];
    const std::string where =
        body.shape == "box"
            ? fmt::format("{} .. {}", vec(body.min, Dim), vec(body.max, Dim))
            : fmt::format("center {}, radius {:g}", vec(body.center, Dim), body.radius);
    fmt::print("  {:<28} {} {}, material {}, velocity {}\n", fmt::format("bodies.{}", b),
               body.shape, where, s.materials[body.material].name, vec(body.velocity, Dim));
  }
  for (std::size_t p = 0; p < s.pins.size(); ++p) {
    fmt::print("  {:<28} box {} .. {}\n", fmt::format("pins.{}", p), vec(s.pins[p].min, Dim),
               vec(s.pins[p].max, Dim));
  }
  for (std::size_t c = 0; c < s.colliders.size(); ++c) {
    const auto& col = s.colliders[c];
    fmt::print("  {:<28} sphere center {}, radius {:g}, velocity {}, wall {}\n",
               fmt::format("colliders.{}", c), vec(col.start, Dim), col.radius,
               vec(col.velocity, Dim), wall_name(col.wall));
  }
  if (!s.reference.empty()) {
    fmt::print("  {:<28} {}\n", "reference.kind", s.reference);
    for (const auto& [k, v] : s.reference_params.values())
      fmt::print("  {:<28} {:g}\n", "reference." + k, v);
  }
  const State<Dim> state = build_state<Dim>(s);
  fmt::print("  {:<28} {}\n", "(particles)", state.particles.size());
}

}  // namespace

int command_describe(const std::string& scene, const Overrides& overrides) {
  const Scene s = load_scene(scene, overrides);
  fmt::print("{}: {}\n{}\n", s.name, s.description, s.source);
  fmt::print("effective parameters after overrides (change any with --set key=value):\n");
  if (s.dim == 1) describe_dim<1>(s);
  if (s.dim == 2) describe_dim<2>(s);
  if (s.dim == 3) describe_dim<3>(s);
  std::cout << "\n# the scene tree after overrides\n" << s.resolved << "\n";
  return kExitOk;
}

}  // namespace mpmtb
