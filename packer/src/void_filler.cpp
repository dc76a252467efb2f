// Void filling on CGAL's regular (weighted Delaunay) triangulation: the only file of the packer that
// includes CGAL's triangulation headers (they are heavy to compile).
//
// Vertices are the placed spheres (weight r^2), their mirror images across nearby boundary pieces
// ("ghosts", which make a void next to a wall a cell like any other) and eight far "frame" points that
// keep the triangulation three-dimensional. Each finite cell whose vertices stand for four distinct
// objects (spheres, or boundary planes through their ghosts) gets the ball tangent to those four; its
// radius, clipped to the distance to the boundary, is the cell's capacity. Voids are kept in an ordered
// set by (capacity, serial); inserting a sphere removes the cells in conflict and evaluates the new ones.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Regular_triangulation_3.h>
#include <CGAL/Regular_triangulation_cell_base_3.h>
#include <CGAL/Regular_triangulation_vertex_base_3.h>
#include <CGAL/Triangulation_cell_base_with_info_3.h>
#include <CGAL/Triangulation_data_structure_3.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <queue>
#include <set>

#include "sphere_grid.hpp"
#include "tangent.hpp"

namespace basalt::packer::detail {

namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
struct CellInfo {
  std::uint64_t serial = 0;
  double cap = -1;  ///< capacity while the cell's void is in the set, else -1
};
using Vb = CGAL::Triangulation_vertex_base_with_info_3<std::int32_t, K,
                                                       CGAL::Regular_triangulation_vertex_base_3<K>>;
using RCb = CGAL::Regular_triangulation_cell_base_3<K, CGAL::Triangulation_cell_base_3<K>,
                                                    CGAL::Discard_hidden_points>;
using Cb = CGAL::Triangulation_cell_base_with_info_3<CellInfo, K, RCb>;
using Tds = CGAL::Triangulation_data_structure_3<Vb, Cb, CGAL::Sequential_tag>;
using Rt = CGAL::Regular_triangulation_3<K, Tds>;
using WPoint = K::Weighted_point_3;
using Point = K::Point_3;
using Cell = Rt::Cell_handle;

constexpr std::int32_t kFrame = -1;  // vertex info: >= 0 sphere index, -1 frame, <= -2 ghost -(2 + g)

struct Void {
  double cap;
  std::uint64_t serial;
  Cell cell;
  Vec3 centre;
  bool operator<(const Void& o) const { return cap != o.cap ? cap < o.cap : serial < o.serial; }
};

/// Dense mode's queue entry: voids are taken block by block (6 rmax square in y and z, the working set stays
/// in cache), and within a slab largest first. Stale entries (their cell has died since) are skipped when
/// taken.
struct QueuedVoid {
  Void v;
  std::int32_t slab;
  bool operator<(const QueuedVoid& o) const {  // "lower priority than"
    if (slab != o.slab) return slab > o.slab;
    if (v.cap != o.v.cap) return v.cap < o.v.cap;
    return v.serial > o.v.serial;
  }
};

Vec3 to_vec(const Point& p) { return {p.x(), p.y(), p.z()}; }

class Filler {
 public:
  explicit Filler(FillContext& ctx)
      : ctx_(ctx),
        vol_(ctx.volume),
        tol_(ctx.options.overlap_tolerance),
        rmin_(ctx.options.rmin),
        rmax_(ctx.options.rmax),
        ghost_reach_(2 * ctx.options.rmax) {}

  void report() const {
    if (std::getenv("BASALT_PACK_DEBUG"))
      std::fprintf(stderr,
                   "evaluate %zu place %zu placed %zu vertices %zu cells %zu voids left %zu fail cap %zu "
                   "fail three %zu probes %zu probed spheres %zu\n",
                   n_eval_, n_place_, ctx_.out.size(), rt_.number_of_vertices(), rt_.number_of_cells(),
                   voids_.size(), n_fail_cap_, n_fail_three_, n_probe_, ctx_.probed_spheres);
  }

