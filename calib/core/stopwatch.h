// THE wall-clock stopwatch of the project: the seconds of a solve, a snooping round or a stage in
// a report's profile. Steady clock (monotonic: never jumps with the system time), seconds as a
// double.
#pragma once

#include <chrono>

namespace aerocal {

class Stopwatch {
 public:
  Stopwatch() : start_(Clock::now()) {}
  /// Wall seconds since construction or the last Restart (>= 0).
  double Seconds() const { return std::chrono::duration<double>(Clock::now() - start_).count(); }
  void Restart() { start_ = Clock::now(); }

 private:
  using Clock = std::chrono::steady_clock;
  Clock::time_point start_;
};

}  // namespace aerocal
