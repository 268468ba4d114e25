#include "scene.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "boundary/walls.hpp"
#include "core/errors.hpp"
#include "core/registry.hpp"
#include "models/registry.hpp"
#include "references/reference.hpp"
#include "table_reader.hpp"

namespace mpmtb {
namespace {

const std::array<std::string, 6> kFaceNames = {"x_min", "x_max", "y_min",
                                               "y_max", "z_min", "z_max"};

template <class Info>
std::vector<std::string> names_of(const std::vector<Info>& list) {
  std::vector<std::string> out;
  for (const auto& i : list) out.push_back(i.name);
  return out;
}

void read_header(TableReader& top, Scene& s) {
  TableReader r(top.table("scene"), "scene");
  s.name = r.string("name");
  s.description = r.string_or("description", "");
  s.dim = r.integer("dim", 1, 3);
  s.dims = r.has("dims") ? r.int_list("dims", 1, 3) : std::vector<int>{s.dim};
  r.finish();
  if (std::find(s.dims.begin(), s.dims.end(), s.dim) == s.dims.end()) {
    throw InputError(fmt::format("scene.dim = {} is not supported by scene '{}'; allowed: {}",
                                 s.dim, s.name, fmt::join(s.dims, ", ")));
  }
}

void read_domain_and_grid(TableReader& top, Scene& s) {
  TableReader d(top.table("domain"), "domain");
  s.domain_min = d.vec3("min");
  s.domain_max = d.vec3("max");
  d.finish();
  for (int a = 0; a < s.dim; ++a) {
    if (!(s.domain_max[a] > s.domain_min[a])) {
      throw InputError(fmt::format("domain.max[{}] = {} must exceed domain.min[{}] = {}", a,
                                   s.domain_max[a], a, s.domain_min[a]));
    }
  }
  TableReader g(top.table("grid"), "grid");
  s.cells = g.integer("cells", 1, 1 << 20);
  s.length = g.number_or("length", s.domain_max[0] - s.domain_min[0], Range::positive());
  s.ppc = g.integer_or("ppc", 2, 1, 16);
  g.finish();
}

void read_method(TableReader& top, Scene& s) {
  TableReader m(top.table("method"), "method");
  s.transfer = m.choice("transfer", names_of(transfer_list()));
  s.kernel = m.choice("kernel", names_of(kernel_list()));
  if (m.has("update_order")) {
    const std::vector<std::string> orders(kUpdateOrderNames.begin(), kUpdateOrderNames.end());
    const std::string order = m.choice("update_order", orders);
    s.update_order =
        static_cast<UpdateOrder>(std::find(orders.begin(), orders.end(), order) - orders.begin());
  } else if (auto* method = s.resolved["method"].as_table()) {
    // Recorded in summaries like the other method keys, default included.
    method->insert("update_order", std::string(update_order_name(s.update_order)));
  }
  // Not recorded in summaries when absent: an explicit run's summary stays as
  // it was before the implicit integrators (the gate compares it exactly).
  if (m.has("integrator")) s.integrator = parse_integrator(m.string("integrator"));
  // The implicit integrators' Newton solve (integrators/implicit_impl.hpp).
  s.implicit.newton_tol = m.number_or("newton_tol", s.implicit.newton_tol, Range::open(0, 1));
  s.implicit.newton_max = m.integer_or("newton_max", s.implicit.newton_max, 1, 10000);
  s.implicit.cg_tol = m.number_or("cg_tol", s.implicit.cg_tol, Range::open(0, 1));
  s.implicit.cg_max = m.integer_or("cg_max", s.implicit.cg_max, 1, 1000000);
  m.finish();
  // A table named after a transfer holds that transfer's parameters ([flip] alpha = ...).
  // Tables of the other transfers are kept for switching with --transfer, but
  // must hold numbers too.
  for (const auto& t : transfer_list()) {
    const toml::table* params = top.table_or_null(t.name);
    Parameters read(t.name);
    if (params) read = TableReader(*params, t.name).numbers_as_parameters({});
    if (t.name == s.transfer) s.transfer_params = read;
  }
}

void read_time(TableReader& top, Scene& s) {
  TableReader t(top.table("time"), "time");
  s.t_end = t.number("t_end", Range::positive());
  if (t.has("dt") == t.has("cfl")) {
    throw InputError("time: give exactly one of 'dt' (fixed step) or 'cfl' (adaptive step)");
  }
  if (t.has("dt")) s.dt = t.number("dt", Range::positive());
  if (t.has("cfl")) s.cfl = t.number("cfl", Range::positive());
  s.output_interval = t.number_or("output_interval", s.t_end / 100, Range::positive());
  t.finish();
}

void read_physics_and_walls(TableReader& top, Scene& s) {
  if (const toml::table* p = top.table_or_null("physics")) {
    TableReader r(*p, "physics");
    s.gravity = r.vec3_or("gravity", Vec3::Zero());
    r.finish();
  }
  std::string fallback = "free";
  s.walls.fill(fallback);
  if (const toml::table* b = top.table_or_null("boundary")) {
    TableReader r(*b, "boundary");
    fallback = r.has("default") ? r.choice("default", wall_names()) : fallback;
    for (std::size_t f = 0; f < kFaceNames.size(); ++f) {
      s.walls[f] = r.has(kFaceNames[f]) ? r.choice(kFaceNames[f], wall_names()) : fallback;
    }
    r.finish();
  }
  if (const toml::table* c = top.table_or_null("checks")) {
    TableReader r(*c, "checks");
    s.energy_limit = r.number_or("energy_limit", s.energy_limit, Range::open(1, 1e300));
    s.J_floor = r.number_or("J_floor", s.J_floor, Range::half_open(0, 1));
    r.finish();
  }
}

void read_materials(TableReader& top, Scene& s) {
  const toml::table& mats = top.table("materials");
  if (mats.empty()) throw InputError("materials: at least one material is required");
  for (const auto& [k, v] : mats) {
    const std::string name(k.str());
    const toml::table* t = v.as_table();
    if (!t) throw InputError(fmt::format("materials.{}: expected a table", name));
    TableReader r(*t, "materials." + name);
    MaterialSpec m;
    m.name = name;
    m.model = r.choice("model", names_of(model_list()));
    m.params = r.numbers_as_parameters({"model"});
    r.finish();
    Parameters probe = m.params;  // validates the parameters now, by the model itself
    make_model<1>(m.model, probe);
    s.materials.push_back(std::move(m));
  }
}

int material_index(const Scene& s, const std::string& name, const std::string& field) {
  std::vector<std::string> names;
  for (std::size_t i = 0; i < s.materials.size(); ++i) {
    if (s.materials[i].name == name) return static_cast<int>(i);
    names.push_back(s.materials[i].name);
  }
  throw InputError(
      fmt::format("{}: unknown material '{}'; defined: {}", field, name, fmt::join(names, ", ")));
}

// A body's `fiber` (and `fiber2`): nonzero in the scene's dimensions, zero in
// the others, normalised; only for a material whose model takes fibres, which
// then needs at least `fiber`.
void read_fibers(TableReader& r, const Scene& s, const std::string& path, BodySpec& b) {
  for (const char* key : {"fiber", "fiber2"}) {
    if (!r.has(key)) continue;
    if (b.fibers.empty() && std::string(key) == "fiber2")
      throw InputError(
          fmt::format("{}.fiber2: give `fiber` first (fiber2 is a second family)", path));
    Vec3 a = r.vec3(key);
    for (int i = s.dim; i < 3; ++i) {
      if (a[i] != 0) {
        throw InputError(
            fmt::format("{}.{}: component {} must be 0 in {}D, got {}", path, key, i, s.dim, a[i]));
      }
    }
    if (!(a.norm() > 0) || !std::isfinite(a.norm())) {
      throw InputError(
          fmt::format("{}.{}: the fibre direction must be a nonzero finite vector [ax, ay, az], "
                      "got [{}, {}, {}]",
                      path, key, a[0], a[1], a[2]));
    }
    b.fibers.push_back(a.normalized());
  }
  const MaterialSpec& m = s.materials[b.material];
  Parameters probe = m.params;
  const int families = make_model<1>(m.model, probe)->fiber_families();
  if (families == 0 && !b.fibers.empty()) {
    throw InputError(fmt::format(
        "{}.fiber: material '{}' uses model '{}', which takes no fibre direction (models with "
        "fibres: aniso-damage)",
        path, m.name, m.model));
  }
  if (families > 0 && b.fibers.empty()) {
    throw InputError(fmt::format(
        "{}: material '{}' uses model '{}', which needs the fibre direction `fiber = [ax, ay, az]`",
        path, m.name, m.model));
  }
  if (static_cast<int>(b.fibers.size()) > families) {
    throw InputError(
        fmt::format("{}.fiber2: model '{}' takes {} fibre family", path, m.model, families));
  }
}

void read_bodies(TableReader& top, Scene& s) {
  const auto bodies = top.table_array("bodies");
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const std::string path = fmt::format("bodies[{}]", i);
    TableReader r(*bodies[i], path);
    BodySpec b;
    b.shape = r.choice("shape", {"box", "sphere", "ring"});
    if (b.shape == "box") {
      b.min = r.vec3("min");
      b.max = r.vec3("max");
      for (int a = 0; a < s.dim; ++a) {
        if (!(b.max[a] > b.min[a])) {
          throw InputError(fmt::format("{}.max[{}] must exceed {}.min[{}]", path, a, path, a));
        }
      }
    } else {
      b.center = r.vec3("center");
      b.radius = r.number("radius", Range::positive());
      if (b.shape == "ring") {
        b.inner_radius = r.number("inner_radius", Range::half_open(0, b.radius));
      }
    }
    b.material = material_index(s, r.string("material"), path + ".material");
    b.velocity = r.vec3_or("velocity", Vec3::Zero());
    b.angular_velocity = r.vec3_or("angular_velocity", Vec3::Zero());
    b.stretch_rate = r.vec3_or("stretch_rate", Vec3::Zero());
    if (r.has("cut_min") || r.has("cut_max")) {
      b.cut_min = r.vec3("cut_min");
      b.cut_max = r.vec3("cut_max");
      for (int a = 0; a < s.dim; ++a) {
        if (!(b.cut_max[a] > b.cut_min[a])) {
          throw InputError(fmt::format("{}.cut_max[{}] must exceed {}.cut_min[{}] (give both)",
                                       path, a, path, a));
        }
      }
    }
    read_fibers(r, s, path, b);
    r.finish();
    Vec3 lo, hi;
    b.bounds(lo, hi);
    for (int a = 0; a < s.dim; ++a) {
      if (lo[a] < s.domain_min[a] || hi[a] > s.domain_max[a]) {
        throw InputError(
            fmt::format("{}: extends outside the domain along axis {} ([{}, {}] vs "
                        "domain [{}, {}])",
                        path, a, lo[a], hi[a], s.domain_min[a], s.domain_max[a]));
      }
    }
    s.bodies.push_back(b);
  }
  if (top.has("colliders")) {
    const auto colliders = top.table_array("colliders");
    for (std::size_t i = 0; i < colliders.size(); ++i) {
      const std::string path = fmt::format("colliders[{}]", i);
      TableReader r(*colliders[i], path);
      r.choice("shape", {"sphere"});
      SphereCollider c;
      c.start = r.vec3("center");
      c.radius = r.number("radius", Range::positive());
      c.velocity = r.vec3_or("velocity", Vec3::Zero());
      c.wall = parse_wall(r.string_or("wall", "sticky"), path + ".wall");
      r.finish();
      if (c.wall == Wall::free) throw InputError(path + ".wall: a collider cannot be free");
      s.colliders.push_back(c);
    }
  }
  if (top.has("pins")) {
    const auto pins = top.table_array("pins");
    for (std::size_t i = 0; i < pins.size(); ++i) {
      TableReader r(*pins[i], fmt::format("pins[{}]", i));
      s.pins.push_back({r.vec3("min"), r.vec3("max")});
      r.finish();
    }
  }
}

void read_reference(TableReader& top, Scene& s) {
  const toml::table* t = top.table_or_null("reference");
  if (!t) return;
  TableReader r(*t, "reference");
  s.reference = r.choice("kind", reference_kinds());
  s.reference_params = r.numbers_as_parameters({"kind"});
  r.finish();
}

// UTF-8 (RFC 3629): scene trees are recorded in summary.json, which must be valid JSON text.
bool is_valid_utf8(const std::string& text) {
  for (std::size_t i = 0; i < text.size();) {
    const auto c = static_cast<unsigned char>(text[i]);
    const int extra = c < 0x80           ? 0
                      : (c >> 5) == 0x6  ? 1
                      : (c >> 4) == 0xE  ? 2
                      : (c >> 3) == 0x1E ? 3
                                         : -1;
    if (extra < 0 || i + extra >= text.size()) return false;
    std::uint32_t code = extra == 0 ? c : c & (0x3F >> extra);
    for (int k = 1; k <= extra; ++k) {
      const auto d = static_cast<unsigned char>(text[i + k]);
      if ((d >> 6) != 0x2) return false;
      code = (code << 6) | (d & 0x3F);
    }
    const std::uint32_t min_code[] = {0, 0x80, 0x800, 0x10000};
    if (code < min_code[extra] || code > 0x10FFFF || (code >= 0xD800 && code <= 0xDFFF)) {
      return false;
    }
    i += 1 + extra;
  }
  return true;
}

}  // namespace