  void run() {
    build();
    if (ctx_.radii) {
      const auto& radii = *ctx_.radii;
      for (; ctx_.next < radii.size(); ++ctx_.next) {
        const double rho = radii[ctx_.next];
        for (;;) {
          auto it = voids_.lower_bound(Void{rho * (1 - 1e-12), 0, {}, {}});
          if (it == voids_.end()) {
            if (!probe(rho, kRadiusProbes, true)) ++ctx_.not_placed;
            break;
          }
          const Void v = take(it);
          if (place(v, rho)) break;
        }
      }
    }
    if (!ctx_.radii) {
      do {
        while (!queue_.empty()) {
          const Void v = queue_.top().v;
          queue_.pop();
          if (v.cell->info().serial != v.serial) continue;  // the cell died
          place(v, std::min(v.cap, rmax_));
        }
      } while (probe(rmin_, kFillProbes, false));
    } else if (ctx_.options.fill_after) {
      do {
        while (!voids_.empty()) {
          const Void v = take(std::prev(voids_.end()));
          place(v, std::min(v.cap, rmax_));
        }
      } while (probe(rmin_, kFillProbes, false));
    }
  }

 private:
  /// Misses in a row after which the volume counts as full: a region of room for a sphere that covers
  /// 0.15 % of the bounding box is found with probability 95 %.
  static constexpr int kFillProbes = 2000;
  static constexpr int kRadiusProbes = 100;  ///< power-law mode, per radius that found no void
  /// Pieces a sphere is mirrored across: a box's six faces; a finely faceted mesh near a sphere could
  /// offer dozens, each a vertex more.
  static constexpr int kMaxMirrorPieces = 6;

  /// Room the triangulation did not offer. The filler sees a void only in a cell whose four vertices
  /// stand for four distinct objects; where the seeds are too few for such cells (a volume only a few
  /// rmax across: 2 seeds in a 2 x 2 x 2 box with rmax 0.5, 1 in a ball of radius 1.2) it saw nothing and
  /// stopped. A probe takes a random point of the bounding box; where a sphere of radius >= `at_least`
  /// fits, it places the largest that fits there (at most rmax), or with `exact` one of radius `at_least`
  /// (the power-law mode's next radius), whose new cells give the filling its start. True when one was
  /// placed.
  bool probe(double at_least, int tries, bool exact) {
    if (!ctx_.rng) return false;
    Random& rng = *ctx_.rng;
    for (int t = 0; t < tries; ++t) {
      ++n_probe_;
      Vec3 c;
      for (int k = 0; k < 3; ++k) c[k] = bounds_.lo[k] + (bounds_.hi[k] - bounds_.lo[k]) * rng.uniform();
      // Most probes land inside a sphere: look in the probe's own grid cell first, then let the overlap
      // test (which stops at the first overlap) rule out the rest before measuring the room (4x less
      // probe time than measuring it for every probe: 0.49 -> 0.12 s of 7.5 s on a 60 mm cube).
      if (ctx_.grid.inside_home_cell(c)) continue;
      const double wall = vol_.signed_distance(c);
      if (!(wall >= at_least)) continue;
      if (ctx_.grid.overlaps(c, at_least, tol_)) continue;
      const double room = std::min(wall, ctx_.grid.clearance(c, rmax_));
      if (!(room >= at_least)) continue;
      const double r = exact ? at_least : std::min(room, rmax_);
      if (ctx_.grid.overlaps(c, r, tol_)) continue;  // rounding
      commit({c, r}, Cell());
      ++ctx_.probed_spheres;
      return true;
    }
    return false;
  }

 public:
 private:
  // ---- triangulation upkeep -------------------------------------------------------------------
  void build() {
    const Bounds b = vol_.bounds();
    double extent = 0;
    for (int k = 0; k < 3; ++k) extent = std::max(extent, b.hi[k] - b.lo[k]);
    const double far = 2 * extent + 10 * rmax_;
    Cell hint;
    for (int corner = 0; corner < 8; ++corner) {
      Point p(corner & 1 ? b.hi[0] + far : b.lo[0] - far, corner & 2 ? b.hi[1] + far : b.lo[1] - far,
              corner & 4 ? b.hi[2] + far : b.lo[2] - far);
      auto v = rt_.insert(WPoint(p, 0.0), hint);
      v->info() = kFrame;
      hint = v->cell();
    }
    for (std::size_t i = 0; i < ctx_.out.size(); ++i) add_vertices(i, Cell());
    for (auto c = rt_.finite_cells_begin(); c != rt_.finite_cells_end(); ++c) evaluate(c);
    live_ = true;
  }

