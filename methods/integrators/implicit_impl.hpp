// The implicit step (integrators/integrator.hpp), instantiated once per dimension
// x kernel by integrators/implicit_*d.cpp: it never depends on the transfer.
// Incremental potential (Gast et al. 2015, eq. 6-8): after P2G (mass m_i and
// the transfer's momentum p_i, v_i^n = p_i / m_i), the grid velocities v of
// the step minimise
//   E(v) = sum_i m_i / 2 |v_i - v~_i|^2 + sum_p V0_p psi(F_p(v)),
//   F_p(v) = (I + h sum_i (b_i + v_i) grad w_ip^T) F_p^n,
// whose stationarity m_i (v_i - v~_i) = -h dPsi/dx_i is the momentum balance
// of the scheme:
//   backward Euler: h = dt, b = 0, v~ = v^n + dt g;
//     the grid moves by dt v^n+1 and the force is taken at the end of the step.
//   Newmark, beta = 1/4, gamma = 1/2 (the trapezoidal rule): h = dt/2,
//     b = v^n, v~ = v^n + dt g + dt/2 f(F^n) / m: the grid moves by
//     dt (v^n + v^n+1)/2 and m (v^n+1 - v^n) = dt/2 (f^n + f^n+1).
//     (Energy and amplification of both: integrators/integrator.hpp.)
// Newton's method on E with CG and a line search: integrators/integrator.hpp.
// The particles' side (F_p(v), stresses, dP/dF blocks, the sums into nodes, in
// parallel and bit-identical for any thread count): integrators/implicit_particles.hpp.
//
// Constraints act inside the solve: the unknowns are the velocities of the
// active nodes; a pinned node (v = 0), a node inside a collider (its velocity
// set by the collider, probed at the start of the step, then held: Dirichlet)
// and the components a wall constrains on its face (sticky: all, slip: the
// normal one; separate: the normal one where v~ presses into the wall) are
// masked out, and the ghosts beyond sticky and slip walls follow their mirror
// nodes, v_ghost = R v_mirror (boundary/walls.hpp): the velocity field is
// v = T u + c, and the solve uses T^T on gradients (the walls' fold).
// Plasticity and damage: F_p^n is the elastic part after the last return map
// and psi is evaluated at the current internal state; the return map runs
// after the solve (the semi-implicit convention of Stomakhin et al. 2013,
// "A material point method for snow simulation", sec. 9).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "core/stencil.hpp"
#include "core/stepper.hpp"
#include "integrators/conjugate_gradient.hpp"
#include "integrators/implicit_particles.hpp"
#include "integrators/integrator.hpp"
#include "kernels/all.hpp"

namespace mpmtb {

template <int Dim, class Kernel>
class ImplicitSolveT final : public ImplicitSolve<Dim> {
  using V = std::vector<Vec<Dim>>;
  using ImplicitSolve<Dim>::stats_;

 public:
  ImplicitSolveT(Integrator i, const ImplicitOptions& o)
      : newmark_(i == Integrator::newmark), opt_(o) {}

  void step(Stepper<Dim>& stepper, State<Dim>& s, Real dt, StepReport& report) override {
    setup(stepper, s, dt);
    V u = solve();
    finish(stepper, s, dt, u, report);
  }

