// The run loop with output (OutputSink): field-saver partial sums from every compute rank, frames
// (checkpoints, VTK) packed from this rank's particles (with the positions at the last rebuild,
// which a restart replays), output errors agreed on by all ranks.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>

#include "basalt/solver/core/errors.hpp"
#include "basalt/solver/simulation.hpp"

namespace basalt::solver {

template <class Real>
bool Simulation<Real>::field_partials(const std::array<double, 3>& pe, std::vector<double>& local,
                                      std::vector<char>& due) const {
  local.clear();
  due.clear();
  bool any = false;
  for (const auto& f : scene_.fields) {
    const bool d = step_ % f.every == 0;
    any = any || d;
    const std::size_t width = f.type == FieldSpec::Type::wall_force ? 3 : 1;
    for (std::size_t c = 0; c < width; ++c) due.push_back(d);
    if (!d) {
      local.insert(local.end(), width, 0.0);
      continue;
    }
    switch (f.type) {
      case FieldSpec::Type::kinetic_energy:
        local.push_back(kinetic_energy_local());
        break;
      case FieldSpec::Type::bond_potential_energy:
        local.push_back(pe[0]);
        break;
      case FieldSpec::Type::contact_potential_energy:
        local.push_back(pe[1]);
        break;
      case FieldSpec::Type::wall_potential_energy:
        local.push_back(pe[2]);
        break;
      case FieldSpec::Type::bond_count:
        local.push_back(double(BondDriver<Real, LinearBond>::count(p_, bonds_)));
        break;
      case FieldSpec::Type::wall_force: {
        std::size_t w = 0;
        while (wall_driver_.spec(w).name != f.wall) ++w;
        const auto& fw = wall_driver_.force(w);
        local.insert(local.end(), fw.begin(), fw.end());
        break;
      }
    }
  }
  return any;
}

template <class Real>
void Simulation<Real>::output_fields(const std::array<double, 3>& pe) {
  // No reduction here: the sink sums the ranks' partials (on an I/O rank, or reduced with Q = 0).
  thread_local std::vector<double> local;
  thread_local std::vector<char> due;
  if (!field_partials(pe, local, due)) return;
  for (std::size_t c = 0; c < local.size(); ++c)
    if (!due[c]) local[c] = std::numeric_limits<double>::quiet_NaN();
  output_->fields(step_, time_, local);
}

template <class Real>
void Simulation<Real>::pack_frame(io::FramePiece& piece, std::uint32_t kinds) const {
  piece.kinds = kinds;
  piece.step = step_;
  piece.time = time_;
  piece.dt = scene_.dt;
  piece.source_rank = comm().rank();
  const std::size_t n = p_.n_owned;
  piece.id.assign(p_.id.begin(), p_.id.begin() + static_cast<std::ptrdiff_t>(n));
  piece.tag.assign(p_.tag.begin(), p_.tag.begin() + static_cast<std::ptrdiff_t>(n));
  piece.position.resize(n);
  piece.velocity.resize(n);
  piece.radius.resize(n);
  piece.mass.resize(n);
  piece.inv_mass.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    piece.position[i] = {double(p_.x[i]), double(p_.y[i]), double(p_.z[i])};
    piece.velocity[i] = {double(p_.vx[i]), double(p_.vy[i]), double(p_.vz[i])};
    piece.radius[i] = double(p_.radius[i]);
    piece.inv_mass[i] = double(p_.inv_mass[i]);
    piece.mass[i] = 1.0 / piece.inv_mass[i];
  }
  // Owned particles now are those of the last rebuild (only a rebuild migrates or reorders them).
  if ((kinds & io::kFrameCheckpoint) && xr_.size() == n) {
    piece.position_at_rebuild.resize(n);
    for (std::size_t i = 0; i < n; ++i)
      piece.position_at_rebuild[i] = {double(xr_[i]), double(yr_[i]), double(zr_[i])};
    piece.rebuild_step = rebuild_step_;
    piece.rebuild_pending = bond_broke_ ? 1 : 0;
  } else {
    piece.position_at_rebuild.clear();
  }
  // Bonds, each exactly once across ranks: both ends owned -> this rank; one end a ghost -> the
  // rank owning the lower id. The bond tag carries the solver's interaction group (restart).
  piece.bonds.clear();
  piece.bond_rest_length.clear();
  piece.bond_broken.clear();
  for (std::size_t k = 0; k < bonds_.size(); ++k) {
    if (k >= bonds_.n_both_owned) {
      const auto i = static_cast<std::size_t>(bonds_.ia[k]), j = static_cast<std::size_t>(bonds_.ib[k]);
      if (!(p_.id[i] < p_.id[j])) continue;
    }
    piece.bonds.push_back({bonds_.a[k], bonds_.b[k], std::int32_t(bonds_.group_of(k))});
    piece.bond_rest_length.push_back(double(bonds_.r0[k]));
    piece.bond_broken.push_back(0);
  }
  // Broken bonds: the bond driver records each once across ranks (same lower-id rule).
  for (const auto& b : broken_) {
    piece.bonds.push_back({b.a, b.b, 0});
    piece.bond_rest_length.push_back(b.rest_length);
    piece.bond_broken.push_back(1);
  }
  // Walls: global; the force is summed over the ranks (collective), rank 0 carries them.
  piece.walls.clear();
  if (wall_driver_.size() > 0) {
    std::vector<double> f;
    for (std::size_t w = 0; w < wall_driver_.size(); ++w)
      f.insert(f.end(), wall_driver_.force(w).begin(), wall_driver_.force(w).end());
    if (comm().size() > 1) comm().sum_all(f);
    if (comm().rank() == 0)
      for (std::size_t w = 0; w < wall_driver_.size(); ++w) {
        const auto& s = wall_driver_.spec(w);
        const auto v = s.motion.velocity_at(time_);
        piece.walls.push_back({s.name,
                               wall_driver_.point(w),
                               s.normal,
                               {v[0], v[1], v[2]},
                               {f[3 * w], f[3 * w + 1], f[3 * w + 2]}});
      }
  }
}

