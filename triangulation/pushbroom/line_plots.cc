#include "triangulation/pushbroom/line_plots.h"

#include "calib/core/string_printf.h"
#include "calib/core/svg.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace aerocal::triangulation {
namespace {

// Value of `sorted` at fraction q (0 .. 1).
double Quantile(const std::vector<double>& sorted, double q) {
  return sorted[std::min(sorted.size() - 1, size_t(q * (sorted.size() - 1) + 0.5))];
}

}  // namespace

std::string LineCalibrationSvg(const LineCalibrationResult& result, const std::string& title) {
  const double pitch = result.camera.pitch_mm;
  const double panel_w = 420, panel_h = 200, left = 70, top = 40, gap_x = 70, gap_y = 60;
  const int rows = int(result.subcameras.size());
  std::ostringstream s;
  s << StringPrintf(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%.0f\" height=\"%.0f\" "
      "font-family=\"sans-serif\" font-size=\"12\">\n<title>%s</title>\n"
      "<text x=\"10\" y=\"18\">%s: reprojection error without the detector calibration (dots), "
      "fitted table (line) and its 1-sigma band, px (pitches)</text>\n",
      left + 2 * panel_w + gap_x + 20,
      top + rows * (panel_h + gap_y),
      SvgEscape(title).c_str(),
      SvgEscape(title).c_str());
  for (int k = 0; k < rows; ++k) {
    const SubcameraRms& sub = result.subcameras[k];
    for (int axis = 0; axis < 2; ++axis) {
      const auto& table = axis == 0 ? result.dx_mm : result.dy_mm;
      const auto& sigma = axis == 0 ? result.dx_sigma_mm : result.dy_sigma_mm;
      std::vector<double> samples;
      std::vector<std::pair<double, double>> dots;
      for (const auto& e : result.error_samples)
        if (e.subcamera == k) {
          dots.emplace_back(e.detector, axis == 0 ? e.across_px : e.along_px);
          samples.push_back(dots.back().second);
        }
      // Value range: the table with its band, and the central 98 % of the samples.
      double lo = 1e300, hi = -1e300;
      for (int i = sub.first; i <= sub.last && i < int(table.size()); ++i) {
        const double band = sigma[i].value_or(0.0) / pitch;
        lo = std::min(lo, table[i] / pitch - band);
        hi = std::max(hi, table[i] / pitch + band);
      }
      if (!samples.empty()) {
        std::sort(samples.begin(), samples.end());
        lo = std::min(lo, Quantile(samples, 0.01));
        hi = std::max(hi, Quantile(samples, 0.99));
      }
      if (!(hi > lo)) lo -= 0.5, hi += 0.5;
      const double pad = 0.05 * (hi - lo);
      lo -= pad, hi += pad;
      const double x0 = left + axis * (panel_w + gap_x), y0 = top + k * (panel_h + gap_y) + panel_h;
      const double span = std::max(1, sub.last - sub.first);
      const auto px = [&](double i) { return x0 + panel_w * (i - sub.first) / span; };
      const auto py = [&](double v) { return y0 - panel_h * (v - lo) / (hi - lo); };
      const char* axis_name = axis == 0 ? "across" : "along";
      s << StringPrintf(
               "<g data-subcamera=\"%s\" data-axis=\"%s\">\n", SvgEscape(sub.id).c_str(), axis_name)
        << StringPrintf(
               "<rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"%.1f\" fill=\"none\" "
               "stroke=\"black\"/>\n",
               x0,
               y0 - panel_h,
               panel_w,
               panel_h);
      if (lo < 0 && hi > 0)
        s << StringPrintf(
            "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#999\"/>\n",
            x0,
            py(0),
            x0 + panel_w,
            py(0));
      s << StringPrintf("<text x=\"%.1f\" y=\"%.1f\">%s, %s track: %.4g .. %.4g px</text>\n",
                        x0,
                        y0 - panel_h - 6,
                        SvgEscape(sub.id).c_str(),
                        axis_name,
                        lo,
                        hi)
        << StringPrintf("<text x=\"%.1f\" y=\"%.1f\">detector %d .. %d</text>\n",
                        x0,
                        y0 + 16,
                        sub.first,
                        sub.last);
      // The band: upper edge forwards, lower edge backwards (only where the sigma is known).
      bool band = true;
      for (int i = sub.first; i <= sub.last; ++i) band = band && sigma[i].has_value();
      if (band) {
        s << "<polygon class=\"band\" fill=\"#1f77b4\" fill-opacity=\"0.25\" stroke=\"none\" "
             "points=\"";
        for (int i = sub.first; i <= sub.last; ++i)
          s << StringPrintf("%.1f,%.2f ", px(i), py((table[i] + *sigma[i]) / pitch));
        for (int i = sub.last; i >= sub.first; --i)
          s << StringPrintf("%.1f,%.2f ", px(i), py((table[i] - *sigma[i]) / pitch));
        s << "\"/>\n";
      }
      for (const auto& [i, v] : dots)
        if (v >= lo && v <= hi)
          s << StringPrintf(
              "<circle cx=\"%.1f\" cy=\"%.2f\" r=\"1.2\" fill=\"#d62728\"/>\n", px(i), py(v));
      s << "<polyline class=\"fit\" fill=\"none\" stroke=\"#1f77b4\" stroke-width=\"1.5\" "
           "points=\"";
      for (int i = sub.first; i <= sub.last; ++i)
        s << StringPrintf("%.1f,%.2f ", px(i), py(table[i] / pitch));
      s << "\"/>\n</g>\n";
    }
  }
  s << "</svg>\n";
  return s.str();
}

}  // namespace aerocal::triangulation
