// The I/O-rank side: IoServer::run receives frames and field batches from the compute ranks it
// serves, assembles the pieces of a step and writes checkpoints (I/O rank 0 writes one file per
// step; the others forward their pieces), VTK pieces and fields.csv; it sleeps while idle.
#include <fmt/format.h>
#include <sys/resource.h>

#include <cstring>
#include <deque>
#include <map>
#include <memory>
#include <stdexcept>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include "basalt/io/io_ranks.hpp"
#include "checkpoint_step.hpp"
#include "field_series.hpp"
#include "messages.hpp"
#include "picture_queue.hpp"
#include "report_reduction.hpp"

namespace basalt::io {

using namespace detail;

namespace {

/// CPU time (user + system) of this process so far: shows that an idle I/O rank sleeps.
double process_cpu_seconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

/// The pieces of one step in one buffer (length-prefixed), for I/O rank 0 to write them.
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

/// The inverse of concat_pieces: appends the pieces in `bytes` to `out`.
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

/// One I/O rank's run: what IoServer::run does, with its state.
class Server {
 public:
  Server(const RankLayout& layout, const OutputConfig& config, const VtkFrameWriter& vtk, Pictures& pictures)
      : L_(layout),
        cfg_(config),
        vtk_(vtk),
        pictures_(pictures),
        io_index_(layout.world_rank - layout.n_compute) {}

  OutputReport run() {
#if defined(__GLIBC__)
    // Blocks of 1 MiB and more come straight from mmap on an I/O rank: freed pieces and columns go
    // back to the system at once and the core driver's growing file image moves by mremap instead of
    // being copied. glibc's own threshold rises to 32 MiB after the first large free, which left the
    // heap fragmented and the second checkpoint's peak 50 % above the first's (issue #14).
    mallopt(M_MMAP_THRESHOLD, 1 << 20);
#endif
    const double wall0 = MPI_Wtime();
    const double cpu0 = process_cpu_seconds();
    // The run's fixed information, from compute rank 0.
    receive_without_spinning(0, kTagInfo, L_.bridge, buffer_);
    info_ = deserialize_run_info(buffer_);
    open_fields();
    start_pictures();

    int done = 0;
    Backoff backoff;
    while (done < L_.n_compute) {
      int flag = 0;
      MPI_Message msg;
      MPI_Status st;
      MPI_Improbe(MPI_ANY_SOURCE, MPI_ANY_TAG, L_.bridge, &flag, &msg, &st);
      if (!flag) {
        backoff.sleep();  // an idle I/O rank must not burn a core
        continue;
      }
      backoff.reset();
      int n = 0;
      MPI_Get_count(&st, MPI_BYTE, &n);
      buffer_.resize(n);
      MPI_Mrecv(buffer_.data(), n, MPI_BYTE, &msg, MPI_STATUS_IGNORE);
      if (queue_ && !pictures_failed_) {
        if (auto e = queue_->error()) {
          pictures_failed_ = true;
          report_error(*e);
        }
      }
      switch (st.MPI_TAG) {
        case kTagFrame:
          add_piece(deserialize(buffer_));
          break;
        case kTagFields:
          add_field_batch(st.MPI_SOURCE);
          break;
        case kTagDone:
          ++done;
          break;
        default:
          report_error(fmt::format("I/O rank {}: unexpected message tag {} from rank {}", io_index_,
                                   st.MPI_TAG, st.MPI_SOURCE));
      }
    }
    if (!pending_.empty())
      report_error(fmt::format("I/O rank {}: step {} is missing pieces from some compute ranks", io_index_,
                               pending_.begin()->first));
    finish_pictures();
    if (csv_) {
      local_.fields.files = 1;
      local_.fields.bytes = csv_->bytes();
      local_.fields.write_seconds = csv_->seconds();
    }
    for (auto& a : acks_) wait_without_spinning(a.request);
    local_.io_cpu_seconds = process_cpu_seconds() - cpu0;
    local_.io_wall_seconds = MPI_Wtime() - wall0;
    OutputReport all = reduce_report(L_.bridge, local_);
    int expected = 0;
    MPI_Allreduce(&errors_sent_, &expected, 1, MPI_INT, MPI_SUM, L_.bridge);
    return all;
  }

