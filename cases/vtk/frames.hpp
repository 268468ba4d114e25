// Particle (and optionally grid) frames of a run for ParaView:
//   DIR/particles.pvd              the time series, rewritten after each frame
//   DIR/frames/particles_NNNNN.vtp one PolyData file per frame
//   DIR/grid.pvd, DIR/frames/grid_NNNNN.vti   with --frames-grid
// Point data per particle: velocity, mass, volume (V0 J), J (total volume
// ratio), von_mises (of the Cauchy stress), every internal variable a model
// declares (damage, dissipated, ...; 0 for materials without it), material, pinned.
// Every file is written atomically; a frame is due every `every` steps and/or
// whenever the time passes a multiple of `interval`, plus the first and last.
#pragma once

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "archive.hpp"
#include "core/errors.hpp"
#include "core/state.hpp"
#include "output.hpp"
#include "vtk/frame_options.hpp"
#include "vtk/vtk_xml.hpp"

namespace mpmtb {

// Von Mises equivalent stress sqrt(3/2 s:s), s = sigma - tr(sigma)/3 I, of a
// Cauchy stress given in Dim dimensions; the missing components are zero.
template <int Dim>
double von_mises(const Mat<Dim>& sigma) {
  Eigen::Matrix3d s = Eigen::Matrix3d::Zero();
  s.template topLeftCorner<Dim, Dim>() = sigma.template cast<double>();
  s -= s.trace() / 3 * Eigen::Matrix3d::Identity();
  return std::sqrt(1.5 * s.squaredNorm());
}

template <int Dim>
vtk::PointCloud particle_cloud(const State<Dim>& s) {
  const auto& P = s.particles;
  const std::size_t n = P.size();
  vtk::PointCloud c;
  c.time = s.time;
  c.step = s.step;
  c.points.assign(3 * n, 0.0);
  std::vector<double> v(3 * n, 0.0), J(n), vm(n), vol(n);
  std::vector<std::int32_t> material(n);
  // Internal variables by name (the union over the materials, first seen
  // first) and where each sits in each material's state (-1: not there).
  std::vector<std::string> names;
  for (const auto& model : s.materials) {
    for (const auto& name : model->state_names()) {
      if (std::find(names.begin(), names.end(), name) == names.end()) names.push_back(name);
    }
  }
  std::vector<std::vector<int>> slot(s.materials.size(), std::vector<int>(names.size(), -1));
  for (std::size_t m = 0; m < s.materials.size(); ++m) {
    const auto own = s.materials[m]->state_names();
    for (std::size_t k = 0; k < names.size(); ++k) {
      const auto it = std::find(own.begin(), own.end(), names[k]);
      if (it != own.end()) slot[m][k] = static_cast<int>(it - own.begin());
    }
  }
  std::vector<std::vector<double>> state(names.size(), std::vector<double>(n, 0.0));
  for (std::size_t p = 0; p < n; ++p) {
    const auto& model = *s.materials[P.material[p]];
    const Real* q = P.state_of(p);
    for (int a = 0; a < Dim; ++a) {
      c.points[3 * p + a] = P.x[p][a];
      v[3 * p + a] = P.v[p][a];
    }
    J[p] = model.total_J(P.F[p], q);
    vol[p] = P.V0[p] * J[p];
    // Cauchy stress sigma = P F^T / det F (F the elastic part for plasticity).
    const Mat<Dim> sigma = model.first_piola(P.F[p], q) * P.F[p].transpose() / P.F[p].determinant();
    vm[p] = von_mises<Dim>(sigma);
    material[p] = P.material[p];
    for (std::size_t k = 0; k < names.size(); ++k) {
      const int at = slot[P.material[p]][k];
      if (at >= 0) state[k][p] = q[at];
    }
  }
  c.point_data.push_back(vtk::DataArray::float64("velocity", v, 3));
  c.point_data.push_back(
      vtk::DataArray::float64("mass", std::vector<double>(P.m.begin(), P.m.end())));
  c.point_data.push_back(vtk::DataArray::float64("volume", vol));
  c.point_data.push_back(vtk::DataArray::float64("J", J));
  c.point_data.push_back(vtk::DataArray::float64("von_mises", vm));
  for (std::size_t k = 0; k < names.size(); ++k)
    c.point_data.push_back(vtk::DataArray::float64(names[k], state[k]));
  c.point_data.push_back(vtk::DataArray::int32("material", material));
  c.point_data.push_back(vtk::DataArray::uint8("pinned", P.pinned));
  return c;
}

// The grid's nodes including the ghost layers, x fastest as VTK orders them:
// nodal mass m_i and velocity v_i of the last step (zero before the first).
template <int Dim>
vtk::ImageGrid grid_image(const State<Dim>& s) {
  const auto& geo = s.grid.geo;
  vtk::ImageGrid g;
  g.time = s.time;
  g.step = s.step;
  g.spacing = geo.dx;
  for (int a = 0; a < Dim; ++a) {
    g.origin[a] = geo.coordinate(a, 0);
    g.nodes[a] = geo.nodes(a);
  }
  const long count = static_cast<long>(g.nodes[0]) * g.nodes[1] * g.nodes[2];
  const bool have = static_cast<long>(s.grid.m.size()) == geo.node_count() &&
                    static_cast<long>(s.grid.v.size()) == geo.node_count();
  std::vector<double> m(count, 0.0), v(3 * count, 0.0);
  for (long k = 0; k < count && have; ++k) {
    long rest = k, node = 0;
    for (int a = 0; a < Dim; ++a) {
      node += (rest % g.nodes[a]) * geo.strides()[a];
      rest /= g.nodes[a];
    }
    m[k] = s.grid.m[node];
    for (int a = 0; a < Dim; ++a) v[3 * k + a] = s.grid.v[node][a];
  }
  g.point_data.push_back(vtk::DataArray::float64("mass", m));
  g.point_data.push_back(vtk::DataArray::float64("velocity", v, 3));
  return g;
}

template <int Dim>
class FrameSeries {
 public:
  FrameSeries(std::filesystem::path dir, FrameOptions options)
      : dir_(std::move(dir)), options_(options), next_time_(options.interval) {}

