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
#include "basalt/solver/integrate/integrators.hpp"
#include "basalt/solver/simulation.hpp"
#include "basalt/solver/stability/critical_step.hpp"

namespace basalt::solver {

template <class Real>
void Simulation<Real>::check_stability(const GeometrySummary& given) {
  // What the geometry alone tells: the smallest mass and radius, and the former one-spring estimate
  // 2 sqrt(m_min / k_max) (printed for comparison). The network's estimate needs the lists:
  // estimate_critical_step(), after the first rebuild. The particles the scene inserts later count.
  GeometrySummary s = given;
  include_flow(s);
  const double m_min = s.m_min_pow, rmax = s.rmax, rmin = s.rmin;
  stability_.m_min = m_min;
  stability_.k_max = forces_.max_stiffness(rmax);
  stability_.rmin = rmin;
  stability_.dt_pair = stability::critical_step(stability_.k_max / m_min);
  stability_.dt_contact = contact_critical_step(m_min, rmax);
}

template <class Real>
double Simulation<Real>::contact_critical_step(double m_min, double rmax) const {
  // A contact that forms later, between two of the lightest particles (omega^2 = 2 k / m_min) or one
  // and a wall (k / m_min): the network at the start does not have it. A tangential spring of rotating
  // particles acts at the contact point, whose compliance 1/m + r^2/I is 3.5/m for a solid sphere (I = 2/5
  // m r^2): omega^2 = 7 ks / m_min between two of them, 3.5 ks / m_min on a wall. A rolling couple k_r <= kr
  // r^2 turns the lightest sphere at up to 2.5 kr / m_min more (on a much heavier one; bounded here by the
  // sum). docs/stability.md, "The rotational step limit"; the power iterations do not see these modes: they
  // move positions, not the springs' history.
  constexpr double kTurn = 1 / 0.4;  // r^2 m / I of a solid sphere
  double future2 = 0;
  for (const auto& c : forces_.computes()) {
    const double k = c->max_stiffness(rmax);
    const double ks = scene_.rotation ? (1 + kTurn) * c->shear_stiffness(rmax) : 0.0;
    const double kr = scene_.rotation ? kTurn * c->rolling_stiffness() : 0.0;
    if (c->kind() == ModelKind::pair) future2 = std::max(future2, std::max(2 * k, 2 * ks + kr) / m_min);
    if (c->kind() == ModelKind::wall) future2 = std::max(future2, std::max(k, ks) / m_min);
  }
  return stability::critical_step(future2);
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

  // The bound: per owned particle 2 sum of its springs to particles + sum of its walls' springs. The
  // sums go to the force arrays (overwritten by the next force computation anyway) in double, and to a
  // scratch vector in float: no full-size copy beside the solver's arrays (peak memory).
  std::vector<double> ks_scratch(sizeof(Real) >= sizeof(double) ? 0 : n, 0.0);
  Real* const ks_real = p_.fx.data();
  const auto add_k = [&](std::size_t i, double k) {
    if constexpr (sizeof(Real) >= sizeof(double))
      ks_real[i] += Real(k);
    else
      ks_scratch[i] += k;
  };
  if constexpr (sizeof(Real) >= sizeof(double)) std::fill(p_.fx.begin(), p_.fx.begin() + long(n), Real(0));
  for (std::size_t b = 0; b < bonds_.size(); ++b) {
    const auto i = static_cast<std::size_t>(bonds_.ia[b]), j = static_cast<std::size_t>(bonds_.ib[b]);
    const double k = 2 * k_of(0, std::max(double(p_.radius[i]), double(p_.radius[j])));
    add_k(i, k);
    if (j < n) add_k(j, k);
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
        if (list->is_bonded(q) || !touching(i, j)) continue;  // (a bond's stiffness is counted above)
        const double k = 2 * k_of(1, std::max(double(p_.radius[i]), double(p_.radius[j])));
        add_k(i, k);
        if (j < n) add_k(j, k);
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
      if (d < double(p_.radius[i]) || walls.spec(w).bonds(p_.tag[i])) add_k(i, k_of(2, double(p_.radius[i])));
    }
  }
  double bound2 = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double ks = sizeof(Real) >= sizeof(double) ? double(ks_real[i]) : ks_scratch[i];
    bound2 = std::max(bound2, ks * double(p_.inv_mass[i]));
  }
  bound2 = comm().max(bound2);
  std::vector<double>().swap(ks_scratch);
  st.dt_bound = stability::critical_step(bound2);

  // Power iterations on M^-1 K, each product K u from the force field, K u = (F(x) - F(x + delta u)) /
  // delta: F(x), computed once and kept (3 values per owned particle while the estimate runs), is
  // negated into the force arrays, where F(x + delta u) then adds onto it: one evaluation per product
  // (central differences, at twice the cost, would drop the O(delta) bias, ~1e-7 here, far below the
  // tolerance, but move the printed estimates' last digits). The iteration vector is kept in float in the
  // float positions of the last rebuild (p_.x0, equal to float(x) right after it; restored at the end) or,
  // after a restart (x0 then belongs to the checkpoint's rebuild), in a float scratch vector. The positions
  // are not copied: each perturbation is a multiple of the ulp of its coordinate and stays within its
  // binade, so x -> x + d -> x is exact (the few coordinates near zero or a power of two, where that
  // fails, are kept in a side list). The products need the ghosts' perturbed positions: a ghost update per
  // force evaluation, as in a step. Peak memory: docs/bench/build_ab_granular.md.
  double lambda = 0;
  st.iterations = 0;
  // A perturbation that breaks a bond (one strained near its strength at the start; float's perturbation is
  // 1000x double's) is tried again 8x and 64x smaller before the start is refused.
  for (int attempt = 0; bound2 > 0; ++attempt) {
    lambda = 0;
    st.iterations = 0;
    const bool parallel = comm().size() > 1;
    std::vector<float> scratch(fresh ? 0 : 3 * n);
    float* const sv[3] = {fresh ? p_.x0.data() : scratch.data(), fresh ? p_.y0.data() : scratch.data() + n,
                          fresh ? p_.z0.data() : scratch.data() + 2 * n};
    Real* const pos[3] = {p_.x.data(), p_.y.data(), p_.z.data()};
    Real* const frc[3] = {p_.fx.data(), p_.fy.data(), p_.fz.data()};
    const double delta = stability::perturbation<Real>() * st.rmin / std::pow(8.0, attempt);
    // Coordinates whose ulp is the same over [c - 2 delta, c + 2 delta] move by a multiple of it,
    // exactly; the others (within 2 delta of zero or of a power of two: a plane of particles at z = 0,
    // say) keep their value in a side list, sorted by 3 i + d.
    const auto movable = [&](Real c) {
      const double a = std::abs(double(c));
      return a > 4 * delta && stability::ulp(Real(a - 2 * delta)) == stability::ulp(Real(a + 2 * delta));
    };
    std::vector<std::size_t> side_at;
    std::vector<Real> side_value;
    for (std::size_t i = 0; i < n; ++i)
      for (int d = 0; d < 3; ++d) {
        sv[d][i] = float(stability::start_component(p_.id[i], d));
        if (!movable(pos[d][i])) {
          side_at.push_back(3 * i + std::size_t(d));
          side_value.push_back(pos[d][i]);
        }
      }
    // Bonds already beyond their break strain break here, as in the first force computation without
    // the estimate; the perturbed ones must not. The estimate leaves the bonds as it found them: the
    // caller's force computation breaks those bonds (a restart at the step they broke replays exactly
    // that), and a model whose breaking bond still acts in that step (rot_bond) applies its force then.
    const bool breakable = forces_.bonds_can_break();
    const Bonds<Real> bonds_at_start = breakable ? bonds_ : Bonds<Real>{};
    const std::vector<std::int32_t> damage_at_start =
        breakable ? p_.bonds_broken : std::vector<std::int32_t>{};
    const std::size_t broken_at_start = broken_.size();
    const bool rebuild_pending_at_start = schedule_.pending();
    auto marks_at_start = breakable ? forces_.bond_marks() : decltype(forces_.bond_marks()){};
    compute_forces<false>();
    // F(x) once for all products (120 force evaluations became 61: half the start-up of a large run,
    // docs/BENCHMARKS.md). Bonds beyond their break strain broke in that evaluation, and a model whose
    // breaking bond still acts then (rot_bond) put its force in: F(x) again without them.
    if (broken_.size() != broken_at_start) compute_forces<false>();
    const std::size_t broken_before = broken_.size();
    std::vector<Real> f_at_x(3 * n);
    for (int d = 0; d < 3; ++d) std::copy(frc[d], frc[d] + n, f_at_x.begin() + std::ptrdiff_t(d * n));
    // Lanczos on the symmetric A = M^-1/2 K M^-1/2 (the same eigenvalues as M^-1 K): q_j in sv (float),
    // q_(j-1) in `previous`, the perturbation along u = M^-1/2 q_j. Its largest Ritz value rises towards
    // omega_max^2 from below as the power iteration's Rayleigh quotient did, but it converges in far
    // fewer products when the top of the spectrum is crowded (a large network: at 9.47 M particles 60
    // power iterations had not converged). q_j is the vector the perturbation actually applied (rounded
    // to the coordinates' ulps), rescaled: rounding enters as a relative 1e-6 error of the product.
    std::vector<float> previous(3 * n, 0.0f);
    std::vector<double> alpha, beta;
    std::vector<double> sums(1);
    const auto norm_of = [&](const auto& value) {  // sqrt of the sum over ranks of value(d, i)^2
      sums[0] = 0;
      for (int d = 0; d < 3; ++d)
        for (std::size_t i = 0; i < n; ++i) sums[0] += value(d, i) * value(d, i);
      comm().sum_all(sums);
      return std::sqrt(sums[0]);
    };
    {  // q_1: the start vector, of unit length
      const double q1 = norm_of([&](int d, std::size_t i) { return double(sv[d][i]); });
      if (q1 > 0)
        for (int d = 0; d < 3; ++d)
          for (std::size_t i = 0; i < n; ++i) sv[d][i] = float(double(sv[d][i]) / q1);
    }
    std::vector<double> sqrt_im(n);
    for (std::size_t i = 0; i < n; ++i) sqrt_im[i] = std::sqrt(double(p_.inv_mass[i]));
    Real* const w[3] = {frc[0], frc[1], frc[2]};  // A q_j and then the next Lanczos vector, in place
    for (int it = 0; it < stability::kMaxIterations; ++it) {
      double umax = 0;
      for (int d = 0; d < 3; ++d)
        for (std::size_t i = 0; i < n; ++i) umax = std::max(umax, std::abs(sqrt_im[i] * double(sv[d][i])));
      umax = comm().max(umax);
      if (!(umax > 0) || !std::isfinite(umax)) break;
      zero_forces(p_);  // ghosts' forces and the torques too
      for (int d = 0; d < 3; ++d)
        for (std::size_t i = 0; i < n; ++i) frc[d][i] = -f_at_x[d * n + i];
      integrator_.mark_zeroed();  // the next evaluation adds F(x + d) onto -F(x)
      // x + d: delta u / umax, rounded to a multiple of the coordinate's ulp where it is movable.
      for (std::size_t i = 0, k = 0; i < n; ++i)
        for (int d = 0; d < 3; ++d) {
          const double want = delta * sqrt_im[i] * double(sv[d][i]) / umax;
          if (k < side_at.size() && side_at[k] == 3 * i + std::size_t(d)) {
            pos[d][i] = Real(double(side_value[k++]) + want);
          } else {
            const Real q = stability::ulp(pos[d][i]);
            pos[d][i] += Real(std::nearbyint(want / double(q))) * q;
          }
        }
      if (parallel) halo_->update_ghosts(p_);
      compute_forces<false>();
      // w = A q_j - beta_(j-1) q_(j-1), with q_j the perturbation actually applied (then undone, exactly).
      const double beta_before = beta.empty() ? 0.0 : beta.back();
      sums[0] = 0;
      for (std::size_t i = 0, k = 0; i < n; ++i) {
        for (int d = 0; d < 3; ++d) {
          double dd;
          if (k < side_at.size() && side_at[k] == 3 * i + std::size_t(d)) {
            dd = double(pos[d][i]) - double(side_value[k]);
            pos[d][i] = side_value[k++];
          } else {
            const Real q = stability::ulp(pos[d][i]);  // the same at x + d as at x
            const Real step =
                Real(std::nearbyint(delta * sqrt_im[i] * double(sv[d][i]) / umax / double(q))) * q;
            pos[d][i] -= step;
            dd = double(step);
          }
          const double u = dd * umax / delta;  // M^-1/2 q_j as applied
          const double qj = sqrt_im[i] > 0 ? u / sqrt_im[i] : 0.0;
          const double aq = -sqrt_im[i] * double(frc[d][i]) * umax / delta;  // M^-1/2 K u
          const double wi = aq - beta_before * double(previous[d * n + i]);
          sv[d][i] = float(qj);
          w[d][i] = Real(wi);
          sums[0] += qj * wi;
        }
      }
      if (parallel) halo_->update_ghosts(p_);
      comm().sum_all(sums);
      ++st.iterations;
      const double a = sums[0];
      if (!std::isfinite(a)) break;
      alpha.push_back(a);
      for (int d = 0; d < 3; ++d)
        for (std::size_t i = 0; i < n; ++i) w[d][i] = Real(double(w[d][i]) - a * double(sv[d][i]));
      const double b = norm_of([&](int d, std::size_t i) { return double(w[d][i]); });
      const double ritz = stability::largest_eigenvalue(alpha, beta);
      const bool converged = it > 2 && std::abs(ritz - lambda) <= stability::kTolerance * ritz;
      lambda = std::max(lambda, ritz);
      if (converged || !(b > 1e-12 * std::max(std::abs(a), lambda))) break;  // or an invariant subspace
      beta.push_back(b);
      for (int d = 0; d < 3; ++d)
        for (std::size_t i = 0; i < n; ++i) {
          previous[d * n + i] = sv[d][i];
          sv[d][i] = float(double(w[d][i]) / b);
        }
    }
    // x0 back to the values rebuild() gives it (the same function sets both). The forces hold the last
    // product: the callers compute them again.
    if (fresh) set_skin_reference();
    // (each break is recorded by one rank: the sum counts each once)
    const long long broke = comm().sum(static_cast<long long>(broken_.size() - broken_before));
    if (broke > 0 && attempt == stability::kPerturbationRetries)
      throw InputError(fmt::format(
          "the critical-step estimate broke {} bond(s) by perturbing positions by {:.3g} (after {} larger "
          "tries): bonds this close to breaking at the start are not supported",
          broke, delta, attempt));
    if (breakable) {
      bonds_ = bonds_at_start;
      p_.bonds_broken = damage_at_start;
      broken_.erase(broken_.begin() + static_cast<std::ptrdiff_t>(broken_at_start), broken_.end());
      schedule_.set_pending(rebuild_pending_at_start);
      forces_.set_bond_marks(std::move(marks_at_start));
    }
    st.perturbation = delta;
    st.retries = attempt;
    if (broke == 0) break;
  }
  st.dt_power = stability::critical_step(lambda);
  // Bonds that break become contacts of the scene's pair model (a broken bond's pair is a contact): the
  // fragments' network is the start's with contacts in place of bonds. With contacts stiffer than the bonds
  // its omega^2 is up to k_pair / k_bond times the start's (every spring scaled by that ratio: the walls and
  // the start's contacts too, on the safe side). A bonded block shattered on a wall with contacts 10x its
  // bonds reached 0.894 of the start's step while the fragments were pressed together (docs/stability.md,
  // "A bonded cascade"); the term gives 0.79.
  st.dt_broken = std::numeric_limits<double>::infinity();
  if (lambda > 0 && forces_.bonds_can_break()) {
    double k_pair = 0, k_bond = std::numeric_limits<double>::infinity();
    for (const auto& c : forces_.computes()) {
      if (c->kind() == ModelKind::pair) k_pair = std::max(k_pair, c->max_stiffness(flow_.rmax()));
      if (c->kind() == ModelKind::bond) k_bond = std::min(k_bond, c->max_stiffness(flow_.rmax()));
    }
    if (k_bond > 0 && k_pair > k_bond) st.dt_broken = stability::critical_step(lambda * k_pair / k_bond);
  }
  // The power iterations approach omega_max from below (2 / omega_power >= the true step, by a few
  // per cent at most once converged, docs/stability.md); the bound is safe but often ~2x too strict.
  // Contacts that do not exist yet count too (particles that start apart and collide later).
  st.dt_critical = std::min({lambda > 0 ? st.dt_power : st.dt_bound, st.dt_contact, st.dt_broken});
  if (!std::isfinite(st.dt_critical)) st.dt_critical = 0;  // no stiffness: nothing to check

  st.dt_fraction = scene_.dt_fraction;
  if (fresh && scene_.dt_fraction > 0) {
    if (!(st.dt_critical > 0))
      throw InputError(
          "run.dt_fraction: the scene has no stiffness (no bonds, contacts or walls touching particles), so "
          "there is no critical step to take a fraction of: give run.dt instead");
    apply_dt(scene_.dt_fraction * st.dt_critical);
  }
  if (!(st.dt_critical > 0)) return;
  judge_step(scene_.dt_fraction > 0 ? fmt::format("dt (run.dt_fraction = {})", scene_.dt_fraction)
                                    : std::string("run.dt"));
  // A stage's dt is refused now, not when the run reaches it (after the earlier stages' output).
  if (!fresh) return;
  for (std::size_t k = 0; k < scene_.stages.size(); ++k) {
    const auto& stage = scene_.stages[k];
    if (stage.dt > 0 && stage.dt > st.dt_critical && !(scene_.force_dt || options_.force_dt))
      throw InputError(fmt::format(
          "stages[{}] \"{}\": dt = {:.6g} is {:.3g} times the critical time step {:.6g}: the stage would be "
          "unstable. Lower it (a safe choice is <= {} x critical), or set run.force_dt = true / --force-dt "
          "to "
          "run anyway",
          k, stage.name, stage.dt, stage.dt / st.dt_critical, st.dt_critical, scene_.dt_safety));
  }
}

