#pragma once
// Rotational bond between two rotating spheres: ESyS-Particle's "RotBond" / "BrittleBeam"
// (ARotBondedInteraction::calcForces, CRotBondedInteraction::broken; Wang, Abe, Latham, Mora 2006,
// "Implementation of particle-scale rotation in the 3-D lattice solid model", PAGEOPH 163) with its
// conventions; LAMMPS's bond_style bpm/rotational carries the same four springs.
//
// Particle 1 is the bond's first end (a), 2 its second (b); q1, q2 their orientations (body -> world),
// D = x2 - x1 at the start of the run (both orientations the identity then), L = |D|, r0 the rest length
// (ESyS: r1 + r2; Basalt's default: L). In 1's body frame, rb = R1^T (x2 - x1):
//   normal   Fr = kn (|rb| - r0) rb/|rb|                            (attractive when stretched)
//   shear    Fst = ks r0 gamma, gamma the angle between rb and D, towards the offset of 2, with the
//            couple Mst = -|Fst| (rb x D)/|rb x D|; and, from the relative rotation r = q1^-1 q2 seen in
//            the frame qm that turns z onto rb: the bending angle theta and torsion angle psi,
//   bending  Mb = kb theta / 2, with a shear force Fs = ks r0 theta / 2 and its couple (Wang eq. 16),
//   torsion  Mt = kt psi about rb.
// The shear couples go to the particles in proportion r1/(r1+r2), r2/(r1+r2) times |x2 - x1| (eq. 19).
// Energy (ESyS's): Fn^2/2kn + Fs^2/2ks + Mt^2/2kt + Mb^2/2kb.
//
// Stiffnesses are given (kn, ks in force/length; kb, kt in moment/radian) or derived from Young's
// modulus E and Poisson's ratio nu (ESyS "BrittleBeamPrms", always scaled per bond): with the bond radius
// R = L/2 (radius_scaling = "mean", ESyS meanR_scaling=True) or min(r1, r2) ("min"), G = E / 2(1+nu):
//   kn = pi E R^2/L, ks = pi G R^2/L, kb = pi E R^4/(4L), kt = pi G R^4/(2L).
// Strengths from cohesion c and tan(phi) (scaled alike): Fn_max = pi c R^2/tan(phi), Fs_max = pi c R^2,
// Mb_max = pi c R^3/(4 tan(phi)), Mt_max = pi c R^3/2; or given directly (max_normal_force, ...).
// Given stiffnesses and strengths with scaling = true (ESyS "RotBondPrms", scaling=True) are per unit and
// scaled per bond alike: kn R^2/L, ks R^2/L, kb R^4/(4L), kt R^4/(2L), Fn_max R^2, Fs_max R^2, Mb_max R^3/4,
// Mt_max R^3/2 (BrittleBeam is this with kn = kb = pi E, ks = kt = pi G).
// Failure (criterion = "esys", ESyS's direct Mohr-Coulomb): with Fn > 0 in tension,
//   normal = Fn/Fn_max + beta1 Mb/Mb_max, shear = Fs/Fs_max + beta2 Mt/Mt_max,
//   broken when normal > truncated or shear > 1 - normal;
// criterion = "sum" (LAMMPS bpm/rotational): max(Fn, 0)/Fn_max + Fs/Fs_max + Mb/Mb_max + Mt/Mt_max >= 1.
// The failure mode recorded is the largest of the four terms (tension, shear, bending, torsion).
//
// Angles (angles = "esys", default): gamma = acos(cos gamma), theta = acos(t0 - t2), psi from acos, as ESyS.
// Near zero acos loses half the digits: a rounding of cos by 1 ulp reads as an angle of sqrt(2 * 1.1e-16)
// = 1.5e-8 rad, so a bond at rest carries loads of ks r0 1.5e-8 in a direction set by rounding; in a free
// specimen these kicks pump energy in (docs/validation-rock.md, "Energy"). angles = "atan2" takes the same
// angles from atan2(|sin|, cos) (gamma = atan2(|rb x D|, rb.D), theta = 2 atan2(sqrt t2, sqrt t0),
// psi = 2 atan2(r.z, r.w)): equal to acos's up to rounding at every angle, exact near zero.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <string_view>
#include <type_traits>
#include <vector>

#include "basalt/solver/models/lanes.hpp"
#include "basalt/solver/models/model.hpp"
#include "basalt/solver/scene/table_reader.hpp"

