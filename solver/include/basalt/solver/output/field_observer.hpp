#pragma once
// The field savers' observer (scene.fields, docs/scenes.md): this rank's partials and due mask of the step
// just observed, handed to the run's OutputSink when a saver was due and read back by saved_field() at that
// step only (the next step's observe() overwrites them, due or not); and the FieldRows
// adapter for a caller that steps with a FieldSink (tests, energy_drift, Python), kept across calls because a
// row may still be in flight. What a saver computes is the Simulation's to say (field_partials).
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "basalt/solver/output/field_rows.hpp"
#include "basalt/solver/output/field_sink.hpp"
#include "basalt/solver/output/output_sink.hpp"
#include "basalt/solver/parallel/communicator.hpp"

namespace basalt::solver {

class FieldObserver {
 public:
  /// The savers at `step`: partials(local, due) fills this rank's partial sums and the due mask (alike on
  /// every rank) and returns whether any saver is due; if one is, the row goes to `out` and is kept.
  template <class Partials>
  void observe(std::int64_t step, double time, OutputSink& out, Partials partials) {
    if (!partials(local_, due_)) return;
    step_ = step;
    // The due mask travels beside the values: a NaN sum stays a NaN ("nan" in fields.csv), never a saver
    // that was not due (an empty cell).
    out.fields(step, time, local_, due_);
  }
  /// Collective: column `column`'s value summed over the ranks when it was saved at step `now`, else nullopt
  /// (alike on every rank: the due mask is).
  std::optional<double> saved(std::size_t column, std::int64_t now, const Comm& comm) const;

  /// The FieldRows adapter on `comm`, sending rows to `sink` from now on.
  FieldRows& rows(const Comm& comm, FieldSink* sink);
  /// Collective: delivers a row of the FieldRows adapter still in flight (none when it was never made).
  void deliver_pending() {
    if (rows_) rows_->deliver_pending();
  }

 private:
  std::vector<double> local_;  ///< this rank's partials at the step just observed (step_ when one was due)
  std::vector<char> due_;      ///< which columns were due then
  std::int64_t step_ = -1;     ///< the last step a saver was due at
  std::unique_ptr<FieldRows> rows_;
};

}  // namespace basalt::solver
