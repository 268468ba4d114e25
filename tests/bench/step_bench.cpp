// Throughput of the step and of each stage, for every transfer x kernel in 2D
// and 3D, on a block of 32^Dim particles (32,768 in 3D, the pinned block's count)
// moving and spinning inside a larger domain. Reported as particle-steps per second.
#include <benchmark/benchmark.h>

#include "core/registry.hpp"
#include "setup.hpp"

namespace mpmtb {
namespace {

Scene block_scene(int dim, const std::string& transfer, const std::string& kernel,
                  const std::string& model) {
  const std::string text =
      "[scene]\nname = \"block\"\ndim = " + std::to_string(dim) +
      "\ndims = [2, 3]\n"
      "[domain]\nmin = [0.0, 0.0, 0.0]\nmax = [1.0, 1.0, 1.0]\n"
      "[grid]\ncells = 32\nppc = 2\n"
      "[method]\ntransfer = \"" +
      transfer + "\"\nkernel = \"" + kernel +
      "\"\n"
      "[time]\nt_end = 1.0\ndt = 1e-4\n"
      "[materials.m]\nmodel = \"" +
      model + "\"\nE = 1e4\nnu = 0.3\ndensity = 1.0\n" +
      (model == "damage" ? "sigma_crit = 1e3\n" : "") +
      "[[bodies]]\nshape = \"box\"\nmin = [0.25, 0.25, 0.25]\nmax = [0.75, 0.75, 0.75]\n"
      "material = \"m\"\nvelocity = [0.5, 0.2, 0.1]\nangular_velocity = [1.0, 2.0, 3.0]\n";
  toml::table tree = parse_scene_text(text, "bench");
  return read_scene(tree, "bench");
}

// p2g includes the stresses (the models' tau), constitutive the return maps.
enum class Stage { step, p2g, grid, g2p, constitutive };

template <int Dim>
void run_stage(benchmark::State& bench, const std::string& transfer, const std::string& kernel,
               const std::string& model, Stage stage) {
  const Scene scene = block_scene(Dim, transfer, kernel, model);
  State<Dim> s = build_state<Dim>(scene);
  Parameters params = scene.transfer_params;
  auto st = make_stepper<Dim>(transfer, kernel, params);
  const Real dt = 1e-4;
  st->step(s, dt);  // warm up: every array allocated
  for (auto _ : bench) {
    switch (stage) {
      case Stage::step:
        st->step(s, dt);
        break;
      case Stage::p2g:
        st->particles_to_grid(s, dt);
        break;
      case Stage::grid:
        st->update_grid(s, dt);
        break;
      case Stage::g2p:
        benchmark::DoNotOptimize(st->grid_to_particles(s, dt));
        break;
      case Stage::constitutive:
        st->constitutive_update(s, dt);
        break;
    }
  }
  const double n = static_cast<double>(s.particles.size());
  bench.counters["particles"] = n;
  bench.counters["particle_steps_per_s"] =
      benchmark::Counter(n * bench.iterations(), benchmark::Counter::kIsRate);
  // kIsRate | kInvert reports seconds per unit: count in units of 1e9 particle-steps.
  bench.counters["ns_per_particle_step"] = benchmark::Counter(
      n * bench.iterations() / 1e9, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

// Registers one benchmark per dimension x transfer x kernel x stage (neo-Hookean),
// and the pinned block's combination (3D, MLS-MPM, quadratic) with damage.
void register_case(int dim, const std::string& transfer, const std::string& kernel,
                   const std::string& model) {
  const std::pair<const char*, Stage> stages[] = {{"step", Stage::step},
                                                  {"p2g", Stage::p2g},
                                                  {"grid", Stage::grid},
                                                  {"g2p", Stage::g2p},
                                                  {"constitutive", Stage::constitutive}};
  for (const auto& [stage_name, stage] : stages) {
    const std::string name = std::to_string(dim) + "d/" + transfer + "/" + kernel + "/" +
                             (model == "neo-hookean" ? "" : model + "/") + stage_name;
    benchmark::RegisterBenchmark(name.c_str(),
                                 [=](benchmark::State& b) {
                                   if (dim == 2) run_stage<2>(b, transfer, kernel, model, stage);
                                   if (dim == 3) run_stage<3>(b, transfer, kernel, model, stage);
                                 })
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
  }
}

const bool registered = [] {
  for (int dim : {2, 3}) {
    for (const auto& t : transfer_list()) {
      for (const auto& k : kernel_list()) {
        if (!unsupported_reason(t.name, k.name).empty()) continue;
        register_case(dim, t.name, k.name, "neo-hookean");
      }
    }
  }
  register_case(3, "mls", "quadratic", "damage");
  return true;
}();

}  // namespace
}  // namespace mpmtb

BENCHMARK_MAIN();
