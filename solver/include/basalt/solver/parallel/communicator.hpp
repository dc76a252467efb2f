#pragma once
// The compute communicator and the collectives the solver needs. With parallel/decomposition.hpp
// and parallel/halo.hpp, the only place in the solver that calls MPI.
#include <mpi.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

namespace basalt::solver {

class Comm {
 public:
  explicit Comm(MPI_Comm comm);
  MPI_Comm raw() const { return comm_; }
  int rank() const { return rank_; }
  int size() const { return size_; }

  double max(double v) const;
  double min(double v) const;
  double sum(double v) const;
  long long sum(long long v) const;
  /// Element-wise sum, result valid on rank 0 only.
  void sum_to_root(std::vector<double>& v) const;
  /// Element-wise sum on every rank.
  void sum_all(std::vector<double>& v) const;
  /// (value, rank) of the largest value across ranks.
  std::pair<double, int> max_loc(double v) const;
  /// Every rank's values, concatenated in rank order, on every rank.
  std::vector<double> all_gather(const std::vector<double>& v) const;
  /// Every rank's value, in rank order, on every rank.
  std::vector<std::int64_t> all_gather(std::int64_t v) const;
  /// Every rank's values, concatenated in rank order.
  std::vector<std::int64_t> all_gather_ids(const std::vector<std::int64_t>& v) const;
  /// Broadcasts a string from `root`.
  std::string broadcast(const std::string& s, int root) const;
  /// Collective: if any rank has an error, every rank gets the message of the lowest such rank.
  std::optional<std::string> agree_error(const std::optional<std::string>& local) const;
  void barrier() const;
  /// Collective personalised exchange (MPI_Alltoallv): sends out[r] to rank r and returns what every rank
  /// sent this one, concatenated in rank order; `counts` (if given) receives how many came from each rank.
  template <class T>
  std::vector<T> exchange(const std::vector<std::vector<T>>& out,
                          std::vector<std::size_t>* counts = nullptr) const {
    static_assert(std::is_trivially_copyable_v<T>, "exchange sends raw bytes");
    std::vector<std::size_t> send_counts(out.size());
    std::size_t total = 0;
    for (std::size_t r = 0; r < out.size(); ++r) total += send_counts[r] = out[r].size();
    std::vector<T> send;
    send.reserve(total);
    for (const auto& v : out) send.insert(send.end(), v.begin(), v.end());
    std::vector<std::size_t> recv_counts;
    std::vector<T> recv;
    exchange_raw(send.data(), send_counts, sizeof(T), recv_counts,
                 [&](std::size_t n) { return static_cast<void*>((recv.resize(n), recv.data())); });
    if (counts) *counts = std::move(recv_counts);
    return recv;
  }
  /// The same, releasing each out[r] once copied into the send buffer: one copy of the data sent is held,
  /// not two (restart and start-up route files' rows this way: peak memory).
  template <class T>
  std::vector<T> exchange(std::vector<std::vector<T>>&& out,
                          std::vector<std::size_t>* counts = nullptr) const {
    static_assert(std::is_trivially_copyable_v<T>, "exchange sends raw bytes");
    std::vector<std::size_t> send_counts(out.size());
    std::size_t total = 0;
    for (std::size_t r = 0; r < out.size(); ++r) total += send_counts[r] = out[r].size();
    std::vector<T> send;
    send.reserve(total);
    for (auto& v : out) {
      send.insert(send.end(), v.begin(), v.end());
      std::vector<T>().swap(v);
    }
    std::vector<std::size_t> recv_counts;
    std::vector<T> recv;
    exchange_raw(send.data(), send_counts, sizeof(T), recv_counts,
                 [&](std::size_t n) { return static_cast<void*>((recv.resize(n), recv.data())); });
    if (counts) *counts = std::move(recv_counts);
    return recv;
  }

 private:
  template <class F>
  void exchange_raw(const void* send, const std::vector<std::size_t>& send_counts, std::size_t bytes,
                    std::vector<std::size_t>& recv_counts, F&& allocate) const {
    std::vector<int> sc, sd, rc, rd;
    const std::size_t n = prepare_exchange(send_counts, sc, sd, rc, rd, recv_counts);
    void* recv = allocate(n);
    alltoallv(send, sc, sd, recv, rc, rd, bytes);
  }
  /// Counts and displacements for alltoallv (exchanges the counts); returns the number of elements to
  /// receive.
  std::size_t prepare_exchange(const std::vector<std::size_t>& send_counts, std::vector<int>& sc,
                               std::vector<int>& sd, std::vector<int>& rc, std::vector<int>& rd,
                               std::vector<std::size_t>& recv_counts) const;
  void alltoallv(const void* send, const std::vector<int>& sc, const std::vector<int>& sd, void* recv,
                 const std::vector<int>& rc, const std::vector<int>& rd, std::size_t bytes) const;

  MPI_Comm comm_;
  int rank_ = 0;
  int size_ = 1;
};

/// A non-blocking element-wise sum to rank 0: start() posts it, finish() waits and returns the sums
/// (meaningful on rank 0). Lets field-saver reductions overlap the next step's work.
class AsyncSum {
 public:
  explicit AsyncSum(const Comm& comm) : comm_(comm) {}
  ~AsyncSum();
  AsyncSum(const AsyncSum&) = delete;
  AsyncSum& operator=(const AsyncSum&) = delete;
  bool active() const { return active_; }
  void start(std::vector<double> values);
  const std::vector<double>& finish();

 private:
  const Comm& comm_;
  std::vector<double> send_, recv_;
  MPI_Request request_ = MPI_REQUEST_NULL;
  bool active_ = false;
};

/// Collective: runs f on this rank; if it throws on any rank, every rank throws the same E with the lowest
/// such rank's message, `prefix` before it (the sliced start-up and restart read their slices this way).
template <class E, class F>
void agreed(const Comm& comm, F&& f, std::string_view prefix = {}) {
  std::optional<std::string> error;
  try {
    f();
  } catch (const std::exception& e) {
    error = std::string(prefix) + e.what();
  }
  if (auto e = comm.agree_error(error)) throw E(*e);
}

}  // namespace basalt::solver
