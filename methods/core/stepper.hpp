// The common step interface: one compiled combination of dimension, kernel and
// transfer scheme. The stages follow the textbook pipeline:
//   P2G (mass, momentum, internal force) -> grid update (divide by mass, gravity,
//   walls, pinned nodes, colliders) -> G2P (v, C, F, x) -> constitutive return map.
// One virtual call per stage; everything inside is monomorphic.
//
// The stress-update order (Sulsky, Zhou & Schreyer 1995; Bardenhagen 2002,
// "Energy conservation error in the material point method for solid
// mechanics", JCP 180) decides which grid velocities update F and stress:
//   usl   update stress last: F from v_i^{n+1} in G2P (the default);
//   usf   update stress first: F and stress from v_i^n = p_i^n / m_i^n, then
//         the forces of the new stress;
//   musl  modified USL: after G2P the new particle momenta go to the grid
//         again and F is updated from those grid velocities.
// The step composes the stages by the order; usf and musl need a transfer whose
// force is -V0 tau grad w and whose F update is (I + dt sum v_i grad w^T) F
// (a gradient-based transfer, see transfer_is_gradient_based).
#pragma once

#include <algorithm>
#include <array>
#include <memory>
#include <string>
#include <string_view>

#include "core/errors.hpp"
#include "core/state.hpp"
#include "integrators/integrator.hpp"

namespace mpmtb {

// What G2P saw, for instability detection at negligible cost.
struct StepReport {
  Real J_min = 1, J_max = 1;
  Real v_max = 0;        // max |v_p|, for the CFL time step
  long non_finite = -1;  // a particle with NaN/Inf position, velocity or F (-1: none)
  long outside = -1;     // a particle that left the domain box (-1: none)
};

enum class UpdateOrder { usl, usf, musl };
inline constexpr std::array<std::string_view, 3> kUpdateOrderNames = {"usl", "usf", "musl"};
inline std::string_view update_order_name(UpdateOrder o) {
  return kUpdateOrderNames[static_cast<int>(o)];
}

// Transfer trait `gradient_based`: the force is -V0_p tau_p grad w_ip and F is
// updated from sum_i v_i grad w_ip^T, so the base may split P2G into momentum
// and force and G2P into motion and deformation, as every order needs. A
// transfer that does not declare it is gradient-based.
template <class Transfer>
constexpr bool transfer_is_gradient_based() {
  if constexpr (requires { Transfer::gradient_based; }) {
    return Transfer::gradient_based;
  } else {
    return true;
  }
}

template <int Dim>
class Stepper {
 public:
  virtual ~Stepper() = default;
  virtual std::string_view transfer_name() const = 0;
  virtual std::string_view kernel_name() const = 0;

  // Whether the transfer supports usf and musl (transfer_is_gradient_based).
  virtual bool gradient_based() const = 0;
  // Throws InputError naming method.update_order for a refused order.
  void set_update_order(UpdateOrder o) {
    if (o != UpdateOrder::usl && !gradient_based()) {
      throw InputError("method.update_order: '" + std::string(update_order_name(o)) +
                       "' is refused with transfer '" + std::string(transfer_name()) +
                       "': its force and F update do not use the kernel gradient (it is not "
                       "gradient-based), so P2G and G2P cannot be split; allowed: usl");
    }
    order_ = o;
  }
  UpdateOrder update_order() const { return order_; }

  // The time integrator (integrators/integrator.hpp); throws InputError naming
  // method.integrator for a transfer or order an implicit one cannot take.
  void set_integrator(Integrator i, const ImplicitOptions& options = {});
  Integrator integrator() const { return integrator_; }
  // The last implicit step's Newton and CG figures (null for explicit).
  const ImplicitStats* implicit_stats() const { return implicit_ ? &implicit_->stats() : nullptr; }

  // One step of size dt: symplectic Euler (explicit), or the implicit solve.
  StepReport step(State<Dim>& s, Real dt) {
    StepReport r;
    if (implicit_) {
      implicit_->step(*this, s, dt, r);
      s.time += dt;
      ++s.step;
      return r;
    }
    switch (order_) {
      case UpdateOrder::usl:
        particles_to_grid(s, dt);
        update_grid(s, dt);
        r = grid_to_particles(s, dt);
        nonlocal_update(s);
        constitutive_update(s, dt);
        break;
      case UpdateOrder::usf: {
        scatter_momentum(s);
        grid_velocities(s, s.time);
        const StepReport deformed = update_deformation(s, dt);
        nonlocal_update(s);
        constitutive_update(s, dt);
        scatter_forces(s, dt);
        update_grid(s, dt);
        r = merged(move_particles(s, dt), deformed);
        break;
      }
      case UpdateOrder::musl: {
        particles_to_grid(s, dt);
        update_grid(s, dt);
        const StepReport moved = move_particles(s, dt);
        scatter_momentum(s);
        grid_velocities(s, s.time + dt);
        r = merged(moved, update_deformation(s, dt));
        nonlocal_update(s);
        constitutive_update(s, dt);
        break;
      }
    }
    s.time += dt;
    ++s.step;
    return r;
  }

