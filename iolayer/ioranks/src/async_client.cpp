// Q >= 1, the compute side: frames and field batches travel to the I/O ranks by non-blocking sends
// from a bounded pool of buffers; the compute rank waits only when all of them are still in flight.
#include <algorithm>
#include <cstring>
#include <deque>

#include "messages.hpp"
#include "output_client_impl.hpp"

namespace basalt::io::detail {

namespace {

class AsyncClient final : public OutputClientImpl {
 public:
  using OutputClientImpl::OutputClientImpl;

  void start() override {
    // The run's fixed information, once, to every I/O rank.
    if (compute_rank != 0) return;
    std::vector<std::byte> bytes;
    serialize(info, bytes);
    for (int q = 0; q < layout.n_io; ++q)
      MPI_Send(bytes.data(), checked_count(bytes.size()), MPI_BYTE, layout.io_bridge_rank(q), kTagInfo,
               layout.bridge);
  }

  void submit_frame(const FrameSource& source) override {
    poll();
    const int bound = std::max(1, cfg.max_frames_in_flight);
    if (static_cast<int>(frames_in_flight_.size()) >= bound)
      complete_front(frames_in_flight_, /*block=*/true);
    // At most `bound` frames whose outcome (written, or the error) this rank does not know: an output
    // error reaches it within that many output steps, however slow the storage (docs/io-ranks.md).
    if (static_cast<int>(unacknowledged_.size()) >= bound)
      wait_for_verdicts(static_cast<std::size_t>(bound - 1));
    const FrameHeader header = source.header();
    const int verdicts = ((header.kinds & kFrameVtk) ? 1 : 0) + ((header.kinds & kFrameCheckpoint) ? 1 : 0);
    if (verdicts > 0) unacknowledged_.push_back({header.step, verdicts});
    InFlight f;
    f.bytes = take_buffer();
    serialize(source, f.bytes);  // written once, in place: the buffer is what is sent
    MPI_Isend(f.bytes.data(), checked_count(f.bytes.size()), MPI_BYTE, layout.my_io_rank, kTagFrame,
              layout.bridge, &f.request);
    frames_in_flight_.push_back(std::move(f));
    ++local.frames_sent;
  }

  void hand_over_field_rows() override {
    if (field_rows_count == 0) return;
    InFlight f;
    f.bytes.resize(field_rows.size() * sizeof(double));
    std::memcpy(f.bytes.data(), field_rows.data(), f.bytes.size());
    MPI_Isend(f.bytes.data(), checked_count(f.bytes.size()), MPI_BYTE, layout.io_bridge_rank(0), kTagFields,
              layout.bridge, &f.request);
    fields_in_flight_.push_back(std::move(f));
    field_rows.clear();
    field_rows_count = 0;
  }

  /// Completes finished sends and picks up errors from I/O ranks.
  void poll() override {
    complete_front(frames_in_flight_, false);
    complete_front(fields_in_flight_, false);
    int flag = 0;
    MPI_Status st;
    MPI_Iprobe(MPI_ANY_SOURCE, kTagError, layout.bridge, &flag, &st);
    while (flag) {
      int len = 0;
      MPI_Get_count(&st, MPI_CHAR, &len);
      std::string text(len, ' ');
      MPI_Recv(text.data(), len, MPI_CHAR, st.MPI_SOURCE, kTagError, layout.bridge, MPI_STATUS_IGNORE);
      ++errors_received_;
      if (!error) error = text;
      MPI_Iprobe(MPI_ANY_SOURCE, kTagError, layout.bridge, &flag, &st);
    }
    take_verdicts();
  }

  void drain() override {
    hand_over_field_rows();
    while (!frames_in_flight_.empty()) complete_front(frames_in_flight_, true);
    while (!fields_in_flight_.empty()) complete_front(fields_in_flight_, true);
    wait_for_verdicts(0);
    for (int q = 0; q < layout.n_io; ++q)
      MPI_Send(nullptr, 0, MPI_BYTE, layout.io_bridge_rank(q), kTagDone, layout.bridge);
  }

