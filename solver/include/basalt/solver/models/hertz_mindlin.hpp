#pragma once
// Hertz-Mindlin contact with viscous (Tsuji) damping and Coulomb friction, for rotating spheres
// (LIGGGHTS "hertz" with "tangential history", ESyS-Particle "HertzMindlinVisco"). With overlap
// d = ri + rj - r > 0, normal n = (x_i - x_j) / r, effective radius R* = ri rj / (ri + rj), effective
// mass m* = mi mj / (mi + mj), E* = E / (2 (1 - nu^2)), G* = G / (2 (2 - nu)), G = E / (2 (1 + nu)):
//   S_n = 2 E* sqrt(R* d),  S_t = 8 G* sqrt(R* d),  beta = ln e / sqrt(ln^2 e + pi^2),
//   normal:     F_n = (4/3 E* sqrt(R*) d^{3/2} - gamma_n v_n) n,  gamma_n = -2 sqrt(5/6) beta sqrt(S_n m*);
//   tangential: shear displacement xi (history, turned onto the tangent plane each step, length kept)
//               xi += v_t dt;  F_t = -S_t xi - gamma_t v_t,  gamma_t = -2 sqrt(5/6) beta sqrt(S_t m*);
//               when |F_t| > mu |F_n| it is cut to mu |F_n| and xi set to match (F_t + gamma_t v_t = -S_t
//               xi).
// v_n, v_t: normal and tangential parts of the contact point's relative velocity (with w x arm; the
// contact point at r ri / (ri + rj) from i's centre). Energy: 8/15 E* sqrt(R*) d^{5/2} + S_t |xi|^2 / 2.
// The dashpots and the Coulomb cut dissipate (ledger term friction_dissipated).
// The wall version (HertzMindlinWall) is the same with R* = r, m* = m and the wall's E, nu.
#include <array>
#include <cmath>
#include <numbers>
#include <string_view>

#include "basalt/solver/models/lanes.hpp"
#include "basalt/solver/models/model.hpp"
#include "basalt/solver/scene/table_reader.hpp"
#include "basalt/solver/stability/impact.hpp"

