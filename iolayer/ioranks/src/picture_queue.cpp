#include "picture_queue.hpp"

#include <fmt/format.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <exception>

#include "basalt/io/frame.hpp"

namespace basalt::io {

void PictureJob::append(const FramePiece& p) {
  id.insert(id.end(), p.id.begin(), p.id.end());
  position.insert(position.end(), p.position.begin(), p.position.end());
  velocity.insert(velocity.end(), p.velocity.begin(), p.velocity.end());
  radius.insert(radius.end(), p.radius.begin(), p.radius.end());
  mass.insert(mass.end(), p.mass.begin(), p.mass.end());
  tag.insert(tag.end(), p.tag.begin(), p.tag.end());
  if (fields.empty())
    for (const auto& f : p.fields) fields.emplace_back(f.first, std::vector<double>{});
  for (std::size_t f = 0; f < fields.size() && f < p.fields.size(); ++f)
    fields[f].second.insert(fields[f].second.end(), p.fields[f].second.begin(), p.fields[f].second.end());
}

std::filesystem::path picture_path(const std::filesystem::path& dir, std::int64_t step) {
  return dir / "pictures" / fmt::format("step_{:06}.png", step);
}

namespace detail {

PictureQueue::PictureQueue(PictureWriter draw, std::filesystem::path dir)
    : draw_(std::move(draw)), dir_(std::move(dir)), thread_([this] { loop(); }) {}

PictureQueue::~PictureQueue() {
  if (thread_.joinable()) finish();
}

std::optional<std::int64_t> PictureQueue::offer(PictureJob job) {
  std::optional<std::int64_t> skipped;
  {
    std::lock_guard lock(m_);
    ++stats_.due;
    if (error_) {  // drawing failed: nothing more is drawn (the error stops the run, or is reported)
      ++stats_.skipped;
      stats_.skipped_steps.push_back(job.step);
      return job.step;
    }
    if (waiting_) {
      skipped = waiting_->step;
      ++stats_.skipped;
      stats_.skipped_steps.push_back(waiting_->step);
    }
    waiting_ = std::move(job);
  }
  cv_.notify_one();
  return skipped;
}

std::optional<std::string> PictureQueue::error() {
  std::lock_guard lock(m_);
  return error_;
}

PictureQueue::Stats PictureQueue::finish() {
  {
    std::lock_guard lock(m_);
    stop_ = true;
  }
  cv_.notify_one();
  if (thread_.joinable()) thread_.join();
  std::lock_guard lock(m_);
  std::sort(stats_.skipped_steps.begin(), stats_.skipped_steps.end());
  return stats_;
}

void PictureQueue::loop() {
  // Below the I/O loop and any compute rank sharing the core (Linux: per thread).
  (void)::setpriority(PRIO_PROCESS, static_cast<id_t>(::gettid()), 10);
  for (;;) {
    PictureJob job;
    {
      std::unique_lock lock(m_);
      cv_.wait(lock, [this] { return stop_ || waiting_.has_value(); });
      if (!waiting_) break;  // stopped, nothing left
      job = std::move(*waiting_);
      waiting_.reset();
      if (error_) {
        ++stats_.skipped;
        stats_.skipped_steps.push_back(job.step);
        continue;
      }
    }
    const auto t0 = std::chrono::steady_clock::now();
    try {
      const std::uint64_t bytes = draw_(job, picture_path(dir_, job.step));
      const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      std::lock_guard lock(m_);
      ++stats_.drawn;
      stats_.bytes += bytes;
      stats_.seconds += s;
      stats_.max_seconds = std::max(stats_.max_seconds, s);
    } catch (const std::exception& e) {
      std::lock_guard lock(m_);
      ++stats_.skipped;
      stats_.skipped_steps.push_back(job.step);
      if (!error_) error_ = fmt::format("picture of step {}: {}", job.step, e.what());
    }
  }
  // The writer holds the OpenGL context and the window: released on this thread.
  draw_ = nullptr;
}

}  // namespace detail
}  // namespace basalt::io
