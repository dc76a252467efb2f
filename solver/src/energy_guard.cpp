#include "basalt/solver/stability/energy_guard.hpp"

namespace basalt::solver {

EnergyGuard::EnergyGuard(const Scene& scene, const Ledger& ledger) : every_(scene.energy_check_every) {
  for (const auto& f : scene.fields) {
    const bool total = f.type == FieldSpec::Type::total_energy, energy = f.type == FieldSpec::Type::energy;
    if (total ||
        (energy && ledger[static_cast<std::size_t>(ledger.find(f.term))].kind == Ledger::Kind::potential))
      potential_every_.push_back(f.every);
    if (total || (energy && f.term == "kinetic_energy")) kinetic_every_.push_back(f.every);
  }
}

}  // namespace basalt::solver