  // Allocates the step's per-grid buffers for this state's grid, as the grid's
  // own fields are allocated with it: a step's cost then follows the particles
  // and the active region, not the domain; and the per-particle ones (the
  // transfer's state, zero as the first step would make it, and the stresses),
  // whose first touch of fresh pages cost 12 % of a 40-step PolyPIC run.
  // Optional (the first step allocates).
  virtual void prepare(State<Dim>& /*s*/) {}

  // The stages, public so that tests can check each transfer direction.
  // P2G: momentum and force together (usl, musl).
  virtual void particles_to_grid(State<Dim>& s, Real dt) = 0;
  // v_i^{n+1} = p_i / m_i + dt f_i / m_i with the boundary conditions.
  virtual void update_grid(State<Dim>& s, Real dt) = 0;
  // G2P: v, C, x and F together (usl).
  virtual StepReport grid_to_particles(State<Dim>& s, Real dt) = 0;
  // The split stages of the other orders. P2G momentum part: mass and the
  // transfer's own momentum (with C_p for affine transfers), no forces.
  virtual void scatter_momentum(State<Dim>& s) = 0;
  // P2G force part: -V0 tau grad w from the current stress and body forces,
  // added to the grid that scatter_momentum filled (for the step dt that
  // follows: a transfer may fold dt f_i into p_i, see NodeSums).
  virtual void scatter_forces(State<Dim>& s, Real dt) = 0;
  // v_i = p_i / m_i with the boundary conditions at time t, leaving m, p and f
  // as they were: the velocities that update F (usf, musl).
  virtual void grid_velocities(State<Dim>& s, Real t) = 0;
  // G2P motion part: v, C and x, F untouched.
  virtual StepReport move_particles(State<Dim>& s, Real dt) = 0;
  // G2P deformation part: F_p <- (I + dt sum v_i grad w_ip^T) F_p; reports J.
  virtual StepReport update_deformation(State<Dim>& s, Real dt) = 0;
  // Grid Laplacians that nonlocal models ask for (core/nonlocal.hpp).
  virtual void nonlocal_update(State<Dim>& /*s*/) {}
  void constitutive_update(State<Dim>& s, Real dt) {
    for (std::size_t m = 0; m < s.materials.size(); ++m) {
      s.materials[m]->return_map(s.particles, s.material_particles[m], dt);
    }
  }

  // Angular momentum carried by the affine matrices, sum_p m_p eps : (C_p D_p)
  // (Jiang et al. 2015, sec. 5.3); zero for transfers without affine momentum.
  virtual Vec3 affine_angular_momentum(const State<Dim>& s) const = 0;

 private:
  // The motion's speed and domain check with the deformation's J.
  static StepReport merged(const StepReport& motion, const StepReport& deformation) {
    StepReport r = motion;
    r.J_min = deformation.J_min;
    r.J_max = deformation.J_max;
    if (deformation.non_finite >= 0)
      r.non_finite = r.non_finite < 0 ? deformation.non_finite
                                      : std::min(r.non_finite, deformation.non_finite);
    return r;
  }

  UpdateOrder order_ = UpdateOrder::usl;
  Integrator integrator_ = Integrator::explicit_euler;
  std::unique_ptr<ImplicitSolve<Dim>> implicit_;
};

template <int Dim>
void Stepper<Dim>::set_integrator(Integrator i, const ImplicitOptions& options) {
  if (i == Integrator::explicit_euler) {
    integrator_ = i;
    implicit_.reset();
    return;
  }
  const std::string name(integrator_name(i));
  if (!gradient_based() || transfer_name() == "xpic") {
    throw InputError(
        "method.integrator: '" + name + "' is refused with transfer '" +
        std::string(transfer_name()) +
        "': the implicit solve needs a gradient-based transfer without a filter "
        "of the old grid velocities; allowed: pic, flip, apic, aflip, asflip, polypic, tpic");
  }
  if (order_ != UpdateOrder::usl) {
    throw InputError("method.integrator: '" + name +
                     "' has its own stage order; method.update_order must be usl");
  }
  implicit_ = make_implicit_solve<Dim>(kernel_name(), i, options);
  integrator_ = i;  // only once accepted: a refused integrator leaves the step as it was
}

}  // namespace mpmtb
