// machine_limits: this machine's ceilings for the roofline (tools/bench/roofline.py, docs/BENCHMARKS.md,
// "Roofline"), on 1 and 2 threads (std::thread; each thread its own arrays, so 2 threads measure what two
// single-rank processes of the solver share):
//   copy, triad   STREAM-like: b = a and a = b + s c over arrays of `--sizes` bytes each; bytes counted as
//                 STREAM does (copy 16 B, triad 24 B per element: the write-allocate read is not counted);
//   gather        sum += x[i]*y[i]*z[i]-like loads through an int32 index array, as the pair and bond loops
//                 read their neighbours' positions: indices in random order and sorted; 28 B per index
//                 (4 B index + 3 doubles) counted, and the time per index;
//   fma           peak flops: 12 independent chains a = a b + c, scalar and in the widest vector the build
//                 targets (AVX-512: 64 B, AVX: 32 B, else 16 B), double and float; 2 flops per lane per FMA.
// Every figure is the best of `--repeats` timed passes (the machine is shared: the best is the least
// disturbed). Output: one JSON object on standard output.
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <barrier>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <functional>
#include <numeric>
#include <random>
#include <string>
#include <thread>
#include <vector>

namespace {

#if defined(__AVX512F__)
constexpr int kVectorBytes = 64;
constexpr const char* kVectorName = "AVX-512";
#elif defined(__AVX__)
constexpr int kVectorBytes = 32;
constexpr const char* kVectorName = "AVX";
#else
constexpr int kVectorBytes = 16;
constexpr const char* kVectorName = "SSE2";
#endif
#if defined(__FMA__)
constexpr bool kFma = true;
#else
constexpr bool kFma = false;
#endif

double now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

/// Keeps a value in a register and the compiler from merging or removing the chains that compute it.
template <class T>
inline void keep(T& v) {
  asm volatile("" : "+v"(v));
}

/// Runs pass(thread) on `threads` threads `repeats` times, all threads starting together; returns the best
/// time of a repeat (the slowest thread's time in that repeat).
double best_time(int threads, int repeats, const std::function<void(int)>& pass) {
  std::vector<double> worst(static_cast<std::size_t>(repeats), 0.0);
  std::barrier sync(threads);
  std::vector<std::vector<double>> times(static_cast<std::size_t>(threads));
  auto body = [&](int t) {
    for (int r = 0; r < repeats; ++r) {
      sync.arrive_and_wait();
      const double t0 = now();
      pass(t);
      times[static_cast<std::size_t>(t)].push_back(now() - t0);
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(body, t);
  body(0);
  for (auto& th : pool) th.join();
  for (const auto& ts : times)
    for (std::size_t r = 0; r < ts.size(); ++r) worst[r] = std::max(worst[r], ts[r]);
  return *std::min_element(worst.begin(), worst.end());
}

struct Arrays {
  std::vector<double> a, b, c;
};

/// copy and triad on each thread's own arrays of n doubles; returns {copy GB/s, triad GB/s} summed over
/// the threads.
std::pair<double, double> stream(std::size_t n, int threads, int repeats) {
  std::vector<Arrays> arr(static_cast<std::size_t>(threads));
  best_time(threads, 1, [&](int t) {  // first touch by the thread that uses them
    auto& v = arr[static_cast<std::size_t>(t)];
    v.a.assign(n, 1.0);
    v.b.assign(n, 2.0);
    v.c.assign(n, 0.5);
  });
  const double copy = best_time(threads, repeats, [&](int t) {
    auto& v = arr[static_cast<std::size_t>(t)];
    const double* __restrict a = v.a.data();
    double* __restrict b = v.b.data();
    for (std::size_t i = 0; i < n; ++i) b[i] = a[i];
    asm volatile("" ::"r"(b) : "memory");
  });
  const double s = 0.75;
  const double triad = best_time(threads, repeats, [&](int t) {
    auto& v = arr[static_cast<std::size_t>(t)];
    double* __restrict a = v.a.data();
    const double* __restrict b = v.b.data();
    const double* __restrict c = v.c.data();
    for (std::size_t i = 0; i < n; ++i) a[i] = b[i] + s * c[i];
    asm volatile("" ::"r"(a) : "memory");
  });
  const double elems = double(n) * threads;
  return {16 * elems / copy * 1e-9, 24 * elems / triad * 1e-9};
}

/// Gathers through n int32 indices into three arrays of n doubles (random order, then sorted); returns
/// {random ns per index, sorted ns per index} (per thread: each thread gathers its own n).
std::pair<double, double> gather(std::size_t n, int threads, int repeats, std::uint64_t seed) {
  struct G {
    std::vector<double> x, y, z;
    std::vector<std::int32_t> idx;
  };
  std::vector<G> g(static_cast<std::size_t>(threads));
  std::vector<double> sink(static_cast<std::size_t>(threads) * 8, 0.0);
  best_time(threads, 1, [&](int t) {
    auto& v = g[static_cast<std::size_t>(t)];
    v.x.assign(n, 1.0);
    v.y.assign(n, 1.0);
    v.z.assign(n, 1.0);
    v.idx.resize(n);
    std::iota(v.idx.begin(), v.idx.end(), 0);
    std::mt19937_64 rng(seed + static_cast<std::uint64_t>(t));
    std::shuffle(v.idx.begin(), v.idx.end(), rng);
  });
  auto pass = [&](int t) {
    const auto& v = g[static_cast<std::size_t>(t)];
    const double* __restrict x = v.x.data();
    const double* __restrict y = v.y.data();
    const double* __restrict z = v.z.data();
    const std::int32_t* __restrict ix = v.idx.data();
    double sx = 0, sy = 0, sz = 0;
    for (std::size_t k = 0; k < n; ++k) {
      const auto j = static_cast<std::size_t>(ix[k]);
      sx += x[j];
      sy += y[j];
      sz += z[j];
    }
    sink[static_cast<std::size_t>(t) * 8] += sx + sy + sz;
  };
  const double random = best_time(threads, repeats, pass);
  best_time(threads, 1, [&](int t) {
    auto& v = g[static_cast<std::size_t>(t)];
    std::sort(v.idx.begin(), v.idx.end());
  });
  const double sorted = best_time(threads, repeats, pass);
  if (sink[0] < 0) fmt::print("");  // keeps the sums alive
  return {random / double(n) * 1e9, sorted / double(n) * 1e9};
}

/// a b + c, fused when the build targets FMA (scalars through std::fma, vectors by contraction).
template <class T, class S>
inline T muladd(T a, T b, T c) {
  if constexpr (sizeof(T) == sizeof(S) && kFma)
    return std::fma(a, b, c);
  else
    return a * b + c;
}

/// Peak flops of 12 independent FMA chains of T (a scalar or a vector type of `lanes` lanes of S).
template <class T, class S>
double fma_peak(int threads, int repeats, int lanes, std::int64_t iters) {
  constexpr int kChains = 12;
  std::vector<double> sink(static_cast<std::size_t>(threads) * 8, 0.0);
  const double t = best_time(threads, repeats, [&](int th) {
    T b = T{} + S(0.999999), c = T{} + S(1e-7);
    keep(b);
    keep(c);
    T a0 = T{} + S(1.00), a1 = T{} + S(1.01), a2 = T{} + S(1.02), a3 = T{} + S(1.03), a4 = T{} + S(1.04),
      a5 = T{} + S(1.05), a6 = T{} + S(1.06), a7 = T{} + S(1.07), a8 = T{} + S(1.08), a9 = T{} + S(1.09),
      a10 = T{} + S(1.10), a11 = T{} + S(1.11);
    auto chains = [&](auto&... a) {
      for (std::int64_t i = 0; i < iters; ++i) ((a = muladd<T, S>(a, b, c), keep(a)), ...);
    };
    chains(a0, a1, a2, a3, a4, a5, a6, a7, a8, a9, a10, a11);
    const T sum = a0 + a1 + a2 + a3 + a4 + a5 + a6 + a7 + a8 + a9 + a10 + a11;
    S total;
    if constexpr (sizeof(T) == sizeof(S))
      total = sum;
    else
      total = sum[0];
    sink[static_cast<std::size_t>(th) * 8] += double(total);
  });
  if (sink[0] < 0) fmt::print("");
  return 2.0 * kChains * double(lanes) * double(iters) * threads / t * 1e-9;
}

typedef double VecD __attribute__((vector_size(kVectorBytes)));
typedef float VecF __attribute__((vector_size(kVectorBytes)));

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"machine_limits: memory bandwidth, gather cost and peak flops of this machine (JSON)"};
  std::vector<double> sizes_mb{0.008, 0.25, 1, 4, 256};
  std::vector<int> thread_counts{1, 2};
  int repeats = 10;
  double gather_mb = 256;
  double gather_cache_mb = 4;
  std::int64_t fma_iters = 20'000'000;
  app.add_option("--sizes", sizes_mb, "array sizes for copy and triad, MB per array (the largest: memory)");
  app.add_option("--gather-mb", gather_mb, "size of the gathered arrays x, y, z together, MB (memory)");
  app.add_option("--gather-cache-mb", gather_cache_mb, "the same, small enough for the caches, MB");
  app.add_option("--threads", thread_counts, "thread counts");
  app.add_option("--repeats", repeats, "timed passes; the best is kept")->check(CLI::PositiveNumber);
  app.add_option("--fma-iters", fma_iters, "iterations of the FMA chains per pass")
      ->check(CLI::PositiveNumber);
  CLI11_PARSE(app, argc, argv);

  std::string out =
      fmt::format("{{\n  \"vector\": \"{}\", \"vector_bytes\": {}, \"fma\": {}, \"repeats\": {},\n",
                  kVectorName, kVectorBytes, kFma ? "true" : "false", repeats);
  out += "  \"stream\": [";
  bool first = true;
  for (const int th : thread_counts)
    for (const double mb : sizes_mb) {
      const auto n = std::max<std::size_t>(64, static_cast<std::size_t>(mb * 1e6 / 8));
      // small arrays: more passes per timing so the clock's resolution does not matter
      const int reps = n < 1'000'000 ? repeats * 20 : repeats;
      const auto [copy, triad] = stream(n, th, reps);
      out +=
          fmt::format("{}\n    {{\"threads\": {}, \"mb\": {}, \"copy_gbs\": {:.3f}, \"triad_gbs\": {:.3f}}}",
                      first ? "" : ",", th, double(n) * 8 / 1e6, copy, triad);
      first = false;
    }
  out += "\n  ],\n  \"gather\": [";
  first = true;
  for (const int th : thread_counts)
    for (const double mb : {gather_cache_mb, gather_mb}) {
      const auto n = std::max<std::size_t>(64, static_cast<std::size_t>(mb * 1e6 / 24));
      const auto [random, sorted] = gather(n, th, n < 1'000'000 ? repeats * 5 : repeats, 7);
      out += fmt::format(
          "{}\n    {{\"threads\": {}, \"mb\": {:.3f}, \"random_ns\": {:.4f}, \"sorted_ns\": {:.4f}, "
          "\"random_gbs\": {:.3f}, \"sorted_gbs\": {:.3f}}}",
          first ? "" : ",", th, double(n) * 24 / 1e6, random, sorted, 28 * th / random, 28 * th / sorted);
      first = false;
    }
  out += "\n  ],\n  \"fma\": [";
  first = true;
  for (const int th : thread_counts) {
    const double d1 = fma_peak<double, double>(th, repeats, 1, fma_iters);
    const double f1 = fma_peak<float, float>(th, repeats, 1, fma_iters);
    const double dv = fma_peak<VecD, double>(th, repeats, kVectorBytes / 8, fma_iters);
    const double fv = fma_peak<VecF, float>(th, repeats, kVectorBytes / 4, fma_iters);
    out += fmt::format(
        "{}\n    {{\"threads\": {}, \"double_scalar_gflops\": {:.3f}, \"float_scalar_gflops\": {:.3f}, "
        "\"double_vector_gflops\": {:.3f}, \"float_vector_gflops\": {:.3f}}}",
        first ? "" : ",", th, d1, f1, dv, fv);
    first = false;
  }
  out += "\n  ]\n}\n";
  fmt::print("{}", out);
  return 0;
}
