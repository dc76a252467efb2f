// Split packs: tiles packed in four colour rounds on several threads (docs/packer.md, "Tiles and threads").
//
// Why the result is exact across tile borders:
//  * Tile (i, j) has colour (i mod 2) + 2 (j mod 2). Its centres lie in the tile widened by rmax on every
//    side (within the box); tiles are at least 4 rmax wide, so two tiles of one colour keep their centres
//    at least 2 rmax apart: they never touch. (Widened only towards earlier neighbours, the first colour's
//    tiles had no room along their open sides and packed their interiors denser: mean coordination 6.20
//    there against 6.62 in the last colour's, a pattern with the tiles' period in the bonded network.)
//  * A tile is packed only after its (up to eight) neighbours of lower colour; their spheres within
//    2 rmax of its centre range are obstacles in its grid and triangulation, so it places nothing that
//    overlaps them (the same overlap test as inside one tile). Tiles further away cannot be reached.
//  * Bonds are found afterwards on the joined spheres by the one bond rule (packer/src/assembly.cpp).
#include "tiles.hpp"

#include <algorithm>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <numeric>
#include <string>
#include <thread>
#include <vector>

namespace basalt::packer::detail {

namespace {

/// A tile of a box: its bounds are the tile's centre range (the box across the third axis); distances,
/// faces and tangent planes are the whole box's, so the tile's open sides are no walls.
class TileView final : public Volume {
 public:
  TileView(const Volume& whole, const Bounds& range, double measure)
      : whole_(whole), range_(range), measure_(measure) {}
  std::string description() const override { return whole_.description(); }
  Bounds bounds() const override { return range_; }
  double measure() const override { return measure_; }
  double signed_distance(const Vec3& x) const override { return whole_.signed_distance(x); }
  void pieces_near(const Vec3& x, double reach, std::vector<BoundaryPiece>& out) const override {
    whole_.pieces_near(x, reach, out);
  }
  Plane tangent_plane(int id, const Vec3& x) const override { return whole_.tangent_plane(id, x); }
  std::vector<std::string> piece_names() const override { return whole_.piece_names(); }

 private:
  const Volume& whole_;
  Bounds range_;
  double measure_;
};

/// splitmix64 of (seed, tile): independent streams per tile.
std::uint64_t tile_seed(std::uint64_t seed, int tile) {
  std::uint64_t z = seed + 0x9e3779b97f4a7c15ULL * (static_cast<std::uint64_t>(tile) + 1);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

}  // namespace

TileLayout tile_layout(const Volume& volume, const PackOptions& o) {
  TileLayout t;
  t.box = volume.bounds();
  if (!volume.fills_bounds() || o.tile_width < 0) return t;
  const double width = o.tile_width > 0 ? std::max(o.tile_width, 4 * o.rmax) : 10 * o.rmax;
  int order[3] = {0, 1, 2};
  const auto extent = [&](int k) { return t.box.hi[k] - t.box.lo[k]; };
  std::stable_sort(order, order + 3, [&](int a, int b) { return extent(a) > extent(b); });
  t.axis[0] = std::min(order[0], order[1]);
  t.axis[1] = std::max(order[0], order[1]);
  for (int a = 0; a < 2; ++a) {
    const double e = extent(t.axis[a]);
    t.n[a] = std::max(1, static_cast<int>(std::min(1e6, std::floor(e / width))));
    t.width[a] = e / t.n[a];
  }
  return t;
}

Packing pack_tiles(const Volume& volume, const PackOptions& opt, const TileLayout& L) {
  const int nt = L.count();
  const double e = opt.rmax;  // widening of every tile's centre range
  const double band = 2 * opt.rmax + opt.overlap_tolerance + 1e-9 * opt.rmax;  // obstacles kept
  auto index = [&](int i, int j) { return j * L.n[0] + i; };
  auto colour = [](int i, int j) { return (i & 1) + 2 * (j & 1); };
  auto edge = [&](int a, int i) {  // the i-th tile edge along cut axis a (exact at the box's faces)
    const int ax = L.axis[a];
    return i == L.n[a] ? L.box.hi[ax] : L.box.lo[ax] + L.width[a] * i;
  };

  std::vector<Bounds> range(nt);
  std::vector<double> measure(nt);
  for (int j = 0; j < L.n[1]; ++j)
    for (int i = 0; i < L.n[0]; ++i) {
      Bounds r = L.box;
      double m = 1;
      const int idx[2] = {i, j};
      for (int a = 0; a < 2; ++a) {
        const int ax = L.axis[a], k = idx[a];
        r.lo[ax] = std::max(L.box.lo[ax], edge(a, k) - e);
        r.hi[ax] = std::min(L.box.hi[ax], edge(a, k + 1) + e);
        m *= edge(a, k + 1) - edge(a, k);
      }
      const int third = 3 - L.axis[0] - L.axis[1];
      m *= L.box.hi[third] - L.box.lo[third];
      range[index(i, j)] = r;
      measure[index(i, j)] = m;
    }
  // Packing order when threads are free: by colour, then tile index.
  std::vector<int> order(nt);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return colour(a % L.n[0], a / L.n[0]) < colour(b % L.n[0], b / L.n[0]);
  });
  // Earlier neighbours of each tile (lower colour), in a fixed order.
  std::vector<std::vector<int>> earlier(nt);
  for (int j = 0; j < L.n[1]; ++j)
    for (int i = 0; i < L.n[0]; ++i)
      for (int dj = -1; dj <= 1; ++dj)
        for (int di = -1; di <= 1; ++di) {
          const int u = i + di, v = j + dj;
          if (u < 0 || v < 0 || u >= L.n[0] || v >= L.n[1] || (di == 0 && dj == 0)) continue;
          if (colour(u, v) < colour(i, j)) earlier[index(i, j)].push_back(index(u, v));
        }

