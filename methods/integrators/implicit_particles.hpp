// The particle side of the implicit step (integrators/implicit_impl.hpp): each
// particle's stencil, its deformation gradient F_p(v) at trial grid velocities,
// its stress and its dP/dF block, and the particle-to-node sums of the
// incremental potential's derivatives (the stress divergence, the
// Hessian-vector product, the Hessian's diagonal, the body force).
//
// Parallel like the explicit step: per-particle loops split the particles
// over the threads, and the sums into nodes scatter over P2G's block colours
// (core/particle_blocks.hpp: the blocks of one colour touch disjoint nodes), so
// that each node adds its particles in an order fixed by the particles'
// positions alone. Sums over all particles (the strain energy, the round-off
// scale) keep each particle's term and add them in index order. The step is
// then bit-identical for any thread count (tests/unit/implicit_threads_test.cpp).
#pragma once

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "core/particle_blocks.hpp"
#include "core/state.hpp"
#include "core/stencil.hpp"

namespace mpmtb {

template <int Dim, class Kernel>
class ImplicitParticles {
  using V = std::vector<Vec<Dim>>;
  using StencilT = Stencil<Dim, Kernel>;
  static constexpr int kD2 = Dim * Dim;
  using Block = Eigen::Matrix<Real, kD2, kD2>;
  using Flat = Eigen::Matrix<Real, kD2, 1>;

 public:
  // The stencils at the step's start (deformed-domain kernels, cpGIMP and CPDI,
  // take F_p^n, as P2G did), the block colouring, F = F^n.
  void setup(const State<Dim>& s) {
    s_ = &s;
    const Particles<Dim>& P = s.particles;
    const long n = static_cast<long>(P.size());
    stencils_.clear();  // (a stencil has no default state to fill in parallel)
    stencils_.reserve(P.size());
    for (long p = 0; p < n; ++p) stencils_.emplace_back(P.x[p], P.F[p], s.grid.geo);
    blocks_.bin(P.x, s.grid.geo, box_);
    Fn_ = P.F;
    F_ = P.F;
    K_.resize(P.size());
    term_.resize(P.size());
  }

  long size() const { return static_cast<long>(Fn_.size()); }
  const std::vector<Mat<Dim>>& Fn() const { return Fn_; }

  // f_i += sum_p w_ip m_p b(x_p, t).
  void scatter_body_force(V& f) const {
    const Particles<Dim>& P = s_->particles;
    blocks_.for_each_coloured(*s_, [&](int p) {
      const Vec<Dim> mb = P.m[p] * s_->body_force(P, p, s_->time);
      stencils_[p].for_each_node(s_->grid.geo, [&](long node, Real w, const Vec<Dim>&,
                                                   const Vec<Dim>&) { f[node] += w * mb; });
    });
  }

  // F_p = (I + h sum_i (b_i + v_i) grad w_ip^T) F_p^n for every particle.
  void update_F(const V& b, const V& v, Real h) {
    const auto& geo = s_->grid.geo;
    const long n = size();
#pragma omp parallel for schedule(static) if (n >= kParallelMinimum)
    for (long p = 0; p < n; ++p) {
      Mat<Dim> G = Mat<Dim>::Zero();
      stencils_[p].for_each_node(geo, [&](long node, Real, const Vec<Dim>& grad, const Vec<Dim>&) {
        G += (b[node] + v[node]) * grad.transpose();
      });
      F_[p] = (Mat<Dim>::Identity() + h * G) * Fn_[p];
    }
  }

  // sum_p V0_p psi(F_p) at the current F (infinity where it is not finite), or at F^n.
  Real strain_energy() {
    return energy_of(F_);
  }
  Real strain_energy_at_Fn() {
    return energy_of(Fn_);
  }

  // out_i += sum_p V0_p P(F_p) F_p^nT grad w_ip (the negative internal force) at
  // the current F; also the round-off scale of psi (psi_noise).
  void stress_divergence(V& out) {
    const Particles<Dim>& P = s_->particles;
    blocks_.for_each_coloured(*s_, [&](int p) {
      const ConstitutiveModel<Dim>& model = *s_->materials[P.material[p]];
      const Mat<Dim> Pp = model.first_piola(F_[p], P.state_of(p));
      const Mat<Dim> Q = P.V0[p] * Pp * Fn_[p].transpose();
      const Real c = model.wave_speed();
      term_[p] = P.V0[p] * (Pp.norm() + model.density() * c * c * F_[p].norm()) * F_[p].norm();
      scatter(p, Q, out);
    });
    psi_noise_ = std::numeric_limits<Real>::epsilon() * sum_terms();
  }
  // eps sum_p V0_p (|P_p| + rho c^2 |F_p|) |F_p| at the last stress divergence.
  Real psi_noise() const {
    return psi_noise_;
  }

  // Each particle's dP/dF at F_p as a Dim^2 x Dim^2 matrix on column-major
  // vec(dF), optionally projected to positive semi-definite.
  void build_blocks(bool project) {
    const Particles<Dim>& P = s_->particles;
    const long n = size();
#pragma omp parallel for schedule(static) if (n >= kParallelMinimum)
    for (long p = 0; p < n; ++p) {
      const ConstitutiveModel<Dim>& model = *s_->materials[P.material[p]];
      Block K;
      for (int j = 0; j < kD2; ++j) {
        Mat<Dim> E = Mat<Dim>::Zero();
        E(j % Dim, j / Dim) = 1;
        const Mat<Dim> dP = model.first_piola_differential(F_[p], E, P.state_of(p));
        K.col(j) = Eigen::Map<const Flat>(dP.data());
      }
      if (project) {
        const Block Ks = Real(0.5) * (K + K.transpose());
        Eigen::SelfAdjointEigenSolver<Block> eig(Ks);
        if (eig.eigenvalues().minCoeff() < 0) {
          K = eig.eigenvectors() * eig.eigenvalues().cwiseMax(Real(0)).asDiagonal() *
              eig.eigenvectors().transpose();
        }
      }
      K_[p] = K;
    }
  }