  /// Inserts one weighted point; while live, keeps the void set in step with the cells.
  Rt::Vertex_handle insert(const Vec3& c, double r, std::int32_t info, Cell hint) {
    const WPoint wp(Point(c[0], c[1], c[2]), r * r);
    if (!live_) {
      auto v = rt_.insert(wp, hint);
      if (v != Rt::Vertex_handle()) v->info() = info;
      return v;
    }
    Rt::Locate_type lt;
    int li, lj;
    Cell start = rt_.locate(wp, lt, li, lj, hint);
    if (lt == Rt::VERTEX) return {};
    conflicts_.clear();
    boundary_.clear();
    rt_.find_conflicts(wp, start, std::back_inserter(boundary_), std::back_inserter(conflicts_));
    if (conflicts_.empty()) return {};  // hidden (cannot happen for non-overlapping spheres)
    for (Cell k : conflicts_) kill(k);
    auto v =
        rt_.insert_in_hole(wp, conflicts_.begin(), conflicts_.end(), boundary_[0].first, boundary_[0].second);
    v->info() = info;
    incident_.clear();
    rt_.incident_cells(v, std::back_inserter(incident_));
    for (Cell n : incident_) evaluate(n);
    return v;
  }

  /// The sphere's vertex and its mirror images across the boundary pieces within reach.
  void add_vertices(std::size_t i, Cell hint) {
    const Vec3 c = ctx_.out.centre[i];
    const double r = ctx_.out.radius[i];
    auto v = insert(c, r, static_cast<std::int32_t>(i), hint);
    Cell near = v != Rt::Vertex_handle() ? v->cell() : hint;
    pieces_.clear();
    vol_.pieces_near(c, r + ghost_reach_, pieces_);
    // Mirror images across every combination of the first three pieces (a corner of a box is three), and
    // single images across up to three further pieces: in a volume only a few rmax across a sphere is within
    // reach of opposite faces too, and a face without its image leaves the cells along it to the frame
    // points, where the filler sees no void (a 2 x 2 x 2 box with rmax 0.5 got 2 spheres).
    const int n = std::min(static_cast<int>(pieces_.size()), kMaxMirrorPieces);
    const int m = std::min(n, 3);
    const int masks = (1 << m) - 1 + (n - m);
    for (int j = 1; j <= masks; ++j) {
      const int mask = j < (1 << m) ? j : 0;
      Vec3 g = c;
      int piece = -1;
      int count = 0;
      for (int k = 0; k < n; ++k)
        if (mask ? (k < m && (mask & (1 << k))) : k == m + (j - (1 << m))) {
          g = pieces_[k].plane.mirror(g);
          piece = pieces_[k].id;
          if (piece_flat_.size() <= static_cast<std::size_t>(piece)) piece_flat_.resize(piece + 1, true);
          piece_flat_[piece] = pieces_[k].flat;
          ++count;
        }
      ghost_piece_.push_back(count == 1 ? piece : -1);
      // Exact mirror images make many coplanar and co-orthospherical vertex sets, which send CGAL's
      // predicates to exact arithmetic. Ghosts stand only for topology (tangency is solved against the
      // plane itself), so a tiny deterministic nudge costs nothing and avoids that.
      std::uint64_t h = 0x9e3779b97f4a7c15ULL * (ghost_piece_.size() + 1);
      for (int k = 0; k < 3; ++k) {
        h ^= h >> 31;
        h *= 0xbf58476d1ce4e5b9ULL;
        h ^= h >> 29;
        g[k] += 1e-7 * rmax_ * (static_cast<double>(h >> 11) * 0x1.0p-53 - 0.5);
      }
      auto gv = insert(g, r, -2 - static_cast<std::int32_t>(ghost_piece_.size() - 1), near);
      if (gv != Rt::Vertex_handle()) near = gv->cell();
    }
  }

  void kill(Cell c) {
    auto& info = c->info();
    if (info.cap >= 0) voids_.erase(Void{info.cap, info.serial, {}, {}});
    info.cap = -1;
    info.serial = 0;
  }