Vec3 BodySpec::rotation_center() const {
  return shape == "box" ? Vec3((min + max) / 2) : center;
}

bool BodySpec::contains(const Vec3& x, int dim) const {
  bool in_cut = cut_max[0] > cut_min[0];
  for (int a = 0; a < dim && in_cut; ++a) in_cut = x[a] >= cut_min[a] && x[a] < cut_max[a];
  if (in_cut) return false;
  if (shape == "box") {
    for (int a = 0; a < dim; ++a) {
      if (x[a] < min[a] || x[a] >= max[a]) return false;
    }
    return true;
  }
  const Real r = (x - center).head(dim).norm();
  return r < radius && r >= inner_radius;
}

void BodySpec::bounds(Vec3& lo, Vec3& hi) const {
  if (shape == "box") {
    lo = min;
    hi = max;
  } else {
    lo = center - Vec3::Constant(radius);
    hi = center + Vec3::Constant(radius);
  }
}

toml::table parse_scene_text(const std::string& text, const std::string& source) {
  try {
    return toml::parse(text, source);
  } catch (const toml::parse_error& e) {
    throw InputError(fmt::format("{}:{}:{}: malformed TOML: {}", source, e.source().begin.line,
                                 e.source().begin.column, e.description()));
  }
}

void apply_set(toml::table& tree, const std::string& assignment) {
  if (!is_valid_utf8(assignment)) {
    throw InputError("--set: the assignment is not valid UTF-8 text");
  }
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == assignment.size()) {
    throw InputError(fmt::format("--set '{}': expected key.path=value", assignment));
  }
  const std::string path = assignment.substr(0, eq), text = assignment.substr(eq + 1);
  // The value is TOML (number, bool, array, quoted string); a bare word is a string.
  toml::table parsed;
  try {
    parsed = toml::parse("v = " + text);
  } catch (const toml::parse_error&) {
    parsed = toml::table{{"v", text}};
  }
  std::vector<std::string> keys;
  std::stringstream ss(path);
  for (std::string k; std::getline(ss, k, '.');) {
    if (k.empty()) throw InputError(fmt::format("--set '{}': empty key in path", assignment));
    keys.push_back(k);
  }
  toml::node* node = &tree;
  for (std::size_t i = 0; i + 1 < keys.size(); ++i) {
    if (auto* t = node->as_table()) {
      if (!t->contains(keys[i])) t->insert(keys[i], toml::table{});
      node = t->get(keys[i]);
    } else if (auto* a = node->as_array()) {
      std::size_t idx = 0;
      try {
        idx = std::stoul(keys[i]);
      } catch (...) {
        idx = a->size();
      }
      if (idx >= a->size()) {
        throw InputError(fmt::format("--set '{}': '{}' is not an index of an array of {} entries",
                                     assignment, keys[i], a->size()));
      }
      node = a->get(idx);
    } else {
      throw InputError(fmt::format("--set '{}': '{}' is not a table", assignment, keys[i]));
    }
  }
  auto* target = node->as_table();
  if (!target)
    throw InputError(fmt::format("--set '{}': cannot assign inside a value", assignment));
  target->insert_or_assign(keys.back(), *parsed.get("v"));
}

