#pragma once
// I/O rank 0's picture thread: takes the steps to draw from the I/O loop without ever making it wait.
// One picture is drawn at a time and one more may wait; a newer step arriving while one waits replaces
// it, and the replaced step is skipped and counted. The I/O loop keeps receiving frames meanwhile, so
// the compute ranks never wait for a picture.
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "basalt/io/pictures.hpp"

namespace basalt::io::detail {

class PictureQueue {
 public:
  struct Stats {
    std::uint64_t due = 0, drawn = 0, skipped = 0, bytes = 0;
    double seconds = 0, max_seconds = 0;  ///< drawing time, summed and the longest
    std::vector<std::int64_t> skipped_steps;
  };

  /// Starts the thread (at lower priority: nice +10). `draw` lives and dies on that thread.
  PictureQueue(PictureWriter draw, std::filesystem::path dir);
  ~PictureQueue();
  PictureQueue(const PictureQueue&) = delete;
  PictureQueue& operator=(const PictureQueue&) = delete;

  /// Hands over the particles of a step to draw; returns at once. Returns the step it skipped, if any.
  std::optional<std::int64_t> offer(PictureJob job);
  /// The first drawing error, if any (then nothing more is drawn).
  std::optional<std::string> error();
  /// Draws what is in hand, stops the thread and returns the counts.
  Stats finish();

 private:
  void loop();

  PictureWriter draw_;
  std::filesystem::path dir_;
  std::mutex m_;
  std::condition_variable cv_;
  std::optional<PictureJob> waiting_;
  bool stop_ = false;
  std::optional<std::string> error_;
  Stats stats_;
  std::thread thread_;
};

}  // namespace basalt::io::detail
