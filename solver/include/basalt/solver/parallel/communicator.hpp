#pragma once
// The compute communicator and the collectives the solver needs. With parallel/decomposition.hpp
// and parallel/halo.hpp, the only place in the solver that calls MPI.
#include <mpi.h>

#include <array>
#include <optional>
#include <string>
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
  /// Broadcasts a string from `root`.
  std::string broadcast(const std::string& s, int root) const;
  /// Collective: if any rank has an error, every rank gets the message of the lowest such rank.
  std::optional<std::string> agree_error(const std::optional<std::string>& local) const;
  void barrier() const;

 private:
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

}  // namespace basalt::solver