namespace basalt::solver {

namespace hertz {

struct Material {
  double E = 0, nu = 0;
};

/// The contact's material constants: E*, G* from two materials, and the damping factor from e.
struct Constants {
  double E_star = 0, G_star = 0, beta = 0, mu = 0;
};

inline Constants constants(const Material& a, const Material& b, double e, double mu) {
  const double Ga = a.E / (2 * (1 + a.nu)), Gb = b.E / (2 * (1 + b.nu));
  Constants c;
  c.E_star = 1 / ((1 - a.nu * a.nu) / a.E + (1 - b.nu * b.nu) / b.E);
  c.G_star = 1 / ((2 - a.nu) / Ga + (2 - b.nu) / Gb);  // G / (2 (2 - nu)) for one material
  const double le = std::log(e);
  c.beta = e >= 1 ? 0.0 : le / std::sqrt(le * le + std::numbers::pi * std::numbers::pi);
  c.mu = mu;
  return c;
}

inline void parse_material(TableReader& t, const char* E, const char* nu, Material& m) {
  m.E = t.positive(E);
  m.nu = t.number_or(nu, 0.25);
  if (!(m.nu > -1 && m.nu < 0.5)) t.fail(nu, "must be in (-1, 0.5)");
}

inline double restitution(TableReader& t) {
  const double e = t.number_or("e", 1.0);
  if (!(e > 0 && e <= 1)) t.fail("e", "must be in (0, 1]");
  return e;
}

/// Hertz's head-on collision, undamped (the check of steps per collision, stability/impact.hpp): with
/// F = K d^{3/2}, K = 4/3 E* sqrt(R*), a contact of effective mass m with overlap d >= 0 and normal speed
/// of approach vn holds the energy W = m vn^2 / 2 + 2/5 K d^{5/2}; its collision came in at v = sqrt(2 W /
/// m), reaches d_max = (5 W / 2 K)^{2/5} and lasts t_c = 2.943275 d_max / v (2 int_0^1 dx / sqrt(1 - x^{5/2})
/// = 2 sqrt(pi) Gamma(7/5) / Gamma(9/10)), i.e. 2.87 (m^2 / (R* E*^2 v))^{1/5}.
inline Collision collision(const Constants& c, double R, double m, double vn, double d) {
  const double K = 4.0 / 3.0 * c.E_star * std::sqrt(R);
  const double W = 0.5 * m * vn * vn + 0.4 * K * d * d * std::sqrt(d);
  Collision out;
  if (!(W > 0) || !std::isfinite(W)) return out;  // (nothing moving, or a fixed particle on a wall)
  out.speed = std::sqrt(2 * W / m);
  out.overlap = std::pow(2.5 * W / K, 0.4);
  out.duration = 2.943275184324706 * out.overlap / out.speed;
  return out;
}

/// The loop's constants: E*, G*, beta, mu, and the dashpot factors -2 sqrt(5/6) beta sqrt(2 E*) and
/// -2 sqrt(5/6) beta sqrt(8 G*) (gamma_n, gamma_t = these times sqrt(m* sqrt(R* d)): one square root
/// per contact for both dashpots).
template <class Real>
struct Coeffs {
  Real E_star, G_star, beta, mu, damp_n, damp_t;
};

template <class Real>
Coeffs<Real> coeffs(const Constants& c) {
  const double k = -2 * 0.9128709291752769 * c.beta;  // -2 sqrt(5/6) beta >= 0
  return {Real(c.E_star),
          Real(c.G_star),
          Real(c.beta),
          Real(c.mu),
          Real(k * std::sqrt(2 * c.E_star)),
          Real(k * std::sqrt(8 * c.G_star))};
}

/// History: the shear displacement.
struct History {
  double x = 0, y = 0, z = 0;
};

/// The law for a contact of effective radius R, effective mass m, overlap d, contact-point relative
/// velocity u (on the first body, relative to the second), normal n; turns and loads the history
/// when Advance; returns the force on the first body and the energy dissipated this step.
template <bool Advance, class Real>
[[gnu::always_inline]] inline void law(const Coeffs<Real>& c, History& h, Real R, Real m, Real d, Real nx,
                                       Real ny, Real nz, Real ux, Real uy, Real uz, Real dt,
                                       ContactForce<Real>& f) {
  const Real root = std::sqrt(R * d);
  const Real St = 8 * c.G_star * root;
  const Real q = std::sqrt(root * m);  // sqrt(S m) = sqrt(2 E*) q (normal), sqrt(8 G*) q (tangential)
  const Real gn = c.damp_n * q, gt = c.damp_t * q;
  const Real un = ux * nx + uy * ny + uz * nz;
  const Real tx = ux - un * nx, ty = uy - un * ny, tz = uz - un * nz;
  const Real fn = Real(4.0 / 3.0) * c.E_star * root * d - gn * un;
  Real sx = Real(h.x), sy = Real(h.y), sz = Real(h.z);
  if constexpr (Advance) {
    const Real before = sx * sx + sy * sy + sz * sz;
    if (before > 0) {  // onto the current tangent plane, length kept
      const Real sn = sx * nx + sy * ny + sz * nz;
      sx -= sn * nx;
      sy -= sn * ny;
      sz -= sn * nz;
      const Real after = sx * sx + sy * sy + sz * sz;
      if (after > 0) {
        const Real s = std::sqrt(before / after);
        sx *= s, sy *= s, sz *= s;
      }
    }
    sx += tx * dt;
    sy += ty * dt;
    sz += tz * dt;
  }
  Real ftx = -St * sx - gt * tx, fty = -St * sy - gt * ty, ftz = -St * sz - gt * tz;
  const Real ft2 = ftx * ftx + fty * fty + ftz * ftz, limit = c.mu * (fn > 0 ? fn : Real(0));
  if (Advance) f.dissipated = double(gn * un * un + gt * (tx * tx + ty * ty + tz * tz)) * double(dt);
  if (ft2 > limit * limit) {
    f.sliding = true;
    const Real scale = limit / std::sqrt(ft2);
    const double before = 0.5 * double(St) * double(sx * sx + sy * sy + sz * sz);
    ftx *= scale, fty *= scale, ftz *= scale;
    if (St > 0) {
      const Real inv_St = Real(1) / St;
      sx = -(ftx + gt * tx) * inv_St;
      sy = -(fty + gt * ty) * inv_St;
      sz = -(ftz + gt * tz) * inv_St;
    }
    if (Advance) f.dissipated += before - 0.5 * double(St) * double(sx * sx + sy * sy + sz * sz);
  }
  if constexpr (Advance) {
    h.x = double(sx);
    h.y = double(sy);
    h.z = double(sz);
  }
  f.fx = fn * nx + ftx;
  f.fy = fn * ny + fty;
  f.fz = fn * nz + ftz;
}

template <class Real>
Real energy(const Coeffs<Real>& c, const History& h, Real R, Real d) {
  const Real root = std::sqrt(R * d);
  const Real St = 8 * c.G_star * root;
  return Real(8.0 / 15.0) * c.E_star * root * d * d +
         Real(0.5) * St * Real(h.x * h.x + h.y * h.y + h.z * h.z);
}

/// hertz::law for W contacts side by side (the pair's and the wall's contact_lanes): the same formulas in
/// the same order, each branch computed in every lane and the right value selected, so that GCC vectorises
/// the loops (divisions and square roots of the unselected side may be inf or NaN; they are dropped). The
/// law is a chain of square roots and divisions, each waiting for the last: one loop over the lanes would
/// run at the chain's latency. So a contact_lanes runs it in passes over the lanes, each with a short
/// chain, whose iterations the processor overlaps; the values one pass hands to the next stay in L1 here.
template <class Real, int W>
struct Stage {
  alignas(64) Real inv_r[W], inv_sum[W], m[W], nx[W], ny[W], nz[W], tx[W], ty[W], tz[W];
  alignas(64) Real px[W], py[W], pz[W], ratio[W], St[W], gt[W], fn[W], si[W], sj[W];
  alignas(64) Real sx[W], sy[W], sz[W], ftx[W], fty[W], ftz[W], ft2[W], limit[W];
};

/// Lane l of the second pass: with effective radius R, effective mass m, overlap d, normal n and the
/// contact point's relative velocity u, the stiffness and dashpots, the normal force, the tangential
/// velocity and the history turned onto the tangent plane (its length ratio, -1: no turn); on real steps
/// the dashpots' dissipation.
template <bool Advance, class Real, int W>
[[gnu::always_inline]] inline void lane_normal(const Coeffs<Real>& c, Stage<Real, W>& g, int l, Real R,
                                               Real d, Real m, Real nx, Real ny, Real nz, Real ux, Real uy,
                                               Real uz, const History& h, Real dt, double& dissipated) {
  const Real root = std::sqrt(R * d);
  const Real St = 8 * c.G_star * root;
  const Real q = std::sqrt(root * m);
  const Real gn = c.damp_n * q, gt = c.damp_t * q;
  const Real un = ux * nx + uy * ny + uz * nz;
  const Real tx = ux - un * nx, ty = uy - un * ny, tz = uz - un * nz;
  const Real fn = Real(4.0 / 3.0) * c.E_star * root * d - gn * un;
  const Real sx = Real(h.x), sy = Real(h.y), sz = Real(h.z);
  g.nx[l] = nx, g.ny[l] = ny, g.nz[l] = nz, g.tx[l] = tx, g.ty[l] = ty, g.tz[l] = tz;
  g.St[l] = St, g.gt[l] = gt, g.fn[l] = fn;
  g.sx[l] = sx, g.sy[l] = sy, g.sz[l] = sz;
  if constexpr (Advance) {
    const Real one = 1;
    const Real before = sx * sx + sy * sy + sz * sz;
    const Real sn = sx * nx + sy * ny + sz * nz;
    const Real px = sx - sn * nx, py = sy - sn * ny, pz = sz - sn * nz;
    const Real after = px * px + py * py + pz * pz;
    g.px[l] = px, g.py[l] = py, g.pz[l] = pz;
    g.ratio[l] = after > 0 ? before / after : one;
    g.ratio[l] = before > 0 ? g.ratio[l] : -one;  // (no turn)
    dissipated = double(gn * un * un + gt * (tx * tx + ty * ty + tz * tz)) * double(dt);
  }
}

/// Lane l of the third pass: the history turned and loaded, the elastic-viscous tangential force and the
/// Coulomb limit.
template <bool Advance, class Real, int W>
[[gnu::always_inline]] inline void lane_load(const Coeffs<Real>& c, Stage<Real, W>& g, int l, Real dt) {
  const Real zero = 0, one = 1;
  Real sx = g.sx[l], sy = g.sy[l], sz = g.sz[l];
  const Real tx = g.tx[l], ty = g.ty[l], tz = g.tz[l];
  if constexpr (Advance) {
    const Real ratio = g.ratio[l];
    const bool turn = ratio >= zero;
    const Real s = std::sqrt(turn ? ratio : one);
    sx = turn ? g.px[l] * s : sx;
    sy = turn ? g.py[l] * s : sy;
    sz = turn ? g.pz[l] * s : sz;
    sx += tx * dt;
    sy += ty * dt;
    sz += tz * dt;
  }
  const Real St = g.St[l], gt = g.gt[l], fn = g.fn[l];
  const Real ftx = -St * sx - gt * tx, fty = -St * sy - gt * ty, ftz = -St * sz - gt * tz;
  g.ft2[l] = ftx * ftx + fty * fty + ftz * ftz;
  g.limit[l] = c.mu * (fn > 0 ? fn : zero);
  g.sx[l] = sx, g.sy[l] = sy, g.sz[l] = sz, g.ftx[l] = ftx, g.fty[l] = fty, g.ftz[l] = ftz;
}

/// Lane l of the fourth pass: the Coulomb cut and the history refitted (written on real steps, with the
/// energy the cut dissipates), whether the contact slides, and the force.
template <bool Advance, class Real, int W>
[[gnu::always_inline]] inline void lane_cut(const Stage<Real, W>& g, int l, History& h, double& dissipated,
                                            Real& sliding, Real& fx, Real& fy, Real& fz) {
  const Real zero = 0, one = 1;
  Real sx = g.sx[l], sy = g.sy[l], sz = g.sz[l], ftx = g.ftx[l], fty = g.fty[l], ftz = g.ftz[l];
  const Real ft2 = g.ft2[l], limit = g.limit[l], St = g.St[l], gt = g.gt[l];
  const Real tx = g.tx[l], ty = g.ty[l], tz = g.tz[l];
  const bool slide = ft2 > limit * limit;
  const Real scale = limit / std::sqrt(ft2);
  const double stored = 0.5 * double(St) * double(sx * sx + sy * sy + sz * sz);
  ftx = slide ? ftx * scale : ftx;
  fty = slide ? fty * scale : fty;
  ftz = slide ? ftz * scale : ftz;
  const bool refit = slide && St > 0;
  const Real inv_St = one / St;
  sx = refit ? -(ftx + gt * tx) * inv_St : sx;
  sy = refit ? -(fty + gt * ty) * inv_St : sy;
  sz = refit ? -(ftz + gt * tz) * inv_St : sz;
  if constexpr (Advance) {
    const double kept = 0.5 * double(St) * double(sx * sx + sy * sy + sz * sz);
    dissipated += slide ? stored - kept : 0.0;
    h.x = double(sx);
    h.y = double(sy);
    h.z = double(sz);
  }
  sliding = slide ? one : zero;
  const Real fn = g.fn[l], nx = g.nx[l], ny = g.ny[l], nz = g.nz[l];
  fx = fn * nx + ftx;
  fy = fn * ny + fty;
  fz = fn * nz + ftz;
}

}  // namespace hertz

struct HertzMindlin {
  static constexpr std::string_view name = "hertz_mindlin";
  static constexpr ModelKind kind = ModelKind::pair;
  static constexpr std::string_view summary =
      "Hertz normal + Mindlin tangential springs, Tsuji dashpots giving restitution e, Coulomb mu (LIGGGHTS "
      "hertz/history, ESyS HertzMindlinVisco)";
  static constexpr std::array keys{
      KeyDoc{"E", "Young's modulus of the particles, force/length^2, > 0 (required)"},
      KeyDoc{"nu", "Poisson's ratio, -1 < nu < 0.5 (default 0.25)"},
      KeyDoc{"e", "coefficient of restitution, 0 < e <= 1 (default 1: no damping)"},
      KeyDoc{"mu", "friction coefficient, >= 0 (default 0.5)"},
      KeyDoc{"tags", "[a, b]: pairs tagged a and b (default: all pairs)"}};
  static constexpr Fields reads = kPosition | kRadius | kId | kVelocity | kInverseMass | kAngularVelocity;
  static constexpr Fields writes = kForce | kTorque;
  static constexpr std::string_view dissipation_term = "friction_dissipated";