 private:
  /// Tells every compute rank (once: one error message per compute rank at most).
  void report_error(const std::string& text) {
    if (local_.error) return;
    local_.error = text;
    for (int c = 0; c < L_.n_compute; ++c)
      MPI_Send(text.data(), static_cast<int>(text.size()), MPI_CHAR, c, kTagError, L_.bridge);
    errors_sent_ = 1;
  }

  /// I/O rank 0 writes fields.csv.
  void open_fields() {
    if (io_index_ == 0 && cfg_.fields_every > 0 && !cfg_.field_names.empty()) {
      try {
        csv_ = std::make_unique<FieldSeriesWriter>(cfg_.dir / "fields.csv", cfg_.field_names,
                                                   cfg_.append_fields);
      } catch (const std::exception& e) {
        report_error(e.what());
      }
    }
    fields_failed_ = !csv_ && io_index_ == 0 && cfg_.fields_every > 0;
  }

  /// Keeps a batch of rows [step, time, due flags..., partials...] from compute rank `source`; appends the
  /// rows every compute rank has sent, in step order (every rank sends its rows in order), each summed in
  /// compute-rank order whatever order the batches arrived in: the same bits in every run.
  void add_field_batch(int source) {
    const std::size_t n_fields = cfg_.field_names.size();
    const std::size_t width = 2 + 2 * n_fields;
    const std::size_t count = buffer_.size() / sizeof(double);
    std::vector<double> values(count);
    std::memcpy(values.data(), buffer_.data(), buffer_.size());
    for (std::size_t r = 0; r + width <= count; r += width) {
      const auto step = static_cast<std::int64_t>(values[r]);
      auto& row = rows_[step];
      if (row.parts.empty()) row.parts.assign(static_cast<std::size_t>(L_.n_compute) * width, 0.0);
      std::memcpy(row.parts.data() + static_cast<std::size_t>(source) * width, values.data() + r,
                  width * sizeof(double));
      ++row.count;
    }
    while (!rows_.empty() && rows_.begin()->second.count == L_.n_compute) {
      const auto& parts = rows_.begin()->second.parts;
      std::vector<double> sum(parts.begin(), parts.begin() + static_cast<std::ptrdiff_t>(width));
      std::fill(sum.begin() + 2, sum.end(), 0.0);
      for (int c = 0; c < L_.n_compute; ++c)
        for (std::size_t k = 2; k < width; ++k) sum[k] += parts[static_cast<std::size_t>(c) * width + k];
      if (csv_ && !fields_failed_) csv_->append_wire_row(sum.data(), n_fields);
      rows_.erase(rows_.begin());
    }
    if (csv_ && !fields_failed_) try {
        csv_->flush();
      } catch (const std::exception& e) {
        fields_failed_ = true;
        report_error(e.what());
      }
  }

  /// Appends the field batches already queued for this rank before a checkpoint is written. Compute
  /// ranks hand their rows over before their checkpoint piece, and MPI keeps one sender's messages in
  /// order, so with one I/O rank every row up to the checkpoint's step is in fields.csv before the
  /// checkpoint is; with more, pieces forwarded by other I/O ranks may overtake rows, which this narrows.
  void take_queued_field_batches() {
    if (!csv_) return;
    int flag = 0;
    MPI_Message msg;
    MPI_Status st;
    for (MPI_Improbe(MPI_ANY_SOURCE, kTagFields, L_.bridge, &flag, &msg, &st); flag;
         MPI_Improbe(MPI_ANY_SOURCE, kTagFields, L_.bridge, &flag, &msg, &st)) {
      int n = 0;
      MPI_Get_count(&st, MPI_BYTE, &n);
      buffer_.resize(static_cast<std::size_t>(n));
      MPI_Mrecv(buffer_.data(), n, MPI_BYTE, &msg, MPI_STATUS_IGNORE);
      add_field_batch(st.MPI_SOURCE);
    }
  }

