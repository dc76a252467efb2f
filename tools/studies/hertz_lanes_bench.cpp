// Micro-benchmark (docs/ARCHITECTURE.md, "Scalar and lane laws"): the Hertz-Mindlin pair law on 16 contacts
// at once (HertzMindlin::contact_lanes) against the scalar law contact() called for each of the same 16
// lanes, which is what one source for both (the scalar law on a lane of one) would run. 64 batches of random
// contacts (fast and slow, sliding and sticking, drawn as tests/solver/test_granular.cpp draws them; 266 kB,
// in L2), 600 passes each, the two forms interleaved 12 times; prints ns per contact and the ratio's median
// and range.
// Built with the solver's flags, from the repository's root:
//   g++ -std=c++20 -O3 -march=native -DNDEBUG -Isolver/include tools/studies/hertz_lanes_bench.cpp
//       -o /tmp/hertz_lanes_bench
//   /tmp/hertz_lanes_bench
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <vector>

#include "basalt/solver/models/hertz_mindlin.hpp"
#include "basalt/solver/models/lanes.hpp"
using namespace basalt::solver;
constexpr int W = kContactLaneWidth;
using L16 = ContactLanes<double, W, HertzMindlin::History>;
static double hu(std::uint64_t k) {
  k += 0x9E3779B97F4A7C15ull;
  k = (k ^ (k >> 30)) * 0xBF58476D1CE4E5B9ull;
  k = (k ^ (k >> 27)) * 0x94D049BB133111EBull;
  k ^= k >> 31;
  return double(k >> 11) * 0x1.0p-53 - 0.5;
}
[[gnu::noinline]] void scalar_lanes(const HertzMindlin::Coeffs<double>& c, L16& b) {
  for (int l = 0; l < W; ++l) {
    ContactKinematics<double> k{
        b.dx[l], b.dy[l], b.dz[l],  std::sqrt(b.r2[l]), b.ri[l],  b.rj[l],  b.imi[l], b.imj[l], b.vx[l],
        b.vy[l], b.vz[l], b.wix[l], b.wiy[l],           b.wiz[l], b.wjx[l], b.wjy[l], b.wjz[l], b.dt};
    ContactForce<double> f;
    HertzMindlin::contact<true>(c, b.h[l], k, f);
    b.fx[l] = f.fx, b.fy[l] = f.fy, b.fz[l] = f.fz, b.r[l] = k.r;
    const double si = -f.arm_i / k.r, sj = (k.r - f.arm_i) / k.r;
    const double cx = k.dy * f.fz - k.dz * f.fy, cy = k.dz * f.fx - k.dx * f.fz,
                 cz = k.dx * f.fy - k.dy * f.fx;
    b.tix[l] = si * cx, b.tiy[l] = si * cy, b.tiz[l] = si * cz;
    b.tjx[l] = -sj * cx, b.tjy[l] = -sj * cy, b.tjz[l] = -sj * cz;
    b.dissipated[l] = f.dissipated;
    b.sliding[l] = f.sliding ? 1 : 0;
  }
}
[[gnu::noinline]] void vector_lanes(const HertzMindlin::Coeffs<double>& c, L16& b) {
  HertzMindlin::contact_lanes<true>(c, b);
}
int main() {
  const auto c = HertzMindlin::coeffs<double>(HertzMindlin::Params{{1.0e7, 0.25}, 0.5, 0.5});
  const int nb = 64;
  std::vector<L16> base(nb);
  for (int b = 0; b < nb; ++b)
    for (int l = 0; l < W; ++l) {
      const std::uint64_t s = 100 * std::uint64_t(b * W + l);
      auto& L = base[b];
      L.ri[l] = 1e-3 * (1 + hu(s));
      L.rj[l] = 1e-3 * (1 + hu(s + 1));
      double nx = hu(s + 2), ny = hu(s + 3), nz = hu(s + 4), nn = std::sqrt(nx * nx + ny * ny + nz * nz);
      double r = (L.ri[l] + L.rj[l]) * (1 - 1e-3 * (0.51 + hu(s + 5)));
      L.dx[l] = r * nx / nn;
      L.dy[l] = r * ny / nn;
      L.dz[l] = r * nz / nn;
      L.r2[l] = L.dx[l] * L.dx[l] + L.dy[l] * L.dy[l] + L.dz[l] * L.dz[l];
      L.imi[l] = 1 / (1e-5 * (1 + hu(s + 6)));
      L.imj[l] = 1 / (1e-5 * (1 + hu(s + 7)));
      const double v = (s / 100) % 2 == 0 ? 0.1 : 1e-4;
      L.vx[l] = v * hu(s + 8);
      L.vy[l] = v * hu(s + 9);
      L.vz[l] = v * hu(s + 10);
      L.wix[l] = 500 * v * hu(s + 11);
      L.wiy[l] = 500 * v * hu(s + 12);
      L.wiz[l] = 500 * v * hu(s + 13);
      L.wjx[l] = 500 * v * hu(s + 14);
      L.wjy[l] = 500 * v * hu(s + 15);
      L.wjz[l] = 500 * v * hu(s + 16);
      L.h[l] = {v * 2e-5 * hu(s + 17), v * 2e-5 * hu(s + 18), v * 2e-5 * hu(s + 19)};
      L.dt = 1e-5;
    }
  auto run = [&](bool vec) {
    std::vector<L16> w = base;
    const int reps = 600;
    auto t0 = std::chrono::steady_clock::now();
    for (int r = 0; r < reps; ++r)
      for (auto& L : w) {
        if (vec)
          vector_lanes(c, L);
        else
          scalar_lanes(c, L);
      }
    auto t1 = std::chrono::steady_clock::now();
    double sum = 0;
    for (auto& L : w) sum += L.fx[3];
    if (sum == 12345.678) std::puts("");
    return std::chrono::duration<double>(t1 - t0).count() * 1e9 / (double(reps) * nb * W);
  };
  std::vector<double> a, s, ratio;
  for (int k = 0; k < 12; ++k) {
    const double ta = run(true), ts = run(false);
    a.push_back(ta);
    s.push_back(ts);
    ratio.push_back(ts / ta);
  }
  std::sort(a.begin(), a.end());
  std::sort(s.begin(), s.end());
  std::sort(ratio.begin(), ratio.end());
  std::printf(
      "ns per contact: lanes median %.2f (min %.2f), scalar law per lane median %.2f (min %.2f); "
      "scalar/lanes median %.2f (range %.2f-%.2f)\n",
      a[6], a[0], s[6], s[0], ratio[6], ratio[0], ratio[11]);
}