namespace basalt::solver {

/// How a bond failed (BrokenBond::mode; linear bonds break in tension).
enum class BondFailure : std::uint8_t { tension = 0, shear = 1, bending = 2, torsion = 3 };
inline constexpr std::array<std::string_view, 4> kBondFailureNames{"tension", "shear", "bending", "torsion"};

namespace beam {

template <class Real>
struct Vec {
  Real x = 0, y = 0, z = 0;
  Vec operator+(const Vec& o) const { return {x + o.x, y + o.y, z + o.z}; }
  Vec operator-(const Vec& o) const { return {x - o.x, y - o.y, z - o.z}; }
  Vec operator*(Real s) const { return {x * s, y * s, z * s}; }
  Real dot(const Vec& o) const { return x * o.x + y * o.y + z * o.z; }
  Vec cross(const Vec& o) const { return {y * o.z - z * o.y, z * o.x - x * o.z, x * o.y - y * o.x}; }
  Real norm() const { return std::sqrt(dot(*this)); }
};

template <class Real>
struct Quat {
  Real w = 1, x = 0, y = 0, z = 0;
  Quat operator*(const Quat& o) const {  // Hamilton product
    return {w * o.w - x * o.x - y * o.y - z * o.z, w * o.x + x * o.w + y * o.z - z * o.y,
            w * o.y - x * o.z + y * o.w + z * o.x, w * o.z + x * o.y - y * o.x + z * o.w};
  }
  /// The conjugate, as ESyS's Quaternion::inverse: the inverse of a unit quaternion (the integrator keeps
  /// orientations of unit length, as ESyS does). Unlike a division by |q|^2 it leaves q^-1 q at rest with no
  /// rounding-level vector part, which acos would read as a 1.5e-8 rad bend (docs/validation-rock.md).
  Quat inverse() const { return {w, -x, -y, -z}; }
  /// R v for the rotation R this quaternion stands for (body -> world): Rot's matrix (below).
  Vec<Real> to_world(const Vec<Real>& v) const;
};

/// The rotation matrix of a unit quaternion (body -> world), built once for the several vectors a bond
/// turns, in the homogeneous form (w^2 + x^2 - y^2 - z^2 ...) of ESyS's Quaternion::to_matrix.
template <class Real>
struct Rot {
  Real m[3][3];
  explicit Rot(const Quat<Real>& q) {
    const Real ww = q.w * q.w, xx = q.x * q.x, yy = q.y * q.y, zz = q.z * q.z;
    m[0][0] = ww + xx - yy - zz, m[0][1] = 2 * (q.x * q.y - q.w * q.z), m[0][2] = 2 * (q.x * q.z + q.w * q.y);
    m[1][0] = 2 * (q.x * q.y + q.w * q.z), m[1][1] = ww - xx + yy - zz, m[1][2] = 2 * (q.y * q.z - q.w * q.x);
    m[2][0] = 2 * (q.x * q.z - q.w * q.y), m[2][1] = 2 * (q.y * q.z + q.w * q.x), m[2][2] = ww - xx - yy + zz;
  }
  /// R v.
  Vec<Real> to_world(const Vec<Real>& v) const {
    return {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z, m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
            m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z};
  }
  /// R (a, b, 0): a vector of the xy-plane.
  Vec<Real> xy_to_world(Real a, Real b) const {
    return {m[0][0] * a + m[0][1] * b, m[1][0] * a + m[1][1] * b, m[2][0] * a + m[2][1] * b};
  }
  /// R^T v.
  Vec<Real> to_body(const Vec<Real>& v) const {
    return {m[0][0] * v.x + m[1][0] * v.y + m[2][0] * v.z, m[0][1] * v.x + m[1][1] * v.y + m[2][1] * v.z,
            m[0][2] * v.x + m[1][2] * v.y + m[2][2] * v.z};
  }
};

template <class Real>
Vec<Real> Quat<Real>::to_world(const Vec<Real>& v) const {
  return Rot<Real>(*this).to_world(v);
}

/// acos c for c in (0.995, 1] (angles below 0.1 rad, where a bond's angles live; larger c, from rounding,
/// read as 1): acos c = 2 asin(s),
/// s = sqrt((1 - c)/2) <= 0.05, by asin's series to s^13 (the next term is below 1e-20 relative): 1 - c is
/// exact for c >= 1/2, so the result is within 1-2 ulp of glibc's acos at a fraction of its cost (test
/// RotBondLaw.FastAcosMatchesAcosToRounding).
/// acos_near_one: the series on (0.995, 1], std::acos elsewhere and in single precision.
template <class Real>
[[gnu::always_inline]] inline Real acos_series(Real c) {
  const Real s = std::sqrt(std::max(Real(0.5) * (Real(1) - c), Real(0))), t = s * s;
  // asin s = s + s t (1/6 + t (3/40 + t (5/112 + t (35/1152 + t (63/2816 + t 231/13312)))))
  const Real p =
      Real(1.0 / 6) +
      t * (Real(3.0 / 40) + t * (Real(5.0 / 112) + t * (Real(35.0 / 1152) +
                                                        t * (Real(63.0 / 2816) + t * Real(231.0 / 13312)))));
  return 2 * (s + s * t * p);
}

/// atan t for |t| <= 0.1 (angles below 0.0997 rad) by its series to t^15 (the next term is below 6e-18
/// relative): atan2(y, x) = atan(y / x) for x > 0, |y| <= 0.1 x, within 1-2 ulp of std::atan2, in vector
/// lanes (test RotBondLaw.AtanSeriesMatchesAtan2ToRounding).
template <class Real>
[[gnu::always_inline]] inline Real atan_series(Real t) {
  const Real u = t * t;
  // atan t = t - t u (1/3 - u (1/5 - u (1/7 - u (1/9 - u (1/11 - u (1/13 - u / 15))))))
  const Real p =
      Real(1.0 / 3) -
      u * (Real(1.0 / 5) -
           u * (Real(1.0 / 7) -
                u * (Real(1.0 / 9) - u * (Real(1.0 / 11) - u * (Real(1.0 / 13) - u * Real(1.0 / 15))))));
  return t - t * u * p;
}

template <class Real>
Real acos_near_one(Real c) {
  if constexpr (std::is_same_v<Real, double>) {
    if (c > 0.995) return acos_series(c);
  }
  return std::acos(c);
}

/// The signed angle whose cosine is c and whose sine has the sign of s (0 for s = 0 or |c| >= 1).
template <class Real>
Real signed_angle(Real s, Real c) {
  if (s == Real(0) || c >= Real(1) || c <= Real(-1)) return 0;
  return s > 0 ? acos_near_one(c) : -acos_near_one(c);
}

}  // namespace beam

struct RotBond {
  static constexpr std::string_view name = "rot_bond";
  static constexpr ModelKind kind = ModelKind::bond;
  static constexpr bool rotational = true;
  static constexpr std::string_view summary =
      "normal, shear, bending and torsion springs of a beam between rotating spheres; Mohr-Coulomb or sum "
      "failure (ESyS RotBond/BrittleBeam, Wang et al. 2006)";
  static constexpr std::array keys{
      KeyDoc{"youngs_modulus", "E, force/length^2: stiffnesses from E and nu per bond (ESyS BrittleBeam)"},
      KeyDoc{"poissons_ratio", "nu, in (-1, 0.5] (with youngs_modulus; required)"},
      KeyDoc{"radius_scaling",
             "\"mean\" (R = L/2, default) or \"min\" (R = min(r1, r2)), with youngs_modulus or scaling"},
      KeyDoc{"kn", "normal stiffness, force/length (instead of youngs_modulus, with ks, kb, kt)"},
      KeyDoc{"ks", "shear stiffness, force/length"},
      KeyDoc{"kb", "bending stiffness, moment/radian"},
      KeyDoc{"kt", "torsion stiffness, moment/radian"},
      KeyDoc{
          "scaling",
          "with kn...: false (default: kn... per bond as given) or true (ESyS RotBondPrms scaling=True: kn, "
          "ks per unit R^2/L, kb per R^4/(4L), kt per R^4/(2L); strengths per R^2, R^3/4, R^3/2)"},
      KeyDoc{"cohesion",
             "c, force/length^2: strengths per bond (with youngs_modulus; default: never breaks)"},
      KeyDoc{"tan_friction_angle", "tan(phi) > 0 (with cohesion; ESyS tanAngle)"},
      KeyDoc{"max_normal_force", "tensile strength, force (with kn...; default: infinite)"},
      KeyDoc{"max_shear_force", "shear strength, force (default: infinite)"},
      KeyDoc{"max_bending_moment", "bending strength, moment (default: infinite)"},
      KeyDoc{"max_torsion_moment", "torsion strength, moment (default: infinite)"},
      KeyDoc{"criterion", "\"esys\" (default: Mohr-Coulomb with cut-off) or \"sum\" (LAMMPS bpm/rotational)"},
      KeyDoc{"truncated", "esys: tension cut-off of the normal term, > 0 (default 1)"},
      KeyDoc{"beta1", "esys: weight of bending in the normal term, >= 0 (default 1)"},
      KeyDoc{"beta2", "esys: weight of torsion in the shear term, >= 0 (default 1)"},
      KeyDoc{"rest_length", "\"initial_distance\" (default) or \"sum_of_radii\" (ESyS)"},
      KeyDoc{"angles", "\"esys\" (default: acos, as ESyS) or \"atan2\" (exact for small angles)"},
      KeyDoc{"tags", "[a, b]: bonds between particles tagged a and b (default: all)"},
      KeyDoc{"bond_tag", "the geometry's bond tag this group takes (default: all)"}};
  static constexpr Fields reads = kPosition | kId | kRadius | kOrientation;
  static constexpr Fields writes = kForce | kTorque;