// The integer at `view`, if it holds one. toml++'s value<int64_t>() would
// also convert a float, and a float beyond int64's range is undefined
// behaviour (UBSan caught dim = 1e308 in the scene fuzz test).
namespace {
std::optional<std::int64_t> integer_at(toml::node_view<toml::node> view) {
  if (const auto* i = view.as_integer()) return i->get();
  return std::nullopt;
}
}  // namespace

void apply_overrides(toml::table& tree, const Overrides& o) {
  // A scene that lists no `dims` supports only its own `dim`: keep that
  // dimension, so that --dim (or --set scene.dim) cannot move it unnoticed.
  const auto* header = tree["scene"].as_table();
  const auto file_dim = integer_at(tree["scene"]["dim"]);
  const bool declares_dims = header && header->contains("dims");
  auto set = [&](const std::string& key, auto value) {
    apply_set(tree, key + "=" + fmt::format("{}", value));
  };
  auto set_string = [&](const std::string& key, const std::string& value) {
    apply_set(tree, key + "=\"" + value + "\"");
  };
  if (o.dim) set("scene.dim", *o.dim);
  if (o.cells) set("grid.cells", *o.cells);
  if (o.ppc) set("grid.ppc", *o.ppc);
  if (o.transfer) set_string("method.transfer", *o.transfer);
  if (o.kernel) set_string("method.kernel", *o.kernel);
  if (o.update_order) set_string("method.update_order", *o.update_order);
  if (o.integrator) set_string("method.integrator", *o.integrator);
  if (o.t_end) set("time.t_end", fmt::format("{:.17g}", *o.t_end));
  if (o.cfl || o.dt) {
    if (auto* t = tree["time"].as_table()) {
      t->erase("cfl");
      t->erase("dt");
    }
    if (o.cfl) set("time.cfl", fmt::format("{:.17g}", *o.cfl));
    if (o.dt) set("time.dt", fmt::format("{:.17g}", *o.dt));
  }
  if (o.model) {
    if (auto* mats = tree["materials"].as_table()) {
      for (auto& [k, v] : *mats) {
        if (auto* t = v.as_table()) t->insert_or_assign("model", *o.model);
      }
    }
  }
  for (const auto& a : o.set) apply_set(tree, a);
  auto* scene = tree["scene"].as_table();  // again: a --set may have replaced the table
  if (scene && file_dim && !declares_dims && integer_at(tree["scene"]["dim"]) != file_dim) {
    scene->insert_or_assign("dims", toml::array{*file_dim});
  }
}

