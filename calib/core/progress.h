// Progress on a terminal for long work (batch stitching, matching, resampling, big adjustments,
// `aerocal batch run`): units done / total, elapsed time, rate and ETA at that rate.
// Draws a single updating line on stderr when stderr is a terminal; prints nothing otherwise, so
// logs and CI output stay clean. Thread-safe Advance().
#pragma once

#include <atomic>
#include <chrono>
#include <functional>
#include <mutex>
#include <string>

namespace aerocal {

class Progress {
 public:
  /// `total` units of work; `label` is shown before the bar.
  Progress(std::string label, long total);
  ~Progress();
  void Advance(long units = 1);
  void Finish();
  /// Force-enable or disable drawing (default: whether stderr is a terminal).
  static void SetEnabled(bool enabled);
  /// Called after every Advance with (done, total) on the advancing thread, whether or not the
  /// line is drawn (the Python module's progress callback). It may throw: the work stops there.
  using Observer = std::function<void(long done, long total)>;
  void SetObserver(Observer observer) { observer_ = std::move(observer); }

 private:
  void Draw(bool final_line);
  std::string label_;
  long total_;
  std::atomic<long> done_{0};
  std::mutex mutex_;
  std::chrono::steady_clock::time_point start_, last_draw_;
  bool finished_ = false;
  bool enabled_;
  Observer observer_;
};

}  // namespace aerocal
