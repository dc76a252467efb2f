#include "messages.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <climits>
#include <stdexcept>
#include <thread>

#include "basalt/io/io_ranks.hpp"

namespace basalt::io {

namespace detail {

int checked_count(std::size_t bytes) {
  if (bytes > static_cast<std::size_t>(INT_MAX))
    throw std::runtime_error(
        fmt::format("output frame of {} bytes exceeds MPI's 2 GiB message limit: "
                    "use more compute ranks",
                    bytes));
  return static_cast<int>(bytes);
}

void Backoff::sleep() {
  std::this_thread::sleep_for(pause_);
  pause_ = std::min(pause_ * 2, std::chrono::microseconds(2000));
}

void receive_without_spinning(int source, int tag, MPI_Comm comm, std::vector<std::byte>& bytes) {
  MPI_Status st;
  int flag = 0;
  Backoff backoff;
  for (MPI_Iprobe(source, tag, comm, &flag, &st); !flag; MPI_Iprobe(source, tag, comm, &flag, &st))
    backoff.sleep();
  int n = 0;
  MPI_Get_count(&st, MPI_BYTE, &n);
  bytes.resize(n);
  MPI_Recv(bytes.data(), n, MPI_BYTE, source, tag, comm, MPI_STATUS_IGNORE);
}

}  // namespace detail

void wait_without_spinning(MPI_Request& request, MPI_Status* status) {
  int done = 0;
  detail::Backoff backoff;
  for (MPI_Test(&request, &done, status); !done; MPI_Test(&request, &done, status)) backoff.sleep();
}

}  // namespace basalt::io
