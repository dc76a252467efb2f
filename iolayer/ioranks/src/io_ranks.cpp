#include "basalt/io/io_ranks.hpp"

#include <fmt/format.h>
#include <sys/resource.h>

#include <algorithm>
#include <climits>
#include <cstring>
#include <deque>
#include <map>
#include <memory>
#include <stdexcept>
#include <thread>

#include "field_series.hpp"

namespace basalt::io {

namespace {

enum Tag : int { kTagInfo = 701, kTagFrame, kTagFields, kTagDone, kTagError, kTagGather };

// Report layout for the final reductions.
enum SumSlot {
  kCkptFiles,
  kCkptBytes,
  kFrameFiles,
  kFrameBytes,
  kFieldFiles,
  kFieldBytes,
  kFramesSent,
  kErrors,
  kSumSlots
};
enum MaxSlot { kCkptSeconds, kFrameSeconds, kFieldSeconds, kWaitSeconds, kIoCpu, kIoWall, kMaxSlots };

int checked_count(std::size_t bytes) {
  if (bytes > static_cast<std::size_t>(INT_MAX))
    throw std::runtime_error(
        fmt::format("output frame of {} bytes exceeds MPI's 2 GiB message limit: "
                    "use more compute ranks",
                    bytes));
  return static_cast<int>(bytes);
}

/// CPU time (user + system) of this process so far: shows that an idle I/O rank sleeps.
double process_cpu_seconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

void throttle(double mb_per_s, std::uint64_t bytes, double elapsed) {
  if (mb_per_s <= 0) return;
  const double want = static_cast<double>(bytes) / (mb_per_s * 1e6);
  if (want > elapsed) std::this_thread::sleep_for(std::chrono::duration<double>(want - elapsed));
}

std::uint64_t file_size_or_zero(const std::filesystem::path& p) {
  std::error_code ec;
  auto s = std::filesystem::file_size(p, ec);
  return ec ? 0 : s;
}

std::filesystem::path checkpoint_path(const std::filesystem::path& dir, std::int64_t step) {
  return dir / fmt::format("ckpt_{:06d}.h5", step);
}

/// Writes one assembled checkpoint; returns bytes written.
std::uint64_t write_checkpoint_step(std::vector<FramePiece>& pieces, const RunInfo& info,
                                    const OutputConfig& cfg, OutputKindReport& rep) {
  const double t0 = MPI_Wtime();
  Checkpoint c = assemble(pieces, info);
  const auto path = checkpoint_path(cfg.dir, c.step);
  write_checkpoint(c, path);
  const auto bytes = file_size_or_zero(path);
  throttle(cfg.throttle_mb_per_s, bytes, MPI_Wtime() - t0);
  rep.files += 1;
  rep.bytes += bytes;
  rep.write_seconds += MPI_Wtime() - t0;
  return bytes;
}

void concat_pieces(const std::vector<FramePiece>& pieces, std::vector<std::byte>& out) {
  out.clear();
  std::vector<std::byte> one;
  for (const auto& p : pieces) {
    serialize(p, one);
    const std::uint64_t n = one.size();
    const std::size_t at = out.size();
    out.resize(at + sizeof(n) + one.size());
    std::memcpy(out.data() + at, &n, sizeof(n));
    std::memcpy(out.data() + at + sizeof(n), one.data(), one.size());
  }
}

void split_pieces(std::span<const std::byte> bytes, std::vector<FramePiece>& out) {
  std::size_t pos = 0;
  while (pos < bytes.size()) {
    std::uint64_t n = 0;
    if (bytes.size() - pos < sizeof(n)) throw std::runtime_error("gathered frame: truncated length");
    std::memcpy(&n, bytes.data() + pos, sizeof(n));
    pos += sizeof(n);
    if (n > bytes.size() - pos) throw std::runtime_error("gathered frame: truncated piece");
    out.push_back(deserialize(bytes.subspan(pos, n)));
    pos += n;
  }
}

/// Sums and maxima of the report over every rank of `comm`; the first error text travels too.
OutputReport reduce_report(MPI_Comm comm, const OutputReport& mine) {
  double sums[kSumSlots] = {double(mine.checkpoints.files), double(mine.checkpoints.bytes),
                            double(mine.frames.files),      double(mine.frames.bytes),
                            double(mine.fields.files),      double(mine.fields.bytes),
                            double(mine.frames_sent),       mine.error ? 1.0 : 0.0};
  double maxs[kMaxSlots] = {
      mine.checkpoints.write_seconds, mine.frames.write_seconds, mine.fields.write_seconds,
      mine.compute_wait_seconds,      mine.io_cpu_seconds,       mine.io_wall_seconds};
  double gsum[kSumSlots], gmax[kMaxSlots];
  MPI_Allreduce(sums, gsum, kSumSlots, MPI_DOUBLE, MPI_SUM, comm);
  MPI_Allreduce(maxs, gmax, kMaxSlots, MPI_DOUBLE, MPI_MAX, comm);
  OutputReport r;
  r.checkpoints = {std::uint64_t(gsum[kCkptFiles]), std::uint64_t(gsum[kCkptBytes]), gmax[kCkptSeconds]};
  r.frames = {std::uint64_t(gsum[kFrameFiles]), std::uint64_t(gsum[kFrameBytes]), gmax[kFrameSeconds]};
  r.fields = {std::uint64_t(gsum[kFieldFiles]), std::uint64_t(gsum[kFieldBytes]), gmax[kFieldSeconds]};
  r.frames_sent = std::uint64_t(gsum[kFramesSent]);
  r.compute_wait_seconds = gmax[kWaitSeconds];
  r.io_cpu_seconds = gmax[kIoCpu];
  r.io_wall_seconds = gmax[kIoWall];
  if (gsum[kErrors] > 0) {
    int rank = 0;
    MPI_Comm_rank(comm, &rank);
    int candidate = mine.error ? rank : INT_MAX, first = 0;
    MPI_Allreduce(&candidate, &first, 1, MPI_INT, MPI_MIN, comm);
    std::string text = mine.error.value_or("");
    int len = static_cast<int>(text.size());
    MPI_Bcast(&len, 1, MPI_INT, first, comm);
    text.resize(len);
    MPI_Bcast(text.data(), len, MPI_CHAR, first, comm);
    r.error = text;
  }
  return r;
}

/// Sleeps between polls, 20 us doubling up to 2 ms: Open MPI's blocking calls busy-poll, and an
/// I/O rank waiting for work must not burn a core.
class Backoff {
 public:
  void sleep() {
    std::this_thread::sleep_for(pause_);
    pause_ = std::min(pause_ * 2, std::chrono::microseconds(2000));
  }
  void reset() { pause_ = std::chrono::microseconds(20); }

