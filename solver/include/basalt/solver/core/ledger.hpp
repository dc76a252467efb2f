#pragma once
// The energy ledger: the named energy terms of a run, each filled by the model or modifier that owns
// it. Potentials are recomputed at steps that need them (field savers, the energy guard); work and
// dissipation terms accumulate over the run. The energy guard balances the whole ledger: kinetic +
// potentials + dissipated - work put in stays at its initial value (docs/solver.md).
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace basalt::solver {

class Ledger {
 public:
  enum class Kind { kinetic, potential, work, dissipated };
  struct Term {
    std::string name;
    Kind kind;
  };

  /// The term called `name` (added on first use).
  std::size_t add(std::string_view name, Kind kind) {
    for (std::size_t k = 0; k < terms_.size(); ++k)
      if (terms_[k].name == name) return k;
    terms_.push_back({std::string(name), kind});
    return terms_.size() - 1;
  }
  /// Index of a term, or -1.
  int find(std::string_view name) const {
    for (std::size_t k = 0; k < terms_.size(); ++k)
      if (terms_[k].name == name) return static_cast<int>(k);
    return -1;
  }
  std::size_t size() const { return terms_.size(); }
  const Term& operator[](std::size_t k) const { return terms_[k]; }
  const std::vector<Term>& terms() const { return terms_; }

  /// kinetic + potentials: the mechanical energy of a set of values (one per term).
  double mechanical(const std::vector<double>& v) const {
    return sum(v, Kind::kinetic) + sum(v, Kind::potential);
  }
  double sum(const std::vector<double>& v, Kind kind) const {
    double s = 0;
    for (std::size_t k = 0; k < terms_.size(); ++k)
      if (terms_[k].kind == kind) s += v[k];
    return s;
  }

 private:
  std::vector<Term> terms_;
};

}  // namespace basalt::solver