template <class Real>
void Simulation<Real>::judge_step(const std::string& what) {
  auto& st = stability_;
  st.fraction = scene_.dt / st.dt_critical;
  st.warn =
      st.fraction > scene_.dt_safety && !(scene_.dt_fraction > 0 && st.fraction <= 1);  // chosen knowingly
  if (st.fraction > 1 && !(scene_.force_dt || options_.force_dt))
    throw InputError(fmt::format(
        "{} = {:.6g} is {:.3g} times the critical time step {:.6g} (2 / omega_max of the network, {} power "
        "iterations, {:.6g}; the bound gives {:.6g}; one new contact of the lightest particle {:.6g}{}): the "
        "run would be unstable. Lower dt (a safe choice is <= {} x critical, e.g. run.dt_fraction = {}), or "
        "set run.force_dt = true / --force-dt to run anyway",
        what, scene_.dt, st.fraction, st.dt_critical, st.iterations, st.dt_power, st.dt_bound, st.dt_contact,
        std::isfinite(st.dt_broken)
            ? fmt::format("; the network with its breakable bonds as stiff as the contacts {:.6g}",
                          st.dt_broken)
            : std::string(),
        scene_.dt_safety, scene_.dt_safety));
}

template <class Real>
std::vector<std::string> Simulation<Real>::step_warnings() const {
  const auto& st = stability_;
  std::vector<std::string> out;
  if (!(st.dt_critical > 0)) return out;
  if (st.warn)
    out.push_back(fmt::format("dt = {} is {:.3g} x the critical time step, above the safe fraction {}{}",
                              scene_.dt, st.fraction, scene_.dt_safety,
                              st.fraction > 1 ? " (forced): expect the blow-up check to stop the run" : ""));
  // ESyS's rotational bonds are not derived from a potential: the estimate (a symmetric network's) is above
  // their limit, measured at 0.502 of it for two bonded spheres (stability::kRotBondFraction).
  const bool rot_bonds = std::any_of(scene_.bonds.begin(), scene_.bonds.end(),
                                     [](const auto& g) { return g.model == "rot_bond"; });
  if (rot_bonds && st.fraction > stability::kRotBondFraction && st.fraction <= 1)
    out.push_back(fmt::format(
        "dt = {:.6g} is {:.3g} x the critical time step: rot_bond networks can be unstable there (two bonded "
        "spheres from 0.502 of it; docs/stability.md, \"Rotational bonds and the critical step\"): use "
        "run.dt_fraction <= {}",
        scene_.dt, st.fraction, stability::kRotBondFraction));
  return out;
}