 private:
  std::chrono::microseconds pause_{20};
};

/// Receives the next message from `source` with `tag` (any size), sleeping while none is there.
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

}  // namespace

void wait_without_spinning(MPI_Request& request, MPI_Status* status) {
  int done = 0;
  Backoff backoff;
  for (MPI_Test(&request, &done, status); !done; MPI_Test(&request, &done, status)) backoff.sleep();
}

// ------------------------------------------------------------------------------------------
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

// ------------------------------------------------------------------------------------------
struct OutputClient::Impl {
  Impl(const RankLayout& l, OutputConfig c, RunInfo i, VtkFrameWriter v)
      : layout(l), cfg(std::move(c)), info(std::move(i)), vtk(std::move(v)) {}
  RankLayout layout;
  OutputConfig cfg;
  RunInfo info;
  VtkFrameWriter vtk;
  int compute_rank = 0;

  struct InFlight {
    std::vector<std::byte> bytes;
    MPI_Request request = MPI_REQUEST_NULL;
  };
  std::deque<InFlight> frames_in_flight;
  std::deque<InFlight> fields_in_flight;
  std::vector<std::vector<std::byte>> spare;  // buffers to reuse (keeps capacity)
  std::vector<std::byte> gather_buffer;       // Q = 0: this rank's frame (reused)

  std::vector<double> field_rows;  // [step, time, v...] per row
  std::size_t field_rows_count = 0;
  std::unique_ptr<detail::FieldSeriesWriter> csv;  // Q = 0, compute rank 0

  OutputReport local;  // Q = 0: what this rank wrote; always: its wait time
  int errors_received = 0;

  bool async() const { return layout.n_io > 0; }

  std::vector<std::byte> take_buffer() {
    if (spare.empty()) return {};
    auto b = std::move(spare.back());
    spare.pop_back();
    return b;
  }

