// Small SVG building blocks shared by the plots the commands write (`camera show --plot`, `rig
// design --svg`, ...): escaped text, axes with "nice" ticks, and a scale bar, so that every plot
// can be read without its caption (issue 33 item 3).
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace aerocal {

/// `text` with & < > " ' replaced by their XML entities: user text (ids, names, paths) is text in
/// an SVG, XML or HTML document, never markup. The camera files' XML writers use it too.
std::string SvgEscape(std::string_view text);

/// Tick values of 1, 2 or 5 times a power of ten covering [lo, hi] with about `count` intervals
/// (at least 2 ticks for lo < hi; {lo} when lo == hi). Requires finite lo <= hi.
std::vector<double> NiceTicks(double lo, double hi, int count = 5);

/// A plot panel: its frame in SVG pixels (left, bottom = lower-left corner; y grows downwards in
/// SVG) and the data ranges it shows.
struct SvgPanel {
  double left = 0, bottom = 0, width = 0, height = 0;
  double x_lo = 0, x_hi = 1, y_lo = 0, y_hi = 1;
  double X(double x) const { return left + width * (x - x_lo) / (x_hi - x_lo); }
  double Y(double y) const { return bottom - height * (y - y_lo) / (y_hi - y_lo); }
};

/// The panel's frame, NiceTicks on both axes with their values, and the axis titles
/// (`x_label` under the axis, `y_label` turned along the left axis).
std::string SvgAxes(const SvgPanel& panel, const std::string& x_label, const std::string& y_label);

/// A scale bar starting at (x, y) (SVG pixels): the longest length of 1, 2 or 5 times a power of
/// ten that fits `max_svg_px` at `units_per_svg_px`, drawn with end ticks and labelled with its
/// length and `unit` ("200 m").
std::string SvgScaleBar(
    double x, double y, double units_per_svg_px, double max_svg_px, const std::string& unit);

}  // namespace aerocal