  enum class RestLength { initial_distance, sum_of_radii };
  enum class Criterion { esys, sum };
  static constexpr double kInf = std::numeric_limits<double>::infinity();
  struct Params {
    bool scaled = false;  ///< stiffnesses and strengths per unit (ESyS scaling): from E, nu, c, tan(phi)
    bool mean_radius = true;
    double kn = 0, ks = 0, kb = 0, kt = 0;                              ///< scaled: pi E, pi G, pi E, pi G
    double fn_max = kInf, fs_max = kInf, mb_max = kInf, mt_max = kInf;  ///< scaled: per unit R^2, R^3
    Criterion criterion = Criterion::esys;
    double truncated = 1, beta1 = 1, beta2 = 1;
    RestLength rest_length = RestLength::initial_distance;
    bool atan2_angles = false;
  };
  template <class Real>
  struct Coeffs {
    bool scaled, mean_radius;
    Real kn, ks, kb, kt;
    Real fn_max, fs_max, mb_max, mt_max;
    bool sum;
    Real truncated, beta1, beta2;
    bool atan2_angles;
  };
  struct History {};  // rest length: the bond store; reference direction: the particles' initial positions

  /// One bond's springs and strengths (after the per-bond scaling).
  template <class Real>
  struct BondCoeffs {
    Real kn, ks, kb, kt;
    Real ifn, ifs, imb, imt;  ///< 1 / strength (0: never)
    bool atan2_angles = false;
  };