  void complete_front(std::deque<InFlight>& q, bool block) {
    while (!q.empty()) {
      int done = 0;
      if (block) {
        const double t0 = MPI_Wtime();
        // A compute rank blocked on a full queue sleeps too: on a shared node its core is what the
        // I/O rank may need to drain the queue.
        wait_without_spinning(q.front().request);
        local.compute_wait_seconds += MPI_Wtime() - t0;
        done = 1;
      } else {
        MPI_Test(&q.front().request, &done, MPI_STATUS_IGNORE);
      }
      if (!done) return;
      // Only frame buffers are kept for reuse: a small field batch handed to the next frame would be
      // grown to the frame's size again, page by page (~50 ms per checkpoint on 590 k particles).
      if (&q == &frames_in_flight) spare.push_back(std::move(q.front().bytes));
      q.pop_front();
      if (block) return;
    }
  }

  /// Q = 0: sums the buffered rows over the compute ranks; compute rank 0 appends them to fields.csv.
  void reduce_field_batch(std::optional<std::string>& error) {
    if (field_rows_count == 0) return;
    const double t0 = MPI_Wtime();
    std::vector<double> sums(compute_rank == 0 ? field_rows.size() : 0);
    MPI_Reduce(field_rows.data(), sums.data(), static_cast<int>(field_rows.size()), MPI_DOUBLE, MPI_SUM, 0,
               layout.compute);
    if (csv && !local.error) {
      // Step and time were summed too: rank 0's own are the row's.
      const std::size_t width = field_rows.size() / field_rows_count;
      for (std::size_t r = 0; r < field_rows_count; ++r) {
        const double* row = field_rows.data() + r * width;
        csv->append(static_cast<std::int64_t>(row[0]), row[1],
                    std::span<const double>(sums.data() + r * width + 2, width - 2));
      }
      try {
        csv->flush();
      } catch (const std::exception& e) {
        local.error = e.what();
        error = local.error;
      }
    }
    field_rows.clear();
    field_rows_count = 0;
    local.compute_wait_seconds += MPI_Wtime() - t0;
  }