  struct Params {
    hertz::Material material;
    double e = 1, mu = 0.5;
  };
  template <class Real>
  using Coeffs = hertz::Coeffs<Real>;
  using History = hertz::History;

  static Params parse(TableReader& t) {
    Params p;
    hertz::parse_material(t, "E", "nu", p.material);
    p.e = hertz::restitution(t);
    p.mu = t.non_negative_or("mu", 0.5);
    return p;
  }
  template <class Real>
  static Coeffs<Real> coeffs(const Params& p) {
    return hertz::coeffs<Real>(hertz::constants(p.material, p.material, p.e, p.mu));
  }
  /// The tangent stiffness at an overlap of 5 % of rmax (for the critical time step estimate).
  static double max_stiffness(const Params& p, double rmax) {
    const auto c = hertz::constants(p.material, p.material, p.e, p.mu);
    return 8 * c.G_star * std::sqrt(0.5 * rmax * 0.05 * rmax) +
           2 * c.E_star * std::sqrt(0.5 * rmax * 0.05 * rmax);
  }
  /// Mindlin's tangential stiffness 8 G* a at the same overlap: it acts at the contact point
  /// (models/contract.hpp).
  static double shear_stiffness(const Params& p, double rmax) {
    return 8 * hertz::constants(p.material, p.material, p.e, p.mu).G_star *
           std::sqrt(0.5 * rmax * 0.05 * rmax);
  }

