// Rotation-variant ("signed") SVD and polar decomposition of a deformation
// gradient in 1, 2 and 3 dimensions, and the cofactor matrix.
//
// signed_svd: F = U Sigma V^T with U and V proper rotations (det +1); the sign
// of det F goes into the last singular value, so sigma_1 >= ... >= |sigma_d|
// and sigma_d < 0 exactly when F is inverted (det F < 0). This is the
// invertible-element SVD of Irving, Teran & Fedkiw 2004 ("Invertible finite
// elements for robust simulation of large deformation", SCA, sec. 4) as used
// by Stomakhin, Howes, Schroeder & Teran 2012 ("Energetically consistent
// invertible elasticity", SCA, sec. 3).
//
// polar: F = R S with R = U V^T a rotation (det +1) also for reflected and
// (near-)singular F, and S = V Sigma V^T symmetric (not positive definite when
// det F < 0). R is the rotation closest to F in the Frobenius norm.
//
// 2x2: closed form from the rotation/reflection split of F: writing
//   E = (F00 + F11)/2, H = (F10 - F01)/2 (the rotation part, angle a2),
//   D = (F00 - F11)/2, G = (F10 + F01)/2 (the reflection part, angle a1),
// F = Rot(alpha) diag(q + r, q - r) Rot(beta) with q = |(E, H)|, r = |(D, G)|,
// alpha = (a2 + a1)/2, beta = (a2 - a1)/2, so U = Rot(alpha), V = Rot(-beta)
// and R = Rot(a2) = [E -H; H E] / q. The angles are never formed: cos and sin
// of a1 and a2 are (D, G)/r and (E, H)/q, those of a1 + a2 follow by the sum
// formulas, alpha by the half-angle formulas (either root: alpha + pi with
// beta + pi flips both U and V, the same SVD), and beta = a2 - alpha. Square
// roots only, no atan2, sin, cos or hypot, which took 40 % of a 2D snow step.
// 3x3: Eigen::JacobiSVD, then the sign of a reflected U or V is moved into
// sigma_3 (Irving et al. 2004, sec. 4).
#pragma once

#include <Eigen/SVD>
#include <cmath>
#include <limits>

#include "core/pack.hpp"  // MPMTB_INLINE
#include "core/types.hpp"