  void send_field_batch() {
    if (field_rows_count == 0) return;
    InFlight f;
    f.bytes.resize(field_rows.size() * sizeof(double));
    std::memcpy(f.bytes.data(), field_rows.data(), f.bytes.size());
    MPI_Isend(f.bytes.data(), checked_count(f.bytes.size()), MPI_BYTE, layout.io_bridge_rank(0), kTagFields,
              layout.bridge, &f.request);
    fields_in_flight.push_back(std::move(f));
    field_rows.clear();
    field_rows_count = 0;
  }
};

OutputClient::OutputClient(const RankLayout& layout, OutputConfig config, RunInfo info, VtkFrameWriter vtk)
    : impl_(new Impl(layout, std::move(config), std::move(info), std::move(vtk))) {
  auto& I = *impl_;
  MPI_Comm_rank(layout.compute, &I.compute_rank);
  if (I.async()) {
    if (I.compute_rank == 0) {
      std::vector<std::byte> bytes;
      serialize(I.info, bytes);
      for (int q = 0; q < layout.n_io; ++q)
        MPI_Send(bytes.data(), checked_count(bytes.size()), MPI_BYTE, layout.io_bridge_rank(q), kTagInfo,
                 layout.bridge);
    }
  } else if (I.compute_rank == 0 && I.cfg.fields_every > 0) {
    try {
      I.csv = std::make_unique<detail::FieldSeriesWriter>(I.cfg.dir / "fields.csv", I.cfg.field_names,
                                                          I.cfg.append_fields);
    } catch (const std::exception& e) {
      I.local.error = e.what();
    }
  }
  if (!I.async()) {
    int bad = I.local.error ? 1 : 0;
    MPI_Bcast(&bad, 1, MPI_INT, 0, layout.compute);
    if (bad && !I.local.error) I.local.error = "fields.csv could not be opened on compute rank 0";
    error_ = I.local.error;
  }
}

OutputClient::~OutputClient() { delete impl_; }

std::uint32_t OutputClient::frame_kinds(std::int64_t step) const {
  std::uint32_t k = 0;
  const auto& c = impl_->cfg;
  if (c.checkpoint_every > 0 && step % c.checkpoint_every == 0) k |= kFrameCheckpoint;
  if (c.frames_every > 0 && impl_->vtk && step % c.frames_every == 0) k |= kFrameVtk;
  return k;
}

bool OutputClient::wants_fields(std::int64_t step) const {
  const auto& c = impl_->cfg;
  return c.fields_every > 0 && !c.field_names.empty() && step % c.fields_every == 0;
}

void OutputClient::submit_frame(const FramePiece& piece) { submit_frame(PieceSource(piece)); }

void OutputClient::submit_frame(const FrameSource& source) {
  auto& I = *impl_;
  if (I.async()) {
    poll();
    if (static_cast<int>(I.frames_in_flight.size()) >= std::max(1, I.cfg.max_frames_in_flight))
      I.complete_front(I.frames_in_flight, /*block=*/true);
    Impl::InFlight f;
    f.bytes = I.take_buffer();
    serialize(source, f.bytes);  // written once, in place: the buffer is what is sent
    MPI_Isend(f.bytes.data(), checked_count(f.bytes.size()), MPI_BYTE, I.layout.my_io_rank, kTagFrame,
              I.layout.bridge, &f.request);
    I.frames_in_flight.push_back(std::move(f));
    ++I.local.frames_sent;
    return;
  }
  // Q = 0: gather to compute rank 0, which writes before anyone goes on (the baseline).
  const double t0 = MPI_Wtime();
  std::vector<std::byte>& mine = I.gather_buffer;
  const FrameHeader header = source.header();
  serialize(source, mine);
  int n = checked_count(mine.size()), size = 1;
  MPI_Comm_size(I.layout.compute, &size);
  std::vector<int> counts(size), displs(size);
  MPI_Gather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, I.layout.compute);
  std::vector<std::byte> all;
  if (I.compute_rank == 0) {
    std::size_t total = 0;
    for (int r = 0; r < size; ++r) {
      displs[r] = static_cast<int>(total);
      total += counts[r];
    }
    all.resize(checked_count(total));
  }
  MPI_Gatherv(mine.data(), n, MPI_BYTE, all.data(), counts.data(), displs.data(), MPI_BYTE, 0,
              I.layout.compute);
  int bad = 0;
  if (I.compute_rank == 0 && !I.local.error) {
    try {
      std::vector<FramePiece> pieces;
      for (int r = 0; r < size; ++r)
        pieces.push_back(deserialize(std::span<const std::byte>(all).subspan(displs[r], counts[r])));
      if (header.kinds & kFrameVtk) {
        const double tv = MPI_Wtime();
        I.local.frames.bytes += I.vtk(pieces, header.step, header.time, 0, 1, I.cfg.dir);
        I.local.frames.files += 1;
        I.local.frames.write_seconds += MPI_Wtime() - tv;
      }
      if (header.kinds & kFrameCheckpoint) write_checkpoint_step(pieces, I.info, I.cfg, I.local.checkpoints);
    } catch (const std::exception& e) {
      I.local.error = e.what();
      bad = 1;
    }
  }
  MPI_Bcast(&bad, 1, MPI_INT, 0, I.layout.compute);
  if (bad) {
    int len = I.local.error ? static_cast<int>(I.local.error->size()) : 0;
    MPI_Bcast(&len, 1, MPI_INT, 0, I.layout.compute);
    std::string text = I.local.error.value_or(std::string(len, ' '));
    MPI_Bcast(text.data(), len, MPI_CHAR, 0, I.layout.compute);
    if (!error_) error_ = text;
  }
  I.local.compute_wait_seconds += MPI_Wtime() - t0;
}

void OutputClient::submit_fields(std::int64_t step, double time, std::span<const double> partials) {
  auto& I = *impl_;
  if (I.async()) {
    I.field_rows.push_back(static_cast<double>(step));
    I.field_rows.push_back(time);
    I.field_rows.insert(I.field_rows.end(), partials.begin(), partials.end());
    if (++I.field_rows_count >= static_cast<std::size_t>(std::max(1, I.cfg.field_batch_rows)))
      I.send_field_batch();
    return;
  }
  // Q = 0: the rows are summed a batch at a time (one reduction per batch, not a per-step collective
  // that would make every rank wait for the slowest at every step) and written by compute rank 0.
  I.field_rows.push_back(static_cast<double>(step));
  I.field_rows.push_back(time);
  I.field_rows.insert(I.field_rows.end(), partials.begin(), partials.end());
  if (++I.field_rows_count >= static_cast<std::size_t>(std::max(1, I.cfg.field_batch_rows)))
    I.reduce_field_batch(error_);
}

void OutputClient::poll() {
  auto& I = *impl_;
  if (!I.async()) return;
  I.complete_front(I.frames_in_flight, false);
  I.complete_front(I.fields_in_flight, false);
  int flag = 0;
  MPI_Status st;
  MPI_Iprobe(MPI_ANY_SOURCE, kTagError, I.layout.bridge, &flag, &st);
  while (flag) {
    int len = 0;
    MPI_Get_count(&st, MPI_CHAR, &len);
    std::string text(len, ' ');
    MPI_Recv(text.data(), len, MPI_CHAR, st.MPI_SOURCE, kTagError, I.layout.bridge, MPI_STATUS_IGNORE);
    ++I.errors_received;
    if (!error_) error_ = text;
    MPI_Iprobe(MPI_ANY_SOURCE, kTagError, I.layout.bridge, &flag, &st);
  }
}

