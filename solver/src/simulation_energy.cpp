// The energy ledger's values (the force field's potentials, the kinetic energy, the work walls put
// in), the energies tests and savers read, and the energy guard's check (stability/energy_guard.hpp) with
// its message.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "basalt/solver/simulation.hpp"

namespace basalt::solver {

template <class Real>
double Simulation<Real>::term_value(std::size_t t, const std::vector<double>& pe) const {
  if (t == forces_.kinetic_term()) return kinetic_energy_local();
  if (t == forces_.wall_work_term()) return guard_.wall_work_in();
  if (forces_.ledger()[t].kind == Ledger::Kind::dissipated) return forces_.dissipated(t);
  return pe[t];
}

template <class Real>
std::vector<double> Simulation<Real>::ledger_totals(const std::vector<double>& pe) const {
  std::vector<double> v(forces_.ledger().size());
  for (std::size_t t = 0; t < v.size(); ++t) v[t] = term_value(t, pe);
  comm().sum_all(v);
  return v;
}

template <class Real>
void Simulation<Real>::rebase_ledger(const std::vector<double>& pe) {
  guard_.rebase(forces_.ledger(), ledger_totals(pe));
  flow_.settled();
}

template <class Real>
std::vector<double> Simulation<Real>::ledger_values() {
  return ledger_totals(compute_forces<true>());
}

template <class Real>
std::array<double, 4> Simulation<Real>::energies() {
  const auto v = ledger_values();
  const auto term = [&](std::string_view name) {
    return v[static_cast<std::size_t>(forces_.ledger().find(name))];
  };
  return {term("kinetic_energy"), term("bond_potential_energy"), term("contact_potential_energy"),
          term("wall_potential_energy")};
}

template <class Real>
void Simulation<Real>::guard_energy(const std::vector<double>& pe) {
  // The balance (stability/energy_guard.hpp) of the ledger summed over the ranks, alike on every rank.
  const auto v = ledger_totals(pe);
  const auto breach = guard_.breach(forces_.ledger(), v, [&](std::size_t t) { return forces_.body_term(t); });
  if (!breach) return;
  // Name the fastest particle.
  double best = -1;
  std::size_t bi = 0;
  for (std::size_t i = 0; i < p_.n_owned; ++i) {
    const double ke =
        0.5 * double(p_.mass(i)) * double(p_.vx[i] * p_.vx[i] + p_.vy[i] * p_.vy[i] + p_.vz[i] * p_.vz[i]);
    if (!(ke <= best)) {
      best = ke;
      bi = i;
    }
  }
  const auto [top, who] = comm().max_loc(std::isfinite(best) ? best : std::numeric_limits<double>::max());
  std::string msg;
  if (comm().rank() == who && p_.n_owned > 0) {
    std::string terms;
    for (std::size_t t = 0; t < v.size(); ++t)
      terms += fmt::format("{}{} {:.6g}", t ? ", " : "", forces_.ledger()[t].name, v[t]);
    msg = fmt::format(
        "step {}: the energy grows without a source: mechanical energy {:.6g} + dissipated {:.6g} - work put "
        "in "
        "{:.6g} exceeds the initial {:.6g} by {:.6g}, more than allowed ({:.6g}); ledger: {}. Fastest "
        "particle: "
        "id {} with kinetic energy {:.6g}, velocity ({:.6g}, {:.6g}, {:.6g}) at ({:.6g}, {:.6g}, {:.6g}). dt "
        "= {} "
        "is {:.3g} x the critical time step {:.6g}",
        clock_.step(), breach->mechanical, breach->dissipated, breach->work, breach->energy0,
        breach->imbalance, breach->allowed, terms, p_.id[bi], best, p_.vx[bi], p_.vy[bi], p_.vz[bi], p_.x[bi],
        p_.y[bi], p_.z[bi], scene_.dt, stability_.fraction, stability_.dt_critical);
  }
  stop(comm().broadcast(msg, who));
}

#define BASALT_INSTANTIATE(R)                                                                  \
  template double Simulation<R>::term_value(std::size_t, const std::vector<double>&) const;    \
  template std::vector<double> Simulation<R>::ledger_totals(const std::vector<double>&) const; \
  template void Simulation<R>::rebase_ledger(const std::vector<double>&);                      \
  template std::vector<double> Simulation<R>::ledger_values();                                 \
  template std::array<double, 4> Simulation<R>::energies();                                    \
  template void Simulation<R>::guard_energy(const std::vector<double>&);
BASALT_INSTANTIATE(double)
BASALT_INSTANTIATE(float)
#undef BASALT_INSTANTIATE

}  // namespace basalt::solver