  // P2G and the step's objective, without solving (also for tests).
  void setup(Stepper<Dim>& stepper, State<Dim>& s, Real dt) override {
    s_ = &s;
    h_ = newmark_ ? dt / 2 : dt;
    Grid<Dim>& g = s.grid;
    stepper.scatter_momentum(s);  // m, p (the transfer's own), pinned nodes; f = 0
    // The active nodes (the box P2G swept).
    nodes_.clear();
    for (long r = 0; r < g.active_rows(); ++r) {
      const auto [first, count] = g.active_row(r);
      for (long i = first; i < first + count; ++i) nodes_.push_back(i);
    }
    const std::size_t N = g.size();
    for (V* f : {&target_, &mask_, &fixed_, &vn_, &base_}) f->assign(N, Vec<Dim>::Zero());
    mass_.assign(N, 0);
    collider_.assign(N, 0);
    particles_.setup(s);
    // Body forces into f before the walls fold it with m and p.
    if (s.body_force) particles_.scatter_body_force(g.f);
    s.walls.fold(g);
    for (const long i : nodes_) {
      if (g.m[i] > 0) {
        mass_[i] = g.m[i];
        vn_[i] = g.p[i] / g.m[i];
        g.v_old[i] = vn_[i];  // what FLIP-like transfers read back
        target_[i] = vn_[i] + dt * s.gravity + (dt / g.m[i]) * g.f[i];
        mask_[i].setOnes();
      }
    }
    build_wall_constraints(g);
    for (const long i : nodes_) {
      if (g.pinned[i]) mask_[i].setZero();
    }
    if (!s.colliders.empty()) probe_colliders(g, s.time + dt);
    // v^n with the constraints (Newmark's b, and the grid energy before the step).
    vn_ = expand(vn_, true);
    if (newmark_) {
      // v~ += dt/2 f(F^n) / m, f(F^n) = -sum_p V0 P(F^n) F^nT grad w (folded;
      // with b = 0 still, v = 0 gives F^n).
      V div(N, Vec<Dim>::Zero());
      stress_divergence(zeros(), div);  // with b = 0 still: at F^n
      fold_ghosts(div);
      for (const long i : nodes_) {
        if (mass_[i] > 0) target_[i] -= (dt / 2 / mass_[i]) * div[i];
      }
      base_ = vn_;
    }
    start_.assign(N, Vec<Dim>::Zero());
    for (const long i : nodes_) start_[i] = mask_[i].cwiseProduct(target_[i]);
  }

  // The objective at unknowns u (values on the masked components are ignored).
  Real energy(const V& u) override {
    const V v = expand(u, true);
    Real kinetic = 0;
    for (const long i : nodes_) kinetic += Real(0.5) * mass_[i] * (v[i] - target_[i]).squaredNorm();
    return kinetic + strain_energy(v);
  }

  // g = T^T dE/dv: the reduced gradient (zero on masked components).
  void gradient(const V& u, V& out) override {
    const V v = expand(u, true);
    out.assign(v.size(), Vec<Dim>::Zero());
    stress_divergence(v, out);
    for (const long i : nodes_) out[i] *= h_;
    fold_ghosts(out);
    for (const long i : nodes_) {
      out[i] = mask_[i].cwiseProduct(out[i] + mass_[i] * (v[i] - target_[i]));
    }
  }

  // H d at unknowns u: the particles' blocks dP/dF at F_p(u), projected to
  // positive semi-definite when `project`.
  void hessian_times(const V& u, const V& d, V& out, bool project) override {
    update_F(expand(u, true));
    particles_.build_blocks(project);
    apply_hessian(d, out);
  }

  const V& start() const override { return start_; }
  const std::vector<long>& active_nodes() const override { return nodes_; }

 private:
  struct Link {
    long ghost, mirror;
    int axis;  // slip: the normal axis; -1: sticky (R = -I)
  };

  static Vec<Dim> reflect(const Link& l, const Vec<Dim>& v) {
    if (l.axis < 0) return -v;
    Vec<Dim> r = v;
    r[l.axis] = -r[l.axis];
    return r;
  }

  V zeros() const { return V(mass_.size(), Vec<Dim>::Zero()); }

  // v = T u (+ c): the masked unknowns, the prescribed values, then the ghosts
  // from their mirrors in the order of Walls::apply.
  V expand(const V& u, bool with_fixed) const {
    V v(mass_.size(), Vec<Dim>::Zero());
    for (const long i : nodes_) {
      v[i] = mask_[i].cwiseProduct(u[i]);
      if (with_fixed) v[i] += fixed_[i];
    }
    for (const Link& l : links_) v[l.ghost] = reflect(l, v[l.mirror]);
    return v;
  }
  // r <- the transpose of the ghost copies (the walls' fold), in reverse order.
  void fold_ghosts(V& r) const {
    for (auto it = links_.rbegin(); it != links_.rend(); ++it) {
      r[it->mirror] += reflect(*it, r[it->ghost]);
      r[it->ghost].setZero();
    }
  }

