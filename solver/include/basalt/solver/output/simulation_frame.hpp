#pragma once
// A compute rank's share of the state at the current step, as an io::FrameSource: the output
// client has it write itself straight into the buffer it sends (basalt/io/frame_writer.hpp), from
// the solver's arrays (a memcpy per column when Real = double), with no intermediate copy and no
// per-particle arithmetic (the I/O side derives masses from the inverse masses).
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "basalt/io/frame_writer.hpp"
#include "basalt/solver/simulation.hpp"

namespace basalt::solver {

template <class Real>
class SimulationFrame final : public io::FrameSource {
 public:
  /// Collective over the compute ranks (sums the wall forces); the frame then refers to `sim`,
  /// which must not step before it is written. Owned particles; bonds each once across ranks;
  /// walls on rank 0 only; positions at the last rebuild with checkpoints.
  SimulationFrame(const Simulation<Real>& sim, std::uint32_t kinds);
  io::FrameHeader header() const override { return header_; }
  void write(io::FrameWriter& w) const override;

 private:
  /// Whether bond k (with one ghost end, k >= n_both_owned) is this rank's to write.
  bool owns_ghost_bond(std::size_t k) const;

  const Simulation<Real>& sim_;
  io::FrameHeader header_;
  std::vector<io::WallState> walls_;
  std::map<std::string, std::string> attributes_;  ///< rank 0, checkpoints: the decomposition's cuts
  /// Checkpoints: history of the pair models that keep one ([k] of the k-th such model).
  std::vector<ContactRecords> history_;
  bool with_bonds_ = true;  ///< false for a frame that is only an in-situ picture
  /// Checkpoints: force (3) and, with rotation, torque (3 more) fields (kick_force_fields).
  std::size_t kick_forces_ = 0;
};

extern template class SimulationFrame<double>;
extern template class SimulationFrame<float>;

}  // namespace basalt::solver