  Void take(std::set<Void>::iterator it) {
    Void v = *it;
    voids_.erase(it);
    v.cell->info().cap = -1;
    return v;
  }

  // ---- geometry of one cell ----------------------------------------------------------------------
  struct CellObjects {
    std::array<Object, 4> o;
    int piece[4] = {-1, -1, -1, -1};  ///< curved boundary piece behind a plane object, else -1
    bool curved = false;
  };

  /// The four distinct objects a cell stands for; false when they are not four (or a frame point).
  bool objects_of(Cell c, CellObjects& co) const {
    int n = 0;
    int seen[4];
    int nseen = 0;
    for (int i = 0; i < 4; ++i) {
      const std::int32_t info = c->vertex(i)->info();
      if (info >= 0) {
        co.o[n].is_plane = false;
        co.o[n].c = ctx_.out.centre[info];
        co.o[n].r = ctx_.out.radius[info];
        co.piece[n] = -1;
        ++n;
        continue;
      }
      if (info == kFrame) return false;
      const int piece = ghost_piece_[-2 - info];
      if (piece < 0) return false;
      if (std::find(seen, seen + nseen, piece) != seen + nseen) continue;
      seen[nseen++] = piece;
      co.o[n].is_plane = true;
      co.piece[n] = piece;
      ++n;
    }
    if (n != 4) return false;
    co.curved = false;
    for (int i = 0; i < 4; ++i)
      if (co.o[i].is_plane) {
        const int piece = co.piece[i];
        co.o[i].plane = vol_.tangent_plane(piece, Vec3{0, 0, 0});
        if (piece_flat_[piece]) {
          co.piece[i] = -1;  // flat: one plane everywhere, nothing to relinearise
        } else {
          co.curved = true;
        }
      }
    return true;
  }

  void relinearise(CellObjects& co, const Vec3& at) const {
    for (int i = 0; i < 4; ++i)
      if (co.o[i].is_plane && co.piece[i] >= 0) co.o[i].plane = vol_.tangent_plane(co.piece[i], at);
  }

  std::optional<Ball> capacity_ball(CellObjects& co, const Vec3& near) const {
    if (co.curved) relinearise(co, near);
    auto ball = tangent_ball(co.o, near);
    for (int it = 0; co.curved && ball && it < 8; ++it) {
      relinearise(co, ball->c);
      auto next = tangent_ball(co.o, ball->c);
      if (!next) return std::nullopt;
      const bool done = norm(next->c - ball->c) < 1e-12 * (1 + norm(ball->c));
      ball = next;
      if (done) break;
    }
    return ball;
  }

  void evaluate(Cell c) {
    ++n_eval_;
    auto& info = c->info();
    info.serial = ++serial_;
    info.cap = -1;
    if (rt_.is_infinite(c)) return;
    CellObjects co;
    if (!objects_of(c, co)) return;
    Vec3 near{0, 0, 0};
    for (int i = 0; i < 4; ++i) near = near + 0.25 * to_vec(c->vertex(i)->point().point());
    auto ball = capacity_ball(co, near);
    if (!ball || ball->r < rmin_ || !ctx_.in_range(ball->c)) return;
    const double cap = std::min(ball->r, vol_.signed_distance(ball->c));
    if (!(cap >= rmin_ * (1 - 1e-12))) return;
    if (!ctx_.radii) {
      queue_.push({Void{cap, info.serial, c, ball->c}, block_of(ball->c)});
      return;
    }
    info.cap = cap;
    voids_.insert(Void{cap, info.serial, c, ball->c});
  }