namespace {

/// A path is blocked where a sphere of radius r swept along it comes within `reach` of something: the
/// segment a + t (b - a), t in [0, 1], against the origin. Returns the closest distance.
double segment_distance(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  const double ux = b[0] - a[0], uy = b[1] - a[1], uz = b[2] - a[2];
  const double uu = ux * ux + uy * uy + uz * uz;
  double t = uu > 0 ? -(a[0] * ux + a[1] * uy + a[2] * uz) / uu : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  return std::hypot(a[0] + t * ux, a[1] + t * uy, a[2] + t * uz);
}

/// 1 for each owned particle (index < n_owned) at an end of a bond, else 0.
template <class Real>
std::vector<char> owned_with_bonds(const Bonds<Real>& bonds, std::size_t n_owned) {
  std::vector<char> bonded(n_owned, 0);
  for (std::size_t k = 0; k < bonds.ia.size(); ++k) {
    if (static_cast<std::size_t>(bonds.ia[k]) < n_owned) bonded[static_cast<std::size_t>(bonds.ia[k])] = 1;
    if (k < bonds.n_both_owned && static_cast<std::size_t>(bonds.ib[k]) < n_owned)
      bonded[static_cast<std::size_t>(bonds.ib[k])] = 1;
  }
  return bonded;
}

std::string xyz(const std::array<double, 3>& v) {
  return fmt::format("({:.6g}, {:.6g}, {:.6g})", v[0], v[1], v[2]);
}

}  // namespace

