#pragma once
// The critical time step of a mass-spring network (docs/stability.md). For the generalized
// eigenproblem K v = omega^2 M v of the linearised network (springs k_ij along the lines of centres,
// walls as springs to an infinite mass), velocity Verlet and symplectic Euler are stable for
// dt < 2 / omega_max. Two estimates:
//  - a bound: with v^T K v = sum_bonds k (n . (v_i - v_j))^2 <= sum_bonds 2 k (|v_i|^2 + |v_j|^2) and
//    a wall term k (n . v_i)^2 <= k |v_i|^2, the Rayleigh quotient v^T K v / v^T M v is at most
//        omega_bound^2 = max_i (2 sum_j k_ij + sum_walls k_iw) / m_i
//    (Gershgorin's bound on M^-1 K in this form; it needs only the owned particle's mass);
//  - power iterations on M^-1 K, each product K v from two force evaluations (positions perturbed
//    along v), so the models' real stiffnesses and the current contacts enter. The Rayleigh
//    quotient rises towards omega_max^2 from below: 2 / omega_power is at least the true step.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <type_traits>
#include <vector>

namespace basalt::solver::stability {

/// The critical step 2 / omega for omega^2 (infinite for no stiffness).
inline double critical_step(double omega2) {
  return omega2 > 0 ? 2 / std::sqrt(omega2) : std::numeric_limits<double>::infinity();
}

/// Start vector of the power iterations: component d of particle `id`, in [-1, 1), a function of the
/// id alone (the same on any number of ranks).
inline double start_component(std::int64_t id, int d) {
  std::uint64_t k = static_cast<std::uint64_t>(id) * 3u + static_cast<std::uint64_t>(d);
  k += 0x9E3779B97F4A7C15ull;
  k = (k ^ (k >> 30)) * 0xBF58476D1CE4E5B9ull;
  k = (k ^ (k >> 27)) * 0x94D049BB133111EBull;
  k ^= k >> 31;
  return double(k >> 11) * 0x1.0p-53 * 2.0 - 1.0;
}

/// The spacing of the floating-point numbers at |c| for a normal c (the distance to the next one away
/// from zero): 2^(exponent of c - mantissa bits), from the exponent bits alone.
template <class Real>
Real ulp(Real c) {
  using Bits = std::conditional_t<sizeof(Real) == 8, std::uint64_t, std::uint32_t>;
  constexpr int kMantissa = std::numeric_limits<Real>::digits - 1;
  constexpr Bits kExponent = ((Bits(1) << (sizeof(Real) * 8 - 1)) - 1) & ~((Bits(1) << kMantissa) - 1);
  Bits b;
  std::memcpy(&b, &c, sizeof b);
  b &= kExponent;  // |c| rounded down to a power of two
  Real p;
  std::memcpy(&p, &b, sizeof p);
  return p * std::numeric_limits<Real>::epsilon();
}

/// The largest eigenvalue of the symmetric tridiagonal matrix with diagonal `alpha` and off-diagonal
/// `beta` (alpha.size() - 1 of them are read), by bisection on the Sturm count: the Lanczos
/// iterations' Ritz value. 0 for an empty matrix.
inline double largest_eigenvalue(const std::vector<double>& alpha, const std::vector<double>& beta) {
  const std::size_t m = alpha.size();
  if (m == 0) return 0;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (std::size_t k = 0; k < m; ++k) {  // Gershgorin's interval
    const double r = (k > 0 ? std::abs(beta[k - 1]) : 0.0) + (k + 1 < m ? std::abs(beta[k]) : 0.0);
    lo = std::min(lo, alpha[k] - r);
    hi = std::max(hi, alpha[k] + r);
  }
  // Eigenvalues above x: negative pivots of T - x I = L D L^T counted from below, so the count of
  // pivots < 0 is the number of eigenvalues below x.
  const auto below = [&](double x) {
    std::size_t count = 0;
    double piv = 1;
    for (std::size_t k = 0; k < m; ++k) {
      const double b2 = k > 0 ? beta[k - 1] * beta[k - 1] : 0.0;
      piv = alpha[k] - x - (k > 0 ? b2 / piv : 0.0);
      if (piv == 0) piv = -1e-300;  // x is an eigenvalue of the leading block: step past it
      if (piv < 0) ++count;
    }
    return count;
  };
  for (int i = 0; i < 200 && hi - lo > 1e-15 * std::max(std::abs(lo), std::abs(hi)); ++i) {
    const double mid = 0.5 * (lo + hi);
    if (below(mid) == m)
      hi = mid;  // every eigenvalue below mid
    else
      lo = mid;
  }
  return hi;
}

/// Power iterations stop when the Rayleigh quotient changed by less than this (relative) between
/// two iterations, or after kMaxIterations.
inline constexpr double kTolerance = 1e-4;
inline constexpr int kMaxIterations = 60;

/// Perturbation of the power iterations: the largest displacement, as a fraction of the smallest
/// radius (large enough against rounding of the positions, small enough to stay linear).
template <class Real>
constexpr double perturbation() {
  return sizeof(Real) >= 8 ? 1e-6 : 1e-3;
}

/// A perturbation that breaks a bond is tried again this many times, 8x smaller each time.
inline constexpr int kPerturbationRetries = 2;

/// The blow-up check: a particle that moved farther than skin/2 + kBlowupRadii x the smallest radius
/// since the last rebuild (which happens as soon as one moved skin/2) moved more than that fraction
/// of the smallest radius in one step.
inline constexpr double kBlowupRadii = 0.5;

/// The fraction of the critical-step estimate above which a rot_bond scene is warned of: two bonded
/// spheres were measured unstable from 0.502 of it, a bonded lattice from 0.78 (docs/stability.md,
/// "Rotational bonds and the critical step"); 0.45 leaves a margin.
inline constexpr double kRotBondFraction = 0.45;

}  // namespace basalt::solver::stability
