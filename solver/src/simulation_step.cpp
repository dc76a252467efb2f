// The step and the run loop, in one place. A step is, in this order:
//   1. drift       first half-kick (and a deferred second one), zeroed forces, drift    (VelocityVerlet)
//   2. walls       prescribed and servo walls to the step's end time
//   3. neighbours  a rebuild (skin exceeded, a bond broke, the balancer asks, particles enter or leave:
//                  simulation_flow.cpp) or the ghosts' new positions
//   4. forces      bonds, contacts, walls, body forces; fixed particles held; bond breaks recorded
//   5. kick        second half-kick, now or deferred to the next step's drift when nothing reads velocities
//   6. wall work   work done by the walls (energy ledger), servo walls steered by the summed force
//   7. observers   field savers, the energy guard
// The run loop repeats it and, after each step, writes the frames due, runs the caller's hooks, agrees
// with the other ranks on output errors and stop signals, and prints progress.
#include <fmt/format.h>

#include <algorithm>
#include <cstdio>
#include <limits>

#include "basalt/solver/core/errors.hpp"
#include "basalt/solver/core/stop_request.hpp"
#include "basalt/solver/output/simulation_frame.hpp"
#include "basalt/solver/simulation.hpp"

namespace basalt::solver {

template <class Real>
void Simulation<Real>::advance(bool may_defer) {
  const double moved2 = drift();
  move_walls(clock_.step() + 1);
  const bool in_flight = refresh_neighbours(moved2);
  clock_.tick();
  const auto& pe = step_forces(in_flight);
  second_kick(may_defer && !observed(clock_.step()) && !flow_.changed());
  wall_work();
  observe(pe);
}

template <class Real>
double Simulation<Real>::drift() {
  Stopwatch sw;
  const double moved2 = integrator_.first_half(p_);
  times_.integration += sw.lap();
  return moved2;
}

template <class Real>
void Simulation<Real>::move_walls(std::int64_t step) {
  if (forces_.walls().empty()) return;
  Stopwatch sw;
  forces_.walls().advance_servos(scene_.dt);
  forces_.walls().move_to(time_at(step));
  times_.communication += sw.lap();
}

template <class Real>
bool Simulation<Real>::refresh_neighbours(double moved2) {
  Stopwatch sw;
  const bool parallel = comm().size() > 1;
  // (the scene's string is compared once per balance_every steps, not at every step)
  const bool balance_due = parallel && clock_.step() > 0 && clock_.step() % scene_.balance_every == 0 &&
                           scene_.balance == "time" && !balancer_.paused() &&
                           balancer_.time_balance_due(balance_run());
  // Particles entering or leaving as this step begins (the scene's [[insert]], [[delete]]): at a rebuild.
  const bool flow =
      (!scene_.inserts.empty() || !scene_.deletes.empty()) && flow_.queue(scene_, clock_.step());
  double need =
      schedule_.need(std::max(moved2, forces_.walls().empty() ? 0.0 : forces_.walls().moved2_since_rebuild()),
                     balance_due || flow);
  if (parallel) need = comm().max(need);
  times_.communication += sw.lap();
  if (schedule_.exceeded(need)) {
    check_blowup();  // simulation_stability.cpp: stops a run that moved absurdly far in this step
    rebuild();       // times itself
    schedule_.set_last_step(clock_.step() +
                            1);  // the positions it used are those of the step being completed
    return false;
  }
  if (!parallel) return false;
  halo_->begin_update_ghosts(p_);
  times_.communication += sw.lap();
  return true;
}

template <class Real>
const std::vector<double>& Simulation<Real>::step_forces(bool in_flight) {
  Stopwatch sw;
  ghost_wait_ = 0;
  const auto& pe = guard_.energy_due(clock_.step()) || flow_.changed()
                       ? compute_forces<true>(in_flight, true)
                       : compute_forces<false>(in_flight, true);
  times_.forces += sw.lap() - ghost_wait_;
  times_.communication += ghost_wait_;
  return pe;
}

template <class Real>
void Simulation<Real>::second_kick(bool defer) {
  Stopwatch sw;
  integrator_.second_half(p_, defer, guard_.kinetic_due(clock_.step()));
  times_.integration += sw.lap();
}

template <class Real>
void Simulation<Real>::wall_work() {
  if (forces_.walls().empty()) return;
  Stopwatch sw;
  guard_.add_wall_work(forces_.walls().power(), scene_.dt);
  steer_servos();
  times_.output += sw.lap();
}

template <class Real>
void Simulation<Real>::observe(const std::vector<double>& pe) {
  Stopwatch sw;
  // No reduction here: the sink sums the ranks' partials (on an I/O rank, or reduced with Q = 0).
  fields_.observe(
      clock_.step(), clock_.time(), *output_,
      [&](std::vector<double>& local, std::vector<char>& due) { return field_partials(pe, local, due); });
  times_.output += sw.lap();
  if (flow_.changed()) rebase_ledger(pe);  // particles came or went: the ledger balances from here
  if (guard_.due(clock_.step())) guard_energy(pe);
}

template <class Real>
bool Simulation<Real>::observed(std::int64_t s) const {
  for (const auto& f : scene_.fields)
    if (s % f.every == 0) return true;
  return guard_.due(s);
}

template <class Real>
void Simulation<Real>::settle_kick() {
  integrator_.settle(p_);
}

namespace {

/// The progress line of a run (rank 0, unless quiet): at most one per progress_seconds, checked every 16
/// steps.
class ProgressLine {
 public:
  explicit ProgressLine(double every) : every_(every) {}
  /// After the done-th of `total` steps; true when a line is due (then seconds() is the run's time so far).
  bool due(std::int64_t done) {
    if ((done & 15) != 0) return false;
    elapsed_ += clock_.lap();
    if (elapsed_ - last_ < every_) return false;
    last_ = elapsed_;
    return true;
  }
  double seconds() const { return elapsed_; }

