#include "calib/core/svg.h"

#include "calib/core/error.h"
#include "calib/core/string_printf.h"

#include <cmath>

namespace aerocal {
namespace {

// 1, 2 or 5 times a power of ten, the largest not above `value` (> 0).
double NiceFloor(double value) {
  const double power = std::pow(10.0, std::floor(std::log10(value)));
  for (double m : {5.0, 2.0, 1.0})
    if (m * power <= value * (1 + 1e-12)) return m * power;
  return power;
}

// A tick value as text: %g with enough digits for the step, and no "-0".
std::string TickText(double value, double step) {
  if (std::abs(value) < 1e-9 * step) value = 0.0;
  return StringPrintf("%.6g", value);
}

}  // namespace

std::string SvgEscape(std::string_view text) {
  std::string out;
  for (char ch : text) {
    switch (ch) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&apos;";
        break;
      default:
        out += ch;
    }
  }
  return out;
}

std::vector<double> NiceTicks(double lo, double hi, int count) {
  AEROCAL_CHECK(std::isfinite(lo) && std::isfinite(hi) && lo <= hi && count >= 1)
      << "NiceTicks(" << lo << ", " << hi << ", " << count << ")";
  if (lo == hi) return {lo};
  // The step: the smallest 1, 2 or 5 times a power of ten not below (hi - lo) / count, so there
  // are at most `count` intervals; the ticks are its multiples within [lo, hi].
  const double raw = (hi - lo) / count;
  const double power = std::pow(10.0, std::floor(std::log10(raw)));
  double step = 10 * power;
  for (double m : {1.0, 2.0, 5.0})
    if (m * power >= raw * (1 - 1e-12)) {
      step = m * power;
      break;
    }
  std::vector<double> ticks;
  const double first = std::ceil(lo / step - 1e-9) * step;
  for (int k = 0; first + k * step <= hi + 1e-9 * step; ++k) ticks.push_back(first + k * step);
  if (ticks.size() < 2) ticks = {lo, hi};
  return ticks;
}

std::string SvgAxes(const SvgPanel& p, const std::string& x_label, const std::string& y_label) {
  std::string s = StringPrintf(
      "<rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"%.1f\" fill=\"none\" "
      "stroke=\"black\"/>\n",
      p.left,
      p.bottom - p.height,
      p.width,
      p.height);
  const std::vector<double> xs = NiceTicks(std::min(p.x_lo, p.x_hi), std::max(p.x_lo, p.x_hi));
  const double x_step = xs.size() > 1 ? xs[1] - xs[0] : 1.0;
  for (double x : xs)
    s += StringPrintf(
        "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"black\"/>"
        "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\" font-size=\"10\">%s</text>\n",
        p.X(x),
        p.bottom,
        p.X(x),
        p.bottom + 5,
        p.X(x),
        p.bottom + 16,
        TickText(x, x_step).c_str());
  const std::vector<double> ys = NiceTicks(std::min(p.y_lo, p.y_hi), std::max(p.y_lo, p.y_hi));
  const double y_step = ys.size() > 1 ? ys[1] - ys[0] : 1.0;
  for (double y : ys)
    s += StringPrintf(
        "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"black\"/>"
        "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"end\" font-size=\"10\">%s</text>\n",
        p.left - 5,
        p.Y(y),
        p.left,
        p.Y(y),
        p.left - 7,
        p.Y(y) + 3.5,
        TickText(y, y_step).c_str());
  s += StringPrintf(
      "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\">%s</text>\n"
      "<text transform=\"translate(%.1f %.1f) rotate(-90)\" text-anchor=\"middle\">%s</text>\n",
      p.left + p.width / 2,
      p.bottom + 32,
      SvgEscape(x_label).c_str(),
      p.left - 42,
      p.bottom - p.height / 2,
      SvgEscape(y_label).c_str());
  return s;
}

std::string SvgScaleBar(
    double x, double y, double units_per_svg_px, double max_svg_px, const std::string& unit) {
  AEROCAL_CHECK(units_per_svg_px > 0 && max_svg_px > 0) << "SvgScaleBar";
  const double length = NiceFloor(units_per_svg_px * max_svg_px);
  const double w = length / units_per_svg_px;
  return StringPrintf(
      "<g class=\"scale-bar\"><line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" "
      "stroke=\"black\" stroke-width=\"2\"/>"
      "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"black\"/>"
      "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"black\"/>"
      "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\">%s %s</text></g>\n",
      x,
      y,
      x + w,
      y,
      x,
      y - 4,
      x,
      y + 4,
      x + w,
      y - 4,
      x + w,
      y + 4,
      x + w / 2,
      y - 7,
      TickText(length, length).c_str(),
      SvgEscape(unit).c_str());
}

}  // namespace aerocal