  // ---- placement ----------------------------------------------------------------------------------
  /// Places a sphere of radius rho in the void: touching three of the cell's objects where it fits,
  /// else concentric with the void's ball. False when nothing fits (the void is then dropped).
  bool place(const Void& v, double rho) {
    ++n_place_;
    CellObjects co;
    if (!objects_of(v.cell, co)) return false;
    candidates_.clear();
    if (rho >= v.cap * (1 - 1e-12)) {
      candidates_.push_back({v.centre, v.cap});
    } else {
      if (co.curved) relinearise(co, v.centre);
      for (int drop = 0; drop < 4; ++drop) {
        int t[3], n = 0;
        for (int i = 0; i < 4; ++i)
          if (i != drop) t[n++] = i;
        Ball sol[2];
        const int ns = tangent_balls(co.o[t[0]], co.o[t[1]], co.o[t[2]], rho, sol);
        for (int s = 0; s < ns; ++s) {
          Ball ball = sol[s];
          if (co.curved && !refine(co, t, rho, ball)) continue;
          if (gap(ball, co.o[drop]) < -tol_) continue;
          candidates_.push_back(ball);
        }
      }
      std::sort(candidates_.begin(), candidates_.end(),
                [&](const Ball& a, const Ball& b) { return norm2(a.c - v.centre) < norm2(b.c - v.centre); });
      candidates_.push_back({v.centre, rho});
    }
    for (const Ball& ball : candidates_) {
      if (!ctx_.in_range(ball.c)) continue;
      if (vol_.signed_distance(ball.c) < ball.r - tol_) continue;
      if (ctx_.grid.overlaps(ball.c, ball.r, tol_)) continue;
      commit(ball, v.cell);
      return true;
    }
    ++(rho >= v.cap * (1 - 1e-12) ? n_fail_cap_ : n_fail_three_);
    return false;
  }

  /// Tangency to a curved piece: re-solve with the tangent plane at the current centre until it settles.
  bool refine(CellObjects co, const int t[3], double rho, Ball& ball) const {
    for (int it = 0; it < 8; ++it) {
      relinearise(co, ball.c);
      Ball sol[2];
      const int ns = tangent_balls(co.o[t[0]], co.o[t[1]], co.o[t[2]], rho, sol);
      if (ns == 0) return false;
      const Ball& best = ns == 2 && norm2(sol[1].c - ball.c) < norm2(sol[0].c - ball.c) ? sol[1] : sol[0];
      const bool done = norm(best.c - ball.c) < 1e-12 * (1 + norm(ball.c));
      ball = best;
      if (done) break;
    }
    return true;
  }

  void commit(const Ball& ball, Cell hint) {
    const std::size_t i = ctx_.out.size();
    ctx_.out.centre.push_back(ball.c);
    ctx_.out.radius.push_back(ball.r);
    ctx_.grid.add(ball.c, ball.r);
    ctx_.placed_solid += 4.0 / 3.0 * std::numbers::pi * ball.r * ball.r * ball.r;
    add_vertices(i, hint);
    if (ctx_.options.progress && (i & 4095) == 0)
      ctx_.options.progress(std::min(0.99, ctx_.placed_solid / ctx_.expected_solid));
  }

  std::size_t n_eval_ = 0, n_place_ = 0, n_fail_cap_ = 0, n_fail_three_ = 0, n_probe_ = 0;
  FillContext& ctx_;
  const Volume& vol_;
  const double tol_, rmin_, rmax_, ghost_reach_;
  Rt rt_;
  bool live_ = false;
  std::uint64_t serial_ = 0;
  std::set<Void> voids_;                   // power-law mode: best fit by capacity
  std::priority_queue<QueuedVoid> queue_;  // dense mode
  const double slab_ = 6 * rmax_;
  const Bounds bounds_ = vol_.bounds();
  const std::int32_t ny_ = 1 + static_cast<std::int32_t>((bounds_.hi[1] - bounds_.lo[1]) / slab_);

  /// Blocks of slab_ x slab_ across y and z (x runs the whole length), z slowest.
  std::int32_t block_of(const Vec3& c) const {
    const auto z = static_cast<std::int32_t>(std::floor((c[2] - bounds_.lo[2]) / slab_));
    const auto y =
        std::clamp(static_cast<std::int32_t>(std::floor((c[1] - bounds_.lo[1]) / slab_)), 0, ny_ - 1);
    return z * ny_ + y;
  }
  std::vector<int> ghost_piece_;
  std::vector<bool> piece_flat_;
  std::vector<Cell> conflicts_, incident_;
  std::vector<Rt::Facet> boundary_;
  std::vector<BoundaryPiece> pieces_;
  std::vector<Ball> candidates_;
};

}  // namespace

void fill_voids(FillContext& ctx) {
  Filler filler(ctx);
  filler.run();
  filler.report();
}

}  // namespace basalt::packer::detail
