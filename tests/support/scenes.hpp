// Small scenes built in code for the tests.
#pragma once

#include <string>

#include "scene.hpp"

namespace mpmtb::testing {

// A box of neo-Hookean material in free flight in the middle of a closed
// domain far from every wall: dim, transfer, kernel; extra TOML appended.
inline std::string free_body_toml(int dim, const std::string& transfer, const std::string& kernel,
                                  const std::string& extra = "") {
  return "[scene]\nname = \"free-body\"\ndim = " + std::to_string(dim) +
         "\ndims = [1, 2, 3]\n"
         "[domain]\nmin = [0.0, 0.0, 0.0]\nmax = [1.0, 1.0, 1.0]\n"
         "[grid]\ncells = 16\nppc = 2\n"
         "[method]\ntransfer = \"" +
         transfer + "\"\nkernel = \"" + kernel +
         "\"\n"
         "[time]\nt_end = 0.01\ndt = 1e-3\n"
         "[materials.jelly]\nmodel = \"neo-hookean\"\nE = 1000.0\nnu = 0.3\ndensity = 10.0\n"
         "[[bodies]]\nshape = \"box\"\nmin = [0.3, 0.35, 0.3]\nmax = [0.62, 0.6, 0.7]\n"
         "material = \"jelly\"\nvelocity = [0.3, -0.2, 0.1]\nangular_velocity = [0.5, -1.0, "
         "2.0]\n" +
         extra;
}

// A jelly cube (square in 2D) spinning about an oblique axis in the middle of
// the unit box, APIC and quadratic unless overridden: 2D or 3D.
inline std::string spinning_body_toml(int dim) {
  return "[scene]\nname = \"spin\"\ndim = " + std::to_string(dim) +
         "\ndims = [2, 3]\n[domain]\nmin = [0.0, 0.0, 0.0]\nmax = [1.0, 1.0, 1.0]\n"
         "[grid]\ncells = 32\nppc = 2\n[method]\ntransfer = \"apic\"\nkernel = \"quadratic\"\n"
         "[time]\nt_end = 1.0\ndt = 1e-3\n"
         "[materials.jelly]\nmodel = \"neo-hookean\"\nE = 2e4\nnu = 0.3\ndensity = 1000.0\n"
         "[[bodies]]\nshape = \"box\"\nmin = [0.35, 0.35, 0.35]\nmax = [0.65, 0.65, 0.65]\n"
         "material = \"jelly\"\nangular_velocity = [0.3, -0.2, 1.0]\n";
}

inline Scene scene_from_toml(const std::string& text, const Overrides& o = {}) {
  toml::table tree = parse_scene_text(text, "test scene");
  apply_overrides(tree, o);
  return read_scene(tree, "test scene");
}

}  // namespace mpmtb::testing