  // Tasks: (round, tile). A power-law pack with --fill takes two rounds (PartSpec::Stage), others one.
  const int rounds = opt.exponent && opt.fill_after ? 2 : 1;
  const int ntask = rounds * nt;
  std::vector<std::vector<int>> neighbours(nt);  // all eight and the tile itself
  for (int j = 0; j < L.n[1]; ++j)
    for (int i = 0; i < L.n[0]; ++i)
      for (int dj = -1; dj <= 1; ++dj)
        for (int di = -1; di <= 1; ++di) {
          const int u = i + di, v = j + dj;
          if (u >= 0 && v >= 0 && u < L.n[0] && v < L.n[1]) neighbours[index(i, j)].push_back(index(u, v));
        }
  // A task waits for the same round of its earlier neighbours, and a fill task for the first round of
  // every neighbour (their radii are its obstacles).
  std::vector<std::vector<int>> needs(ntask);
  for (int t = 0; t < nt; ++t) {
    for (int u : earlier[t]) needs[t].push_back(u);
    if (rounds == 2) {
      for (int u : neighbours[t]) needs[nt + t].push_back(u);
      for (int u : earlier[t]) needs[nt + t].push_back(nt + u);
    }
  }
  std::vector<int> task_order;
  for (int r = 0; r < rounds; ++r)
    for (int t : order) task_order.push_back(r * nt + t);

  std::vector<Packing> result(ntask);
  std::vector<char> taken(ntask, 0), done(ntask, 0);
  std::vector<double> progress(ntask, 0.0);
  const double round_weight[2] = {rounds == 2 ? 0.75 : 1.0, 0.25};
  const double total_measure = std::accumulate(measure.begin(), measure.end(), 0.0);
  std::mutex mutex;
  std::condition_variable changed;
  std::exception_ptr failure;

  auto pack_one = [&](int task) {
    const int round = task / nt, t = task % nt;
    Packing fixed;
    Bounds near = range[t];
    for (int a = 0; a < 2; ++a) {
      near.lo[L.axis[a]] -= band;
      near.hi[L.axis[a]] += band;
    }
    auto take = [&](const Packing& p) {  // finished: no thread writes it any more
      for (std::size_t s = 0; s < p.size(); ++s) {
        const Vec3& c = p.centre[s];
        if (c[0] >= near.lo[0] && c[0] <= near.hi[0] && c[1] >= near.lo[1] && c[1] <= near.hi[1] &&
            c[2] >= near.lo[2] && c[2] <= near.hi[2]) {
          fixed.centre.push_back(c);
          fixed.radius.push_back(p.radius[s]);
        }
      }
    };
    if (round == 0) {
      for (int u : earlier[t]) take(result[u]);
    } else {
      for (int u : neighbours[t]) take(result[u]);
      for (int u : earlier[t]) take(result[nt + u]);
    }
    PackOptions o = opt;
    if (rounds == 2 && round == 0) o.fill_after = false;
    o.progress = [&, task](double f) {
      if (!opt.progress) return;
      std::lock_guard<std::mutex> lock(mutex);
      progress[task] = f;
      double sum = 0;
      for (int k = 0; k < ntask; ++k) sum += progress[k] * measure[k % nt] * round_weight[k / nt];
      opt.progress(std::min(0.99, sum / total_measure));
    };
    const TileView view(volume, range[t], measure[t]);
    PartSpec spec;
    spec.stage = rounds == 1 ? PartSpec::kWhole : round == 0 ? PartSpec::kPowerLaw : PartSpec::kFill;
    spec.seed = tile_seed(opt.seed, task);
    spec.centre_range = range[t];
    spec.fixed = fixed.size() ? &fixed : nullptr;
    return pack_part(view, o, spec);
  };

  auto worker = [&] {
    std::unique_lock<std::mutex> lock(mutex);
    for (;;) {
      int pick = -1;
      bool left = false;
      for (int t : task_order) {
        if (taken[t]) continue;
        left = true;
        if (std::all_of(needs[t].begin(), needs[t].end(), [&](int u) { return done[u] != 0; })) {
          pick = t;
          break;
        }
      }
      if (!left || failure) return;
      if (pick < 0) {
        changed.wait(lock);
        continue;
      }
      taken[pick] = 1;
      lock.unlock();
      Packing r;
      std::exception_ptr err;
      try {
        r = pack_one(pick);
      } catch (...) {
        err = std::current_exception();
      }
      lock.lock();
      if (err && !failure) failure = err;
      result[pick] = std::move(r);
      done[pick] = 1;
      progress[pick] = 1;
      changed.notify_all();
    }
  };
  const int threads = std::clamp(opt.threads, 1, ntask);
  std::vector<std::thread> pool;
  for (int k = 1; k < threads; ++k) pool.emplace_back(worker);
  worker();
  for (auto& th : pool) th.join();
  if (failure) std::rethrow_exception(failure);

  Packing out;
  std::size_t total = 0;
  for (const auto& p : result) total += p.size();
  out.centre.reserve(total);
  out.radius.reserve(total);
  for (int k = 0; k < ntask; ++k) {  // tile by tile, its rounds in order
    Packing& p = result[(k % rounds) * nt + k / rounds];
    out.centre.insert(out.centre.end(), p.centre.begin(), p.centre.end());
    out.radius.insert(out.radius.end(), p.radius.begin(), p.radius.end());
    out.seeds += p.seeds;
    out.requested += p.requested;
    out.not_placed += p.not_placed;
    p = Packing{};
  }
  return out;
}

}  // namespace basalt::packer::detail
