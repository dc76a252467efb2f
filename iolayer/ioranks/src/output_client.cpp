// The compute side's output client: picks the asynchronous client (Q >= 1) or the synchronous
// writer (Q = 0) and does what both share (which kinds are due, field rows, the final report).
#include <algorithm>

#include "output_client_impl.hpp"
#include "report_reduction.hpp"

namespace basalt::io {

namespace detail {

OutputClientImpl::OutputClientImpl(const RankLayout& l, OutputConfig c, RunInfo i, VtkFrameWriter v,
                                   std::optional<std::string>& e)
    : layout(l), cfg(std::move(c)), info(std::move(i)), vtk(std::move(v)), error(e) {
  MPI_Comm_rank(layout.compute, &compute_rank);
}

void OutputClientImpl::add_field_row(std::int64_t step, double time, std::span<const double> partials,
                                     std::span<const char> due) {
  field_rows.push_back(static_cast<double>(step));
  field_rows.push_back(time);
  for (std::size_t c = 0; c < partials.size(); ++c) field_rows.push_back(due.empty() || due[c] ? 1.0 : 0.0);
  field_rows.insert(field_rows.end(), partials.begin(), partials.end());
  if (++field_rows_count >= static_cast<std::size_t>(std::max(1, cfg.field_batch_rows)))
    hand_over_field_rows();
}

}  // namespace detail

OutputClient::OutputClient(const RankLayout& layout, OutputConfig config, RunInfo info, VtkFrameWriter vtk)
    : impl_((layout.n_io > 0 ? detail::make_async_client : detail::make_sync_writer)(
          layout, std::move(config), std::move(info), std::move(vtk), error_)) {
  impl_->start();
}

OutputClient::~OutputClient() = default;

std::uint32_t OutputClient::frame_kinds(std::int64_t step) const {
  std::uint32_t k = 0;
  const auto& c = impl_->cfg;
  if (c.checkpoint_every > 0 && step % c.checkpoint_every == 0) k |= kFrameCheckpoint;
  if (c.frames_every > 0 && impl_->vtk && step % c.frames_every == 0) k |= kFrameVtk;
  // Pictures are drawn by I/O rank 0 only (basalt-run refuses them with --io-ranks 0).
  if (c.render_every > 0 && impl_->layout.n_io > 0 && step % c.render_every == 0) k |= kFramePicture;
  return k;
}

bool OutputClient::wants_fields(std::int64_t step) const {
  const auto& c = impl_->cfg;
  return c.fields_every > 0 && !c.field_names.empty() && step % c.fields_every == 0;
}

void OutputClient::submit_frame(const FramePiece& piece) { submit_frame(PieceSource(piece)); }

void OutputClient::submit_frame(const FrameSource& source) {
  // The field rows up to a checkpoint's step go out before it, so that a complete checkpoint on disk
  // implies fields.csv holds every row up to its step: a run killed after the checkpoint and restarted
  // from it has no gap in fields.csv (found by tools/soak/soak.py).
  if (source.header().kinds & kFrameCheckpoint) impl_->hand_over_field_rows();
  impl_->submit_frame(source);
}

void OutputClient::submit_fields(std::int64_t step, double time, std::span<const double> partials,
                                 std::span<const char> due) {
  impl_->add_field_row(step, time, partials, due);
}

void OutputClient::poll() { impl_->poll(); }

OutputReport OutputClient::finish() {
  impl_->drain();
  OutputReport mine = impl_->local;
  if (!mine.error && error_) mine.error = error_;
  OutputReport all = detail::reduce_report(impl_->layout.bridge, mine);
  impl_->settle();
  if (all.error) error_ = all.error;
  return all;
}

}  // namespace basalt::io
