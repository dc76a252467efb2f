#pragma once
// Linear spring with Coulomb friction between touching, unbonded spheres (ESyS-Particle
// "NRotFriction" and "RotFriction"). With n = (x_i - x_j) / r and overlap d = ri + rj - r > 0:
//   normal:     F_n = K d n on i;
//   tangential: a shear force F_s on i (the history), carried in the tangent plane. Each step it is
//               turned onto the current tangent plane (length kept) and loaded by the tangential slip of the
//               contact point, F_s -= Ks v_t dt (v_t: velocity of i's contact point relative to j's,
//               with w x arm for rotating particles); when |F_s| > mu |F_n| (mu_static while sticking,
//               mu_dynamic while sliding) the contact slides and F_s is cut to mu_dynamic |F_n|;
//   contact point at r ri / (ri + rj) from i's centre (where ESyS puts it): torques arm x F_s.
//   Energy: K d^2 / 2 + |F_s|^2 / (2 Ks); a cut dissipates the spring energy it
// removes beyond the work the particles did (cut_energy()).
// The shear force resets when the spheres part. Units: K, Ks in force/length.
#include <array>
#include <cmath>
#include <string_view>

#include "basalt/solver/models/model.hpp"
#include "basalt/solver/scene/table_reader.hpp"

namespace basalt::solver {

template <bool Rotating>
struct CoulombFriction {
  static constexpr std::string_view name = Rotating ? "rot_friction" : "friction";
  static constexpr ModelKind kind = ModelKind::pair;
  static constexpr std::string_view summary =
      Rotating ? "F = K d n + shear spring Ks cut at Coulomb mu |F_n|, contact velocity with w x r; torques "
                 "(ESyS RotFriction)"
               : "F = K d n + shear spring Ks cut at Coulomb mu |F_n|, no rotation (ESyS NRotFriction)";
  static constexpr std::array keys{
      KeyDoc{"K", "normal stiffness, force/length, >= 0 (required; ESyS normalK)"},
      KeyDoc{"Ks", "shear stiffness, force/length, >= 0 (required; ESyS shearK)"},
      KeyDoc{"mu", "static friction coefficient, >= 0 (required; ESyS staticMu)"},
      KeyDoc{"mu_dynamic",
             "dynamic (sliding) friction coefficient, 0 <= mu_dynamic <= mu (default mu; ESyS "
             "dynamicMu)"},
      KeyDoc{"convention",
             "\"basalt\" (default) or \"esys\": ESyS-Particle 2.3.5's rules (the shear force is "
             "never turned with the contact; the slide threshold is always mu)"},
      KeyDoc{"scaling",
             "ESyS's scaling: K and Ks times (ri + rj) / 4 (rot_friction) or (ri + rj) / 2 (friction) "
             "(default false)"},
      KeyDoc{"tags", "[a, b]: pairs tagged a and b (default: all pairs)"}};
  static constexpr Fields reads =
      kPosition | kRadius | kId | kVelocity | kInverseMass | (Rotating ? kAngularVelocity : kNoFields);
  static constexpr Fields writes = kForce | (Rotating ? kTorque : kNoFields);
  static constexpr std::string_view dissipation_term = "friction_dissipated";

  struct Params {
    double K = 0, Ks = 0, mu = 0, mu_dynamic = 0;
    bool esys = false, scaling = false;
  };
  template <class Real>
  struct Coeffs {
    Real K, Ks, mu, mu_dynamic;
    bool esys, scaling;
  };
  struct History {
    double fx = 0, fy = 0, fz = 0;  ///< shear force on the first particle of the listed pair
    double sliding = 0;             ///< 1 while the contact slides
  };

  static Params parse(TableReader& t) {
    Params p;
    p.K = t.non_negative("K");
    p.Ks = t.non_negative("Ks");
    p.mu = t.non_negative("mu");
    p.mu_dynamic = t.non_negative_or("mu_dynamic", p.mu);
    if (p.mu_dynamic > p.mu) t.fail("mu_dynamic", "must not exceed mu (the static coefficient)");
    p.esys = t.choice_or("convention", {"basalt", "esys"}, "basalt") == "esys";
    p.scaling = t.boolean_or("scaling", false);
    return p;
  }
  template <class Real>
  static Coeffs<Real> coeffs(const Params& p) {
    return {Real(p.K), Real(p.Ks), Real(p.mu), Real(p.mu_dynamic), p.esys, p.scaling};
  }
  static double max_stiffness(const Params& p, double rmax) {
    return std::max(p.K, p.Ks) * (p.scaling ? scale_factor(rmax, rmax) : 1.0);
  }
  /// The shear spring acts at the contact point, which a sphere's rotation makes lighter
  /// (models/contract.hpp); without rotation (ESyS's NRotFriction) it only pulls the centres, as
  /// max_stiffness counts.
  static double shear_stiffness(const Params& p, double rmax) requires Rotating {
    return p.Ks * (p.scaling ? scale_factor(rmax, rmax) : 1.0);
  }
  /// ESyS's stiffness scaling (RotFricInteraction.cpp: R^2 / (ri + rj) with R = (ri + rj) / 2;
  /// FrictionInteraction.cpp: (ri + rj) / 2).
  static double scale_factor(double ri, double rj) { return Rotating ? (ri + rj) / 4 : (ri + rj) / 2; }