  // The faces' constraints, in the order of Walls::apply (boundary/walls.cpp).
  void build_wall_constraints(const Grid<Dim>& g) {
    links_.clear();
    constexpr int pad = GridGeometry<Dim>::pad;
    const GridGeometry<Dim>& geo = g.geo;
    for (int axis = 0; axis < Dim; ++axis) {
      const long stride = geo.strides()[axis];
      const long block = stride * geo.nodes(axis);
      const long outer = geo.node_count() / block;
      const int mirrored = std::min(pad, geo.cells[axis]);
      for (int side = 0; side < 2; ++side) {
        const Wall w = s_->walls.face[2 * axis + side];
        if (w == Wall::free) continue;
        const int outward = side == 0 ? -1 : 1;
        const long out = outward * stride;
        const int face_index = side == 0 ? pad : pad + geo.cells[axis];
        for (long o = 0; o < outer; ++o) {
          for (long st = 0; st < stride; ++st) {
            const long face = o * block + face_index * stride + st;
            constrain(w, axis, outward, face);
            for (int k = 1; k <= pad; ++k) {
              const long ghost = face + k * out;
              if (g.m[ghost] <= 0) continue;
              if (w != Wall::separate && k <= mirrored) {
                links_.push_back({ghost, face - k * out, w == Wall::sticky ? -1 : axis});
                mask_[ghost].setZero();
                mass_[ghost] = 0;  // folded into the mirror
              } else {
                constrain(w, axis, outward, ghost);
              }
            }
          }
        }
      }
    }
  }
  void constrain(Wall w, int axis, int outward, long node) {
    if (w == Wall::sticky) {
      mask_[node].setZero();
    } else if (w == Wall::slip || (w == Wall::separate && target_[node][axis] * outward > 0)) {
      mask_[node][axis] = 0;
    }
  }

  // Nodes a collider acts on (at v~) are held at the velocity it gives them.
  void probe_colliders(Grid<Dim>& g, Real t) {
    for (const long i : nodes_) g.v[i] = mask_[i].cwiseProduct(target_[i]);
    const V before(g.v);
    Vec3 impulse = Vec3::Zero();
    Real work = 0;
    s_->colliders.apply(g, t, impulse, work);
    for (const long i : nodes_) {
      if (g.v[i] != before[i]) {
        mask_[i].setZero();
        fixed_[i] = g.v[i];
        collider_[i] = 1;
      }
      g.v[i].setZero();
    }
  }

  void update_F(const V& v) { particles_.update_F(base_, v, h_); }

  Real strain_energy(const V& v) {
    update_F(v);
    return particles_.strain_energy();
  }

  // out_i += sum_p V0_p P(F_p(v)) F_p^nT grad w_ip (the negative internal force).
  void stress_divergence(const V& v, V& out) {
    update_F(v);
    particles_.stress_divergence(out);
  }

  // out = M d + T^T h^2 sum_p V0 (K_p : dF_p) F^nT grad w (masked), d masked.
  void apply_hessian(const V& d, V& out) {
    out.assign(mass_.size(), Vec<Dim>::Zero());
    particles_.hessian_times(expand(d, false), h_, out);
    fold_ghosts(out);
    for (const long i : nodes_) out[i] = mask_[i].cwiseProduct(out[i] + mass_[i] * d[i]);
  }

  // The Jacobi preconditioner: 1 / diag(H) on the free components.
  void build_preconditioner() {
    V diag(mass_.size(), Vec<Dim>::Zero());
    particles_.hessian_diagonal(h_, diag);
    for (auto it = links_.rbegin(); it != links_.rend(); ++it) {
      diag[it->mirror] += diag[it->ghost];
    }
    inv_diag_.assign(mass_.size(), Vec<Dim>::Zero());
    for (const long i : nodes_) {
      for (int a = 0; a < Dim; ++a) {
        const Real d = diag[i][a] + mass_[i];
        inv_diag_[i][a] = mask_[i][a] > 0 && d > 0 ? 1 / d : 0;
      }
    }
  }

  Real dot(const V& a, const V& b) const { return node_dot<Dim>(nodes_, a, b); }

