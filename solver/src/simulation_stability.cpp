// Numerical stability (docs/stability.md): the critical time step of the network of bonds, contacts
// and walls (a bound and power iterations, basalt/solver/stability/critical_step.hpp), the time step
// chosen as a fraction of it (run.dt_fraction), the refusal of a dt above it unless forced, and the
// blow-up check that stops a run before absurd values reach a field saver or a checkpoint.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "basalt/solver/core/errors.hpp"
#include "basalt/solver/simulation.hpp"
#include "basalt/solver/stability/critical_step.hpp"

namespace basalt::solver {

template <class Real>
void Simulation<Real>::check_stability(const io::Geometry& g) {
  // What the geometry alone tells: the smallest mass and radius, and the former one-spring estimate
  // 2 sqrt(m_min / k_max) (printed for comparison). The network's estimate needs the lists:
  // estimate_critical_step(), after the first rebuild.
  double m_min = std::numeric_limits<double>::infinity(), rmax = 0,
         rmin = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < g.size(); ++i) {
    const double m =
        g.has_mass() ? g.mass[i] : scene_.density * 4.0 / 3.0 * std::numbers::pi * std::pow(g.radius[i], 3);
    m_min = std::min(m_min, m);
    rmax = std::max(rmax, g.radius[i]);
    rmin = std::min(rmin, g.radius[i]);
  }
  stability_.m_min = m_min;
  stability_.k_max = forces_.max_stiffness(rmax);
  stability_.rmin = rmin;
  stability_.dt_pair = stability::critical_step(stability_.k_max / m_min);
  // A contact that forms later, between two of the lightest particles (omega^2 = 2 k / m_min) or one
  // and a wall (k / m_min): the network at the start does not have it.
  double future2 = 0;
  for (const auto& c : forces_.computes()) {
    if (c->kind() == ModelKind::pair) future2 = std::max(future2, 2 * c->max_stiffness(rmax) / m_min);
    if (c->kind() == ModelKind::wall) future2 = std::max(future2, c->max_stiffness(rmax) / m_min);
  }
  stability_.dt_contact = stability::critical_step(future2);
}