template <class Real>
std::optional<std::string> Simulation<Real>::blocked_path(std::vector<double>& fast,
                                                          bool since_rebuild) const {
  // fast: kFastValues doubles per particle of this rank (id, tag, start, end, radius, bonded, velocity);
  // replaced by every rank's, in rank order. The others' paths: since the last rebuild (x0 to x) when
  // `since_rebuild`, else the next step's (x to x + v dt), as the fast ones'.
  fast = comm().size() > 1 ? comm().all_gather(fast) : fast;
  const std::size_t n = fast.size() / kFastValues;
  const double dt = scene_.dt;
  const auto& o = p_.skin_origin;
  std::optional<std::string> hit;
  std::vector<MeshContact> touching;
  for (std::size_t f = 0; f < n && !hit; ++f) {
    const double* v = &fast[f * kFastValues];
    const auto id = static_cast<std::int64_t>(v[0]);
    const std::array<double, 3> a{v[2], v[3], v[4]}, b{v[5], v[6], v[7]};
    const double r = v[8];
    if (v[9] != 0) {
      hit = fmt::format("{}: it is bonded, and no bond follows a particle that far in one step", f);
      break;
    }
    // Every owned particle (the fast one itself excepted): their relative path, within the sum of radii.
    for (std::size_t j = 0; j < p_.n_owned && !hit; ++j) {
      if (p_.id[j] == id) continue;
      std::array<double, 3> s{}, e{};
      if (since_rebuild) {
        s = {double(p_.x0[j]) + o[0], double(p_.y0[j]) + o[1], double(p_.z0[j]) + o[2]};
        e = {double(p_.x[j]), double(p_.y[j]), double(p_.z[j])};
      } else {
        s = {double(p_.x[j]), double(p_.y[j]), double(p_.z[j])};
        e = {s[0] + double(p_.vx[j]) * dt, s[1] + double(p_.vy[j]) * dt, s[2] + double(p_.vz[j]) * dt};
      }
      const double reach = r + double(p_.radius[j]);
      const double d =
          segment_distance({a[0] - s[0], a[1] - s[1], a[2] - s[2]}, {b[0] - e[0], b[1] - e[1], b[2] - e[2]});
      if (d < reach)
        hit = fmt::format(
            "{}: its path comes within {:.4g} of particle id {} (radius {:.4g}; the two touch below "
            "{:.4g}): it could pass through it",
            f, d, p_.id[j], double(p_.radius[j]), reach);
    }
    const auto& walls = forces_.walls();
    const auto tag = static_cast<std::int64_t>(v[1]);
    auto touches = [&](const TagFilter& tags) {
      return tags.empty() || std::find(tags.begin(), tags.end(), tag) != tags.end();
    };
    for (std::size_t w = 0; w < walls.size() && !hit; ++w) {
      if (!touches(walls.spec(w).tags)) continue;
      const auto& q = walls.point(w);
      const auto& nrm = walls.spec(w).normal;
      auto side = [&](const std::array<double, 3>& x) {
        return (x[0] - q[0]) * nrm[0] + (x[1] - q[1]) * nrm[1] + (x[2] - q[2]) * nrm[2];
      };
      const double d = std::min(side(a), side(b));  // linear along the path: the least at an end
      if (d < r)
        hit = fmt::format(
            "{}: its path comes within {:.4g} of wall \"{}\" (or through it) and its radius is {:.4g}: "
            "it could pass through the wall",
            f, d, walls.spec(w).name, r);
    }
    // Mesh walls: spheres of radius 1.12 r every r along the path cover the swept sphere of radius r.
    const double len = std::hypot(b[0] - a[0], b[1] - a[1], b[2] - a[2]);
    const auto samples = static_cast<std::size_t>(std::ceil(len / std::max(r, 1e-300))) + 1;
    for (std::size_t k = 0; k < walls.meshes() && !hit; ++k) {
      if (!touches(walls.mesh_spec(k).tags)) continue;
      for (std::size_t m = 0; m <= samples && !hit; ++m) {
        const double t = double(m) / double(samples);
        touching.clear();
        const std::array<double, 3> c{a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]),
                                      a[2] + t * (b[2] - a[2])};
        if (walls.mesh(k).contacts(c, 1.12 * r, touching) > 0)
          hit = fmt::format("{}: its path meets mesh wall \"{}\" at {}: it could pass through the wall", f,
                            walls.mesh_spec(k).name, xyz(c));
      }
    }
  }
  if (comm().size() > 1) hit = comm().agree_error(hit);
  return hit;
}