  void settle() override {
    // Error messages the I/O ranks sent to this rank: each I/O rank sends at most one per compute
    // rank; the count travels in the reduction so none is left unreceived.
    int expected = 0, zero = 0;
    MPI_Allreduce(&zero, &expected, 1, MPI_INT, MPI_SUM, layout.bridge);
    while (errors_received_ < expected) {
      MPI_Status st;
      MPI_Probe(MPI_ANY_SOURCE, kTagError, layout.bridge, &st);
      poll();
    }
  }

 private:
  struct InFlight {
    std::vector<std::byte> bytes;
    MPI_Request request = MPI_REQUEST_NULL;
  };

  struct Unacknowledged {
    std::int64_t step = 0;
    int verdicts = 0;  // still to come: one per kind written (VTK piece, checkpoint file)
  };

  /// Receives the I/O ranks' verdicts that have arrived (kTagAck: step, then the error text if any).
  void take_verdicts() {
    int flag = 0;
    MPI_Status st;
    for (MPI_Iprobe(MPI_ANY_SOURCE, kTagAck, layout.bridge, &flag, &st); flag;
         MPI_Iprobe(MPI_ANY_SOURCE, kTagAck, layout.bridge, &flag, &st)) {
      int n = 0;
      MPI_Get_count(&st, MPI_BYTE, &n);
      verdict_.resize(static_cast<std::size_t>(n));
      MPI_Recv(verdict_.data(), n, MPI_BYTE, st.MPI_SOURCE, kTagAck, layout.bridge, MPI_STATUS_IGNORE);
      std::int64_t step = 0;
      std::memcpy(&step, verdict_.data(), sizeof(step));
      if (verdict_.size() > sizeof(step) && !error)
        error = std::string(reinterpret_cast<const char*>(verdict_.data()) + sizeof(step),
                            verdict_.size() - sizeof(step));
      for (auto& u : unacknowledged_)
        if (u.step == step) {
          --u.verdicts;
          break;
        }
      while (!unacknowledged_.empty() && unacknowledged_.front().verdicts <= 0) unacknowledged_.pop_front();
    }
  }

  /// Blocks (sleeping, measured as waiting for output) until at most `left` frames await their verdict.
  void wait_for_verdicts(std::size_t left) {
    if (unacknowledged_.size() <= left) return;
    const double t0 = MPI_Wtime();
    Backoff backoff;
    for (take_verdicts(); unacknowledged_.size() > left; take_verdicts()) backoff.sleep();
    local.compute_wait_seconds += MPI_Wtime() - t0;
  }

  std::vector<std::byte> take_buffer() {
    if (spare_.empty()) return {};
    auto b = std::move(spare_.back());
    spare_.pop_back();
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
      // grown to the frame's size again, page by page (~50 ms per checkpoint on 590 k particles). A
      // frame larger than kKeptFrameBytes is released: kept, it would stay resident between checkpoints
      // (1 GB per compute rank at 4.7 M particles: the run's steady memory grew from 3.0 to 5.1 GB after
      // its first checkpoint), to save less than a second per checkpoint of a run that long.
      if (&q == &frames_in_flight_ && q.front().bytes.capacity() <= kKeptFrameBytes)
        spare_.push_back(std::move(q.front().bytes));
      q.pop_front();
      if (block) return;
    }
  }

  std::deque<InFlight> frames_in_flight_;
  std::deque<InFlight> fields_in_flight_;
  std::vector<std::vector<std::byte>> spare_;  // buffers to reuse (keeps capacity)
  static constexpr std::size_t kKeptFrameBytes = std::size_t{256} << 20;
  int errors_received_ = 0;
  std::deque<Unacknowledged> unacknowledged_;  // frames posted whose verdict has not arrived
  std::vector<std::byte> verdict_;             // receive buffer
};

}  // namespace

std::unique_ptr<OutputClientImpl> make_async_client(const RankLayout& layout, OutputConfig config,
                                                    RunInfo info, VtkFrameWriter vtk,
                                                    std::optional<std::string>& error) {
  return std::make_unique<AsyncClient>(layout, std::move(config), std::move(info), std::move(vtk), error);
}

}  // namespace basalt::io::detail