  // Preconditioned CG on H x = b to |r| <= tol; returns the iterations.
  long conjugate_gradients(const V& b, V& x, Real tol) {
    return preconditioned_cg<Dim>(nodes_, inv_diag_, b, x, tol, opt_.cg_max,
                                  [&](const V& q, V& Aq) { apply_hessian(q, Aq); });
  }

  // Newton's method from v~; fills stats_.
  V solve() {
    stats_ = ImplicitStats{};
    V u = start_;
    Real E = energy(u);
    if (!std::isfinite(E)) {
      // v~ inverts a particle: start from the velocities that keep F^n.
      for (const long i : nodes_) u[i] = -base_[i];
      E = energy(u);
    }
    V grad, d, trial;
    gradient(u, grad);
    const Real g0 = std::sqrt(dot(grad, grad));
    // The round-off floor of |g|: the momenta it sums, and the stresses, each
    // known to about eps times the stiffness rho c^2 (F is I + O(eps) at rest),
    // times h V0 |grad w| ~ h V0 2 Dim / dx per particle.
    Real scale = 0;
    for (const long i : nodes_) scale += mass_[i] * (target_[i].norm() + base_[i].norm());
    scale += particles_.stress_scale(h_);
    const Real floor = 64 * std::numeric_limits<Real>::epsilon() * std::max(scale, g0);
    Real gnorm = g0;
    while (gnorm > opt_.newton_tol * g0 && gnorm > floor) {
      if (stats_.newton >= opt_.newton_max) {
        stats_.converged = false;
        break;
      }
      ++stats_.newton;
      update_F(expand(u, true));
      particles_.build_blocks(true);
      build_preconditioner();
      V rhs = grad;
      for (const long i : nodes_) rhs[i] = -grad[i];
      const Real eta = std::min(opt_.cg_tol, gnorm / g0);
      const Real cg_tol = std::max(eta * gnorm, Real(0.1) * opt_.newton_tol * g0);
      stats_.cg += conjugate_gradients(rhs, d, cg_tol);
      Real slope = dot(grad, d);
      if (!(slope < 0)) {  // no descent (CG stopped at once): the preconditioned gradient
        for (const long i : nodes_) d[i] = -inv_diag_[i].cwiseProduct(grad[i]);
        slope = dot(grad, d);
      }
      // Backtracking (Armijo) on E. Near the solution the decrease a Newton step
      // promises, |slope|/2, falls below the round-off of E itself (a sum of
      // terms of size E): a full step whose E is level with E to round-off is
      // then accepted when it reduces |g|, so that the last iterations are
      // judged by the gradient, which keeps its relative accuracy.
      Real alpha = 1, E_new = E;
      bool accepted = false;
      V grad_new;
      for (int ls = 0; ls < 40; ++ls, alpha *= Real(0.5)) {
        trial = u;
        for (const long i : nodes_) trial[i] += alpha * d[i];
        E_new = energy(trial);
        if (!std::isfinite(E_new)) continue;
        if (E_new <= E + Real(1e-4) * alpha * slope) {
          accepted = true;
          break;
        }
        // The round-off of E: eps |E|, and per particle eps V0 (|P| + rho c^2 |F|) |F|:
        // psi(F) is known to P : dF with |dF| ~ eps |F| where F - I cancels at
        // small strain, and its terms of size rho c^2 |F|^2 cancel near rest
        // (neo-Hookean's mu/2 tr(F^T F) against mu ln J).
        const Real noise =
            64 * (std::numeric_limits<Real>::epsilon() * std::abs(E) + particles_.psi_noise());
        if (ls == 0 && E_new - E <= noise) {
          gradient(trial, grad_new);
          if (dot(grad_new, grad_new) < gnorm * gnorm) {
            accepted = true;
            break;
          }
        }
      }
      if (!accepted) {
        stats_.converged = false;
        break;
      }
      u.swap(trial);
      E = E_new;
      gradient(u, grad);
      gnorm = std::sqrt(dot(grad, grad));
    }
    // 0 where v~ already solves the step to round-off (free fall, rest).
    stats_.residual = g0 > floor ? gnorm / g0 : 0;
    if (!std::isfinite(gnorm)) stats_.converged = false;
    return u;
  }