template <class Real>
void Simulation<Real>::estimate_critical_step(bool fresh) {
  auto& st = stability_;
  const std::size_t n = p_.n_owned;
  // The stiffness of each kind for radius r: the largest of the scene's models of that kind (exact
  // with one group per kind; a bound otherwise).
  std::vector<const ForceCompute<Real>*> of_kind[3];
  for (const auto& c : forces_.computes())
    if (c->kind() == ModelKind::bond || c->kind() == ModelKind::pair || c->kind() == ModelKind::wall)
      of_kind[c->kind() == ModelKind::bond ? 0 : c->kind() == ModelKind::pair ? 1 : 2].push_back(c.get());
  const auto k_of = [&](int kind, double r) {
    double k = 0;
    for (const auto* c : of_kind[kind]) k = std::max(k, c->max_stiffness(r));
    return k;
  };

  // The bound: per owned particle 2 sum of its springs to particles + sum of its walls' springs.
  std::vector<double> ks(n, 0.0);
  for (std::size_t b = 0; b < bonds_.size(); ++b) {
    const auto i = static_cast<std::size_t>(bonds_.ia[b]), j = static_cast<std::size_t>(bonds_.ib[b]);
    const double k = 2 * k_of(0, std::max(double(p_.radius[i]), double(p_.radius[j])));
    ks[i] += k;
    if (j < n) ks[j] += k;
  }
  const auto touching = [&](std::size_t i, std::size_t j) {
    const double dx = double(p_.x[i]) - double(p_.x[j]), dy = double(p_.y[i]) - double(p_.y[j]),
                 dz = double(p_.z[i]) - double(p_.z[j]), rs = double(p_.radius[i]) + double(p_.radius[j]);
    return dx * dx + dy * dy + dz * dz < rs * rs;
  };
  for (const PairList* list : {&forces_.own_pairs(), &forces_.ghost_pairs()}) {
    if (list->offset.size() < 2) continue;
    for (std::size_t i = 0; i + 1 < list->offset.size() && i < n; ++i)
      for (auto q = list->offset[i]; q < list->offset[i + 1]; ++q) {
        const auto j = static_cast<std::size_t>(list->neigh[q]);
        if (!touching(i, j)) continue;
        const double k = 2 * k_of(1, std::max(double(p_.radius[i]), double(p_.radius[j])));
        ks[i] += k;
        if (j < n) ks[j] += k;
      }
  }
  const auto& walls = forces_.walls();
  for (std::size_t w = 0; w < walls.size(); ++w) {
    const auto& nrm = walls.spec(w).normal;
    const auto& pt = walls.point(w);
    for (const auto ci : walls.candidates(w)) {
      const auto i = static_cast<std::size_t>(ci);
      const double d = (double(p_.x[i]) - pt[0]) * nrm[0] + (double(p_.y[i]) - pt[1]) * nrm[1] +
                       (double(p_.z[i]) - pt[2]) * nrm[2];
      if (d < double(p_.radius[i])) ks[i] += k_of(2, double(p_.radius[i]));
    }
  }
  double bound2 = 0;
  for (std::size_t i = 0; i < n; ++i) bound2 = std::max(bound2, ks[i] * double(p_.inv_mass[i]));
  bound2 = comm().max(bound2);
  std::vector<double>().swap(ks);
  st.dt_bound = stability::critical_step(bound2);

  // Power iterations on M^-1 K: K v = (F(x) - F(x + e v)) / e from the force field itself. The
  // products need the ghosts' perturbed positions: a ghost update per iteration, as in a step.
  double lambda = 0;
  st.iterations = 0;
  if (bound2 > 0) {
    const bool parallel = comm().size() > 1;
    const std::vector<Real> x0(p_.x.begin(), p_.x.begin() + long(n)),
        y0(p_.y.begin(), p_.y.begin() + long(n)), z0(p_.z.begin(), p_.z.begin() + long(n));
    // Bonds already beyond their break strain break here, as in the first force computation without
    // the estimate; the perturbed ones must not. The estimate leaves the bonds as it found them: the
    // caller's force computation breaks those bonds (a restart at the step they broke replays exactly
    // that), and a model whose breaking bond still acts in that step (rot_bond) applies its force then.
    const bool breakable = forces_.bonds_can_break();
    const Bonds<Real> bonds_at_start = breakable ? bonds_ : Bonds<Real>{};
    const std::vector<std::int32_t> damage_at_start =
        breakable ? p_.bonds_broken : std::vector<std::int32_t>{};
    const std::size_t broken_at_start = broken_.size();
    const bool bond_broke_at_start = bond_broke_;
    compute_forces<false>();
    const std::size_t broken_before = broken_.size();
    const std::vector<double> f0x(p_.fx.begin(), p_.fx.begin() + long(n)),
        f0y(p_.fy.begin(), p_.fy.begin() + long(n)), f0z(p_.fz.begin(), p_.fz.begin() + long(n));
    std::vector<double> vx(n), vy(n), vz(n);
    for (std::size_t i = 0; i < n; ++i) {
      vx[i] = stability::start_component(p_.id[i], 0);
      vy[i] = stability::start_component(p_.id[i], 1);
      vz[i] = stability::start_component(p_.id[i], 2);
    }
    const double delta = stability::perturbation<Real>() * st.rmin;
    std::vector<double> sums(2);
    for (int it = 0; it < stability::kMaxIterations; ++it) {
      double vmax = 0;
      for (std::size_t i = 0; i < n; ++i)
        vmax = std::max({vmax, std::abs(vx[i]), std::abs(vy[i]), std::abs(vz[i])});
      vmax = comm().max(vmax);
      if (!(vmax > 0) || !std::isfinite(vmax)) break;
      for (std::size_t i = 0; i < n; ++i) {  // |v| <= 1, the perturbation at most delta
        vx[i] /= vmax;
        vy[i] /= vmax;
        vz[i] /= vmax;
        p_.x[i] = Real(double(x0[i]) + delta * vx[i]);
        p_.y[i] = Real(double(y0[i]) + delta * vy[i]);
        p_.z[i] = Real(double(z0[i]) + delta * vz[i]);
      }
      if (parallel) halo_->update_ghosts(p_);
      compute_forces<false>();
      sums[0] = sums[1] = 0;
      for (std::size_t i = 0; i < n; ++i) {
        // The perturbation actually applied (rounded to Real) and K times it.
        const double ux = (double(p_.x[i]) - double(x0[i])) / delta,
                     uy = (double(p_.y[i]) - double(y0[i])) / delta,
                     uz = (double(p_.z[i]) - double(z0[i])) / delta;
        const double wx = (f0x[i] - double(p_.fx[i])) / delta, wy = (f0y[i] - double(p_.fy[i])) / delta,
                     wz = (f0z[i] - double(p_.fz[i])) / delta;
        const double im = double(p_.inv_mass[i]);
        sums[0] += ux * wx + uy * wy + uz * wz;
        sums[1] += (ux * ux + uy * uy + uz * uz) / im;
        vx[i] = wx * im;
        vy[i] = wy * im;
        vz[i] = wz * im;
      }
      comm().sum_all(sums);
      ++st.iterations;
      if (!(sums[1] > 0)) break;
      const double rq = sums[0] / sums[1];
      const bool converged = it > 2 && std::abs(rq - lambda) <= stability::kTolerance * rq;
      lambda = std::max(lambda, rq);
      if (converged) break;
    }
    // Back to the positions of the start (the caller computes the forces again).
    std::copy(x0.begin(), x0.end(), p_.x.begin());
    std::copy(y0.begin(), y0.end(), p_.y.begin());
    std::copy(z0.begin(), z0.end(), p_.z.begin());
    if (parallel) halo_->update_ghosts(p_);
    if (broken_.size() != broken_before)
      throw InputError(fmt::format(
          "the critical-step estimate broke {} bond(s) by perturbing positions by {:.3g}: bonds this close "
          "to breaking at the start are not supported",
          broken_.size() - broken_before, delta));
    if (breakable) {
      bonds_ = bonds_at_start;
      p_.bonds_broken = damage_at_start;
      broken_.erase(broken_.begin() + static_cast<std::ptrdiff_t>(broken_at_start), broken_.end());
      bond_broke_ = bond_broke_at_start;
    }
  }
  st.dt_power = stability::critical_step(lambda);
  // The power iterations approach omega_max from below (2 / omega_power >= the true step, by a few
  // per cent at most once converged, docs/stability.md); the bound is safe but often ~2x too strict.
  // Contacts that do not exist yet count too (particles that start apart and collide later).
  st.dt_critical = std::min(lambda > 0 ? st.dt_power : st.dt_bound, st.dt_contact);
  if (!std::isfinite(st.dt_critical)) st.dt_critical = 0;  // no stiffness: nothing to check

  st.dt_fraction = scene_.dt_fraction;
  if (fresh && scene_.dt_fraction > 0) {
    if (!(st.dt_critical > 0))
      throw InputError(
          "run.dt_fraction: the scene has no stiffness (no bonds, contacts or walls touching particles), so "
          "there is no critical step to take a fraction of: give run.dt instead");
    scene_.dt = scene_.dt_fraction * st.dt_critical;
    const bool se = scene_.integrator == Integrator::symplectic_euler;
    kick1_ = Real(se ? scene_.dt : scene_.dt / 2);
    kick2_ = Real(se ? 0.0 : scene_.dt / 2);
  }
  if (!(st.dt_critical > 0)) return;
  st.fraction = scene_.dt / st.dt_critical;
  st.warn =
      st.fraction > scene_.dt_safety && !(scene_.dt_fraction > 0 && st.fraction <= 1);  // chosen knowingly
  if (st.fraction > 1 && !(scene_.force_dt || options_.force_dt))
    throw InputError(fmt::format(
        "{} = {:.6g} is {:.3g} times the critical time step {:.6g} (2 / omega_max of the network, {} power "
        "iterations, {:.6g}; the bound gives {:.6g}; one new contact of the lightest particle {:.6g}): the "
        "run "
        "would be unstable. Lower dt (a safe choice is <= {} x "
        "critical, e.g. run.dt_fraction = {}), or set run.force_dt = true / --force-dt to run anyway",
        scene_.dt_fraction > 0 ? fmt::format("dt (run.dt_fraction = {})", scene_.dt_fraction)
                               : std::string("run.dt"),
        scene_.dt, st.fraction, st.dt_critical, st.iterations, st.dt_power, st.dt_bound, st.dt_contact,
        scene_.dt_safety, scene_.dt_safety));
}