  // out_i += h^2 sum_p V0_p (K_p : dF_p) F_p^nT grad w_ip, dF_p = sum_j dv_j grad w_jp^T F_p^n
  // (gathered and scattered per particle, one colour at a time).
  void hessian_times(const V& dv, Real h, V& out) const {
    const Particles<Dim>& P = s_->particles;
    const auto& geo = s_->grid.geo;
    blocks_.for_each_coloured(*s_, [&](int p) {
      Mat<Dim> G = Mat<Dim>::Zero();
      stencils_[p].for_each_node(geo, [&](long node, Real, const Vec<Dim>& grad, const Vec<Dim>&) {
        G += dv[node] * grad.transpose();
      });
      const Mat<Dim> dF = h * G * Fn_[p];
      Mat<Dim> dP;
      Eigen::Map<Flat>(dP.data()) = K_[p] * Eigen::Map<const Flat>(dF.data());
      scatter(p, (h * P.V0[p]) * dP * Fn_[p].transpose(), out);
    });
  }

  // diag_i[a] += the Hessian's diagonal less the mass: h^2 sum_p V0_p b^T K_p(a.,a.) b,
  // b = F_p^nT grad w_ip (dF = e_a b^T h for a unit velocity e_a at node i).
  void hessian_diagonal(Real h, V& diag) const {
    const Particles<Dim>& P = s_->particles;
    blocks_.for_each_coloured(*s_, [&](int p) {
      const Mat<Dim> FnT = Fn_[p].transpose();
      const Block& K = K_[p];
      stencils_[p].for_each_node(s_->grid.geo,
                                 [&](long node, Real, const Vec<Dim>& grad, const Vec<Dim>&) {
                                   const Vec<Dim> b = h * (FnT * grad);
                                   for (int a = 0; a < Dim; ++a) {
                                     Real sum = 0;
                                     for (int c = 0; c < Dim; ++c) {
                                       for (int e = 0; e < Dim; ++e)
                                         sum += b[c] * b[e] * K(a + Dim * c, a + Dim * e);
                                     }
                                     diag[node][a] += h * P.V0[p] * sum;
                                   }
                                 });
    });
  }

  // shift_p = sum_i w_ip dt/2 (b_i - v_i): Newmark's position correction
  // (integrators/implicit_impl.hpp, finish).
  void interpolate_difference(const V& b, const V& v, Real scale, V& shift) const {
    const long n = size();
    shift.assign(Fn_.size(), Vec<Dim>::Zero());
#pragma omp parallel for schedule(static) if (n >= kParallelMinimum)
    for (long p = 0; p < n; ++p) {
      stencils_[p].for_each_node(s_->grid.geo,
                                 [&](long node, Real w, const Vec<Dim>&, const Vec<Dim>&) {
                                   shift[p] += (scale * w) * (b[node] - v[node]);
                                 });
    }
  }

  // sum_p h V0_p rho c^2 (2 Dim / dx) max(1, |F_p^n|^2): the stresses' share of
  // the round-off floor of |g| (implicit_impl.hpp, solve).
  Real stress_scale(Real h) {
    const Particles<Dim>& P = s_->particles;
    const Real inv_dx = s_->grid.geo.inv_dx;
    const long n = size();
#pragma omp parallel for schedule(static) if (n >= kParallelMinimum)
    for (long p = 0; p < n; ++p) {
      const ConstitutiveModel<Dim>& model = *s_->materials[P.material[p]];
      const Real c = model.wave_speed();
      term_[p] = h * P.V0[p] * model.density() * c * c * (2 * Dim * inv_dx) *
                 std::max(Real(1), Fn_[p].squaredNorm());
    }
    return sum_terms();
  }

 private:
  void scatter(int p, const Mat<Dim>& Q, V& out) const {
    stencils_[p].for_each_node(s_->grid.geo, [&](long node, Real, const Vec<Dim>& grad,
                                                 const Vec<Dim>&) { out[node] += Q * grad; });
  }

  Real energy_of(const std::vector<Mat<Dim>>& F) {
    const Particles<Dim>& P = s_->particles;
    const long n = size();
#pragma omp parallel for schedule(static) if (n >= kParallelMinimum)
    for (long p = 0; p < n; ++p) {
      term_[p] = P.V0[p] * s_->materials[P.material[p]]->energy_density(F[p], P.state_of(p));
    }
    const Real sum = sum_terms();
    return std::isfinite(sum) ? sum : std::numeric_limits<Real>::infinity();
  }

  // The particles' terms added in index order: the same bits for any thread count.
  Real sum_terms() const {
    Real sum = 0;
    for (const Real t : term_) sum += t;
    return sum;
  }

  const State<Dim>* s_ = nullptr;
  std::vector<StencilT> stencils_;
  ParticleBlocks<Dim, Kernel> blocks_;
  NodeBox<Dim> box_;  // the nodes the stencils reach (set by the binning; unused otherwise)
  std::vector<Mat<Dim>> Fn_, F_;
  std::vector<Block, Eigen::aligned_allocator<Block>> K_;
  std::vector<Real> term_;  // per-particle terms of a sum
  Real psi_noise_ = 0;
};

}  // namespace mpmtb
