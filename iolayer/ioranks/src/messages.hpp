#pragma once
// What compute and I/O ranks share about their messages: the tags, the size check, and waiting for a
// message without spinning (Open MPI busy-polls in its blocking calls; an idle I/O rank must not burn
// a core).
#include <mpi.h>

#include <chrono>
#include <cstddef>
#include <vector>

namespace basalt::io::detail {

/// Message tags on the bridge (compute <-> I/O) and among the I/O ranks (kTagGather). kTagAck: an I/O
/// rank's verdict on one step's output (the step as int64, then the error text when it failed).
enum Tag : int { kTagInfo = 701, kTagFrame, kTagFields, kTagDone, kTagError, kTagGather, kTagAck };

/// `bytes` as an MPI count; throws std::runtime_error beyond MPI's 2 GiB message limit.
int checked_count(std::size_t bytes);

/// Sleeps between polls, 20 us doubling up to 2 ms.
class Backoff {
 public:
  void sleep();
  void reset() { pause_ = std::chrono::microseconds(20); }

 private:
  std::chrono::microseconds pause_{20};
};

/// Receives the next message from `source` with `tag` (any size), sleeping while none is there.
void receive_without_spinning(int source, int tag, MPI_Comm comm, std::vector<std::byte>& bytes);

}  // namespace basalt::io::detail