OutputReport OutputClient::finish() {
  auto& I = *impl_;
  if (I.async()) {
    I.send_field_batch();
    while (!I.frames_in_flight.empty()) I.complete_front(I.frames_in_flight, true);
    while (!I.fields_in_flight.empty()) I.complete_front(I.fields_in_flight, true);
    for (int q = 0; q < I.layout.n_io; ++q)
      MPI_Send(nullptr, 0, MPI_BYTE, I.layout.io_bridge_rank(q), kTagDone, I.layout.bridge);
  } else {
    I.reduce_field_batch(error_);
  }
  if (!I.async() && I.csv) {
    const double t0 = MPI_Wtime();
    try {
      I.csv->flush();
    } catch (const std::exception& e) {
      if (!I.local.error) I.local.error = e.what();
    }
    I.local.fields.files = 1;
    I.local.fields.bytes = I.csv->bytes();
    I.local.fields.write_seconds = I.csv->seconds();
    I.local.compute_wait_seconds += MPI_Wtime() - t0;
    I.csv.reset();
  }
  // Error messages the I/O ranks sent to this rank: each I/O rank sends at most one per compute
  // rank; the count travels in the reduction so none is left unreceived.
  OutputReport mine = I.local;
  if (!mine.error && error_) mine.error = error_;
  OutputReport all = reduce_report(I.layout.bridge, mine);
  if (I.async()) {
    int expected = 0, zero = 0;
    MPI_Allreduce(&zero, &expected, 1, MPI_INT, MPI_SUM, I.layout.bridge);
    while (I.errors_received < expected) {
      MPI_Status st;
      MPI_Probe(MPI_ANY_SOURCE, kTagError, I.layout.bridge, &st);
      poll();
    }
  }
  if (all.error) error_ = all.error;
  return all;
}

// ------------------------------------------------------------------------------------------
IoServer::IoServer(const RankLayout& layout, OutputConfig config, VtkFrameWriter vtk)
    : layout_(layout), config_(std::move(config)), vtk_(std::move(vtk)) {}