  static void apart(History& h) { h = History{}; }
  /// The shear spring's energy, lost when the spheres part (the ledger counts it as dissipated).
  template <class Real>
  static double parting_energy(const Coeffs<Real>& c, const History& h) {
    // (Scaled stiffness: the radii are not known here; the unscaled Ks is close enough for the ledger.)
    return c.Ks > 0 ? (h.fx * h.fx + h.fy * h.fy + h.fz * h.fz) / (2 * double(c.Ks)) : 0.0;
  }
  static History flip(const History& h) { return {-h.fx, -h.fy, -h.fz, h.sliding}; }

  /// Advance: a real step (the shear force moves on); otherwise the force from the stored shear force.
  template <bool Advance, class Real>
  static void contact(const Coeffs<Real>& c, History& h, const ContactKinematics<Real>& k,
                      ContactForce<Real>& f) {
    const Real inv_r = Real(1) / k.r;
    const Real nx = k.dx * inv_r, ny = k.dy * inv_r, nz = k.dz * inv_r;
    const Real scale = c.scaling ? Real(scale_factor(double(k.ri), double(k.rj))) : Real(1);
    const Real K = c.K * scale, Ks = c.Ks * scale;
    const Real fn = K * (k.ri + k.rj - k.r);
    f.arm_i = k.r * k.ri / (k.ri + k.rj);
    // Velocity of i's contact point relative to j's: v_i - v_j + w_i x (-arm_i n) - w_j x (arm_j n).
    Real ux = k.vx, uy = k.vy, uz = k.vz;
    if constexpr (Rotating) {
      if constexpr (Advance) {
        const Real ai = f.arm_i, aj = k.r - f.arm_i;
        const Real ox = -(ai * k.wix + aj * k.wjx), oy = -(ai * k.wiy + aj * k.wjy),
                   oz = -(ai * k.wiz + aj * k.wjz);
        ux += oy * nz - oz * ny;
        uy += oz * nx - ox * nz;
        uz += ox * ny - oy * nx;
      }
    }
    shear<Advance>(c, Ks, h, nx, ny, nz, fn, ux, uy, uz, k.dt, f);
  }

  /// The Coulomb law shared by pairs and walls: on a real step the stored shear force is turned onto
  /// the tangent plane of n (unless esys), loaded by the tangential part of the contact point's
  /// velocity u and cut at the Coulomb limit; f gets F_n n + F_s and what the cut dissipated.
  template <bool Advance, class Real>
  static void shear(const Coeffs<Real>& c, Real Ks, History& h, Real nx, Real ny, Real nz, Real fn, Real ux,
                    Real uy, Real uz, Real dt, ContactForce<Real>& f) {
    Real sx = Real(h.fx), sy = Real(h.fy), sz = Real(h.fz);
    if constexpr (Advance) {
      const Real un = ux * nx + uy * ny + uz * nz;
      ux -= un * nx;
      uy -= un * ny;
      uz -= un * nz;
      if (!c.esys) turn_into_plane(sx, sy, sz, nx, ny, nz);  // ESyS never turns it
      const Real px = sx, py = sy, pz = sz;
      sx -= Ks * dt * ux;
      sy -= Ks * dt * uy;
      sz -= Ks * dt * uz;
      const Real s2 = sx * sx + sy * sy + sz * sz;
      const Real limit = (h.sliding != 0 && !c.esys ? c.mu_dynamic : c.mu) * fn;
      if (s2 > limit * limit) {
        const Real s = std::sqrt(s2), cut = c.mu_dynamic * fn, shrink = cut / s;
        f.dissipated = cut_energy(Ks, s, cut, (px * sx + py * sy + pz * sz) / s);
        sx *= shrink;
        sy *= shrink;
        sz *= shrink;
        h.sliding = 1;
        f.sliding = true;
      } else {
        h.sliding = 0;
      }
      h.fx = double(sx);
      h.fy = double(sy);
      h.fz = double(sz);
    }
    f.fx = fn * nx + sx;
    f.fy = fn * ny + sy;
    f.fz = fn * nz + sz;
  }

  /// Energy a cut of the shear force dissipates: the cut takes the trial force (length s, unit
  /// direction t) back to `cut` along t, and the particles moved under the mean of the previous force
  /// p and the new one (velocity Verlet's work over a step), so the energy the ledger balances leaves
  /// as D = (s - cut) (p . t + cut) / (2 Ks): in steady sliding mu_dynamic |F_n| times the slip, at
  /// the switch from static to dynamic friction the spring's drop as well.
  template <class Real>
  static double cut_energy(Real Ks, Real s, Real cut, Real p_dot_t) {
    if (!(Ks > 0)) return 0;
    return (double(s) - double(cut)) * (double(p_dot_t) + double(cut)) / (2 * double(Ks));
  }

