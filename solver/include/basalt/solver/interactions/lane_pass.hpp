#pragma once
// A contact model's lane pass (Model::contact_lanes), written once for the pair and the wall drivers. A
// driver walks its contact entries (listed pairs, a wall's candidates) in order; the pass keeps those in
// contact, kContactLaneWidth at a time in the order found, has the model evaluate them side by side, and
// hands their results back in that order. Every contact goes through the lanes (a short last batch repeats
// its last contact and drops the copies' results), so a contact's result depends neither on the rank nor on
// its place in a batch.
//
// The pass owns what every kind of contact shares: the batch's histories (loaded into the lanes, stored back
// on real steps), the histories of the entries found apart (cleared batch by batch, what they held tallied
// as parting energy), and the tallies (energy, dissipation, sliding contacts). The driver
// owns the particles, through four callables:
//   find(e, l) -> LaneFound   entry e's test with positions and radii alone; its particles written to lane l
//                             of the driver's own arrays whether it touches or not (kept only if it does)
//   load(filled)              the lanes' particle inputs of the batch; lanes from `filled` on repeat lane
//                             filled - 1 (LanePass::pad)
//   add(l) -> bool            lane l's force and torques added where they go; whether its energies are
//                             this rank's to count (a pair to a ghost: the rank owning the smaller id)
//   kinematics(l)             lane l's kinematics for Model::energy (energy steps)
#include <cstddef>
#include <cstdint>

#include "basalt/solver/models/lanes.hpp"
#include "basalt/solver/models/model.hpp"

namespace basalt::solver {

/// What a lane pass tallies. A driver with several passes (one per wall) hands the same tally to each: the
/// sums run on in pass order.
struct LaneTally {
  double energy = 0;      ///< Model::energy of the counted contacts (energy steps)
  double dissipated = 0;  ///< what the counted contacts dissipated (real steps)
  double parted = 0;      ///< what the histories of counted entries found apart held (real steps)
  std::size_t sliding = 0;
};

/// A driver's answer about one entry: whether it is a contact, and whether its parting energy is this
/// rank's to count.
struct LaneFound {
  bool touch;
  bool counted;
};

template <class Real, class Model, class Lanes>
class LanePass {
 public:
  static constexpr int kWidth = kContactLaneWidth;
  using Coeffs = typename Model::template Coeffs<Real>;
  using History = typename Model::History;
  static constexpr bool kHistory = history_bytes<Model>() > 0;

  /// Entries [begin, end), entry e's history hist[e] (unused without history), with coefficients c.
  template <bool Energy, bool Advance, class Find, class Load, class Add, class Kinematics>
  static void run(const Coeffs& c, Lanes& L, [[maybe_unused]] History* hist, std::uint32_t begin,
                  std::uint32_t end, LaneTally& tally, Find&& find, Load&& load, Add&& add,
                  Kinematics&& kinematics) {
    // The tallies in locals: the finding loop keeps `filled` and `parted` in registers (a counter captured
    // by a lambda would go through memory every entry).
    double energy = tally.energy, dissipated = tally.dissipated, parted = tally.parted;
    std::size_t sliding = tally.sliding;
    alignas(64) std::uint32_t entry[kWidth];
    // Every entry before `cleared` has been seen: the histories of those apart are cleared (the contacts get
    // theirs back after the evaluation).
    std::uint32_t cleared = begin;
    const auto complete = [&](const int filled, const std::uint32_t last) {
      pad(entry, filled);
      load(filled);
      if constexpr (kHistory)
        for (int l = 0; l < kWidth; ++l) L.h[l] = hist[entry[l]];
      if constexpr (kHistory && Advance) {
        for (std::uint32_t e = cleared; e < last; ++e) clear(hist[e]);
        cleared = last;
      }
    };
    const auto evaluate = [&](const int filled) {
      Model::template contact_lanes<Advance>(c, L);
      for (int l = 0; l < filled; ++l) {
        const bool counted = add(l);
        if constexpr (kHistory && Advance) hist[entry[l]] = L.h[l];
        if (counted) {
          if constexpr (Advance) {
            dissipated += L.dissipated[l];
            sliding += L.sliding[l] != Real(0);
          }
          if constexpr (Energy) energy += double(Model::energy(c, L.h[l], kinematics(l)));
        }
      }
    };
    int filled = 0;
    for (std::uint32_t e = begin; e < end; ++e) {
      const int l = filled;
      const LaneFound f = find(e, l);
      entry[l] = e;
      if constexpr (kHistory && Advance) {
        // What an entry apart still held is lost with its history (a shear spring's energy): dissipated.
        const double lost = Model::parting_energy(c, hist[e]);
        parted += !f.touch && f.counted ? lost : 0.0;
      }
      filled += f.touch;
      if (filled == kWidth) {
        complete(filled, e + 1);
        evaluate(filled);
        filled = 0;
      }
    }
    if (filled > 0) {
      complete(filled, end);
      evaluate(filled);
    } else if constexpr (kHistory && Advance) {
      for (std::uint32_t e = cleared; e < end; ++e) clear(hist[e]);
    }
    tally.energy = energy, tally.dissipated = dissipated, tally.parted = parted, tally.sliding = sliding;
  }

  /// An entry's history cleared: by the pair model's apart(), a wall model's to a new contact's (History{}).
  static void clear(History& h) {
    if constexpr (requires { Model::apart(h); })
      Model::apart(h);
    else
      h = History{};
  }

  /// Lanes from `filled` on take lane filled - 1's value (a short batch's copies of its last contact).
  template <class T>
  static void pad(T* a, const int filled) {
    for (int l = filled; l < kWidth; ++l) a[l] = a[filled - 1];
  }
};

}  // namespace basalt::solver