  /// Writes a step once every compute rank this I/O rank serves has sent its piece, then tells the
  /// compute ranks the outcome (acknowledge): the VTK piece to the ranks it serves, the checkpoint (I/O
  /// rank 0 writes the file) to every compute rank. Checkpoints and pictures need every piece: the other
  /// I/O ranks hand theirs to I/O rank 0. A picture gets no verdict: the compute ranks never wait for one.
  void add_piece(FramePiece piece) {
    const auto step = piece.step;
    auto& list = pending_[step];
    list.push_back(std::move(piece));
    if (list.size() != L_.served.size()) return;
    const auto kinds = list.front().kinds;
    if (kinds & kFrameVtk) {
      const bool ok = write_vtk(list, step);
      for (int c : L_.served) acknowledge(c, step, ok);
    }
    if (kinds & (kFrameCheckpoint | kFramePicture)) {
      gather(list);
      if (io_index_ == 0 && (kinds & kFramePicture)) offer_picture(list);
    }
    if (kinds & kFrameCheckpoint) {
      take_queued_field_batches();
      // The receive buffers last held a whole piece: free them before the checkpoint needs the memory.
      std::vector<std::byte>().swap(buffer_);
      std::vector<std::byte>().swap(gathered_);
      const bool ok = write_checkpoint(list);
      if (io_index_ == 0)
        for (int c = 0; c < L_.n_compute; ++c) acknowledge(c, step, ok);
    }
    pending_.erase(step);
  }

  /// I/O ranks other than 0 send their pieces to I/O rank 0, which appends them to its own.
  void gather(std::vector<FramePiece>& pieces) {
    if (io_index_ != 0) {
      concat_pieces(pieces, gathered_);
      MPI_Request req;
      MPI_Isend(gathered_.data(), checked_count(gathered_.size()), MPI_BYTE, 0, kTagGather, L_.io, &req);
      wait_without_spinning(req);
      return;
    }
    for (int q = 1; q < L_.n_io; ++q) {
      receive_without_spinning(q, kTagGather, L_.io, gathered_);
      split_pieces(gathered_, pieces);
    }
  }

  /// I/O rank 0 with pictures asked for: the picture thread, or the reason there is none (an error).
  void start_pictures() {
    if (io_index_ != 0 || cfg_.render_every <= 0) return;
    std::string why = pictures_.error;
    if (why.empty() && !pictures_.draw) why = "no picture writer (basalt-run's render module was not loaded)";
    if (why.empty()) {
      std::error_code ec;
      std::filesystem::create_directories(cfg_.dir / "pictures", ec);
      if (ec)
        why = fmt::format("{}: cannot create the pictures' folder: {}", (cfg_.dir / "pictures").string(),
                          ec.message());
    }
    if (!why.empty()) {
      pictures_failed_ = true;
      report_error(why);
      return;
    }
    queue_ = std::make_unique<PictureQueue>(std::move(pictures_.draw), cfg_.dir);
  }

  /// Hands the particles of a picture step to the picture thread, which never makes this loop wait.
  void offer_picture(const std::vector<FramePiece>& pieces) {
    PictureJob job;
    job.step = pieces.front().step;
    job.time = pieces.front().time;
    job.units = info_.units;
    for (const auto& p : pieces) job.append(p);
    if (!queue_) {  // failed at the start (reported then)
      ++local_.pictures_due;
      if (++local_.pictures_skipped <= 20)
        local_.pictures_skipped_steps +=
            fmt::format("{}{}", local_.pictures_skipped > 1 ? ", " : "", job.step);
      else if (local_.pictures_skipped == 21)
        local_.pictures_skipped_steps += ", ...";
      return;
    }
    if (const auto skipped = queue_->offer(std::move(job)); skipped && ++skip_lines_ <= 5)
      fmt::print(stderr,
                 "basalt-run: picture of step {} skipped: a newer frame (step {}) came while it waited to be "
                 "drawn{}\n",
                 *skipped, pieces.front().step, skip_lines_ == 5 ? " (further skips: see the report)" : "");
  }

  void finish_pictures() {
    if (!queue_) return;
    const PictureQueue::Stats st = queue_->finish();
    if (auto e = queue_->error(); e && !pictures_failed_) {
      pictures_failed_ = true;
      report_error(*e);
    }
    local_.pictures.files += st.drawn;
    local_.pictures.bytes += st.bytes;
    local_.pictures.write_seconds += st.seconds;
    local_.pictures_due += st.due;
    local_.pictures_skipped += st.skipped;
    local_.picture_max_seconds = st.max_seconds;
    std::string steps;
    for (std::size_t k = 0; k < st.skipped_steps.size() && k < 20; ++k)
      steps += fmt::format("{}{}", k ? ", " : "", st.skipped_steps[k]);
    if (st.skipped_steps.size() > 20) steps += ", ...";
    local_.pictures_skipped_steps = steps;
    queue_.reset();
  }