  /// Why a group with these parameters cannot run in single precision, or "" (the registry refuses such a
  /// scene in float and mixed precision). ESyS's angles are arccosines of cosines near 1: a float cosine
  /// is 1 or at most 1 - 2^-24 there, so no angle between 0 and sqrt(2 * 2^-24) = 3.5e-4 rad is resolved
  /// (double: 1.5e-8), and a brittle bond fails at angles of that order (UCS-esys: about 1e-3 rad).
  static std::string_view float_problem(const Params& p) {
    if (p.atan2_angles) return {};
    return "angles = \"esys\" (the default: ESyS's arccosines) cannot run in single precision: float "
           "resolves the arccosine of a cosine near 1 no finer than 3.5e-4 rad, a large part of a bond's "
           "angle at failure, and the bonds' jumps between 0 and that angle pump energy into the run. Set "
           "angles = \"atan2\" (exact near zero, in float too), or run in double";
  }

  static Params parse(TableReader& t) {
    Params p;
    const bool modulus = t.has("youngs_modulus");
    if (modulus) {
      for (const char* k : {"kn", "ks", "kb", "kt", "max_normal_force", "max_shear_force",
                            "max_bending_moment", "max_torsion_moment", "scaling"})
        if (t.has(k))
          t.fail(k, "give either youngs_modulus (with poissons_ratio) or kn, ks, kb, kt, not both");
      p.scaled = true;
      const double E = t.positive("youngs_modulus"), nu = t.number("poissons_ratio");
      if (!(nu > -1 && nu <= 0.5)) t.fail("poissons_ratio", "must be in (-1, 0.5]");
      const double G = E / (2 * (1 + nu)), pi = std::numbers::pi;
      p.kn = pi * E, p.ks = pi * G, p.kb = pi * E, p.kt = pi * G;
      p.mean_radius = t.choice_or("radius_scaling", {"mean", "min"}, "mean") == "mean";
      if (t.has("cohesion")) {
        const double c = t.positive("cohesion"), ta = t.positive("tan_friction_angle");
        p.fn_max = pi * c / ta, p.fs_max = pi * c, p.mb_max = pi * c / ta, p.mt_max = pi * c;
      } else if (t.has("tan_friction_angle")) {
        t.fail("tan_friction_angle", "needs cohesion");
      }
    } else {
      for (const char* k : {"poissons_ratio", "cohesion", "tan_friction_angle"})
        if (t.has(k)) t.fail(k, "only with youngs_modulus");
      // ESyS RotBondPrms(scaling=True): the given stiffnesses and strengths scaled per bond as BrittleBeam's.
      p.scaled = t.boolean_or("scaling", false);
      if (p.scaled)
        p.mean_radius = t.choice_or("radius_scaling", {"mean", "min"}, "mean") == "mean";
      else if (t.has("radius_scaling"))
        t.fail("radius_scaling", "only with youngs_modulus or scaling = true");
      p.kn = t.non_negative("kn"), p.ks = t.non_negative("ks"), p.kb = t.non_negative("kb");
      p.kt = t.non_negative("kt");
      if (t.has("max_normal_force")) p.fn_max = t.positive("max_normal_force");
      if (t.has("max_shear_force")) p.fs_max = t.positive("max_shear_force");
      if (t.has("max_bending_moment")) p.mb_max = t.positive("max_bending_moment");
      if (t.has("max_torsion_moment")) p.mt_max = t.positive("max_torsion_moment");
    }
    p.criterion =
        t.choice_or("criterion", {"esys", "sum"}, "esys") == "sum" ? Criterion::sum : Criterion::esys;
    if (t.has("truncated")) p.truncated = t.positive("truncated");
    if (t.has("beta1")) p.beta1 = t.non_negative("beta1");
    if (t.has("beta2")) p.beta2 = t.non_negative("beta2");
    p.rest_length =
        t.choice_or("rest_length", {"initial_distance", "sum_of_radii"}, "initial_distance") == "sum_of_radii"
            ? RestLength::sum_of_radii
            : RestLength::initial_distance;
    p.atan2_angles = t.choice_or("angles", {"esys", "atan2"}, "esys") == "atan2";
    return p;
  }
  template <class Real>
  static Coeffs<Real> coeffs(const Params& p) {
    return {p.scaled,
            p.mean_radius,
            Real(p.kn),
            Real(p.ks),
            Real(p.kb),
            Real(p.kt),
            Real(p.fn_max),
            Real(p.fs_max),
            Real(p.mb_max),
            Real(p.mt_max),
            p.criterion == Criterion::sum,
            Real(p.truncated),
            Real(p.beta1),
            Real(p.beta2),
            p.atan2_angles};
  }
  /// The stiffest spring (critical step): kn, or with scaling kn at the largest bond (R = rmax, L = 2 rmax);
  /// the shear spring adds to it in the network.
  static double max_stiffness(const Params& p, double rmax) {
    return p.scaled ? (p.kn + p.ks) * rmax / 2 : p.kn + p.ks;
  }
  static bool breakable(const Params& p) {
    return std::isfinite(p.fn_max) || std::isfinite(p.fs_max) || std::isfinite(p.mb_max) ||
           std::isfinite(p.mt_max);
  }
  static double rest_length(const Params& p, double ri, double rj, double r) {
    return p.rest_length == RestLength::sum_of_radii ? ri + rj : r;
  }