Scene read_scene(const toml::table& tree, const std::string& source) {
  try {
    Scene s;
    s.source = source;
    s.resolved = tree;
    TableReader top(tree, "");
    read_header(top, s);
    read_domain_and_grid(top, s);
    read_method(top, s);
    read_time(top, s);
    read_physics_and_walls(top, s);
    read_materials(top, s);
    read_bodies(top, s);
    read_reference(top, s);
    top.finish();
    return s;
  } catch (const InputError& e) {
    throw InputError(fmt::format("{}: {}", source, e.what()));
  }
}

Scene load_scene(const std::string& name_or_path, const Overrides& o) {
  std::string text, source;
  for (const auto& b : builtin_scenes()) {
    if (b.name == name_or_path) {
      text = b.text;
      source = "scene '" + b.name + "'";
    }
  }
  if (source.empty()) {
    std::ifstream in(name_or_path);
    if (!in) {
      std::vector<std::string> names;
      for (const auto& b : builtin_scenes()) names.push_back(b.name);
      throw InputError(fmt::format("scene '{}': no such file or built-in scene; built-in: {}",
                                   name_or_path, fmt::join(names, ", ")));
    }
    std::stringstream buf;
    buf << in.rdbuf();
    text = buf.str();
    source = name_or_path;
  }
  return scene_from_text(text, source, o);
}

Scene scene_from_text(const std::string& text, const std::string& source, const Overrides& o) {
  toml::table tree = parse_scene_text(text, source);
  try {
    apply_overrides(tree, o);
  } catch (const InputError& e) {
    throw InputError(fmt::format("{}: {}", source, e.what()));
  }
  return read_scene(tree, source);
}

}  // namespace mpmtb
