#include "calib/core/progress.h"

#include "calib/core/log.h"

#include <algorithm>
#include <cstdio>
#include <unistd.h>

namespace aerocal {
namespace {
int& EnabledOverride() {
  static int value = -1;  // -1: decide by isatty
  return value;
}
}  // namespace

void Progress::SetEnabled(bool enabled) { EnabledOverride() = enabled ? 1 : 0; }

Progress::Progress(std::string label, long total)
    : label_(std::move(label)),
      total_(total > 0 ? total : 1),
      start_(std::chrono::steady_clock::now()),
      last_draw_(start_),
      enabled_(EnabledOverride() >= 0 ? EnabledOverride() == 1 : ::isatty(STDERR_FILENO) == 1),
      logged_(!enabled_ && EnabledOverride() != 0 && GetLogLevel() != LogLevel::kQuiet) {
  if (enabled_) Draw(false);
}

void Progress::Stage(const std::string& name) {
  std::lock_guard<std::mutex> lock(mutex_);
  stage_ = name;
  if (enabled_) Draw(false);
}

// A line when `done` reaches the next tenth of the work (every unit up to 20 units).
void Progress::LogLine(long done) {
  const long step = total_ <= 20 ? 1 : (total_ + 9) / 10;
  if (done < total_ && done / step == last_logged_ / step) return;
  last_logged_ = done;
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  std::fprintf(stderr,
               "%s: %ld/%ld%s%s (%.1f s)\n",
               label_.c_str(),
               done,
               total_,
               stage_.empty() ? "" : " ",
               stage_.c_str(),
               seconds);
  std::fflush(stderr);
}

Progress::~Progress() { Finish(); }

void Progress::Advance(long units) {
  const long done = done_ += units;
  if (observer_) observer_(std::min(done, total_), total_);
  if (logged_) {
    std::lock_guard<std::mutex> lock(mutex_);
    LogLine(std::min(done, total_));
  }
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  std::lock_guard<std::mutex> lock(mutex_);
  if (now - last_draw_ < std::chrono::milliseconds(100) && done_ < total_) return;
  last_draw_ = now;
  Draw(false);
}

void Progress::Finish() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (finished_) return;
  finished_ = true;
  if (enabled_) Draw(true);
}

void Progress::Draw(bool final_line) {
  const long done = std::min<long>(done_, total_);
  const double fraction = static_cast<double>(done) / static_cast<double>(total_);
  const int width = 30;
  const int filled = static_cast<int>(fraction * width);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  std::string bar(filled, '#');
  bar.resize(width, '.');
  // Rate and the time left at that rate, once a unit is done (the first says nothing of the rest
  // before it finishes); blanks at the end clear a longer previous line.
  char rate[64] = "";
  if (done > 0 && seconds > 0) {
    const double per_second = done / seconds;
    std::snprintf(
        rate, sizeof(rate), ", %.3g/s, ETA %.0f s", per_second, (total_ - done) / per_second);
  }
  std::fprintf(stderr,
               "\r%s [%s] %ld/%ld %5.1f s%s%s%s   %s",
               label_.c_str(),
               bar.c_str(),
               done,
               total_,
               seconds,
               rate,
               stage_.empty() ? "" : " ",
               stage_.c_str(),
               final_line ? "\n" : "");
  std::fflush(stderr);
}

}  // namespace aerocal