  /// The collision of a pair of effective radius R and mass m (hertz::collision).
  static Collision collision(const Params& p, double R, double m, double vn, double d) {
    return hertz::collision(hertz::constants(p.material, p.material, p.e, p.mu), R, m, vn, d);
  }

  static void apart(History& h) { h = History{}; }
  static History flip(const History& h) { return {-h.x, -h.y, -h.z}; }
  template <class Real>
  static double parting_energy(const Coeffs<Real>&, const History&) {
    return 0;  // the tangential stiffness vanishes with the overlap
  }

  template <bool Advance, class Real>
  static void contact(const Coeffs<Real>& c, History& h, const ContactKinematics<Real>& k,
                      ContactForce<Real>& f) {
    const Real inv_r = Real(1) / k.r;
    const Real nx = k.dx * inv_r, ny = k.dy * inv_r, nz = k.dz * inv_r;
    const Real inv_sum = Real(1) / (k.ri + k.rj);
    f.arm_i = k.r * k.ri * inv_sum;
    const Real ai = f.arm_i, aj = k.r - f.arm_i;
    const Real ox = -(ai * k.wix + aj * k.wjx), oy = -(ai * k.wiy + aj * k.wjy),
               oz = -(ai * k.wiz + aj * k.wjz);
    const Real ux = k.vx + oy * nz - oz * ny, uy = k.vy + oz * nx - ox * nz, uz = k.vz + ox * ny - oy * nx;
    const Real R = k.ri * k.rj * inv_sum, m = Real(1) / (k.imi + k.imj);
    hertz::law<Advance>(c, h, R, m, k.ri + k.rj - k.r, nx, ny, nz, ux, uy, uz, k.dt, f);
  }
  /// contact() for W pairs at once (lanes.hpp, ContactLanes), in four passes over the lanes (hertz::Stage).
  template <bool Advance, class Real, int W>
  BASALT_WIDE_LANES static void contact_lanes(const Coeffs<Real>& c, ContactLanes<Real, W, History>& b) {
    const Real dt = b.dt, one = 1;
    hertz::Stage<Real, W> g;
    // 1: the distance and the three reciprocals.
#pragma GCC ivdep
    for (int l = 0; l < W; ++l) {
      const Real r = std::sqrt(b.r2[l]);
      b.r[l] = r;
      g.inv_r[l] = one / r;
      g.inv_sum[l] = one / (b.ri[l] + b.rj[l]);
      g.m[l] = one / (b.imi[l] + b.imj[l]);
    }
    // 2: the contact point's velocity, then the law's stiffness, dashpots, normal force and history turn.
#pragma GCC ivdep
    for (int l = 0; l < W; ++l) {
      const Real dx = b.dx[l], dy = b.dy[l], dz = b.dz[l], ri = b.ri[l], rj = b.rj[l], r = b.r[l];
      const Real inv_r = g.inv_r[l], inv_sum = g.inv_sum[l];
      const Real nx = dx * inv_r, ny = dy * inv_r, nz = dz * inv_r;
      const Real ai = r * ri * inv_sum, aj = r - ai;
      const Real ox = -(ai * b.wix[l] + aj * b.wjx[l]), oy = -(ai * b.wiy[l] + aj * b.wjy[l]),
                 oz = -(ai * b.wiz[l] + aj * b.wjz[l]);
      const Real ux = b.vx[l] + oy * nz - oz * ny, uy = b.vy[l] + oz * nx - ox * nz,
                 uz = b.vz[l] + ox * ny - oy * nx;
      const Real R = ri * rj * inv_sum, d = ri + rj - r;
      g.si[l] = -ai * inv_r, g.sj[l] = aj * inv_r;
      hertz::lane_normal<Advance>(c, g, l, R, d, g.m[l], nx, ny, nz, ux, uy, uz, b.h[l], dt, b.dissipated[l]);
    }
    // 3: the history turned and loaded, the tangential force and the Coulomb limit.
#pragma GCC ivdep
    for (int l = 0; l < W; ++l) hertz::lane_load<Advance>(c, g, l, dt);
      // 4: the Coulomb cut, the history refitted, forces and torques out.
#pragma GCC ivdep
    for (int l = 0; l < W; ++l) {
      Real fx, fy, fz;
      hertz::lane_cut<Advance>(g, l, b.h[l], b.dissipated[l], b.sliding[l], fx, fy, fz);
      b.fx[l] = fx;
      b.fy[l] = fy;
      b.fz[l] = fz;
      // Torques (c - x_i) x F on i and (c - x_j) x (-F) on j: arms -ai n and aj n, n = d / r.
      const Real dx = b.dx[l], dy = b.dy[l], dz = b.dz[l], si = g.si[l], sj = g.sj[l];
      const Real cx = dy * fz - dz * fy, cy = dz * fx - dx * fz, cz = dx * fy - dy * fx;
      b.tix[l] = si * cx, b.tiy[l] = si * cy, b.tiz[l] = si * cz;
      b.tjx[l] = -(sj * cx), b.tjy[l] = -(sj * cy), b.tjz[l] = -(sj * cz);
    }
  }
  template <class Real>
  static Real energy(const Coeffs<Real>& c, const History& h, const ContactKinematics<Real>& k) {
    return hertz::energy(c, h, k.ri * k.rj / (k.ri + k.rj), k.ri + k.rj - k.r);
  }
};

struct HertzMindlinWall {
  static constexpr std::string_view name = "hertz_mindlin";
  static constexpr ModelKind kind = ModelKind::wall;
  static constexpr std::string_view summary =
      "Hertz-Mindlin with Tsuji damping and Coulomb friction against a planar wall (R* = r, m* = m)";
  static constexpr std::array keys{KeyDoc{"E", "Young's modulus of the particles, > 0 (required)"},
                                   KeyDoc{"nu", "Poisson's ratio of the particles (default 0.25)"},
                                   KeyDoc{"E_wall", "Young's modulus of the wall (default E)"},
                                   KeyDoc{"nu_wall", "Poisson's ratio of the wall (default nu)"},
                                   KeyDoc{"e", "coefficient of restitution, 0 < e <= 1 (default 1)"},
                                   KeyDoc{"mu", "friction coefficient, >= 0 (default 0.5)"}};
  static constexpr Fields reads = kPosition | kRadius | kTag | kVelocity | kInverseMass | kAngularVelocity;
  static constexpr Fields writes = kForce | kTorque;
  static constexpr std::string_view dissipation_term = "friction_dissipated";

