#include "basalt/solver/parallel/communicator.hpp"

#include <climits>
#include <stdexcept>

namespace basalt::solver {

Comm::Comm(MPI_Comm comm) : comm_(comm) {
  MPI_Comm_rank(comm_, &rank_);
  MPI_Comm_size(comm_, &size_);
}

double Comm::max(double v) const {
  double out = v;
  MPI_Allreduce(&v, &out, 1, MPI_DOUBLE, MPI_MAX, comm_);
  return out;
}

double Comm::min(double v) const {
  double out = v;
  MPI_Allreduce(&v, &out, 1, MPI_DOUBLE, MPI_MIN, comm_);
  return out;
}

double Comm::sum(double v) const {
  double out = v;
  MPI_Allreduce(&v, &out, 1, MPI_DOUBLE, MPI_SUM, comm_);
  return out;
}

long long Comm::sum(long long v) const {
  long long out = v;
  MPI_Allreduce(&v, &out, 1, MPI_LONG_LONG, MPI_SUM, comm_);
  return out;
}

void Comm::sum_to_root(std::vector<double>& v) const {
  if (size_ == 1 || v.empty()) return;
  if (rank_ == 0)
    MPI_Reduce(MPI_IN_PLACE, v.data(), static_cast<int>(v.size()), MPI_DOUBLE, MPI_SUM, 0, comm_);
  else
    MPI_Reduce(v.data(), nullptr, static_cast<int>(v.size()), MPI_DOUBLE, MPI_SUM, 0, comm_);
}

void Comm::sum_all(std::vector<double>& v) const {
  if (size_ == 1 || v.empty()) return;
  MPI_Allreduce(MPI_IN_PLACE, v.data(), static_cast<int>(v.size()), MPI_DOUBLE, MPI_SUM, comm_);
}

std::pair<double, int> Comm::max_loc(double v) const {
  struct {
    double v;
    int r;
  } in{v, rank_}, out{v, rank_};
  MPI_Allreduce(&in, &out, 1, MPI_DOUBLE_INT, MPI_MAXLOC, comm_);
  return {out.v, out.r};
}

std::vector<double> Comm::all_gather(const std::vector<double>& v) const {
  if (size_ == 1) return v;
  const int n = static_cast<int>(v.size());
  std::vector<int> counts(static_cast<std::size_t>(size_)), displs(static_cast<std::size_t>(size_), 0);
  MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, comm_);
  for (std::size_t r = 1; r < counts.size(); ++r) displs[r] = displs[r - 1] + counts[r - 1];
  std::vector<double> all(static_cast<std::size_t>(displs.back() + counts.back()));
  MPI_Allgatherv(v.data(), n, MPI_DOUBLE, all.data(), counts.data(), displs.data(), MPI_DOUBLE, comm_);
  return all;
}

std::vector<std::int64_t> Comm::all_gather(std::int64_t v) const {
  std::vector<std::int64_t> all(static_cast<std::size_t>(size_));
  MPI_Allgather(&v, 1, MPI_INT64_T, all.data(), 1, MPI_INT64_T, comm_);
  return all;
}

std::vector<std::int64_t> Comm::all_gather_ids(const std::vector<std::int64_t>& v) const {
  if (size_ == 1) return v;
  const int n = static_cast<int>(v.size());
  std::vector<int> counts(static_cast<std::size_t>(size_)), displs(static_cast<std::size_t>(size_), 0);
  MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, comm_);
  for (std::size_t r = 1; r < counts.size(); ++r) displs[r] = displs[r - 1] + counts[r - 1];
  std::vector<std::int64_t> all(static_cast<std::size_t>(displs.back() + counts.back()));
  MPI_Allgatherv(v.data(), n, MPI_INT64_T, all.data(), counts.data(), displs.data(), MPI_INT64_T, comm_);
  return all;
}

std::string Comm::broadcast(const std::string& s, int root) const {
  if (size_ == 1) return s;
  int n = static_cast<int>(s.size());
  MPI_Bcast(&n, 1, MPI_INT, root, comm_);
  std::string out = rank_ == root ? s : std::string(static_cast<std::size_t>(n), '\0');
  MPI_Bcast(out.data(), n, MPI_CHAR, root, comm_);
  return out;
}

std::optional<std::string> Comm::agree_error(const std::optional<std::string>& local) const {
  int mine = local ? rank_ : size_;
  int first = mine;
  MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, comm_);
  if (first == size_) return std::nullopt;
  return broadcast(local ? *local : std::string(), first);
}

void Comm::barrier() const { MPI_Barrier(comm_); }

std::size_t Comm::prepare_exchange(const std::vector<std::size_t>& send_counts, std::vector<int>& sc,
                                   std::vector<int>& sd, std::vector<int>& rc, std::vector<int>& rd,
                                   std::vector<std::size_t>& recv_counts) const {
  const auto p = static_cast<std::size_t>(size_);
  sc.assign(p, 0);
  sd.assign(p, 0);
  rc.assign(p, 0);
  rd.assign(p, 0);
  long long sent = 0;
  for (std::size_t r = 0; r < p && r < send_counts.size(); ++r) {
    sc[r] = static_cast<int>(send_counts[r]);
    sd[r] = static_cast<int>(sent);
    sent += static_cast<long long>(send_counts[r]);
  }
  MPI_Alltoall(sc.data(), 1, MPI_INT, rc.data(), 1, MPI_INT, comm_);
  long long received = 0;
  recv_counts.assign(p, 0);
  for (std::size_t r = 0; r < p; ++r) {
    rd[r] = static_cast<int>(received);
    recv_counts[r] = static_cast<std::size_t>(rc[r]);
    received += rc[r];
  }
  // Displacements are ints in elements of the exchanged record type.
  if (sent > INT_MAX || received > INT_MAX)
    throw std::length_error("Comm::exchange: more than 2^31 records to or from one rank");
  return static_cast<std::size_t>(received);
}

void Comm::alltoallv(const void* send, const std::vector<int>& sc, const std::vector<int>& sd, void* recv,
                     const std::vector<int>& rc, const std::vector<int>& rd, std::size_t bytes) const {
  MPI_Datatype record = MPI_DATATYPE_NULL;
  MPI_Type_contiguous(static_cast<int>(bytes), MPI_BYTE, &record);
  MPI_Type_commit(&record);
  MPI_Alltoallv(send, sc.data(), sd.data(), record, recv, rc.data(), rd.data(), record, comm_);
  MPI_Type_free(&record);
}

AsyncSum::~AsyncSum() {
  if (active_) MPI_Wait(&request_, MPI_STATUS_IGNORE);
}

void AsyncSum::start(std::vector<double> values) {
  if (active_) finish();
  send_ = std::move(values);
  recv_.assign(send_.size(), 0.0);
  MPI_Ireduce(send_.data(), recv_.data(), static_cast<int>(send_.size()), MPI_DOUBLE, MPI_SUM, 0, comm_.raw(),
              &request_);
  active_ = true;
}

const std::vector<double>& AsyncSum::finish() {
  if (active_) MPI_Wait(&request_, MPI_STATUS_IGNORE);
  active_ = false;
  return recv_;
}

}  // namespace basalt::solver
