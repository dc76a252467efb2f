#pragma once
// The solver's OutputSink on top of the I/O layer's OutputClient (dedicated I/O ranks, or
// synchronous writing from the compute ranks with --io-ranks 0).
#include "basalt/io/io_ranks.hpp"
#include "basalt/solver/output/output_sink.hpp"

namespace basalt::run {

class ClientSink final : public solver::OutputSink {
 public:
  ClientSink(io::OutputClient& client, bool continue_on_error)
      : client_(client), continue_(continue_on_error) {}
  void begin(const std::vector<std::string>&) override {}  // the client knows the columns (OutputConfig)
  void fields(std::int64_t step, double time, std::span<const double> partials,
              std::span<const char> due) override {
    client_.submit_fields(step, time, partials, due);
  }
  std::uint32_t frame_kinds(std::int64_t step) const override { return client_.frame_kinds(step); }
  void frame(const io::FrameSource& source) override { client_.submit_frame(source); }
  std::optional<std::string> poll() override {
    client_.poll();
    return client_.error();
  }
  bool continue_on_error() const override { return continue_; }
  void flush() override {}  // OutputClient::finish, after the run, flushes and reports

 private:
  io::OutputClient& client_;
  bool continue_;
};

}  // namespace basalt::run