  // Writes the frame if one is due after this step (always at the first and `last`).
  void after_step(const State<Dim>& s, bool last, Real dt) {
    if (!options_.enabled()) return;
    bool due = last || (options_.every > 0 && s.step % options_.every == 0);
    if (options_.interval > 0 && s.time >= next_time_ - 1e-9 * dt) {
      due = true;
      while (next_time_ <= s.time + 1e-9 * dt) next_time_ += options_.interval;
    }
    if (due) write(s);
  }
  void write(const State<Dim>& s) {
    if (!options_.enabled() || (!particles_.empty() && last_step_ == s.step)) return;
    const auto t0 = std::chrono::steady_clock::now();
    // frames/ belongs to the run: drop the frames of an earlier run in DIR.
    if (particles_.empty()) std::filesystem::remove_all(dir_ / "frames");
    const std::string name = fmt::format("frames/particles_{:05d}.vtp", particles_.size());
    const std::string vtp = vtk::render_vtp(particle_cloud(s));
    bytes_ += vtp.size();
    write_atomically(dir_ / name, vtp);
    particles_.emplace_back(s.time, name);
    write_atomically(dir_ / "particles.pvd", vtk::render_pvd(particles_));
    if (options_.grid) {
      const std::string gname = fmt::format("frames/grid_{:05d}.vti", grids_.size());
      const std::string vti = vtk::render_vti(grid_image(s));
      bytes_ += vti.size();
      write_atomically(dir_ / gname, vti);
      grids_.emplace_back(s.time, gname);
      write_atomically(dir_ / "grid.pvd", vtk::render_pvd(grids_));
    }
    last_step_ = s.step;
    seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  // For summary.json: what was written and how long it took.
  nlohmann::json summary() const {
    nlohmann::json j;
    j["count"] = particles_.size();
    j["pvd"] = "particles.pvd";
    if (options_.grid) j["grid_pvd"] = "grid.pvd";
    if (options_.every > 0) j["every_steps"] = options_.every;
    if (options_.interval > 0) j["interval"] = options_.interval;
    j["bytes"] = bytes_;
    j["seconds"] = seconds_;
    return j;
  }
  bool enabled() const { return options_.enabled(); }

  // For a checkpoint: which frames exist and when the next is due, so that a
  // resumed run writes the frames (and .pvd lists) an uninterrupted one would.
  void save(ArchiveWriter& a) const {
    a.put("frames.next_time", next_time_);
    a.put("frames.last_step", last_step_);
    a.put("frames.bytes", bytes_);
    a.put("frames.seconds", seconds_);
    save_list(a, "frames.particles", particles_);
    save_list(a, "frames.grids", grids_);
  }
  void restore(ArchiveReader& a) {
    a.get("frames.next_time", next_time_);
    a.get("frames.last_step", last_step_);
    a.get("frames.bytes", bytes_);
    a.get("frames.seconds", seconds_);
    particles_ = restore_list(a, "frames.particles");
    grids_ = restore_list(a, "frames.grids");
  }

 private:
  using List = std::vector<std::pair<double, std::string>>;
  // Times as raw doubles, names one per line (they are frames/NAME_NNNNN.ext).
  static void save_list(ArchiveWriter& a, const std::string& key, const List& list) {
    std::vector<double> times;
    std::string names;
    for (const auto& [t, name] : list) times.push_back(t), names += name + '\n';
    a.put_vector(key + ".times", times);
    a.put_string(key + ".names", names);
  }
  static List restore_list(ArchiveReader& a, const std::string& key) {
    std::vector<double> times;
    a.get_vector(key + ".times", times);
    const std::string names = a.get_string(key + ".names");
    List list;
    std::size_t at = 0;
    for (double t : times) {
      const std::size_t end = names.find('\n', at);
      if (end == std::string::npos) break;
      list.emplace_back(t, names.substr(at, end - at));
      at = end + 1;
    }
    if (list.size() != times.size())
      throw InputError(a.source() + ": field `" + key + ".names`: fewer names than times");
    return list;
  }

  std::filesystem::path dir_;
  FrameOptions options_;
  Real next_time_;
  List particles_, grids_;
  long last_step_ = -1;
  std::size_t bytes_ = 0;
  double seconds_ = 0;
};

}  // namespace mpmtb
