// A scene: bodies, materials, domain and walls, method, time stepping and an
// optional analytic reference, read from TOML (schema: cases/README.md) and
// validated before anything runs.
#pragma once

#include <toml++/toml.h>

#include <array>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "boundary/colliders.hpp"
#include "core/parameters.hpp"
#include "core/stepper.hpp"
#include "core/types.hpp"

namespace mpmtb {

struct MaterialSpec {
  std::string name;
  std::string model;
  Parameters params;  // E, nu, density and the model's own parameters
};

struct BodySpec {
  std::string shape;                            // box | sphere | ring
  Vec3 min = Vec3::Zero(), max = Vec3::Zero();  // box
  Vec3 center = Vec3::Zero();                   // sphere, ring
  Real radius = 0, inner_radius = 0;            // sphere, ring
  int material = 0;
  Vec3 velocity = Vec3::Zero();
  Vec3 angular_velocity = Vec3::Zero();  // about the body's centre; 2D uses z
  // Homogeneous stretching about the body's centre: v += diag(stretch_rate) (x - centre)
  // (`stretch_rate`, 1/s per axis; bar_stretch.toml).
  Vec3 stretch_rate = Vec3::Zero();
  // A box cut out of the body (`cut_min`, `cut_max`: a notch or a slot); empty when
  // cut_max does not exceed cut_min.
  Vec3 cut_min = Vec3::Zero(), cut_max = Vec3::Zero();
  // Material (fibre) directions, unit length in the scene's dimension: `fiber`
  // and optionally `fiber2`, for models that take them (aniso-damage).
  std::vector<Vec3> fibers;
  Vec3 rotation_center() const;
  bool contains(const Vec3& x, int dim) const;
  // Axis-aligned bounding box.
  void bounds(Vec3& lo, Vec3& hi) const;
};

struct PinSpec {
  Vec3 min = Vec3::Zero(), max = Vec3::Zero();  // particles inside are pinned
};

struct Scene {
  std::string name, description, source;
  int dim = 1;
  std::vector<int> dims;  // dimensions the scene supports
  Vec3 domain_min = Vec3::Zero(), domain_max = Vec3::Zero();
  int cells = 16;   // cells along `length`
  Real length = 1;  // dx = length / cells
  int ppc = 2;      // particles per cell per axis
  std::string transfer, kernel;
  Parameters transfer_params;
  UpdateOrder update_order = UpdateOrder::usl;         // stress-update order (core/stepper.hpp)
  Integrator integrator = Integrator::explicit_euler;  // integrators/integrator.hpp
  ImplicitOptions implicit;  // the Newton solve's controls ([method] newton_tol, ...)
  Real t_end = 1;
  std::optional<Real> dt, cfl;  // exactly one is set
  Real output_interval = 0.1;
  Vec3 gravity = Vec3::Zero();
  std::array<std::string, 6> walls;  // x_min, x_max, y_min, y_max, z_min, z_max
  std::vector<MaterialSpec> materials;
  std::vector<BodySpec> bodies;
  std::vector<PinSpec> pins;
  std::vector<SphereCollider> colliders;
  std::string reference;  // analytic reference kind, empty for none
  Parameters reference_params;
  Real energy_limit = 2;  // unstable when K + S exceeds this times the energy put in
  Real J_floor = 0;       // unstable when a particle's J = det F falls to this or below
  toml::table resolved;   // the whole tree after overrides, recorded in summaries

  Real dx() const { return length / cells; }
};

// The command-line and `--set` changes applied to a scene tree before it is read.
struct Overrides {
  std::optional<int> dim = {};
  std::optional<int> cells = {};
  std::optional<int> ppc = {};
  std::optional<std::string> transfer = {};
  std::optional<std::string> kernel = {};
  std::optional<std::string> update_order = {};
  std::optional<std::string> integrator = {};
  std::optional<std::string> model = {};
  std::optional<Real> cfl = {};
  std::optional<Real> dt = {};
  std::optional<Real> t_end = {};
  std::vector<std::string> set = {};  // "dotted.key=value"
};

// Parses TOML text; `source` names it in messages. Throws InputError.
toml::table parse_scene_text(const std::string& text, const std::string& source);
// Applies `key.path=value` (value parsed as TOML, else taken as a string).
void apply_set(toml::table& tree, const std::string& assignment);
void apply_overrides(toml::table& tree, const Overrides& o);
// Validates the tree into a Scene. Throws InputError naming the field.
Scene read_scene(const toml::table& tree, const std::string& source);

// Loads a built-in scene by name or a scene file by path, then applies overrides.
Scene load_scene(const std::string& name_or_path, const Overrides& o = {});
// The same from the scene's text; every message starts with `source`.
Scene scene_from_text(const std::string& text, const std::string& source, const Overrides& o = {});

struct BuiltinScene {
  std::string name;
  std::string text;
};
const std::vector<BuiltinScene>& builtin_scenes();

}  // namespace mpmtb