 private:
  double every_;
  Stopwatch clock_;
  double elapsed_ = 0, last_ = 0;
};

}  // namespace

template <class Real>
void Simulation<Real>::progress(std::int64_t done, std::int64_t total, double seconds) const {
  const double sps = done / std::max(seconds, 1e-9);
  fmt::print("step {:>8}/{}  {:8.1f} steps/s  {:6.2f} M particle-steps/s  ETA {:.1f} s\n", clock_.step(),
             clock_.step() + (total - done), sps, sps * double(n_global_) * 1e-6,
             (total - done) / std::max(sps, 1e-9));
  std::fflush(stdout);
}

template <class Real>
bool Simulation<Real>::hooks_due(std::span<const StepHook> hooks, std::int64_t s) {
  return std::any_of(hooks.begin(), hooks.end(),
                     [s](const StepHook& h) { return h.reads_velocities && s % h.every == 0; });
}

template <class Real>
void Simulation<Real>::write_frame(OutputSink& out, std::uint32_t kinds, std::vector<double>& seconds) {
  // No checkpoint or frame from a state with non-finite values or blown up (simulation_stability.cpp):
  // the last complete checkpoint stays the newest, a valid restart point.
  auto bad = check_frame_state();
  if (comm().size() > 1) bad = comm().agree_error(bad);
  if (bad)
    throw RunError(fmt::format("{}; the {} of step {} is not written (the checkpoints written before stay)",
                               *bad, (kinds & io::kFrameCheckpoint) ? "checkpoint" : "frame", clock_.step()));
  Stopwatch frame_clock;
  out.frame(SimulationFrame<Real>(*this, kinds));
  seconds.push_back(frame_clock.lap());
  if (kinds & io::kFrameCheckpoint) checkpoint_step_ = clock_.step();
}

template <class Real>
void Simulation<Real>::checkpoint_now(OutputSink& out) {
  if (checkpoint_step_ == clock_.step()) return;
  settle_kick();
  std::vector<double> seconds;
  write_frame(out, io::kFrameCheckpoint, seconds);
  bool reported = false;
  agree_on_output(out, reported);
}

template <class Real>
bool Simulation<Real>::agree_on_output(OutputSink& out, bool& reported) {
  // A stop asked by a signal (SIGTERM, SIGINT) is agreed here too: every rank stops at this step, and the
  // rows and frames handed over so far are written before basalt-run exits.
  const bool parallel = comm().size() > 1;
  int sig = stop_signal;
  if (parallel) sig = static_cast<int>(comm().max(static_cast<double>(sig)));
  if (sig != 0)
    throw StopRequested(fmt::format("stopped by {} at step {}: the output due up to this step is written; "
                                    "--restart from the last checkpoint continues the run",
                                    signal_name(sig), clock_.step()),
                        sig, clock_.step());
  auto error = out.poll();
  if (parallel) error = comm().agree_error(error);
  if (!error || reported) return true;
  if (!out.continue_on_error())
    throw RunError(fmt::format("output failed at step {}: {}", clock_.step(), *error));
  if (comm().rank() == 0)
    fmt::print(
        stderr,
        "basalt-run: warning: output failed at step {} (on_error = \"continue\"; the run goes on without "
        "it): {}\n",
        clock_.step(), *error);
  reported = true;
  return true;
}

template <class Real>
std::int64_t Simulation<Real>::run(std::int64_t steps, OutputSink& out, std::span<const StepHook> hooks) {
  if (steps < 0) steps = scene_.steps;
  output_ = &out;
  struct Reset {
    OutputSink*& p;
    ~Reset() { p = nullptr; }
  } reset{output_};
  out.begin(field_columns(scene_));
  ProgressLine line(options_.progress_seconds);
  const bool show = !options_.quiet && comm().rank() == 0;
  bool reported = false;
  std::vector<double> frame_seconds;  // pack + submit of each frame (BASALT_FRAME_TIMES=1 prints them)
  // A second half-kick deferred by the last step is made on every way out (an error, a stop signal).
  const SettleOnExit settle{*this};
  std::int64_t k = 0;
  for (bool go = true; go && k < steps;) {
    // Frames and hooks read the velocities: the step before one makes its second half-kick.
    advance(k + 1 < steps && out.frame_kinds(clock_.step() + 1) == 0 && !hooks_due(hooks, clock_.step() + 1));
    ++k;
    Stopwatch sw;
    const std::uint32_t kinds = out.frame_kinds(clock_.step());
    if (kinds != 0) write_frame(out, kinds, frame_seconds);
    for (const auto& h : hooks)
      if (clock_.step() % h.every == 0 && !h.call(clock_.step())) go = false;
    // Completed sends and errors from the I/O ranks are picked up at output steps and every 32 steps,
    // where the ranks also agree on errors so that all stop at the same step (one small reduction, not
    // one per step; polling every step costs more than it gains: MPI's progress engine yields the core
    // when idle).
    if (kinds != 0 || (k & 31) == 0 || k == steps || !go) agree_on_output(out, reported);
    times_.output += sw.lap();
    if (show && line.due(k)) progress(k, steps, line.seconds());
  }
  out.flush();
  report_frame_times(frame_seconds);
  return k;
}

template <class Real>
void Simulation<Real>::run(std::int64_t steps, FieldSink* sink) {
  run(steps, fields_.rows(comm(), sink));
}

template <class Real>
void Simulation<Real>::step(FieldSink* sink) {
  output_ = &fields_.rows(comm(), sink);
  struct Reset {
    OutputSink*& p;
    ~Reset() { p = nullptr; }
  } reset{output_};
  advance(false);
}

template <class Real>
void Simulation<Real>::flush_fields(FieldSink* sink) {
  fields_.rows(comm(), sink).finish();
}

template <class Real>
void Simulation<Real>::stop(const std::string& message) {
  // Collective (every caller has agreed on the error): deliver what output is held back, then stop.
  if (output_)
    output_->deliver_pending();
  else
    fields_.deliver_pending();
  throw RunError(message);
}

#define BASALT_INSTANTIATE(R)                                                                     \
  template void Simulation<R>::advance(bool);                                                     \
  template double Simulation<R>::drift();                                                         \
  template void Simulation<R>::move_walls(std::int64_t);                                          \
  template bool Simulation<R>::refresh_neighbours(double);                                        \
  template const std::vector<double>& Simulation<R>::step_forces(bool);                           \
  template void Simulation<R>::second_kick(bool);                                                 \
  template void Simulation<R>::wall_work();                                                       \
  template void Simulation<R>::observe(const std::vector<double>&);                               \
  template bool Simulation<R>::observed(std::int64_t) const;                                      \
  template void Simulation<R>::settle_kick();                                                     \
  template void Simulation<R>::progress(std::int64_t, std::int64_t, double) const;                \
  template bool Simulation<R>::hooks_due(std::span<const StepHook>, std::int64_t);                \
  template void Simulation<R>::write_frame(OutputSink&, std::uint32_t, std::vector<double>&);     \
  template void Simulation<R>::checkpoint_now(OutputSink&);                                       \
  template bool Simulation<R>::agree_on_output(OutputSink&, bool&);                               \
  template std::int64_t Simulation<R>::run(std::int64_t, OutputSink&, std::span<const StepHook>); \
  template void Simulation<R>::run(std::int64_t, FieldSink*);                                     \
  template void Simulation<R>::step(FieldSink*);                                                  \
  template void Simulation<R>::flush_fields(FieldSink*);                                          \
  template void Simulation<R>::stop(const std::string&);
BASALT_INSTANTIATE(double)
BASALT_INSTANTIATE(float)
#undef BASALT_INSTANTIATE

}  // namespace basalt::solver