  // The solved velocities to the grid, then G2P and the return maps.
  void finish(Stepper<Dim>& stepper, State<Dim>& s, Real dt, const V& u, StepReport& report) {
    Grid<Dim>& g = s.grid;
    const V v = expand(u, true);
    // Grid energy before and after (kinetic with P2G's constrained velocities).
    V grad_full = zeros();
    stress_divergence(v, grad_full);
    Real after = strain_energy(v), before = particles_.strain_energy_at_Fn();
    for (const long i : nodes_) {
      after += Real(0.5) * mass_[i] * v[i].squaredNorm();
      before += Real(0.5) * mass_[i] * vn_[i].squaredNorm();
    }
    stats_.grid_energy = before;
    stats_.grid_energy_change = after - before;
    // Reactions of the pinned nodes and colliders: the constraint impulse
    // m_i (v_i - v~_i) + h dPsi/dv_i at the nodes they hold.
    for (const long i : nodes_) grad_full[i] *= h_;
    fold_ghosts(grad_full);
    Vec3 pin = Vec3::Zero(), col = Vec3::Zero();
    Real work = 0;
    for (const long i : nodes_) {
      const Vec<Dim> J = mass_[i] * (v[i] - target_[i]) + grad_full[i];
      if (collider_[i]) {
        col += to3<Dim>(J);
        work += J.dot(v[i]);
      } else if (g.pinned[i]) {
        pin += to3<Dim>(J);
      }
    }
    s.pin_impulse += pin;
    s.collider_impulse += col;
    s.collider_work += work;

    const Particles<Dim>& P = s.particles;
    V shift;
    if (newmark_) {
      // F^n+1 = (I + dt (v^n + v^n+1)/2 grad w^T) F^n; x^n+1 = x^n + dt (v^n + v^n+1)/2,
      // the transfer's G2P moving by dt v^n+1 and the difference added after.
      for (const long i : nodes_) g.v[i] = Real(0.5) * (base_[i] + v[i]);
      particles_.interpolate_difference(base_, v, dt / 2, shift);
    } else {
      for (const long i : nodes_) g.v[i] = v[i];
    }
    const StepReport deformed = stepper.update_deformation(s, dt);
    for (const long i : nodes_) g.v[i] = v[i];
    report = stepper.move_particles(s, dt);
    if (newmark_) {
      for (std::size_t p = 0; p < P.size(); ++p) s.particles.x[p] += shift[p];
    }
    report.J_min = deformed.J_min;
    report.J_max = deformed.J_max;
    if (deformed.non_finite >= 0) {
      report.non_finite = report.non_finite < 0 ? deformed.non_finite
                                                : std::min(report.non_finite, deformed.non_finite);
    }
    stepper.nonlocal_update(s);
    stepper.constitutive_update(s, dt);
  }
  bool newmark_;
  ImplicitOptions opt_;
  State<Dim>* s_ = nullptr;
  Real h_ = 0;
  ImplicitParticles<Dim, Kernel> particles_;
  std::vector<long> nodes_;  // the active nodes
  std::vector<Real> mass_;   // m_i, folded; 0 at ghosts that follow a mirror
  V target_;                 // v~
  V mask_;                   // 1: free component, 0: prescribed
  V fixed_;                  // the prescribed values (colliders)
  V vn_;                     // P2G's v^n with the constraints
  V base_;                   // b: v^n for Newmark, 0 for backward Euler
  V start_;                  // the initial guess
  V inv_diag_;
  std::vector<std::uint8_t> collider_;
  std::vector<Link> links_;
};

template <int Dim>
std::unique_ptr<ImplicitSolve<Dim>> make_implicit_solve(std::string_view kernel,
                                                        Integrator integrator,
                                                        const ImplicitOptions& options) {
  std::unique_ptr<ImplicitSolve<Dim>> solve;
  AllKernels::for_each([&]<class K>() {
    if (!solve && K::name == kernel)
      solve = std::make_unique<ImplicitSolveT<Dim, K>>(integrator, options);
  });
  if (!solve)
    throw InputError("method.integrator: no implicit solve for kernel '" + std::string(kernel) +
                     "'");
  return solve;
}

}  // namespace mpmtb