  struct Params {
    hertz::Material particle, wall;
    double e = 1, mu = 0.5;
  };
  template <class Real>
  using Coeffs = hertz::Coeffs<Real>;
  using History = hertz::History;

  static Params parse(TableReader& t) {
    Params p;
    hertz::parse_material(t, "E", "nu", p.particle);
    p.wall = p.particle;
    if (t.has("E_wall")) p.wall.E = t.positive("E_wall");
    if (t.has("nu_wall")) {
      p.wall.nu = t.number("nu_wall");
      if (!(p.wall.nu > -1 && p.wall.nu < 0.5)) t.fail("nu_wall", "must be in (-1, 0.5)");
    }
    p.e = hertz::restitution(t);
    p.mu = t.non_negative_or("mu", 0.5);
    return p;
  }
  template <class Real>
  static Coeffs<Real> coeffs(const Params& p) {
    return hertz::coeffs<Real>(hertz::constants(p.particle, p.wall, p.e, p.mu));
  }
  static double max_stiffness(const Params& p, double rmax) {
    const auto c = hertz::constants(p.particle, p.wall, p.e, p.mu);
    return (8 * c.G_star + 2 * c.E_star) * std::sqrt(rmax * 0.05 * rmax);
  }
  static double shear_stiffness(const Params& p, double rmax) {
    return 8 * hertz::constants(p.particle, p.wall, p.e, p.mu).G_star * std::sqrt(rmax * 0.05 * rmax);
  }
  /// The collision of a particle of radius R and mass m with the wall (hertz::collision).
  static Collision collision(const Params& p, double R, double m, double vn, double d) {
    return hertz::collision(hertz::constants(p.particle, p.wall, p.e, p.mu), R, m, vn, d);
  }
  template <class Real>
  static double parting_energy(const Coeffs<Real>&, const History&) {
    return 0;
  }