template <class Real>
RestartLayout Simulation<Real>::restart_layout() const {
  RestartLayout r;
  r.box_min = dec_->box_min();
  r.box_max = dec_->box_max();
  r.ghost_width = ghost_width_;
  r.contact_cutoff = contact_cutoff_;
  return r;
}

template <class Real>
void Simulation<Real>::run(std::int64_t steps, OutputSink& out) {
  if (steps < 0) steps = scene_.steps;
  output_ = &out;
  struct Reset {
    OutputSink*& p;
    ~Reset() { p = nullptr; }
  } reset{output_};
  out.begin(field_columns(scene_));
  Stopwatch clock;
  double elapsed = 0, last = 0;
  const bool show = !options_.quiet && comm().rank() == 0;
  const bool parallel = comm().size() > 1;
  bool reported = false;
  io::FramePiece piece;
  std::vector<double> frame_seconds;  // pack + submit of each frame (BASALT_FRAME_TIMES=1 prints them)
  for (std::int64_t k = 0; k < steps; ++k) {
    step(nullptr);
    Stopwatch sw;
    const std::uint32_t kinds = out.frame_kinds(step_);
    if (kinds != 0) {
      Stopwatch frame_clock;
      pack_frame(piece, kinds);
      out.frame(piece);
      frame_seconds.push_back(frame_clock.lap());
    }
    // Completed sends and errors from the I/O ranks are picked up at output steps and every 32 steps,
    // where the ranks also agree on errors so that all stop at the same step (one small reduction,
    // not one per step; polling every step costs more than it gains: MPI's progress engine yields
    // the core when idle).
    if (kinds != 0 || (k & 31) == 31 || k + 1 == steps) {
      auto error = out.poll();
      if (parallel) error = comm().agree_error(error);
      if (error && !reported) {
        if (!out.continue_on_error())
          throw RunError(fmt::format("output failed at step {}: {}", step_, *error));
        if (comm().rank() == 0)
          fmt::print(stderr,
                     "basalt-run: warning: output failed at step {} (on_error = \"continue\"; the run goes "
                     "on without it): {}\n",
                     step_, *error);
        reported = true;
      }
    }
    times_.output += sw.lap();
    if (show && (k & 15) == 15) {
      elapsed += clock.lap();
      if (elapsed - last >= options_.progress_seconds) {
        progress(k + 1, steps, elapsed);
        last = elapsed;
      }
    }
  }
  out.flush();
  report_frame_times(frame_seconds);
}

template <class Real>
void Simulation<Real>::report_frame_times(std::vector<double> seconds) const {
  // Benchmark aid (tools/bench): this compute rank's cost of handing frames to the output.
  const char* want = std::getenv("BASALT_FRAME_TIMES");
  if (want == nullptr || *want == '\0' || *want == '0' || seconds.empty()) return;
  std::sort(seconds.begin(), seconds.end());
  const double median = seconds.size() % 2 ? seconds[seconds.size() / 2]
                                           : 0.5 * (seconds[seconds.size() / 2 - 1] + seconds[seconds.size() / 2]);
  fmt::print("frame times (rank {}): {} frames, median {:.3f} ms, min {:.3f} ms, max {:.3f} ms\n", comm().rank(),
             seconds.size(), 1e3 * median, 1e3 * seconds.front(), 1e3 * seconds.back());
}

#define BASALT_INSTANTIATE(R)                                                                     \
  template bool Simulation<R>::field_partials(const std::array<double, 3>&, std::vector<double>&, \
                                              std::vector<char>&) const;                          \
  template void Simulation<R>::output_fields(const std::array<double, 3>&);                       \
  template void Simulation<R>::pack_frame(io::FramePiece&, std::uint32_t) const;                  \
  template RestartLayout Simulation<R>::restart_layout() const;                                   \
  template void Simulation<R>::report_frame_times(std::vector<double>) const;                     \
  template void Simulation<R>::run(std::int64_t, OutputSink&);
BASALT_INSTANTIATE(double)
BASALT_INSTANTIATE(float)
#undef BASALT_INSTANTIATE

}  // namespace basalt::solver
