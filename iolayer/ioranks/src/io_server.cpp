// The I/O-rank side: IoServer::run receives frames and field batches from the compute ranks it
// serves, assembles the pieces of a step and writes checkpoints (I/O rank 0 writes one file per
// step; the others forward their pieces), VTK pieces and fields.csv; it sleeps while idle.
#include <fmt/format.h>
#include <sys/resource.h>

#include <cstring>
#include <map>
#include <memory>
#include <stdexcept>

#include "basalt/io/io_ranks.hpp"
#include "checkpoint_step.hpp"
#include "field_series.hpp"
#include "messages.hpp"
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

}  // namespace

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