  template <bool Advance, class Real>
  static void contact(const Coeffs<Real>& c, History& h, const WallKinematics<Real>& k,
                      ContactForce<Real>& f) {
    f.arm_i = k.d;
    const Real ux = k.vx - k.d * (k.wy * k.nz - k.wz * k.ny), uy = k.vy - k.d * (k.wz * k.nx - k.wx * k.nz),
               uz = k.vz - k.d * (k.wx * k.ny - k.wy * k.nx);
    hertz::law<Advance>(c, h, k.r, Real(1) / k.im, k.r - k.d, k.nx, k.ny, k.nz, ux, uy, uz, k.dt, f);
  }
  /// contact() for W particles at once (lanes.hpp, WallLanes), in the passes of the pair's contact_lanes.
  template <bool Advance, class Real, int W>
  BASALT_WIDE_LANES static void contact_lanes(const Coeffs<Real>& c, WallLanes<Real, W, History>& b) {
    const Real dt = b.dt, one = 1, nx = b.nx, ny = b.ny, nz = b.nz;
    hertz::Stage<Real, W> g;
    // 1: the mass.
#pragma GCC ivdep
    for (int l = 0; l < W; ++l) g.m[l] = one / b.im[l];
      // 2: the contact point's velocity, then the law's stiffness, dashpots, normal force and history turn.
#pragma GCC ivdep
    for (int l = 0; l < W; ++l) {
      const Real d = b.d[l], wx = b.wx[l], wy = b.wy[l], wz = b.wz[l];
      const Real ux = b.vx[l] - d * (wy * nz - wz * ny), uy = b.vy[l] - d * (wz * nx - wx * nz),
                 uz = b.vz[l] - d * (wx * ny - wy * nx);
      hertz::lane_normal<Advance>(c, g, l, b.r[l], b.r[l] - d, g.m[l], nx, ny, nz, ux, uy, uz, b.h[l], dt,
                                  b.dissipated[l]);
    }
    // 3: the history turned and loaded, the tangential force and the Coulomb limit.
#pragma GCC ivdep
    for (int l = 0; l < W; ++l) hertz::lane_load<Advance>(c, g, l, dt);
      // 4: the Coulomb cut, the history refitted, force and torque out: (c - x) x F with c - x = -d n.
#pragma GCC ivdep
    for (int l = 0; l < W; ++l) {
      Real fx, fy, fz;
      hertz::lane_cut<Advance>(g, l, b.h[l], b.dissipated[l], b.sliding[l], fx, fy, fz);
      b.fx[l] = fx;
      b.fy[l] = fy;
      b.fz[l] = fz;
      const Real d = b.d[l];
      b.tx[l] = -d * (ny * fz - nz * fy);
      b.ty[l] = -d * (nz * fx - nx * fz);
      b.tz[l] = -d * (nx * fy - ny * fx);
    }
  }
  template <class Real>
  static Real energy(const Coeffs<Real>& c, const History& h, const WallKinematics<Real>& k) {
    return hertz::energy(c, h, k.r, k.r - k.d);
  }
};

}  // namespace basalt::solver