template <class Real>
void Simulation<Real>::check_blowup() {
  // Called before a rebuild, when some particle (or wall) moved more than skin/2 since the last one.
  // Moving farther than skin/2 + kBlowupRadii rmin since then means moving more than kBlowupRadii rmin
  // in this one step. That alone is not a blow-up: a particle in free flight (ejecta, a projectile) may
  // move any distance per step, the lists being rebuilt as often as needed. It is one where the path
  // could take it through something: a particle or a wall within reach of the path (a contact cannot be
  // resolved in one step), or a bond (blocked_path); and where a position went non-finite. Runs in
  // which no particle moves that far never get past the first return: nothing changes for them. The
  // positions at the last rebuild are p_.x0 (float, relative to p_.skin_origin).
  const double limit = 0.5 * scene_.skin + stability::kBlowupRadii * stability_.rmin;
  double worst = 0;
  std::size_t wi = 0;
  const auto& o = p_.skin_origin;
  auto moved = [&](std::size_t i) {
    const double dx = double(p_.x[i]) - o[0] - double(p_.x0[i]),
                 dy = double(p_.y[i]) - o[1] - double(p_.y0[i]),
                 dz = double(p_.z[i]) - o[2] - double(p_.z0[i]);
    return dx * dx + dy * dy + dz * dz;
  };
  for (std::size_t i = 0; i < p_.n_owned; ++i) {
    const double d2 = moved(i);
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
  auto blowup = [&](std::size_t i, double far, const std::string& what) {
    return fmt::format(
        "step {}: blow-up: particle id {} moved {} in one step (more than {} x the smallest radius {:.4g}; "
        "{:.4g} since the last rebuild, limit skin/2 + that = {:.4g}){}: position ({:.6g}, {:.6g}, {:.6g}), "
        "velocity ({:.6g}, {:.6g}, {:.6g}). dt = {:.6g} is {:.3g} x the critical time step {:.6g}{}",
        clock_.step() + 1, p_.id[i],
        far >= std::numeric_limits<double>::max() ? "to a non-finite position" : "too far",
        stability::kBlowupRadii, stability_.rmin, far, limit, what, double(p_.x[i]), double(p_.y[i]),
        double(p_.z[i]), double(p_.vx[i]), double(p_.vy[i]), double(p_.vz[i]), scene_.dt, stability_.fraction,
        stability_.dt_critical, stability_.fraction > 1 ? " (forced): lower dt" : "");
  };
  if (!(top < std::numeric_limits<double>::max())) {
    const int who = parallel ? comm().max_loc(mine).second : 0;
    const std::string msg = comm().rank() == who ? blowup(wi, mine, "") : std::string();
    stop(parallel ? comm().broadcast(msg, who) : msg);
  }
  // The particles that moved that far, with their paths since the last rebuild.
  const std::vector<char> bonded = owned_with_bonds(bonds_, p_.n_owned);
  std::vector<double> fast;
  std::vector<std::size_t> mine_fast;
  for (std::size_t i = 0; i < p_.n_owned; ++i) {
    if (!(moved(i) > limit * limit)) continue;
    mine_fast.push_back(i);
    fast.insert(fast.end(),
                {double(p_.id[i]), double(p_.tag[i]), double(p_.x0[i]) + o[0], double(p_.y0[i]) + o[1],
                 double(p_.z0[i]) + o[2], double(p_.x[i]), double(p_.y[i]), double(p_.z[i]),
                 double(p_.radius[i]), double(bonded[i]), std::sqrt(moved(i))});
  }
  // This rank's first fast particle's index in the gathered list.
  std::size_t offset = 0;
  if (parallel) {
    const auto counts = comm().all_gather(static_cast<std::int64_t>(mine_fast.size()));
    for (int r = 0; r < comm().rank(); ++r)
      offset += static_cast<std::size_t>(counts[static_cast<std::size_t>(r)]);
  }
  auto hit = blocked_path(fast, true);
  if (!hit) {
    schedule_.allow_far_moves();  // the rebuild's migration may carry them across several ranks' regions
    return;
  }
  // "<index>: reason": the owner of that fast particle writes the message.
  const std::size_t colon = hit->find(':');
  const auto f = static_cast<std::size_t>(std::stoull(hit->substr(0, colon)));
  const std::string why = ", and " + hit->substr(colon + 2);
  std::string msg;
  const int owner = [&] {
    if (!parallel) return 0;
    const bool here = f >= offset && f < offset + mine_fast.size();
    return comm().max_loc(here ? double(comm().rank()) : -1.0).second;
  }();
  if (comm().rank() == owner) {
    const std::size_t i = mine_fast[f - offset];
    msg = blowup(i, fast[f * kFastValues + 10], why);
  }
  stop(parallel ? comm().broadcast(msg, owner) : msg);
}

template <class Real>
std::optional<std::string> Simulation<Real>::check_frame_state() const {
  const auto bad = check_finite();
  // Collective (the caller agrees on the outcome). A state that blew up but is still finite (speeds of
  // 1e122) would pass check_finite and be saved as a valid restart point, with check_blowup stopping
  // the run only at the next step's rebuild. A particle whose speed moves it farther in one step than
  // check_blowup's whole allowance (skin/2 + kBlowupRadii rmin, from any position within skin/2 of its
  // last rebuild) and whose next step's path meets a particle or a wall, or that is bonded, trips that
  // check at the next step; refusing the frame now leaves the newest checkpoint a state that ran. A
  // particle in free flight, whose path is clear, is saved.
  const double limit = scene_.skin + stability::kBlowupRadii * stability_.rmin;
  const double vmax = limit / scene_.dt;
  double worst = 0;
  std::vector<double> fast;
  std::vector<std::size_t> mine_fast;
  const double dt = scene_.dt;
  for (std::size_t i = 0; i < p_.n_owned && !bad; ++i) {  // (every rank goes on to the reductions)
    const double v2 = double(p_.vx[i]) * double(p_.vx[i]) + double(p_.vy[i]) * double(p_.vy[i]) +
                      double(p_.vz[i]) * double(p_.vz[i]);
    worst = std::max(worst, v2);
    if (!(std::sqrt(v2) > vmax)) continue;
    mine_fast.push_back(i);
    const double x = double(p_.x[i]), y = double(p_.y[i]), z = double(p_.z[i]);
    fast.insert(fast.end(), {double(p_.id[i]), double(p_.tag[i]), x, y, z, x + double(p_.vx[i]) * dt,
                             y + double(p_.vy[i]) * dt, z + double(p_.vz[i]) * dt, double(p_.radius[i]), 0.0,
                             std::sqrt(v2)});
  }
  const bool parallel = comm().size() > 1;
  const double top = parallel ? comm().max(std::sqrt(worst)) : std::sqrt(worst);
  if (!(top > vmax)) return bad;
  // Bonded: marked as check_blowup marks them.
  const std::vector<char> bonded = owned_with_bonds(bonds_, p_.n_owned);
  for (std::size_t m = 0; m < mine_fast.size(); ++m) fast[m * kFastValues + 9] = double(bonded[mine_fast[m]]);
  auto hit = blocked_path(fast, false);
  if (bad || !hit) return bad;
  const std::size_t colon = hit->find(':');
  const auto f = static_cast<std::size_t>(std::stoull(hit->substr(0, colon)));
  const double* v = &fast[f * kFastValues];
  return fmt::format(
      "step {}: blow-up: particle id {} has the speed {:.6g}, which moves it {:.6g} in one step of dt = "
      "{:.6g} "
      "(more than skin + {} x the smallest radius = {:.4g}), and {}: position {}, next step at {}. dt is "
      "{:.3g} x "
      "the critical time step {:.6g}{}",
      clock_.step(), static_cast<std::int64_t>(v[0]), v[10], v[10] * scene_.dt, scene_.dt,
      stability::kBlowupRadii, limit, hit->substr(colon + 2), xyz({v[2], v[3], v[4]}),
      xyz({v[5], v[6], v[7]}), stability_.fraction, stability_.dt_critical,
      stability_.fraction > 1 ? " (forced): lower dt" : "");
}

#define BASALT_INSTANTIATE(R)                                                   \
  template std::optional<std::string> Simulation<R>::check_frame_state() const; \
  template void Simulation<R>::check_stability(const GeometrySummary&);         \
  template void Simulation<R>::estimate_critical_step(bool);                    \
  template void Simulation<R>::judge_step(const std::string&);                  \
  template std::vector<std::string> Simulation<R>::step_warnings() const;       \
  template double Simulation<R>::contact_critical_step(double, double) const;   \
  template void Simulation<R>::check_blowup();                                  \
  template std::optional<std::string> Simulation<R>::blocked_path(std::vector<double>&, bool) const;
BASALT_INSTANTIATE(double)
BASALT_INSTANTIATE(float)
#undef BASALT_INSTANTIATE

}  // namespace basalt::solver
