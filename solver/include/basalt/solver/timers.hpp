#pragma once
// Wall-clock time per phase of the stepping loop.
#include <chrono>

namespace basalt::solver {

struct PhaseTimes {
  double forces = 0, neighbor = 0, communication = 0, integration = 0, output = 0;
  double total() const { return forces + neighbor + communication + integration + output; }
};

class Stopwatch {
 public:
  Stopwatch() : t_(std::chrono::steady_clock::now()) {}
  /// Seconds since construction or the last lap; restarts.
  double lap() {
    const auto now = std::chrono::steady_clock::now();
    const double s = std::chrono::duration<double>(now - t_).count();
    t_ = now;
    return s;
  }

 private:
  std::chrono::steady_clock::time_point t_;
};

}  // namespace basalt::solver
