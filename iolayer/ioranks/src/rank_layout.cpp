// Splitting the world into compute and I/O ranks (the only place that takes MPI_COMM_WORLD).
#include <fmt/format.h>

#include <stdexcept>

#include "basalt/io/io_ranks.hpp"

namespace basalt::io {

RankLayout split_ranks(MPI_Comm world, int io_ranks) {
  int rank = 0, size = 1;
  MPI_Comm_rank(world, &rank);
  MPI_Comm_size(world, &size);
  if (io_ranks < 0) throw std::invalid_argument(fmt::format("--io-ranks must be >= 0, got {}", io_ranks));
  if (io_ranks > 0 && size - io_ranks < io_ranks)
    throw std::invalid_argument(
        fmt::format("--io-ranks {} with {} ranks in all leaves {} compute ranks; each I/O rank needs at "
                    "least one compute rank "
                    "(start more ranks: mpirun -np P+Q)",
                    io_ranks, size, size - io_ranks));
  RankLayout L;
  L.world_rank = rank;
  L.n_io = io_ranks;
  L.n_compute = size - io_ranks;
  L.is_io = rank >= L.n_compute;
  MPI_Comm_dup(world, &L.bridge);
  MPI_Comm part = MPI_COMM_NULL;
  MPI_Comm_split(world, L.is_io ? 1 : 0, rank, &part);
  if (L.is_io) {
    L.io = part;
    const int idx = rank - L.n_compute;
    for (int c = 0; c < L.n_compute; ++c)
      if (c % io_ranks == idx) L.served.push_back(c);
  } else {
    L.compute = part;
    if (io_ranks > 0) L.my_io_rank = L.n_compute + rank % io_ranks;
  }
  return L;
}

void free_layout(RankLayout& L) {
  for (MPI_Comm* c : {&L.compute, &L.io, &L.bridge})
    if (*c != MPI_COMM_NULL) MPI_Comm_free(c);
}

}  // namespace basalt::io
