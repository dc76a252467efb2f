// Q = 0: the compute ranks write their output themselves, synchronously (the baseline the I/O ranks
// must beat). Frames are gathered to compute rank 0, which writes them before anyone goes on; field
// rows are summed a batch at a time and compute rank 0 appends them to fields.csv.
#include <mpi.h>

#include "checkpoint_step.hpp"
#include "field_series.hpp"
#include "messages.hpp"
#include "output_client_impl.hpp"

namespace basalt::io::detail {

namespace {

class SyncWriter final : public OutputClientImpl {
 public:
  using OutputClientImpl::OutputClientImpl;

  void start() override {
    if (compute_rank == 0 && cfg.fields_every > 0) {
      try {
        csv_ =
            std::make_unique<FieldSeriesWriter>(cfg.dir / "fields.csv", cfg.field_names, cfg.append_fields);
      } catch (const std::exception& e) {
        local.error = e.what();
      }
    }
    int bad = local.error ? 1 : 0;
    MPI_Bcast(&bad, 1, MPI_INT, 0, layout.compute);
    if (bad && !local.error) local.error = "fields.csv could not be opened on compute rank 0";
    error = local.error;
  }

  void submit_frame(const FrameSource& source) override {
    const double t0 = MPI_Wtime();
    std::vector<std::byte>& mine = gather_buffer_;
    const FrameHeader header = source.header();
    serialize(source, mine);
    int n = checked_count(mine.size()), size = 1;
    MPI_Comm_size(layout.compute, &size);
    std::vector<int> counts(size), displs(size);
    MPI_Gather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, layout.compute);
    std::vector<std::byte> all;
    if (compute_rank == 0) {
      std::size_t total = 0;
      for (int r = 0; r < size; ++r) {
        displs[r] = static_cast<int>(total);
        total += counts[r];
      }
      all.resize(checked_count(total));
    }
    MPI_Gatherv(mine.data(), n, MPI_BYTE, all.data(), counts.data(), displs.data(), MPI_BYTE, 0,
                layout.compute);
    int bad = 0;
    if (compute_rank == 0 && !local.error) {
      try {
        std::vector<FramePiece> pieces;
        for (int r = 0; r < size; ++r)
          pieces.push_back(deserialize(std::span<const std::byte>(all).subspan(displs[r], counts[r])));
        std::vector<std::byte>().swap(all);  // the pieces hold it all now
        if (header.kinds & kFrameVtk) {
          const double tv = MPI_Wtime();
          local.frames.bytes += vtk(pieces, header.step, header.time, 0, 1, cfg.dir);
          local.frames.files += 1;
          local.frames.write_seconds += MPI_Wtime() - tv;
        }
        if (header.kinds & kFrameCheckpoint) write_checkpoint_step(pieces, info, cfg, local.checkpoints);
      } catch (const std::exception& e) {
        local.error = e.what();
        bad = 1;
      }
    }
    MPI_Bcast(&bad, 1, MPI_INT, 0, layout.compute);
    if (bad) {
      int len = local.error ? static_cast<int>(local.error->size()) : 0;
      MPI_Bcast(&len, 1, MPI_INT, 0, layout.compute);
      std::string text = local.error.value_or(std::string(len, ' '));
      MPI_Bcast(text.data(), len, MPI_CHAR, 0, layout.compute);
      if (!error) error = text;
    }
    local.compute_wait_seconds += MPI_Wtime() - t0;
  }

  /// Sums the buffered rows over the compute ranks (one reduction per batch, not a per-step
  /// collective that would make every rank wait for the slowest at every step); compute rank 0
  /// appends them to fields.csv.
  void hand_over_field_rows() override {
    if (field_rows_count == 0) return;
    const double t0 = MPI_Wtime();
    std::vector<double> sums(compute_rank == 0 ? field_rows.size() : 0);
    MPI_Reduce(field_rows.data(), sums.data(), static_cast<int>(field_rows.size()), MPI_DOUBLE, MPI_SUM, 0,
               layout.compute);
    // Only a failure of fields.csv itself stops the rows: a failed checkpoint or frame must not drop the
    // rows computed before it (they are handed over when the run stops).
    if (csv_ && !fields_failed_) {
      // Step and time were summed too: rank 0's own are the row's.
      const std::size_t width = field_rows.size() / field_rows_count;
      const std::size_t n_fields = (width - 2) / 2;
      for (std::size_t r = 0; r < field_rows_count; ++r) {
        double* row = sums.data() + r * width;
        row[0] = field_rows[r * width];
        row[1] = field_rows[r * width + 1];
        csv_->append_wire_row(row, n_fields);
      }
      try {
        csv_->flush();
      } catch (const std::exception& e) {
        fields_failed_ = true;
        if (!local.error) local.error = e.what();
        if (!error) error = local.error;
      }
    }
    field_rows.clear();
    field_rows_count = 0;
    local.compute_wait_seconds += MPI_Wtime() - t0;
  }

  void drain() override {
    hand_over_field_rows();
    if (!csv_) return;
    const double t0 = MPI_Wtime();
    try {
      if (!fields_failed_) csv_->flush();
    } catch (const std::exception& e) {
      fields_failed_ = true;
      if (!local.error) local.error = e.what();
    }
    local.fields.files = 1;
    local.fields.bytes = csv_->bytes();
    local.fields.write_seconds = csv_->seconds();
    local.compute_wait_seconds += MPI_Wtime() - t0;
    csv_.reset();
  }

 private:
  std::vector<std::byte> gather_buffer_;    // this rank's frame (reused)
  std::unique_ptr<FieldSeriesWriter> csv_;  // compute rank 0
  bool fields_failed_ = false;              // fields.csv itself could not be written
};

}  // namespace

std::unique_ptr<OutputClientImpl> make_sync_writer(const RankLayout& layout, OutputConfig config,
                                                   RunInfo info, VtkFrameWriter vtk,
                                                   std::optional<std::string>& error) {
  return std::make_unique<SyncWriter>(layout, std::move(config), std::move(info), std::move(vtk), error);
}

}  // namespace basalt::io::detail
