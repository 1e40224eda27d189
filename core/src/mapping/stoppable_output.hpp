#pragma once
// An output stream buffer that passes bytes on to another one until a stop
// request fires, then refuses them. OctoMap writes a tree in one call with no
// way to stop it; through this buffer the write fails within a few thousand
// node records of the request, and the caller turns that into Cancelled.

#include <functional>
#include <streambuf>

namespace boicp {

class StoppableOutput : public std::streambuf {
 public:
  /// `sink` receives the bytes and must outlive this buffer; `stop` may be
  /// empty (never stops).
  StoppableOutput(std::streambuf& sink, std::function<bool()> stop)
      : sink_(sink), stop_(std::move(stop)) {}

  /// Whether a write was refused because the stop request fired.
  bool stopped() const { return stopped_; }

 protected:
  std::streamsize xsputn(const char* bytes, std::streamsize count) override {
    return Stopping() ? 0 : sink_.sputn(bytes, count);
  }

  int_type overflow(int_type c) override {
    if (traits_type::eq_int_type(c, traits_type::eof())) return traits_type::not_eof(c);
    return Stopping() ? traits_type::eof() : sink_.sputc(traits_type::to_char_type(c));
  }

  int sync() override { return sink_.pubsync(); }

 private:
  // The request is polled on one write in kWritesPerPoll: a tree writes one
  // small record per node, so polling on each would cost more than it says.
  static constexpr unsigned kWritesPerPoll = 4096;

  bool Stopping() {
    if (stopped_ || !stop_) return stopped_;
    if (++writes_ % kWritesPerPoll == 0) stopped_ = stop_();
    return stopped_;
  }

  std::streambuf& sink_;
  std::function<bool()> stop_;
  unsigned writes_ = 0;
  bool stopped_ = false;
};

}  // namespace boicp