  /// The verdict on one step's output for compute rank `c`: the step, then the error text if it failed.
  /// Compute ranks wait for it before they have more than frames_in_flight frames whose outcome they do
  /// not know, so an output error reaches them within that many output steps (docs/io-ranks.md).
  /// Non-blocking: a compute rank may be in a collective with the others while this travels.
  void acknowledge(int c, std::int64_t step, bool ok) {
    while (!acks_.empty()) {
      int done = 0;
      MPI_Test(&acks_.front().request, &done, MPI_STATUS_IGNORE);
      if (!done) break;
      acks_.pop_front();
    }
    Ack& a = acks_.emplace_back();
    a.bytes.resize(sizeof(step));
    std::memcpy(a.bytes.data(), &step, sizeof(step));
    if (!ok && local_.error) {
      const auto* text = reinterpret_cast<const std::byte*>(local_.error->data());
      a.bytes.insert(a.bytes.end(), text, text + local_.error->size());
    }
    MPI_Isend(a.bytes.data(), checked_count(a.bytes.size()), MPI_BYTE, c, kTagAck, L_.bridge, &a.request);
  }

  /// This I/O rank's piece of the VTK frame (and, on I/O rank 0, the frame's index and the series).
  /// False when this kind of output has failed (now or before).
  bool write_vtk(const std::vector<FramePiece>& pieces, std::int64_t step) {
    if (!vtk_) return true;
    if (frames_failed_) return false;
    try {
      const double t0 = MPI_Wtime();
      const auto bytes = vtk_(pieces, step, pieces.front().time, io_index_, L_.n_io, cfg_.dir);
      throttle(cfg_.throttle_mb_per_s, bytes, MPI_Wtime() - t0);
      local_.frames.files += 1;
      local_.frames.bytes += bytes;
      local_.frames.write_seconds += MPI_Wtime() - t0;
    } catch (const std::exception& e) {
      frames_failed_ = true;
      report_error(e.what());
    }
    return !frames_failed_;
  }

  /// One file per checkpoint, written by I/O rank 0 from every piece (gathered before). False (on I/O
  /// rank 0) when checkpoints have failed (now or before).
  bool write_checkpoint(std::vector<FramePiece>& pieces) {
    if (io_index_ != 0) return true;
    if (checkpoints_failed_) return false;
    try {
      write_checkpoint_step(pieces, info_, cfg_, local_.checkpoints);
    } catch (const std::exception& e) {
      checkpoints_failed_ = true;
      report_error(e.what());
    }
    return !checkpoints_failed_;
  }

  struct Ack {
    std::vector<std::byte> bytes;
    MPI_Request request = MPI_REQUEST_NULL;
  };
  std::deque<Ack> acks_;  // verdicts in flight (a deque: their buffers must not move)

  struct Row {
    std::vector<double> parts;  // per compute rank: [step, time, due flags, partial values]
    int count = 0;
  };

  const RankLayout& L_;
  const OutputConfig& cfg_;
  const VtkFrameWriter& vtk_;
  Pictures& pictures_;
  const int io_index_;
  std::unique_ptr<PictureQueue> queue_;
  bool pictures_failed_ = false;
  int skip_lines_ = 0;
  RunInfo info_;
  OutputReport local_;
  int errors_sent_ = 0;
  std::unique_ptr<FieldSeriesWriter> csv_;
  std::map<std::int64_t, Row> rows_;  // field rows not yet complete
  bool fields_failed_ = false, checkpoints_failed_ = false, frames_failed_ = false;
  std::map<std::int64_t, std::vector<FramePiece>> pending_;  // pieces of steps not yet complete
  std::vector<std::byte> buffer_, gathered_;
};

}  // namespace

IoServer::IoServer(const RankLayout& layout, OutputConfig config, VtkFrameWriter vtk, Pictures pictures)
    : layout_(layout), config_(std::move(config)), vtk_(std::move(vtk)), pictures_(std::move(pictures)) {}

OutputReport IoServer::run() { return Server(layout_, config_, vtk_, pictures_).run(); }

}  // namespace basalt::io
