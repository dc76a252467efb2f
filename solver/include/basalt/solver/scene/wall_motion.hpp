#pragma once
// Prescribed motion of a planar wall: position offset and velocity as closed-form functions of time.
//   fixed:             u(t) = 0
//   constant_velocity: v(t) = v
//   half_sine:         v(t) = A sin(2 pi t / T) e for 0 <= t <= T/2, then 0   (the paper's pulse)
//   sine:              v(t) = A sin(2 pi t / T) e
// e is the direction (default: the wall normal), A the amplitude (length/time), T the period.
#include <array>
#include <cmath>
#include <numbers>

namespace basalt::solver {

struct WallMotion {
  enum class Type { fixed, constant_velocity, half_sine, sine };
  Type type = Type::fixed;
  std::array<double, 3> direction{0, 0, 1};
  std::array<double, 3> velocity{0, 0, 0};  ///< constant_velocity only
  double amplitude = 0;
  double period = 1;

  bool moves() const { return type != Type::fixed; }

  std::array<double, 3> velocity_at(double t) const {
    switch (type) {
      case Type::fixed:
        return {0, 0, 0};
      case Type::constant_velocity:
        return velocity;
      case Type::half_sine:
        if (t < 0 || t > period / 2) return {0, 0, 0};
        [[fallthrough]];
      case Type::sine: {
        const double s = amplitude * std::sin(2 * std::numbers::pi * t / period);
        return {s * direction[0], s * direction[1], s * direction[2]};
      }
    }
    return {0, 0, 0};
  }

  /// Displacement from the initial position at time t (exact integral of velocity_at).
  std::array<double, 3> displacement_at(double t) const {
    double s = 0;
    switch (type) {
      case Type::fixed:
        return {0, 0, 0};
      case Type::constant_velocity:
        return {velocity[0] * t, velocity[1] * t, velocity[2] * t};
      case Type::half_sine: {
        const double tc = std::min(std::max(t, 0.0), period / 2);
        s = amplitude * period / (2 * std::numbers::pi) * (1 - std::cos(2 * std::numbers::pi * tc / period));
        break;
      }
      case Type::sine:
        s = amplitude * period / (2 * std::numbers::pi) * (1 - std::cos(2 * std::numbers::pi * t / period));
        break;
    }
    return {s * direction[0], s * direction[1], s * direction[2]};
  }
};

}  // namespace basalt::solver
