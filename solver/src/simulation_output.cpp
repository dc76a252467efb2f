// Output of a run (OutputSink): field-saver partial sums from every compute rank, the decomposition's
// layout for checkpoints, the frame timing report. The run loop that writes frames is simulation_step.cpp.
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <limits>

#include "basalt/solver/core/errors.hpp"
#include "basalt/solver/core/stop_request.hpp"
#include "basalt/solver/integrate/integrators.hpp"
#include "basalt/solver/output/simulation_frame.hpp"
#include "basalt/solver/simulation.hpp"

namespace basalt::solver {

template <class Real>
bool Simulation<Real>::field_partials(const std::vector<double>& pe, std::vector<double>& local,
                                      std::vector<char>& due) const {
  local.clear();
  due.clear();
  bool any = false;
  for (const auto& f : scene_.fields) {
    const bool d = clock_.step() % f.every == 0;
    any = any || d;
    const std::size_t width = f.width();
    for (std::size_t c = 0; c < width; ++c) due.push_back(d);
    if (!d) {
      local.insert(local.end(), width, 0.0);
      continue;
    }
    switch (f.type) {
      case FieldSpec::Type::energy:
        local.push_back(term_value(static_cast<std::size_t>(forces_.ledger().find(f.term)), pe));
        break;
      case FieldSpec::Type::total_energy: {
        double e = 0;
        for (std::size_t t = 0; t < forces_.ledger().size(); ++t)
          if (forces_.ledger()[t].kind == Ledger::Kind::kinetic ||
              forces_.ledger()[t].kind == Ledger::Kind::potential)
            e += term_value(t, pe);
        local.push_back(e);
        break;
      }
      case FieldSpec::Type::bond_count:
        local.push_back(double(local_bond_count()));
        break;
      case FieldSpec::Type::rotational_kinetic_energy:
        local.push_back(rotational_energy(p_));
        break;
      case FieldSpec::Type::sliding_contacts: {
        std::size_t n = 0;
        for (const auto& c : forces_.computes()) n += c->sliding_contacts();
        local.push_back(double(n));
        break;
      }
      case FieldSpec::Type::runout: {
        // Collective (every rank computes its savers at the same steps); the value goes to rank 0's
        // partial, so the ranks' partials sum to it.
        const double r = runout(f);
        local.push_back(comm().rank() == 0 ? r : 0.0);
        break;
      }
      case FieldSpec::Type::wall_force: {
        const auto& walls = forces_.walls();
        std::size_t w = 0;
        while (w < walls.size() && walls.spec(w).name != f.wall) ++w;
        if (w < walls.size()) {
          local.insert(local.end(), walls.force(w).begin(), walls.force(w).end());
          break;
        }
        std::size_t m = 0;  // a mesh wall (the scene checked the name)
        while (walls.mesh_spec(m).name != f.wall) ++m;
        local.insert(local.end(), walls.mesh_force(m).begin(), walls.mesh_force(m).end());
        break;
      }
      case FieldSpec::Type::wall_position: {  // the same on every rank: rank 0's partial carries it
        const auto& walls = forces_.walls();
        std::size_t w = 0;
        while (w < walls.size() && walls.spec(w).name != f.wall) ++w;
        std::array<double, 3> x{0, 0, 0};
        if (w < walls.size()) {
          x = walls.point(w);
        } else {
          std::size_t m = 0;  // a mesh wall: where its rotation axis point has been carried
          while (walls.mesh_spec(m).name != f.wall) ++m;
          x = walls.mesh_axis_point(m);
        }
        for (std::size_t k = 0; k < 3; ++k) x[k] += origin_[k];  // absolute (mixed: out of the frame)
        if (comm().rank() != 0) x = {0, 0, 0};
        local.insert(local.end(), x.begin(), x.end());
        break;
      }
      case FieldSpec::Type::broken_bonds: {  // each break is recorded by one rank (bond drivers)
        std::array<double, 4> n{};
        for (const auto& b : broken_) n[std::min<std::size_t>(b.mode, 3)] += 1;
        local.insert(local.end(), n.begin(), n.end());
        break;
      }
      case FieldSpec::Type::mass_below: {  // owned particles' share; the sink sums the ranks
        double mass = 0;
        for (std::size_t i = 0; i < p_.n_owned; ++i)
          if (double(p_.z[i]) < f.z && p_.inv_mass[i] > 0) mass += 1.0 / double(p_.inv_mass[i]);
        local.push_back(mass);
        break;
      }
      case FieldSpec::Type::mean_vz_above: {
        // Collective: the count above z over all ranks, so that the ranks' partials sum to the mean
        // (0 when no particle is above z).
        double sum = 0, count = 0;
        for (std::size_t i = 0; i < p_.n_owned; ++i)
          if (double(p_.z[i]) > f.z && p_.inv_mass[i] > 0) {
            sum += double(p_.vz[i]);
            count += 1;
          }
        const double total = comm().size() > 1 ? comm().sum(count) : count;
        local.push_back(total > 0 ? sum / total : 0.0);
        break;
      }
    }
  }
  return any;
}

template <class Real>
double Simulation<Real>::runout(const FieldSpec& f) const {
  std::vector<double> s(p_.n_owned);
  for (std::size_t i = 0; i < p_.n_owned; ++i)
    s[i] = (double(p_.x[i]) - f.origin[0]) * f.direction[0] +
           (double(p_.y[i]) - f.origin[1]) * f.direction[1] +
           (double(p_.z[i]) - f.origin[2]) * f.direction[2];
  if (f.percentile >= 100) {
    double m = -std::numeric_limits<double>::infinity();
    for (double v : s) m = std::max(m, v);
    return comm().size() > 1 ? comm().max(m) : m;
  }
  auto all = comm().size() > 1 ? comm().all_gather(s) : std::move(s);
  if (all.empty()) return 0;
  // The value below which `percentile` % of the particles lie (nearest rank).
  const auto k = static_cast<std::size_t>(
      std::min<double>(double(all.size()) - 1, std::ceil(f.percentile / 100.0 * double(all.size())) - 1));
  std::nth_element(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(k), all.end());
  return all[k];
}

template <class Real>
std::optional<double> Simulation<Real>::saved_field(std::size_t column) const {
  return fields_.saved(column, clock_.step(), comm());
}

template <class Real>
RestartLayout Simulation<Real>::restart_layout() const {
  RestartLayout r;
  r.box_min = dec_->box_min();
  r.box_max = dec_->box_max();
  r.ghost_width = ghost_width_;
  r.contact_cutoff = contact_cutoff_;
  for (int d = 0; d < 3; ++d) r.cuts[static_cast<std::size_t>(d)] = dec_->cuts(d);
  r.origin = origin_;
  return r;
}

template <class Real>
void Simulation<Real>::report_frame_times(std::vector<double> seconds) const {
  // Benchmark aid (tools/bench): this compute rank's cost of handing frames to the output.
  const char* want = std::getenv("BASALT_FRAME_TIMES");
  if (want == nullptr || *want == '\0' || *want == '0' || seconds.empty()) return;
  std::sort(seconds.begin(), seconds.end());
  const double median = seconds.size() % 2
                            ? seconds[seconds.size() / 2]
                            : 0.5 * (seconds[seconds.size() / 2 - 1] + seconds[seconds.size() / 2]);
  fmt::print("frame times (rank {}): {} frames, median {:.3f} ms, min {:.3f} ms, max {:.3f} ms\n",
             comm().rank(), seconds.size(), 1e3 * median, 1e3 * seconds.front(), 1e3 * seconds.back());
}

#define BASALT_INSTANTIATE(R)                                                                   \
  template bool Simulation<R>::field_partials(const std::vector<double>&, std::vector<double>&, \
                                              std::vector<char>&) const;                        \
  template std::optional<double> Simulation<R>::saved_field(std::size_t) const;                 \
  template double Simulation<R>::runout(const FieldSpec&) const;                                \
  template RestartLayout Simulation<R>::restart_layout() const;                                 \
  template void Simulation<R>::report_frame_times(std::vector<double>) const;
BASALT_INSTANTIATE(double)
BASALT_INSTANTIATE(float)
#undef BASALT_INSTANTIATE

}  // namespace basalt::solver