namespace mpmtb {

template <int Dim>
struct SignedSvd {
  Mat<Dim> U;      // rotation, det U = +1
  Vec<Dim> sigma;  // sigma_1 >= ... >= |sigma_d|; sign(sigma_d) = sign(det F)
  Mat<Dim> V;      // rotation, det V = +1
};

template <int Dim>
struct PolarDecomposition {
  Mat<Dim> R;  // rotation, det R = +1
  Mat<Dim> S;  // symmetric, F = R S
};

namespace detail {
inline Mat<2> rotation2(Real c, Real s) {
  Mat<2> R;
  R << c, -s, s, c;
  return R;
}
// |(a, b)| without hypot's cost where the squares neither overflow nor
// underflow (every deformation gradient of a run), hypot beyond.
// Exact zero too (an undeformed or rigidly moving F has no reflection part).
// The bounds are the precision's own: a sum of squares above min / eps keeps
// every bit (its larger square is a normal number), below max eps it cannot
// overflow. (A fixed 1e-30 sent the reflection part of a nearly rotated F,
// round-off of 1e-17 in double, to hypot: 5 % of a 2D snow step.)
inline Real norm2(Real a, Real b) {
  const Real s = a * a + b * b;
  constexpr Real eps = std::numeric_limits<Real>::epsilon();
  constexpr Real lo = std::numeric_limits<Real>::min() / eps;
  constexpr Real hi = std::numeric_limits<Real>::max() * eps;
  if (s > lo && s < hi) return std::sqrt(s);
  return a == 0 && b == 0 ? Real(0) : std::hypot(a, b);
}
// (cos, sin) of the angle of (x, y) at radius n (atan2's angle; 0 at the origin).
inline void unit2(Real x, Real y, Real n, Real& c, Real& s) {
  if (n > 0) {
    const Real inv = 1 / n;
    c = x * inv, s = y * inv;
  } else {
    c = 1, s = 0;
  }
}
// The rotation part (E, H) and the reflection part (D, G) of a 2x2 F, and
// their lengths q and r (the header's 2x2 closed form): the singular values are
// q + r and q - r.
struct Parts2 {
  Real E, H, D, G, q, r;
};
inline Parts2 parts2(const Mat<2>& F) {
  Parts2 t;
  t.E = Real(0.5) * (F(0, 0) + F(1, 1)), t.H = Real(0.5) * (F(1, 0) - F(0, 1));
  t.D = Real(0.5) * (F(0, 0) - F(1, 1)), t.G = Real(0.5) * (F(1, 0) + F(0, 1));
  t.q = norm2(t.E, t.H), t.r = norm2(t.D, t.G);
  return t;
}
}  // namespace detail

template <int Dim>
SignedSvd<Dim> signed_svd(const Mat<Dim>& F) {
  static_assert(Dim >= 1 && Dim <= 3);
  SignedSvd<Dim> out;
  if constexpr (Dim == 1) {
    out.U = out.V = Mat<1>::Identity();
    out.sigma(0) = F(0, 0);
  } else if constexpr (Dim == 2) {
    const auto [E, H, D, G, q, r] = detail::parts2(F);
    Real c1, s1, c2, s2;  // angles a1 of (D, G) and a2 of (E, H)
    detail::unit2(D, G, r, c1, s1);
    detail::unit2(E, H, q, c2, s2);
    const Real c12 = c1 * c2 - s1 * s2, s12 = s1 * c2 + c1 * s2;  // a1 + a2 = 2 alpha
    Real ca, sa;  // half angle: the larger of the two roots first (no cancellation)
    if (c12 >= 0) {
      ca = std::sqrt(Real(0.5) * (1 + c12));
      sa = s12 / (2 * ca);
    } else {
      sa = std::sqrt(Real(0.5) * (1 - c12));
      ca = s12 / (2 * sa);
    }
    const Real cb = c2 * ca + s2 * sa, sb = s2 * ca - c2 * sa;  // beta = a2 - alpha
    out.U = detail::rotation2(ca, sa);
    out.V = detail::rotation2(cb, -sb);
    out.sigma << q + r, q - r;
  } else {
// GCC 12 at -O3 reports a false -Wmaybe-uninitialized inside Eigen's fixed-size
// JacobiSVD (its singular values are all written by compute()).
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
    const Eigen::JacobiSVD<Mat<3>> svd(F, Eigen::ComputeFullU | Eigen::ComputeFullV);
    out.U = svd.matrixU();
    out.V = svd.matrixV();
    out.sigma = svd.singularValues();
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif
    if (out.U.determinant() < 0) {
      out.U.col(2) *= -1;
      out.sigma(2) *= -1;
    }
    if (out.V.determinant() < 0) {
      out.V.col(2) *= -1;
      out.sigma(2) *= -1;
    }
  }
  return out;
}

// The signed singular values alone, the same bits as signed_svd(F).sigma: in 2D
// q + r and q - r, two square roots instead of the rotations' four divisions
// and a third root (a return map that leaves most particles elastic needs only
// these); in 1D and 3D from signed_svd.
template <int Dim>
Vec<Dim> signed_singular_values(const Mat<Dim>& F) {
  if constexpr (Dim == 2) {
    const detail::Parts2 t = detail::parts2(F);
    return Vec<2>(t.q + t.r, t.q - t.r);
  } else {
    return signed_svd<Dim>(F).sigma;
  }
}

// R of the polar decomposition F = R S (a rotation for every F).
namespace detail {
inline Mat<3> polar_rotation3(const Mat<3>& F) {
  const SignedSvd<3> svd = signed_svd<3>(F);
  return svd.U * svd.V.transpose();
}
}  // namespace detail

// Inlined into its callers (the stress passes): called, the 2x2 rotation came
// back through the stack, and the caller's wider load of it waited on the
// narrower stores (perf, 2D snow: a sixth of fixed_corotated_tau's samples).
template <int Dim>
MPMTB_INLINE inline Mat<Dim> polar_rotation(const Mat<Dim>& F) {
  if constexpr (Dim == 1) {
    return Mat<1>::Identity();
  } else if constexpr (Dim == 2) {
    const Real E = Real(0.5) * (F(0, 0) + F(1, 1)), H = Real(0.5) * (F(1, 0) - F(0, 1));
    const Real q = detail::norm2(E, H);
    if (!(q > 0)) return Mat<2>::Identity();  // F = symmetric traceless: R = I is a minimizer
    return detail::rotation2(E / q, H / q);
  } else {
    return detail::polar_rotation3(F);
  }
}

template <int Dim>
PolarDecomposition<Dim> polar(const Mat<Dim>& F) {
  PolarDecomposition<Dim> out;
  out.R = polar_rotation<Dim>(F);
  const Mat<Dim> S = out.R.transpose() * F;  // symmetric up to round-off
  out.S = Real(0.5) * (S + S.transpose());
  return out;
}

// cof(F) = J F^-T, written without the inverse so that it is defined for
// singular and inverted F (d det F / dF = cof F).
template <int Dim>
Mat<Dim> cofactor(const Mat<Dim>& F) {
  if constexpr (Dim == 1) {
    return Mat<1>::Identity();
  } else if constexpr (Dim == 2) {
    Mat<2> C;
    C << F(1, 1), -F(1, 0), -F(0, 1), F(0, 0);
    return C;
  } else {
    Mat<3> C;
    C.col(0) = F.col(1).cross(F.col(2));
    C.col(1) = F.col(2).cross(F.col(0));
    C.col(2) = F.col(0).cross(F.col(1));
    return C;
  }
}

}  // namespace mpmtb
