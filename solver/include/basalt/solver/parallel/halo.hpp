#pragma once
// Ghost exchange and migration over the six faces of a rank's region, one axis after the other
// (ghosts received along x are forwarded along y and z, which fills edges and corners).
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "basalt/solver/core/bonds.hpp"
#include "basalt/solver/core/contact_history.hpp"
#include "basalt/solver/core/particles.hpp"
#include "basalt/solver/parallel/decomposition.hpp"

namespace basalt::solver {

template <class Real>
class Halo {
 public:
  explicit Halo(const Decomposition& dec) : dec_(dec) {}

  /// Sends owned particles that left this rank's region (with every bond touching them, and a copy of
  /// every contact-history record naming them: `history`, one set per pair model, null entries for
  /// models without history) to the neighbour in that direction. Requires no ghosts. Returns an error
  /// message (not thrown: the caller agrees on errors across ranks) when a particle arrives outside its
  /// new owner's region. far (collective: after the cuts moved, parallel/balance.hpp): particles go on
  /// hop by hop along each axis until every one reaches its owner, however many regions away.
  std::optional<std::string> migrate(Particles<Real>& p, Bonds<Real>& bonds,
                                     const std::vector<ContactRecords*>& history = {}, bool far = false);

  /// Appends as ghosts copies of the neighbours' particles within `width` of this rank's faces and
  /// remembers the lists for update_ghosts(). Requires no ghosts.
  void build_ghosts(Particles<Real>& p, double width);

  /// Refreshes ghost positions along the lists of the last build_ghosts().
  void update_ghosts(Particles<Real>& p) {
    begin_update_ghosts(p);
    end_update_ghosts(p);
  }
  /// Starts the refresh: the exchanges along every active axis but the last complete here (later axes
  /// forward what earlier ones received); the last one is posted non-blocking, so work on owned
  /// particles can overlap it. end_update_ghosts() completes it.
  void begin_update_ghosts(Particles<Real>& p);
  /// Lets MPI move the refresh in flight along (a large message moves only inside MPI calls); no wait.
  void progress_ghosts();
  void end_update_ghosts(Particles<Real>& p);

  /// Bytes held by the send lists and buffers.
  std::size_t memory_bytes() const;

 private:
  const Decomposition& dec_;
  std::array<std::array<std::vector<std::int32_t>, 2>, 3> send_;  ///< [axis][side] local indices
  std::array<std::array<std::size_t, 2>, 3> recv_begin_{};  ///< where ghosts from [axis][from side] start
  std::array<std::array<std::size_t, 2>, 3> recv_count_{};
  std::vector<Real> sbuf_, rbuf_;
  std::array<std::vector<Real>, 2> async_send_, async_recv_;
  std::array<MPI_Request, 4> requests_{MPI_REQUEST_NULL, MPI_REQUEST_NULL, MPI_REQUEST_NULL,
                                       MPI_REQUEST_NULL};
  int async_axis_ = -1;
};

}  // namespace basalt::solver