  /// A bond's springs and strengths from its initial length L and radii (ESyS CRotBondedInteraction's
  /// constructor).
  template <class Real>
  static BondCoeffs<Real> bond_coeffs(const Coeffs<Real>& c, Real L, Real r1, Real r2) {
    const auto inv = [](Real s) { return std::isfinite(s) ? Real(1) / s : Real(0); };
    if (!c.scaled)
      return {c.kn,          c.ks,          c.kb,          c.kt,          inv(c.fn_max),
              inv(c.fs_max), inv(c.mb_max), inv(c.mt_max), c.atan2_angles};
    const Real R = c.mean_radius ? Real(0.5) * L : std::min(r1, r2);
    const Real A = R * R, J = Real(0.5) * A * A, I = Real(0.5) * J;
    return {c.kn * A / L,      c.ks * A / L,          c.kb * I / L,          c.kt * J / L,  inv(c.fn_max * A),
            inv(c.fs_max * A), inv(c.mb_max * I / R), inv(c.mt_max * J / R), c.atan2_angles};
  }

  /// What the bond sees: particle 1 and 2 (the bond's ends a, b).
  template <class Real>
  struct Geometry {
    beam::Vec<Real> x1, x2;
    beam::Quat<Real> q1, q2;
    beam::Vec<Real> d;  ///< x2 - x1 at the start
    Real r1, r2, r0;
  };
  /// Force on 1 (2 gets the opposite), moments on 1 and 2, and the four loads the criterion reads.
  template <class Real>
  struct Result {
    beam::Vec<Real> f1, m1, m2;
    Real fn;  ///< normal force, > 0 in tension
    Real fs, mb, mt;
  };

  /// What a bond's evaluation takes from its initial state alone (cached per bond by the driver).
  template <class Real>
  struct Fixed {
    Real inv_d;   ///< 1 / |d|
    Real e1, e2;  ///< r1/(r1+r2), r2/(r1+r2): the shares of the shear couple
  };
  template <class Real>
  static Fixed<Real> fixed(const Geometry<Real>& g) {
    return {Real(1) / g.d.norm(), g.r1 / (g.r1 + g.r2), g.r2 / (g.r1 + g.r2)};
  }

  template <class Real>
  static Result<Real> evaluate(const BondCoeffs<Real>& k, const Geometry<Real>& g) {
    return evaluate(k, g, fixed(g));
  }

  template <class Real>
  static Result<Real> evaluate(const BondCoeffs<Real>& k, const Geometry<Real>& g, const Fixed<Real>& f) {
    using V = beam::Vec<Real>;
    using Q = beam::Quat<Real>;
    const Real h = Real(0.5) * std::sqrt(Real(2));
    const V rbp = g.x2 - g.x1;
    const Real lp = rbp.norm();
    const beam::Rot<Real> R1(g.q1);
    const V rb = R1.to_body(rbp);
    const Real nb = rb.norm(), inb = Real(1) / nb, r0 = g.r0;
    const V fr = rb * (k.kn * (nb - r0) * inb);
    // Shear from the turn of the line of centres away from D, in 1's frame: |Fst| = ks r0 gamma along
    // rb x (rb x D) (of norm |rb| |rb x D|), its couple -|Fst| along rb x D.
    const V c0 = rb.cross(g.d);
    const Real n0 = c0.norm(), dot = rb.dot(g.d);
    const Real gc = dot * (inb * f.inv_d);
    const Real gamma = k.atan2_angles                    ? std::atan2(n0, dot)
                       : (gc < Real(1) && gc > Real(-1)) ? beam::acos_near_one(gc)
                                                         : Real(0);
    V fst{}, mst{};
    if (n0 != Real(0)) {
      const Real a = k.ks * r0 * gamma / n0;
      fst = rb.cross(c0) * (a * inb);
      mst = c0 * -a;
    }
    // qm turns z onto rb; r is the relative rotation seen in that frame.
    Q qm{h * std::sqrt((nb + rb.z) * inb), 0, 0, 0};
    const Real s = h * std::sqrt((nb - rb.z) * inb), rxy2 = rb.x * rb.x + rb.y * rb.y;
    qm.x = -s, qm.y = s;
    if (rxy2 != Real(0)) {
      const Real irxy = s / std::sqrt(rxy2);
      qm.x = -rb.y * irxy, qm.y = rb.x * irxy;
    }
    const beam::Rot<Real> Rm(qm);
    const Q r = qm.inverse() * (g.q1.inverse() * g.q2) * qm;
    const Real t0 = r.w * r.w + r.z * r.z, t2 = r.x * r.x + r.y * r.y;
    Real psi = 0;
    if (t0 != Real(0)) {
      const Real ist = Real(1) / std::sqrt(t0);
      psi = k.atan2_angles ? 2 * std::atan2(r.z, r.w) : 2 * beam::signed_angle(r.z * ist, r.w * ist);
    }
    const Real mt = k.kt * psi;
    const V mtr{Rm.m[0][2] * mt, Rm.m[1][2] * mt, Rm.m[2][2] * mt};
    V mbr{}, fsr{}, msr{};
    Real mb = 0;
    if (t2 != Real(0)) {
      const Real t1 = t0 - t2;
      const Real theta = k.atan2_angles                      ? 2 * std::atan2(std::sqrt(t2), std::sqrt(t0))
                         : (t1 >= Real(1) || t1 <= Real(-1)) ? Real(0)
                                                             : beam::acos_near_one(t1);
      Real cf, sf;
      if (t0 == Real(0)) {
        const Real iq = Real(1) / std::sqrt(t2);
        cf = r.y * iq, sf = -r.x * iq;
      } else {
        const Real iq = Real(1) / std::sqrt(t0 * t2);
        cf = (r.x * r.z + r.w * r.y) * iq, sf = (r.y * r.z - r.w * r.x) * iq;
      }
      const Real b = Real(0.5) * k.kb * theta, sh = Real(0.5) * k.ks * theta * r0;
      mb = std::abs(b);  // |Rm (-b sf, b cf, 0)|
      mbr = Rm.xy_to_world(-b * sf, b * cf);
      fsr = Rm.xy_to_world(-sh * cf, -sh * sf);
      msr = Rm.xy_to_world(sh * sf, -sh * cf);
    }
    const V ms = msr + mst, fs = fst + fsr;
    Result<Real> out;
    out.f1 = R1.to_world(fr + fs);
    out.m1 = R1.to_world(mbr + mtr + ms * (f.e1 * lp));
    out.m2 = R1.to_world(ms * (f.e2 * lp) - mbr - mtr);
    out.fn = (lp < r0 ? Real(-1) : Real(1)) * fr.norm();
    out.fs = fs.norm();
    out.mb = mb;
    out.mt = std::abs(mt);
    return out;
  }

