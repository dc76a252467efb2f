#include "report_reduction.hpp"

#include <climits>
#include <string>

namespace basalt::io::detail {

namespace {

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
  kPictureFiles,
  kPictureBytes,
  kPicturesDue,
  kPicturesSkipped,
  kSumSlots
};
enum MaxSlot {
  kCkptSeconds,
  kFrameSeconds,
  kFieldSeconds,
  kWaitSeconds,
  kIoCpu,
  kIoWall,
  kPictureSeconds,
  kPictureMaxSeconds,
  kMaxSlots
};

/// The text of the lowest rank whose `mine` is not empty ("" when none).
std::string first_text(MPI_Comm comm, const std::string& mine) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  int candidate = mine.empty() ? INT_MAX : rank, first = INT_MAX;
  MPI_Allreduce(&candidate, &first, 1, MPI_INT, MPI_MIN, comm);
  if (first == INT_MAX) return {};
  std::string text = mine;
  int len = static_cast<int>(text.size());
  MPI_Bcast(&len, 1, MPI_INT, first, comm);
  text.resize(static_cast<std::size_t>(len));
  MPI_Bcast(text.data(), len, MPI_CHAR, first, comm);
  return text;
}

}  // namespace

OutputReport reduce_report(MPI_Comm comm, const OutputReport& mine) {
  double sums[kSumSlots] = {
      double(mine.checkpoints.files), double(mine.checkpoints.bytes), double(mine.frames.files),
      double(mine.frames.bytes),      double(mine.fields.files),      double(mine.fields.bytes),
      double(mine.frames_sent),       mine.error ? 1.0 : 0.0,         double(mine.pictures.files),
      double(mine.pictures.bytes),    double(mine.pictures_due),      double(mine.pictures_skipped)};
  double maxs[kMaxSlots] = {
      mine.checkpoints.write_seconds, mine.frames.write_seconds, mine.fields.write_seconds,
      mine.compute_wait_seconds,      mine.io_cpu_seconds,       mine.io_wall_seconds,
      mine.pictures.write_seconds,    mine.picture_max_seconds};
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
  r.pictures = {std::uint64_t(gsum[kPictureFiles]), std::uint64_t(gsum[kPictureBytes]),
                gmax[kPictureSeconds]};
  r.pictures_due = std::uint64_t(gsum[kPicturesDue]);
  r.pictures_skipped = std::uint64_t(gsum[kPicturesSkipped]);
  r.picture_max_seconds = gmax[kPictureMaxSeconds];
  if (r.pictures_skipped > 0) r.pictures_skipped_steps = first_text(comm, mine.pictures_skipped_steps);
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

}  // namespace basalt::io::detail
