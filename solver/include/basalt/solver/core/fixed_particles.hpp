#pragma once
// The owned particles of the scene's fixed tags (particles.fixed_tags, set_fixed_tags): held, they feel
// forces (walls and field savers see them) but neither kick moves or turns them, because their forces and
// torques are zeroed after every force computation. The list holds local indices, found again at every
// rebuild (the particles' order changes only there) and when the tags change. Owned by Simulation; free of
// MPI.
#include <algorithm>
#include <cstdint>
#include <vector>

#include "basalt/solver/core/particles.hpp"

namespace basalt::solver {

class FixedParticles {
 public:
  /// The owned particles of p whose tag is one of `tags`, in local order.
  template <class Real>
  void find(const Particles<Real>& p, const std::vector<std::int64_t>& tags) {
    index_.clear();
    if (tags.empty()) return;
    for (std::size_t i = 0; i < p.n_owned; ++i)
      if (std::find(tags.begin(), tags.end(), p.tag[i]) != tags.end())
        index_.push_back(static_cast<std::uint32_t>(i));
  }
  /// Zeroes their forces and torques (after each force computation: the next kick leaves them in place).
  template <class Real>
  void hold(Particles<Real>& p) const {
    for (const auto i : index_) {
      p.fx[i] = p.fy[i] = p.fz[i] = 0;
      if (p.with_rotation) p.tx[i] = p.ty[i] = p.tz[i] = 0;
    }
  }
  /// Brings them to rest (velocities and spins zero: held from now on).
  template <class Real>
  void stop(Particles<Real>& p) const {
    for (const auto i : index_) {
      p.vx[i] = p.vy[i] = p.vz[i] = 0;
      if (p.with_rotation) p.wx[i] = p.wy[i] = p.wz[i] = 0;
    }
  }
  const std::vector<std::uint32_t>& indices() const { return index_; }

 private:
  std::vector<std::uint32_t> index_;
};

}  // namespace basalt::solver