  /// Every bond's constants in arrays indexed by bond, what evaluate_lanes reads: its ends' local indices
  /// (n1 = its first end), its BondCoeffs, Fixed, initial offset d and rest length, and its group's
  /// criterion. Kept by the driver while the bond list is unchanged; padded to a whole number of batches.
  /// With one bond group (`one_group`), the group's columns (truncated ... atan2) hold kSpan copies of its
  /// values instead of one per bond, which every batch reads from the start: 40 B less per bond.
  template <class Real>
  struct Table {
    enum Col {
      dx,
      dy,
      dz,
      r0,
      inv_d,
      e1,
      e2,
      kn,
      ks,
      kb,
      kt,
      ifn,
      ifs,
      imb,
      imt,
      truncated,
      beta1,
      beta2,
      sum,
      atan2,
      kCols
    };
    static constexpr int kSpan = 64;  ///< the widest batch evaluate_lanes may be given
    std::vector<std::uint32_t> n1, n2;
    std::array<std::vector<Real>, kCols> col;
    bool one_group = false;

    /// Column j holds a value per bond (else kSpan copies of the one group's).
    bool per_bond(int j) const { return !one_group || j < truncated; }
    /// n bonds; one_group must be set first.
    void resize(std::size_t n) {
      n1.resize(n), n2.resize(n);
      for (int j = 0; j < kCols; ++j)
        col[static_cast<std::size_t>(j)].resize(per_bond(j) ? n : std::size_t(kSpan));
    }
    std::size_t bytes() const {
      std::size_t b = (n1.capacity() + n2.capacity()) * sizeof(std::uint32_t);
      for (const auto& c : col) b += c.capacity() * sizeof(Real);
      return b;
    }
    /// Where column j's values for bonds k0 ... start.
    const Real* at(int j, std::size_t k0) const {
      return col[static_cast<std::size_t>(j)].data() + (per_bond(j) ? k0 : 0);
    }
    /// Bond k: ends n1 (first) and n2, its constants and its group's.
    void set(std::size_t k, std::uint32_t a, std::uint32_t b, const Coeffs<Real>& c,
             const BondCoeffs<Real>& bk, const Fixed<Real>& f, const beam::Vec<Real>& d, Real rest) {
      n1[k] = a, n2[k] = b;
      const Real v[kCols] = {d.x,         d.y,     d.z,     rest,        f.inv_d,
                             f.e1,        f.e2,    bk.kn,   bk.ks,       bk.kb,
                             bk.kt,       bk.ifn,  bk.ifs,  bk.imb,      bk.imt,
                             c.truncated, c.beta1, c.beta2, Real(c.sum), Real(bk.atan2_angles)};
      for (int j = 0; j < kCols; ++j) {
        if (per_bond(j)) {
          col[static_cast<std::size_t>(j)][k] = v[j];
        } else if (k == 0) {
          for (auto& x : col[static_cast<std::size_t>(j)]) x = v[j];
        }
      }
    }
    /// Removes the bonds at the ascending positions `gone` from the first n, keeping the others' order
    /// (column by column, each run of kept bonds moved at once); returns the bonds left.
    std::size_t erase(const std::vector<std::size_t>& gone, std::size_t n) {
      if (gone.empty()) return n;
      const auto squeeze = [&](auto& v) {
        auto to = v.begin() + static_cast<std::ptrdiff_t>(gone[0]);
        for (std::size_t g = 0; g < gone.size(); ++g) {
          const std::size_t from = gone[g] + 1, end = g + 1 < gone.size() ? gone[g + 1] : n;
          to = std::copy(v.begin() + static_cast<std::ptrdiff_t>(from),
                         v.begin() + static_cast<std::ptrdiff_t>(end), to);
        }
      };
      squeeze(n1), squeeze(n2);
      for (int j = 0; j < kCols; ++j)
        if (per_bond(j)) squeeze(col[static_cast<std::size_t>(j)]);
      return n - gone.size();
    }
    void copy(std::size_t to, std::size_t from) {
      n1[to] = n1[from], n2[to] = n2[from];
      for (int j = 0; j < kCols; ++j)
        if (per_bond(j)) col[static_cast<std::size_t>(j)][to] = col[static_cast<std::size_t>(j)][from];
    }
    BondCoeffs<Real> coeffs(std::size_t k) const {
      return {col[kn][k],  col[ks][k],  col[kb][k],  col[kt][k],        col[ifn][k],
              col[ifs][k], col[imb][k], col[imt][k], *at(atan2, k) != 0};
    }
    Fixed<Real> fixed(std::size_t k) const { return {col[inv_d][k], col[e1][k], col[e2][k]}; }
    beam::Vec<Real> d(std::size_t k) const { return {col[dx][k], col[dy][k], col[dz][k]}; }
  };

