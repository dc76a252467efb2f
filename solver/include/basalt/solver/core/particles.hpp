#pragma once
// Particle state as structure-of-arrays. Owned particles come first (indices [0, n_owned)), ghosts
// (copies of other ranks' particles near this rank's faces) follow. Interactions work on these local
// indices; global ids travel with the particles. Real is the floating-point type of positions,
// velocities and forces (double by default).
//
// One list of arrays, for_each_array(), says what each array is: the field it belongs to, whether
// ghosts have it too, whether it travels with a migrating particle, whether the scene may leave it
// out. Growing, reordering and removing particles, migration and ghost records, the memory report
// and the "fields:" line at start are all derived from that list: a new per-particle array is one
// member plus one line there.
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace basalt::solver {

/// Groups of arrays a scene may leave out (Particles::enabled()).
enum class FieldGroup { core, exact_rebuild, damage, rotation, orientation, bond_frame, compensation };

/// What an array of Particles is (for_each_array()).
struct ArrayInfo {
  std::string_view field;  ///< the field it is (part of): "position" for x, y and z
  bool ghosts;             ///< owned and ghost particles have it (else owned only)
  bool migrates;           ///< travels with a particle that changes rank (else recomputed there)
  FieldGroup group;        ///< core (always) or an optional group
  /// Written to frames and checkpoints as the particle field of this name (/particles/<name>) and
  /// restored from it on restart ("" for the core arrays, which have fixed places in the schema).
  std::string_view output = {};
};

/// Origin of the skin reference x0 for the decomposition's box [lo, hi]: zero along an axis where the
/// box lies within its own width of the coordinate origin (every such scene keeps x0 = float(x)), else
/// the box's centre there, so that float rounding of x0 scales with the box, not with the offset.
inline std::array<double, 3> skin_origin(const std::array<double, 3>& lo, const std::array<double, 3>& hi) {
  std::array<double, 3> o{};
  for (std::size_t d = 0; d < 3; ++d) {
    const double c = 0.5 * (lo[d] + hi[d]), w = hi[d] - lo[d];
    if (std::isfinite(c) && std::isfinite(w) && std::abs(c) > w) o[d] = c;
  }
  return o;
}

template <class Real>
struct Particles {
  std::size_t n_owned = 0;
  // Owned + ghosts:
  std::vector<Real> x, y, z;
  std::vector<Real> radius;
  std::vector<std::int64_t> id;
  std::vector<std::int32_t> tag;
  // Owned only (ghosts need no velocity, force or mass):
  std::vector<Real> vx, vy, vz;
  std::vector<Real> fx, fy, fz;
  std::vector<Real> inv_mass;     ///< 1 / mass (the mass itself is mass(i))
  std::vector<float> x0, y0, z0;  ///< positions at the last neighbour-list rebuild relative to
                                  ///< skin_origin (float: only compared with half the skin)
  /// Origin of x0: zero for a geometry near the coordinate origin, else the centre of the
  /// decomposition's box (skin_origin()), so that float keeps x0 to the box's size, not to |x|.
  std::array<double, 3> skin_origin{};
  /// Optional (with_exact_rebuild, i.e. checkpoints on): the same positions exactly, which a
  /// checkpoint stores so that a restart can replay that rebuild (docs/ARCHITECTURE.md).
  std::vector<Real> xr, yr, zr;
  bool with_exact_rebuild = false;
  /// Optional (with_damage: the scene has breakable bonds): each particle's bonds at the start and
  /// how many of them broke; damage = bonds_broken / bonds_initial (frames, checkpoints).
  std::vector<std::int32_t> bonds_initial, bonds_broken;
  bool with_damage = false;
  /// Optional (with_rotation: the scene's particles rotate, ESyS "RotSphere"): angular velocity and
  /// torque. The moment of inertia is that of a solid sphere, 2/5 m r^2 (inverse_inertia(i)): nothing is
  /// stored for it.
  std::vector<Real> wx, wy, wz;
  std::vector<Real> tx, ty, tz;
  bool with_rotation = false;
  /// Optional (with_orientation, only with rotation: a model reads orientations, or the scene keeps them
  /// for its output): each particle's orientation, a unit quaternion w + xi + yj + zk, identity at the
  /// start, turned by w at every drift. A sphere's dynamics never read it: without it a rotating scene
  /// computes the same forces and motion bit for bit, 32 B per particle and the turn of each step less.
  std::vector<Real> qw, qx, qy, qz;
  bool with_orientation = false;
  /// Optional (with_bond_frame: rotational bonds, ESyS "RotBond"/"BrittleBeam"): each particle's position
  /// at the start of the run (ESyS's initial position), from which a bond's reference direction and length
  /// follow (x_b0 - x_a0); ghosts have it, and with it ghosts carry orientations refreshed every step.
  std::vector<Real> xi, yi, zi;
  bool with_bond_frame = false;
  /// Optional (with_compensation: run.precision = "mixed"): each position's rounding remainder of the
  /// drift x += v dt (Kahan): the part of the increments that float rounding dropped from x, owed to it
  /// (the position is x - c). Small increments (v dt below half an ulp of x) then still move the
  /// particles on average instead of being lost (docs/stability.md, "Mixed precision").
  std::vector<Real> cx, cy, cz;
  bool with_compensation = false;
  /// Ghosts carry velocities (and angular velocities with rotation), refreshed every step with their
  /// positions: set when a model reads the velocities of both particles of a pair (friction, damping).
  bool ghost_velocity = false;

  /// Whether the arrays of a group are allocated.
  bool enabled(const ArrayInfo& a) const {
    return a.group == FieldGroup::core || (a.group == FieldGroup::exact_rebuild && with_exact_rebuild) ||
           (a.group == FieldGroup::damage && with_damage) ||
           (a.group == FieldGroup::rotation && with_rotation) ||
           (a.group == FieldGroup::orientation && with_orientation) ||
           (a.group == FieldGroup::bond_frame && with_bond_frame) ||
           (a.group == FieldGroup::compensation && with_compensation);
  }

  /// Calls f(ArrayInfo, vector&) for every array, in a fixed order.
  template <class F>
  void for_each_array(F&& f) {
    for_each(*this, f);
  }
  template <class F>
  void for_each_array(F&& f) const {
    for_each(*this, f);
  }

  Real mass(std::size_t i) const { return Real(1) / inv_mass[i]; }
  /// 1 / I for a solid sphere, I = 2/5 m r^2.
  Real inverse_inertia(std::size_t i) const { return Real(2.5) * inv_mass[i] / (radius[i] * radius[i]); }

  /// The arrays a ghost refresh sends every step, in order: positions, then with ghost_velocity the
  /// velocities and (with rotation) angular velocities, then with rotational bonds (with_bond_frame) the
  /// orientations.
  template <class P>
  static auto step_arrays(P& p) {
    std::array<decltype(&p.x), 13> a{&p.x, &p.y, &p.z, &p.vx, &p.vy, &p.vz, &p.wx, &p.wy, &p.wz};
    std::size_t n = !p.ghost_velocity ? 3 : (p.with_rotation ? 9 : 6);
    if (p.with_bond_frame) {
      a[n++] = &p.qw;
      a[n++] = &p.qx;
      a[n++] = &p.qy;
      a[n++] = &p.qz;
    }
    return std::pair{a, n};
  }

  std::size_t size() const { return x.size(); }
  std::size_t n_ghost() const { return x.size() - n_owned; }

  /// Resizes the arrays every particle has (owned + ghosts).
  void resize_all(std::size_t n) {
    for_each_array([&](const ArrayInfo& a, auto& v) {
      if (a.ghosts) v.resize(n);
    });
  }
  /// Capacity for n owned particles (exact: no growth slack).
  void reserve_owned(std::size_t n) {
    for_each_array([&](const ArrayInfo& a, auto& v) {
      if (enabled(a)) v.reserve(n);
    });
  }
  /// Room for `owned` owned particles and `total` particles with the ghosts, an eighth to spare where an
  /// array must grow: the ghosts and migrants appended at a rebuild then leave no array at twice the
  /// particles' count (std::vector's doubling did at 2 ranks, where the ghosts come on top of an exact
  /// reserve).
  void make_room(std::size_t owned, std::size_t total) {
    for_each_array([&](const ArrayInfo& a, auto& v) {
      if (!enabled(a)) return;
      const std::size_t n = a.ghosts ? total : owned;
      if (v.capacity() < n) v.reserve(n + n / 8);
    });
  }
  /// Drops ghosts, keeps owned particles.
  void drop_ghosts() { resize_all(n_owned); }

  /// Appends an owned particle with every value zero and returns its index; requires no ghosts.
  std::size_t append_owned() {
    for_each_array([&](const ArrayInfo& a, auto& v) {
      if (enabled(a)) v.emplace_back();
    });
    return n_owned++;
  }

  /// Appends an owned particle (im = 1 / mass); requires that there are no ghosts.
  void push_owned(std::int64_t gid, Real px, Real py, Real pz, Real r, std::int32_t t, Real im, Real pvx = 0,
                  Real pvy = 0, Real pvz = 0) {
    const std::size_t i = append_owned();
    x[i] = px;
    y[i] = py;
    z[i] = pz;
    radius[i] = r;
    id[i] = gid;
    tag[i] = t;
    vx[i] = pvx;
    vy[i] = pvy;
    vz[i] = pvz;
    inv_mass[i] = im;
    if (with_orientation) qw[i] = 1;
    if (with_bond_frame) {
      xi[i] = px;
      yi[i] = py;
      zi[i] = pz;
    }
    x0[i] = float(double(px) - skin_origin[0]);
    y0[i] = float(double(py) - skin_origin[1]);
    z0[i] = float(double(pz) - skin_origin[2]);
  }

  /// Reorders the owned particles: new index k holds old index order[k]. Requires no ghosts.
  void permute_owned(const std::vector<std::uint32_t>& order) {
    for_each_array([&](const ArrayInfo& a, auto& v) {
      if (!enabled(a) || v.empty()) return;
      auto copy = v;
      for (std::size_t k = 0; k < order.size(); ++k) v[k] = copy[order[k]];
    });
  }

  /// Removes owned particle i by moving the last owned one into its place. Requires no ghosts.
  void swap_remove_owned(std::size_t i) {
    const std::size_t last = n_owned - 1;
    for_each_array([&](const ArrayInfo& a, auto& v) {
      if (!enabled(a) || v.empty()) return;
      v[i] = v[last];
      v.pop_back();
    });
    --n_owned;
  }

  /// Bytes of one particle's record in migration (migrating arrays) or ghost records (ghost arrays).
  std::size_t record_bytes(bool ghost) const {
    std::size_t b = 0;
    for_each_array([&](const ArrayInfo& a, const auto& v) {
      if (enabled(a) && (ghost ? a.ghosts : a.migrates)) b += sizeof(v[0]);
    });
    return b;
  }
  /// Appends particle i's record (migration or ghost) to `out`.
  void pack(std::size_t i, bool ghost, std::vector<std::byte>& out) const {
    for_each_array([&](const ArrayInfo& a, const auto& v) {
      if (!enabled(a) || !(ghost ? a.ghosts : a.migrates)) return;
      const auto* p = reinterpret_cast<const std::byte*>(&v[i]);
      out.insert(out.end(), p, p + sizeof(v[i]));
    });
  }
  /// Appends a particle from a record: an owned one (migration; requires no ghosts) or a ghost.
  void unpack(const std::byte* rec, bool ghost) {
    std::size_t i = ghost ? size() : append_owned();
    for_each_array([&](const ArrayInfo& a, auto& v) {
      if (!enabled(a) || !(ghost ? a.ghosts : a.migrates)) return;
      if (ghost) v.emplace_back();
      std::memcpy(static_cast<void*>(&v[i]), rec, sizeof(v[i]));
      rec += sizeof(v[i]);
    });
  }

  /// Bytes per particle of each field the scene allocates, in list order: ("position", 24), ...
  std::vector<std::pair<std::string, std::size_t>> field_bytes() const {
    std::vector<std::pair<std::string, std::size_t>> out;
    for_each_array([&](const ArrayInfo& a, const auto& v) {
      if (!enabled(a)) return;
      if (out.empty() || out.back().first != a.field) out.emplace_back(std::string(a.field), 0);
      out.back().second += sizeof(v[0]);
    });
    return out;
  }
  /// Bytes held by the arrays (capacity).
  std::size_t memory_bytes() const {
    std::size_t b = 0;
    for_each_array([&](const ArrayInfo&, const auto& v) { b += v.capacity() * sizeof(v[0]); });
    return b;
  }

 private:
  template <class P, class F>
  static void for_each(P& p, F& f) {
    using G = FieldGroup;
    constexpr ArrayInfo pos{"position", true, true, G::core}, rad{"radius", true, true, G::core},
        ident{"id", true, true, G::core}, tg{"tag", true, true, G::core}, frc{"force", false, false, G::core},
        ref{"skin_reference", false, false, G::core},
        exact{"position_at_rebuild", false, false, G::exact_rebuild},
        initial{"bond_damage", false, true, G::damage, "bonds_initial"},
        broken{"bond_damage", false, true, G::damage, "bonds_broken"},
        trq{"torque", false, false, G::rotation};
    // Velocities (and inverse masses: effective masses of dashpots) go to ghosts when a model reads both
    // particles' velocities.
    const bool gv = p.ghost_velocity, go = p.with_bond_frame;
    const ArrayInfo vel{"velocity", gv, true, G::core}, im{"inverse_mass", gv, true, G::core},
        ang_x{"angular_velocity", gv, true, G::rotation, "angular_velocity_x"},
        ang_y{"angular_velocity", gv, true, G::rotation, "angular_velocity_y"},
        ang_z{"angular_velocity", gv, true, G::rotation, "angular_velocity_z"},
        ori{"orientation", go, true, G::orientation, "orientation_w"},
        ori_x{"orientation", go, true, G::orientation, "orientation_x"},
        ori_y{"orientation", go, true, G::orientation, "orientation_y"},
        ori_z{"orientation", go, true, G::orientation, "orientation_z"},
        init_x{"initial_position", go, true, G::bond_frame, "initial_position_x"},
        init_y{"initial_position", go, true, G::bond_frame, "initial_position_y"},
        init_z{"initial_position", go, true, G::bond_frame, "initial_position_z"};
    constexpr ArrayInfo rem_x{"position_remainder", false, true, G::compensation, "position_remainder_x"},
        rem_y{"position_remainder", false, true, G::compensation, "position_remainder_y"},
        rem_z{"position_remainder", false, true, G::compensation, "position_remainder_z"};
    f(pos, p.x), f(pos, p.y), f(pos, p.z);
    f(rad, p.radius);
    f(ident, p.id);
    f(tg, p.tag);
    f(vel, p.vx), f(vel, p.vy), f(vel, p.vz);
    f(frc, p.fx), f(frc, p.fy), f(frc, p.fz);
    f(im, p.inv_mass);
    f(ref, p.x0), f(ref, p.y0), f(ref, p.z0);
    f(exact, p.xr), f(exact, p.yr), f(exact, p.zr);
    f(initial, p.bonds_initial), f(broken, p.bonds_broken);
    f(ang_x, p.wx), f(ang_y, p.wy), f(ang_z, p.wz);
    f(trq, p.tx), f(trq, p.ty), f(trq, p.tz);
    f(ori, p.qw), f(ori_x, p.qx), f(ori_y, p.qy), f(ori_z, p.qz);
    f(init_x, p.xi), f(init_y, p.yi), f(init_z, p.zi);
    f(rem_x, p.cx), f(rem_y, p.cy), f(rem_z, p.cz);
  }
};

}  // namespace basalt::solver
