// Progress for long work (batch stitching, matching, resampling, big adjustments, the flight and
// its report, `aerocal batch run`): units done / total, elapsed time, rate and ETA at that rate.
// On a terminal: a single updating line on stderr. Otherwise (a log, a batch job's output): one
// line per stage, `LABEL: DONE/TOTAL STAGE (S s)`, printed for every unit when there are at most
// 20, else at every tenth of the work, so a long run shows it is alive without flooding the log;
// --quiet (LogLevel::kQuiet) and SetEnabled(false) print nothing. Thread-safe Advance().
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
  /// Names the stage now running (shown on the next line drawn or logged; "" for none).
  void Stage(const std::string& name);
  /// Force-enable or disable the terminal line (default: whether stderr is a terminal); disabled
  /// by this call, nothing is logged either.
  static void SetEnabled(bool enabled);
  /// Called after every Advance with (done, total) on the advancing thread, whether or not the
  /// line is drawn (the Python module's progress callback). It may throw: the work stops there.
  using Observer = std::function<void(long done, long total)>;
  void SetObserver(Observer observer) { observer_ = std::move(observer); }

 private:
  void Draw(bool final_line);
  void LogLine(long done);
  std::string label_, stage_;
  long total_;
  std::atomic<long> done_{0};
  std::mutex mutex_;
  std::chrono::steady_clock::time_point start_, last_draw_;
  bool finished_ = false;
  bool enabled_;           // the terminal line
  bool logged_;            // line-per-stage log (not a terminal, not disabled, not --quiet)
  long last_logged_ = -1;  // the `done` of the last logged line
  Observer observer_;
};

}  // namespace aerocal
