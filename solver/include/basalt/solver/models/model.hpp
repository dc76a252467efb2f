#pragma once
// What every model header declares, so that the registry (models/registry.hpp), the scene parser,
// `basalt-run --list-models` and the drivers can treat models alike (docs/ARCHITECTURE.md, "How to
// add a model"). A model is a struct of static members:
//
//   static constexpr std::string_view name;        // scene key value: type = "<name>"
//   static constexpr ModelKind kind;               // bond, pair or wall: which driver loops it
//   static constexpr std::string_view summary;     // one line: formula and source
//   static constexpr std::array<KeyDoc, N> keys;   // its scene keys
//   static constexpr Fields reads, writes;         // particle fields it uses (traits)
//   struct Params;                                 // parsed from the scene, double precision
//   template <class Real> struct Coeffs;           // Params prepared for the loop (what the driver keeps)
//   struct History;                                // per contact, empty when none (no storage then)
//   static Params parse(TableReader&);             // names the bad key in its error
//   template <class Real> static Coeffs<Real> coeffs(const Params&);
//   static double max_stiffness(const Params&, double rmax);   // for the critical time step
//   ... and the force law itself, whose signature depends on the kind (see the driver of that kind).
//
// The driver owns loops, Newton's third law, ghost ownership, energy tallies and history storage;
// the model is a pure function of its coefficients, its history and the pair's geometry.
#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <type_traits>

namespace basalt::solver {

/// Which driver loops a model: bonds, pairs in contact, planar walls, or a force on each particle
/// from its own state (body forces: gravity).
enum class ModelKind { bond, pair, wall, body };

constexpr std::string_view kind_name(ModelKind k) {
  return k == ModelKind::bond
             ? "bond"
             : (k == ModelKind::pair ? "pair" : (k == ModelKind::wall ? "wall" : "body force"));
}

/// One scene key of a model: its name and what it means (units, range, default).
struct KeyDoc {
  std::string_view key;
  std::string_view doc;
};

/// Particle fields (bit set), for a model's reads/writes traits and the scene's field list.
enum Fields : std::uint32_t {
  kNoFields = 0,
  kPosition = 1u << 0,
  kVelocity = 1u << 1,
  kForce = 1u << 2,
  kRadius = 1u << 3,
  kInverseMass = 1u << 4,
  kId = 1u << 5,
  kTag = 1u << 6,
  kAngularVelocity = 1u << 7,
  kTorque = 1u << 8,
  kOrientation = 1u << 9,
};
constexpr Fields operator|(Fields a, Fields b) { return Fields(std::uint32_t(a) | std::uint32_t(b)); }

/// What a velocity-dependent pair model (one with kVelocity in its reads: friction, viscous damping)
/// sees of a pair i, j in contact. The driver fills it; angular velocities are zero for particles
/// that do not rotate.
template <class Real>
struct ContactKinematics {
  Real dx, dy, dz;     ///< x_i - x_j
  Real r;              ///< |x_i - x_j|
  Real ri, rj;         ///< radii
  Real imi, imj;       ///< inverse masses
  Real vx, vy, vz;     ///< v_i - v_j (centres)
  Real wix, wiy, wiz;  ///< angular velocity of i
  Real wjx, wjy, wjz;  ///< angular velocity of j
  Real dt;             ///< the time step (tangential springs integrate the slip over it)
};

/// What such a model returns: the force on i (j gets the opposite), where it acts, and a couple.
template <class Real>
struct ContactForce {
  Real fx = 0, fy = 0, fz = 0;  ///< force on i
  /// Distance from i's centre to the contact point along -n (n = (x_i - x_j) / r); the point is
  /// r - arm_i from j's centre. The torques are (c - x_i) x F on i and (c - x_j) x (-F) on j.
  Real arm_i = 0;
  Real mx = 0, my = 0, mz = 0;  ///< a couple on i (rolling resistance), -m on j
  double dissipated = 0;        ///< energy the contact dissipated this step (friction, dashpots)
  bool sliding = false;         ///< the contact slides (Coulomb limit reached) this step
};

/// What a velocity-dependent wall model (kVelocity in its reads: friction) sees of a particle
/// touching a planar wall. The contact point is the particle's point nearest the plane.
template <class Real>
struct WallKinematics {
  Real nx, ny, nz;  ///< the wall's unit normal (into the particles' side)
  Real d;           ///< signed distance of the centre from the plane (overlap r - d > 0)
  Real r;           ///< radius
  Real im;          ///< inverse mass
  Real vx, vy, vz;  ///< particle velocity minus the wall's
  Real wx, wy, wz;  ///< angular velocity (0 without rotation)
  Real dt;
};

/// What a body-force model sees of one particle (velocities and torques zero where not kept).
template <class Real>
struct BodyState {
  Real m;           ///< mass
  Real im;          ///< inverse mass (as stored)
  Real x, y, z;     ///< position
  Real vx, vy, vz;  ///< velocity
  Real fx, fy, fz;  ///< the force from every other model this step (body forces come last)
  Real inertia;     ///< moment of inertia (0 without rotation)
  Real wx, wy, wz;  ///< angular velocity
  Real tx, ty, tz;  ///< the torque from the other models
  Real dt;
};

/// What a body-force model adds to one particle.
template <class Real>
struct BodyForce {
  Real fx = 0, fy = 0, fz = 0;
  Real tx = 0, ty = 0, tz = 0;
  double dissipated = 0;  ///< energy it takes out this step (damping)
};

/// Every owned particle at once, for a body-force model with `apply_all` (BodyDriver, one group taking
/// every particle): the particles' arrays in (the rotational ones null without rotation), forces and
/// torques added to in place, and each particle's dissipated energy out (a model with a dissipation
/// term). A model with a potential energy takes it on the steps that do not tally the energy, and must
/// give the bits of apply() there. One loop over the arrays runs in vector registers, with no copy of the
/// particles' state into lanes and back.
template <class Real>
struct BodyArrays {
  std::size_t n = 0;
  const Real *im = nullptr, *radius = nullptr;
  const Real *vx = nullptr, *vy = nullptr, *vz = nullptr;
  const Real *wx = nullptr, *wy = nullptr, *wz = nullptr;
  Real *fx = nullptr, *fy = nullptr, *fz = nullptr;
  Real *tx = nullptr, *ty = nullptr, *tz = nullptr;
  double* dissipated = nullptr;  ///< out: n values
  std::uint8_t* flag = nullptr;  ///< n bytes of scratch for the model
  Real dt = 0;
};

/// Bytes of per-contact history a model keeps (0 for an empty History: nothing is stored).
template <class Model>
constexpr std::size_t history_bytes() {
  return std::is_empty_v<typename Model::History> ? 0 : sizeof(typename Model::History);
}

/// A history entry is saved in checkpoints as float64 values: History must be made of doubles.
template <class Model>
constexpr std::size_t history_width() {
  static_assert(std::is_trivially_copyable_v<typename Model::History>, "a History is copied as bytes");
  static_assert(history_bytes<Model>() % sizeof(double) == 0, "a History holds doubles only");
  return history_bytes<Model>() / sizeof(double);
}

}  // namespace basalt::solver