  /// What evaluate_lanes reads (the particles' positions and orientations, the bond table and the batch's
  /// first bond k0) and writes for W bonds side by side.
  template <class Real, int W>
  struct Lanes {
    const Real *x, *y, *z, *qw, *qx, *qy, *qz;  ///< the particles' arrays (local index)
    const Table<Real>* table;
    std::size_t k0;
    alignas(64) Real f1[3][W], m1[3][W], m2[3][W], fn[W], fs[W], mb[W], mt[W];
    alignas(64) Real general[W];  ///< 1: the lane is a case evaluate_lanes leaves to evaluate (see there)
    alignas(64) Real broken[W];   ///< 1: the bond fails under its group's criterion (lanes not general)
  };

  /// evaluate() and failure()'s test for the W bonds k0 ... k0 + W - 1 of the table at once, written without
  /// branches so that the compiler can run the lanes in vector registers, the particles' values gathered by
  /// index (it needs -fno-math-errno, set for the whole project, to vectorise sqrt): the same formulas in the
  /// same order, with each of evaluate()'s special cases computed anyway and the lane marked `general`
  /// instead. Those are the bonds at exactly zero shear, bend or lateral offset (at the start of a run, the
  /// bonds no load has reached yet), angles beyond the series (acos: cosines <= 0.995, above 0.1 rad; atan2:
  /// tangents above 0.1) and bonds whose angles are not the batch's kind (Atan2: angles = "atan2", taken by
  /// atan_series as atan(y / x), within 1-2 ulp of evaluate()'s std::atan2): the caller evaluates them with
  /// evaluate() and failure(). A bond's result depends on its own inputs only, never on its lane or its
  /// neighbours in the batch.
  template <class Real, int W, bool Atan2 = false>
  BASALT_WIDE_LANES static void evaluate_lanes(Lanes<Real, W>& b) {
    using V = beam::Vec<Real>;
    using Q = beam::Quat<Real>;
    using T = Table<Real>;
    const Real h = Real(0.5) * std::sqrt(Real(2)), one = 1, zero = 0;
    const Real* __restrict px = b.x, * __restrict py = b.y, * __restrict pz = b.z;
    const Real* __restrict pqw = b.qw, * __restrict pqx = b.qx, * __restrict pqy = b.qy, * __restrict pqz = b.qz;
    const std::uint32_t* __restrict n1 = b.table->n1.data() + b.k0, * __restrict n2 =
                                                                        b.table->n2.data() + b.k0;
    const Real* __restrict c[T::kCols];
    static_assert(W <= T::kSpan);
    for (int j = 0; j < T::kCols; ++j) c[j] = b.table->at(j, b.k0);
#pragma GCC ivdep
    for (int l = 0; l < W; ++l) {
      const std::uint32_t i1 = n1[l], i2 = n2[l];
      const V x1{px[i1], py[i1], pz[i1]}, x2{px[i2], py[i2], pz[i2]};
      const Q q1{pqw[i1], pqx[i1], pqy[i1], pqz[i1]}, q2{pqw[i2], pqx[i2], pqy[i2], pqz[i2]};
      const V d{c[T::dx][l], c[T::dy][l], c[T::dz][l]};
      const Real r0 = c[T::r0][l], ks = c[T::ks][l];
      const V rbp = x2 - x1;
      const Real lp = rbp.norm();
      const beam::Rot<Real> R1(q1);
      const V rb = R1.to_body(rbp);
      const Real nb = rb.norm(), inb = one / nb;
      const V fr = rb * (c[T::kn][l] * (nb - r0) * inb);
      const V c0 = rb.cross(d);
      const Real n0 = c0.norm(), dot = rb.dot(d);
      const Real gc = dot * (inb * c[T::inv_d][l]);
      const Real gamma = Atan2 ? beam::atan_series(n0 / dot) : beam::acos_series(gc);
      const Real a = ks * r0 * gamma / (n0 != zero ? n0 : one);
      const V fst = rb.cross(c0) * (a * inb), mst = c0 * -a;
      const Real s = h * std::sqrt((nb - rb.z) * inb), rxy2 = rb.x * rb.x + rb.y * rb.y;
      const Real irxy = s / std::sqrt(rxy2 != zero ? rxy2 : one);
      const Q qm{h * std::sqrt((nb + rb.z) * inb), -rb.y * irxy, rb.x * irxy, 0};
      const beam::Rot<Real> Rm(qm);
      const Q r = qm.inverse() * (q1.inverse() * q2) * qm;
      const Real t0 = r.w * r.w + r.z * r.z, t2 = r.x * r.x + r.y * r.y;
      const Real ist = one / std::sqrt(t0 != zero ? t0 : one);
      const Real cpsi = r.w * ist, spsi = r.z * ist;
      const Real apsi = Atan2 ? zero : beam::acos_series(cpsi);
      const Real psi = Atan2 ? 2 * beam::atan_series(r.z / r.w)
                             : 2 * (spsi > zero   ? apsi
                                    : spsi < zero ? -apsi
                                                  : zero);
      const Real mt = c[T::kt][l] * psi;
      const V mtr{Rm.m[0][2] * mt, Rm.m[1][2] * mt, Rm.m[2][2] * mt};
      const Real t1 = t0 - t2, st2 = Atan2 ? std::sqrt(t2) : zero, st0 = Atan2 ? std::sqrt(t0) : one;
      const Real theta = Atan2 ? 2 * beam::atan_series(st2 / st0) : beam::acos_series(t1);
      const Real iq = one / std::sqrt(t0 * t2 != zero ? t0 * t2 : one);
      const Real cf = (r.x * r.z + r.w * r.y) * iq, sf = (r.y * r.z - r.w * r.x) * iq;
      const Real bb = Real(0.5) * c[T::kb][l] * theta, sh = Real(0.5) * ks * theta * r0;
      const V mbr = Rm.xy_to_world(-bb * sf, bb * cf), fsr = Rm.xy_to_world(-sh * cf, -sh * sf),
              msr = Rm.xy_to_world(sh * sf, -sh * cf);
      const V ms = msr + mst, fs = fst + fsr;
      const V f1 = R1.to_world(fr + fs), m1 = R1.to_world(mbr + mtr + ms * (c[T::e1][l] * lp)),
              m2 = R1.to_world(ms * (c[T::e2][l] * lp) - mbr - mtr);
      b.f1[0][l] = f1.x, b.f1[1][l] = f1.y, b.f1[2][l] = f1.z;
      b.m1[0][l] = m1.x, b.m1[1][l] = m1.y, b.m1[2][l] = m1.z;
      b.m2[0][l] = m2.x, b.m2[1][l] = m2.y, b.m2[2][l] = m2.z;
      const Real fn = (lp < r0 ? -one : one) * fr.norm(), fsn = fs.norm(), mb = std::abs(bb),
                 amt = std::abs(mt);
      b.fn[l] = fn, b.fs[l] = fsn, b.mb[l] = mb, b.mt[l] = amt;
      // failure()'s test, both criteria, the group's taken.
      const Real tn = fn * c[T::ifn][l], ts = fsn * c[T::ifs][l], tb = mb * c[T::imb][l],
                 tt = amt * c[T::imt][l];
      const Real normal = tn + c[T::beta1][l] * tb, shear = ts + c[T::beta2][l] * tt;
      const Real esys = Real((normal > c[T::truncated][l]) | (shear > one - normal));
      const Real sum = Real(((tn > zero ? tn : zero) + ts + tb + tt) >= one);
      b.broken[l] = esys + c[T::sum][l] * (sum - esys);  // (a select here would be a branch)
      // (& not &&: no branches in the loop)
      const bool frames = (n0 != zero) & (rxy2 != zero) & (t0 != zero) & (t2 != zero);
      if constexpr (Atan2) {
        const Real lim = Real(0.1);  // atan_series' range: each angle's tangent
        b.general[l] = Real(!(frames & (dot > zero) & (n0 <= lim * dot) & (r.w > zero) &
                              (std::abs(r.z) <= lim * r.w) & (st2 <= lim * st0) & (c[T::atan2][l] != zero)));
      } else {
        const Real lim = Real(0.995);
        b.general[l] = Real(
            !(frames & (gc > lim) & (t1 > lim) & ((cpsi > lim) | (spsi == zero)) & (c[T::atan2][l] == zero)));
      }
    }
  }

