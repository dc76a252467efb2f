#pragma once
// The run's clock: the step last completed, its time, the time step, and the time of any step. The time
// counts from the last change of dt (time_at(s) = base time + (s - base step) x dt; a step x dt clock
// would jump when dt changes, and the walls' motions with it). With no change of dt the base is (0, 0),
// which gives step x dt to the bit. Owned by Simulation; free of MPI.
#include <cstdint>

namespace basalt::solver {

class Clock {
 public:
  /// The step last completed (0 before the first).
  std::int64_t step() const { return step_; }
  /// Its time.
  double time() const { return time_; }
  /// The time step.
  double dt() const { return dt_; }
  /// The time of step s at the current dt.
  double time_at(std::int64_t s) const { return time_base_ + double(s - step_base_) * dt_; }

  /// One more step completed: its number and time.
  void tick() {
    ++step_;
    time_ = time_at(step_);
  }
  /// The time step from now on (Simulation::apply_dt, the one place it changes).
  void set_dt(double dt) { dt_ = dt; }
  /// The time counts on from the current step and time (before a new dt: set_dt).
  void rebase() {
    time_base_ = time_;
    step_base_ = step_;
  }
  /// The step and time the time counts from (a scene's clock base: a staged run's dt change replayed).
  void set_base(std::int64_t step, double time) {
    step_base_ = step;
    time_base_ = time;
  }
  /// The current step and time (a restart: the checkpoint's).
  void set(std::int64_t step, double time) {
    step_ = step;
    time_ = time;
  }
  /// The current step alone, the time kept (a restart replaying the last rebuild at its step).
  void set_step(std::int64_t step) { step_ = step; }

 private:
  std::int64_t step_ = 0;
  double time_ = 0;
  double dt_ = 0;
  double time_base_ = 0;        ///< the time at the last change of dt (or the scene's clock base)
  std::int64_t step_base_ = 0;  ///< the step at the last change of dt
};

}  // namespace basalt::solver
