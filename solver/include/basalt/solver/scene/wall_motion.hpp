#pragma once
// Prescribed motion of a planar wall: position offset and velocity as closed-form functions of time.
//   fixed:             u(t) = 0
//   constant_velocity: v(t) = v
//   half_sine:         v(t) = A sin(2 pi t / T) e for 0 <= t <= T/2, then 0   (the paper's pulse)
//   sine:              v(t) = A sin(2 pi t / T) e
//   ramp:              v(t) = 0 before t0, V (t - t0) / T_r while ramping, then V (ESyS's WallLoader
//                      ramps linearly over rampTime steps; docs/scenes.md gives the exact relation)
//   servo:             no closed form: Walls moves the wall from the force on it (ServoControl)
// e is the direction (default: the wall normal), A the amplitude (length/time), T the period.
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

namespace basalt::solver {

/// A servo wall's control (motion type servo): each step the wall moves along its normal n at
///   v = clamp(gain (F_target - F_n), -max_speed, max_speed),
/// F_n = -F_wall . n the compressive force the particles put on it (summed over every rank at the end of
/// the previous step), so it closes in while the force is below the target and backs off above it.
/// gain is in velocity per force; the loop is stable while gain k dt << 1 (k the sample's stiffness
/// seen by the wall): docs/scenes.md.
struct ServoControl {
  double target_force = 0;  ///< F_target (force); target_stress x area when given so
  double gain = 0;          ///< length / (time force)
  double max_speed = 0;     ///< length / time
  /// The wall's speed along its normal for the next step, from the compressive force on it now.
  double speed(double normal_force) const {
    const double v = gain * (target_force - normal_force);
    return std::clamp(v, -max_speed, max_speed);
  }
};

struct WallMotion {
  enum class Type { fixed, constant_velocity, half_sine, sine, ramp, servo };
  Type type = Type::fixed;
  std::array<double, 3> direction{0, 0, 1};
  std::array<double, 3> velocity{0, 0, 0};  ///< constant_velocity and ramp (the final velocity)
  double amplitude = 0;
  double period = 1;
  double ramp_time = 0;   ///< ramp: T_r, the time from rest to the full velocity (0: a step)
  double start_time = 0;  ///< ramp: t0, the wall rests before it (>= -ramp_time: may precede the start)
  ServoControl servo;     ///< servo only
  /// When its clock starts: a motion set mid-run (Walls::set_motion) runs on t - origin_time (0 for the
  /// scene's: t - 0 is t to the bit).
  double origin_time = 0;

  /// ramp: the fraction of the full velocity at time t, and its integral from 0 to t.
  double ramp_fraction(double t) const {
    const double s = t - start_time;
    if (s <= 0) return 0;
    return s < ramp_time ? s / ramp_time : 1;
  }
  double ramp_integral(double t) const {
    const double s = t - start_time;
    if (s <= 0) return 0;
    return s < ramp_time ? s * s / (2 * ramp_time) : s - ramp_time / 2;
  }

  bool moves() const { return type != Type::fixed; }

  std::array<double, 3> velocity_at(double t) const {
    t -= origin_time;
    switch (type) {
      case Type::fixed:
      case Type::servo:
        return {0, 0, 0};
      case Type::constant_velocity:
        return velocity;
      case Type::ramp: {
        const double f = ramp_fraction(t);
        return {f * velocity[0], f * velocity[1], f * velocity[2]};
      }
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
    t -= origin_time;
    double s = 0;
    switch (type) {
      case Type::fixed:
      case Type::servo:
        return {0, 0, 0};
      case Type::constant_velocity:
        return {velocity[0] * t, velocity[1] * t, velocity[2] * t};
      case Type::ramp: {
        const double f = ramp_integral(t);
        return {f * velocity[0], f * velocity[1], f * velocity[2]};
      }
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