template <class Real>
void Simulation<Real>::check_blowup() {
  // Called before a rebuild, when some particle (or wall) moved more than skin/2 since the last one.
  // Moving farther than skin/2 + kBlowupRadii rmin since then means moving more than kBlowupRadii rmin
  // in this one step: no DEM contact is resolved that way, the run has blown up (or a position went
  // non-finite). The positions at the last rebuild are p_.x0 (float).
  const double limit = 0.5 * scene_.skin + stability::kBlowupRadii * stability_.rmin;
  double worst = 0;
  std::size_t wi = 0;
  for (std::size_t i = 0; i < p_.n_owned; ++i) {
    const double dx = double(p_.x[i]) - double(p_.x0[i]), dy = double(p_.y[i]) - double(p_.y0[i]),
                 dz = double(p_.z[i]) - double(p_.z0[i]);
    const double d2 = dx * dx + dy * dy + dz * dz;
    if (!(d2 <= worst)) {  // NaN wins
      worst = d2;
      wi = i;
      if (!std::isfinite(d2)) break;
    }
  }
  const double mine = std::isfinite(worst) ? std::sqrt(worst) : std::numeric_limits<double>::max();
  const bool parallel = comm().size() > 1;
  const double top = parallel ? comm().max(mine) : mine;
  if (top <= limit) return;
  const int who = parallel ? comm().max_loc(mine).second : 0;
  std::string msg;
  if (comm().rank() == who) {
    const auto i = wi;
    msg = fmt::format(
        "step {}: blow-up: particle id {} moved {} in one step (more than {} x the smallest radius {:.4g}; "
        "{:.4g} since the last rebuild, limit skin/2 + that = {:.4g}): position ({:.6g}, {:.6g}, {:.6g}), "
        "velocity ({:.6g}, {:.6g}, {:.6g}). dt = {:.6g} is {:.3g} x the critical time step {:.6g}{}",
        step_ + 1, p_.id[i],
        mine >= std::numeric_limits<double>::max() ? "to a non-finite position" : "too far",
        stability::kBlowupRadii, stability_.rmin, mine, limit, double(p_.x[i]), double(p_.y[i]),
        double(p_.z[i]), double(p_.vx[i]), double(p_.vy[i]), double(p_.vz[i]), scene_.dt, stability_.fraction,
        stability_.dt_critical, stability_.fraction > 1 ? " (forced): lower dt" : "");
  }
  stop(parallel ? comm().broadcast(msg, who) : msg);
}

#define BASALT_INSTANTIATE(R)                                        \
  template void Simulation<R>::check_stability(const io::Geometry&); \
  template void Simulation<R>::estimate_critical_step(bool);         \
  template void Simulation<R>::check_blowup();
BASALT_INSTANTIATE(double)
BASALT_INSTANTIATE(float)
#undef BASALT_INSTANTIATE

}  // namespace basalt::solver