  /// ESyS's potential energy of the bond for these loads.
  template <class Real>
  static double energy(const BondCoeffs<Real>& k, const Result<Real>& q) {
    const auto e = [](double f, double s) { return s != 0 ? 0.5 * f * f / s : 0.0; };
    return e(q.fn, k.kn) + e(q.fs, k.ks) + e(q.mt, k.kt) + e(q.mb, k.kb);
  }

  /// -1 when the bond holds, else the failure mode (BondFailure) under the group's criterion.
  template <class Real>
  static int failure(const Coeffs<Real>& c, const BondCoeffs<Real>& k, const Result<Real>& q) {
    const Real tn = q.fn * k.ifn, ts = q.fs * k.ifs, tb = q.mb * k.imb, tt = q.mt * k.imt;
    bool broken;
    if (c.sum) {
      broken = std::max(tn, Real(0)) + ts + tb + tt >= Real(1);
    } else {
      const Real normal = tn + c.beta1 * tb, shear = ts + c.beta2 * tt;
      broken = normal > c.truncated || shear > Real(1) - normal;
    }
    return broken ? failure_mode(c, k, q) : -1;
  }

  /// The failure mode of a bond that fails: the largest term of the criterion.
  template <class Real>
  static int failure_mode(const Coeffs<Real>& c, const BondCoeffs<Real>& k, const Result<Real>& q) {
    const Real tn = q.fn * k.ifn, ts = q.fs * k.ifs, tb = q.mb * k.imb, tt = q.mt * k.imt;
    const Real wb = c.sum ? tb : c.beta1 * tb, wt = c.sum ? tt : c.beta2 * tt;
    int mode = int(BondFailure::tension);
    Real top = tn;
    if (ts > top) top = ts, mode = int(BondFailure::shear);
    if (wb > top) top = wb, mode = int(BondFailure::bending);
    if (wt > top) mode = int(BondFailure::torsion);
    return mode;
  }
};

}  // namespace basalt::solver