OutputReport IoServer::run() {
  const RankLayout& L = layout_;
  const int io_index = L.world_rank - L.n_compute;
  OutputReport local;
  const double wall0 = MPI_Wtime();
  const double cpu0 = process_cpu_seconds();
  int errors_sent = 0;

  auto report_error = [&](const std::string& text) {
    if (local.error) return;  // one error message per compute rank at most
    local.error = text;
    for (int c = 0; c < L.n_compute; ++c) {
      MPI_Send(text.data(), static_cast<int>(text.size()), MPI_CHAR, c, kTagError, L.bridge);
    }
    errors_sent = 1;
  };

  // The run's fixed information, from compute rank 0.
  RunInfo info;
  {
    std::vector<std::byte> bytes;
    receive_without_spinning(0, kTagInfo, L.bridge, bytes);
    info = deserialize_run_info(bytes);
  }

  std::unique_ptr<detail::FieldSeriesWriter> csv;
  if (io_index == 0 && config_.fields_every > 0 && !config_.field_names.empty()) {
    try {
      csv = std::make_unique<detail::FieldSeriesWriter>(config_.dir / "fields.csv", config_.field_names,
                                                        config_.append_fields);
    } catch (const std::exception& e) {
      report_error(e.what());
    }
  }
  const std::size_t n_fields = config_.field_names.size();
  struct Row {
    double time = 0;
    std::vector<double> sum;
    int count = 0;
  };
  std::map<std::int64_t, Row> rows;
  bool fields_failed = !csv && io_index == 0 && config_.fields_every > 0;
  bool checkpoints_failed = false, frames_failed = false;

  std::map<std::int64_t, std::vector<FramePiece>> pending;
  std::vector<std::byte> buffer, gathered;

  auto process_step = [&](std::int64_t step) {
    auto& pieces = pending[step];
    const auto kinds = pieces.front().kinds;
    if ((kinds & kFrameVtk) && vtk_ && !frames_failed) {
      try {
        const double t0 = MPI_Wtime();
        const auto bytes = vtk_(pieces, step, pieces.front().time, io_index, L.n_io, config_.dir);
        throttle(config_.throttle_mb_per_s, bytes, MPI_Wtime() - t0);
        local.frames.files += 1;
        local.frames.bytes += bytes;
        local.frames.write_seconds += MPI_Wtime() - t0;
      } catch (const std::exception& e) {
        frames_failed = true;
        report_error(e.what());
      }
    }
    if (kinds & kFrameCheckpoint) {
      if (L.n_io == 1) {
        if (!checkpoints_failed) try {
            write_checkpoint_step(pieces, info, config_, local.checkpoints);
          } catch (const std::exception& e) {
            checkpoints_failed = true;
            report_error(e.what());
          }
      } else if (io_index != 0) {
        // One file per checkpoint: hand the pieces to I/O rank 0, which writes it.
        concat_pieces(pieces, gathered);
        MPI_Request req;
        MPI_Isend(gathered.data(), checked_count(gathered.size()), MPI_BYTE, 0, kTagGather, L.io, &req);
        wait_without_spinning(req);
      } else {
        for (int q = 1; q < L.n_io; ++q) {
          receive_without_spinning(q, kTagGather, L.io, gathered);
          split_pieces(gathered, pieces);
        }
        if (!checkpoints_failed) try {
            write_checkpoint_step(pieces, info, config_, local.checkpoints);
          } catch (const std::exception& e) {
            checkpoints_failed = true;
            report_error(e.what());
          }
      }
    }
    pending.erase(step);
  };

  int done = 0;
  Backoff backoff;
  while (done < L.n_compute) {
    int flag = 0;
    MPI_Message msg;
    MPI_Status st;
    MPI_Improbe(MPI_ANY_SOURCE, MPI_ANY_TAG, L.bridge, &flag, &msg, &st);
    if (!flag) {
      backoff.sleep();  // an idle I/O rank must not burn a core
      continue;
    }
    backoff.reset();
    int n = 0;
    MPI_Get_count(&st, MPI_BYTE, &n);
    buffer.resize(n);
    MPI_Mrecv(buffer.data(), n, MPI_BYTE, &msg, MPI_STATUS_IGNORE);
    switch (st.MPI_TAG) {
      case kTagFrame: {
        FramePiece piece = deserialize(buffer);
        const auto step = piece.step;
        auto& list = pending[step];
        list.push_back(std::move(piece));
        if (list.size() == L.served.size()) process_step(step);
        break;
      }
      case kTagFields: {
        const std::size_t width = 2 + n_fields;
        const std::size_t count = buffer.size() / sizeof(double);
        std::vector<double> values(count);
        std::memcpy(values.data(), buffer.data(), buffer.size());
        for (std::size_t r = 0; r + width <= count; r += width) {
          const auto step = static_cast<std::int64_t>(values[r]);
          auto& row = rows[step];
          if (row.sum.empty()) row.sum.assign(n_fields, 0.0);
          row.time = values[r + 1];
          for (std::size_t k = 0; k < n_fields; ++k) row.sum[k] += values[r + 2 + k];
          ++row.count;
        }
        // Rows complete in step order (every rank sends its rows in order).
        while (!rows.empty() && rows.begin()->second.count == L.n_compute) {
          if (csv && !fields_failed)
            csv->append(rows.begin()->first, rows.begin()->second.time, rows.begin()->second.sum);
          rows.erase(rows.begin());
        }
        if (csv && !fields_failed) try {
            csv->flush();
          } catch (const std::exception& e) {
            fields_failed = true;
            report_error(e.what());
          }
        break;
      }
      case kTagDone:
        ++done;
        break;
      default:
        report_error(fmt::format("I/O rank {}: unexpected message tag {} from rank {}", io_index, st.MPI_TAG,
                                 st.MPI_SOURCE));
    }
  }
  if (!pending.empty())
    report_error(fmt::format("I/O rank {}: step {} is missing pieces from some compute ranks", io_index,
                             pending.begin()->first));
  if (csv) {
    local.fields.files = 1;
    local.fields.bytes = csv->bytes();
    local.fields.write_seconds = csv->seconds();
  }
  local.io_cpu_seconds = process_cpu_seconds() - cpu0;
  local.io_wall_seconds = MPI_Wtime() - wall0;
  OutputReport all = reduce_report(L.bridge, local);
  int expected = 0;
  MPI_Allreduce(&errors_sent, &expected, 1, MPI_INT, MPI_SUM, L.bridge);
  return all;
}

}  // namespace basalt::io
