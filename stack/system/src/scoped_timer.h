#pragma once
#include <chrono>

namespace trimbot::stack {

// Adds the wall-clock time of a scope to a timing counter (StackTimings).
class ScopedTimer {
 public:
  using Clock = std::chrono::steady_clock;
  explicit ScopedTimer(double* total) : total_(total), start_(Clock::now()) {}
  ~ScopedTimer() { *total_ += std::chrono::duration<double>(Clock::now() - start_).count(); }
  ScopedTimer(const ScopedTimer&) = delete;
  ScopedTimer& operator=(const ScopedTimer&) = delete;

 private:
  double* total_;
  Clock::time_point start_;
};

}  // namespace trimbot::stack