  /// The shear force carried onto the tangent plane of the current normal n, its length kept (the
  /// contact turned; projecting alone would shorten it and lose spring energy nothing accounts for).
  template <class Real>
  static void turn_into_plane(Real& sx, Real& sy, Real& sz, Real nx, Real ny, Real nz) {
    const Real before = sx * sx + sy * sy + sz * sz;
    if (before == Real(0)) return;
    const Real sn = sx * nx + sy * ny + sz * nz;
    sx -= sn * nx;
    sy -= sn * ny;
    sz -= sn * nz;
    const Real after = sx * sx + sy * sy + sz * sz;
    if (after > Real(0)) {
      const Real scale = std::sqrt(before / after);
      sx *= scale;
      sy *= scale;
      sz *= scale;
    }
  }

  template <class Real>
  static Real energy(const Coeffs<Real>& c, const History& h, const ContactKinematics<Real>& k) {
    const Real scale = c.scaling ? Real(scale_factor(double(k.ri), double(k.rj))) : Real(1);
    const Real d = k.ri + k.rj - k.r;
    const Real s2 = Real(h.fx * h.fx + h.fy * h.fy + h.fz * h.fz);
    return Real(0.5) * c.K * scale * d * d + (c.Ks > 0 ? s2 / (2 * c.Ks * scale) : Real(0));
  }
};

/// A planar wall with Coulomb friction (Basalt's own: ESyS-Particle has no frictional wall): normal
/// force K o (o = r - d the overlap), and a shear spring on the contact point's slip against the wall
/// (the particle's point nearest the plane, d from its centre, so rolling without slip is
/// slip-free), cut at mu |F_n| as for CoulombFriction. Energy K o^2 / 2 + |F_s|^2 / (2 Ks).
struct FrictionWall {
  static constexpr std::string_view name = "friction";
  static constexpr ModelKind kind = ModelKind::wall;
  static constexpr std::string_view summary =
      "F = K (r - d) n + shear spring Ks cut at Coulomb mu |F_n| (frictional wall, rolling aware)";
  static constexpr std::array keys{
      KeyDoc{"K", "normal stiffness, force/length, >= 0 (required)"},
      KeyDoc{"Ks", "shear stiffness, force/length, >= 0 (required)"},
      KeyDoc{"mu", "static friction coefficient, >= 0 (required)"},
      KeyDoc{"mu_dynamic", "dynamic friction coefficient, 0 <= mu_dynamic <= mu (default mu)"}};
  static constexpr Fields reads = kPosition | kRadius | kTag | kVelocity | kAngularVelocity;
  static constexpr Fields writes = kForce | kTorque;
  static constexpr std::string_view dissipation_term = "friction_dissipated";

  using Params = CoulombFriction<true>::Params;
  template <class Real>
  using Coeffs = CoulombFriction<true>::Coeffs<Real>;
  using History = CoulombFriction<true>::History;

  static Params parse(TableReader& t) {
    Params p;
    p.K = t.non_negative("K");
    p.Ks = t.non_negative("Ks");
    p.mu = t.non_negative("mu");
    p.mu_dynamic = t.non_negative_or("mu_dynamic", p.mu);
    if (p.mu_dynamic > p.mu) t.fail("mu_dynamic", "must not exceed mu (the static coefficient)");
    return p;
  }
  template <class Real>
  static double parting_energy(const Coeffs<Real>& c, const History& h) {
    return CoulombFriction<true>::parting_energy(c, h);
  }
  template <class Real>
  static Coeffs<Real> coeffs(const Params& p) {
    return CoulombFriction<true>::coeffs<Real>(p);
  }
  static double max_stiffness(const Params& p, double) { return std::max(p.K, p.Ks); }
  /// The shear spring acts at the contact point, k.d from the centre (models/contract.hpp).
  static double shear_stiffness(const Params& p, double) { return p.Ks; }

  template <bool Advance, class Real>
  static void contact(const Coeffs<Real>& c, History& h, const WallKinematics<Real>& k,
                      ContactForce<Real>& f) {
    const Real fn = c.K * (k.r - k.d);
    f.arm_i = k.d;
    // Contact point velocity: v + w x (-d n).
    const Real ux = k.vx - k.d * (k.wy * k.nz - k.wz * k.ny), uy = k.vy - k.d * (k.wz * k.nx - k.wx * k.nz),
               uz = k.vz - k.d * (k.wx * k.ny - k.wy * k.nx);
    CoulombFriction<true>::shear<Advance>(c, c.Ks, h, k.nx, k.ny, k.nz, fn, ux, uy, uz, k.dt, f);
  }

  template <class Real>
  static Real energy(const Coeffs<Real>& c, const History& h, const WallKinematics<Real>& k) {
    const Real o = k.r - k.d;
    const Real s2 = Real(h.fx * h.fx + h.fy * h.fy + h.fz * h.fz);
    return Real(0.5) * c.K * o * o + (c.Ks > 0 ? s2 / (2 * c.Ks) : Real(0));
  }
};

using Friction = CoulombFriction<false>;
using RotFriction = CoulombFriction<true>;

}  // namespace basalt::solver
