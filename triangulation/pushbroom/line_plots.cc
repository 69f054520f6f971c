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

// The page layout (px): panel size, margins and gaps.
constexpr double kPanelW = 420, kPanelH = 200, kLeft = 70, kTop = 40, kGapX = 70, kGapY = 60;

// One panel: a sub-camera's table on one axis against the detector index.
struct Panel {
  double x0, y0;  // bottom-left corner
  double lo, hi;  // value range, px
  int first, last;
  double X(double i) const { return x0 + kPanelW * (i - first) / std::max(1, last - first); }
  double Y(double v) const { return y0 - kPanelH * (v - lo) / (hi - lo); }
};

// Value range: the table with its band, and the central 98 % of the samples; padded by 5 %.
void ValueRange(const std::vector<double>& table,
                const std::vector<std::optional<double>>& sigma,
                const SubcameraRms& sub,
                std::vector<double> samples,
                double pitch,
                Panel* panel) {
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
  panel->lo = lo - pad;
  panel->hi = hi + pad;
}

// The panel's frame, zero line and captions.
void WritePanelFrame(const Panel& p,
                     const SubcameraRms& sub,
                     const char* axis_name,
                     std::ostringstream& s) {
  s << StringPrintf(
           "<g data-subcamera=\"%s\" data-axis=\"%s\">\n", SvgEscape(sub.id).c_str(), axis_name)
    << StringPrintf(
           "<rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"%.1f\" fill=\"none\" "
           "stroke=\"black\"/>\n",
           p.x0,
           p.y0 - kPanelH,
           kPanelW,
           kPanelH);
  if (p.lo < 0 && p.hi > 0)
    s << StringPrintf("<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#999\"/>\n",
                      p.x0,
                      p.Y(0),
                      p.x0 + kPanelW,
                      p.Y(0));
  s << StringPrintf("<text x=\"%.1f\" y=\"%.1f\">%s, %s track: %.4g .. %.4g px</text>\n",
                    p.x0,
                    p.y0 - kPanelH - 6,
                    SvgEscape(sub.id).c_str(),
                    axis_name,
                    p.lo,
                    p.hi)
    << StringPrintf("<text x=\"%.1f\" y=\"%.1f\">detector %d .. %d</text>\n",
                    p.x0,
                    p.y0 + 16,
                    p.first,
                    p.last);
}

// The fitted table with its band (upper edge forwards, lower edge backwards, only where the
// sigma is known), the error samples as dots.
void WritePanelData(const Panel& p,
                    const std::vector<double>& table,
                    const std::vector<std::optional<double>>& sigma,
                    const std::vector<std::pair<double, double>>& dots,
                    double pitch,
                    std::ostringstream& s) {
  bool band = true;
  for (int i = p.first; i <= p.last; ++i) band = band && sigma[i].has_value();
  if (band) {
    s << "<polygon class=\"band\" fill=\"#1f77b4\" fill-opacity=\"0.25\" stroke=\"none\" "
         "points=\"";
    for (int i = p.first; i <= p.last; ++i)
      s << StringPrintf("%.1f,%.2f ", p.X(i), p.Y((table[i] + *sigma[i]) / pitch));
    for (int i = p.last; i >= p.first; --i)
      s << StringPrintf("%.1f,%.2f ", p.X(i), p.Y((table[i] - *sigma[i]) / pitch));
    s << "\"/>\n";
  }
  for (const auto& [i, v] : dots)
    if (v >= p.lo && v <= p.hi)
      s << StringPrintf(
          "<circle cx=\"%.1f\" cy=\"%.2f\" r=\"1.2\" fill=\"#d62728\"/>\n", p.X(i), p.Y(v));
  s << "<polyline class=\"fit\" fill=\"none\" stroke=\"#1f77b4\" stroke-width=\"1.5\" "
       "points=\"";
  for (int i = p.first; i <= p.last; ++i)
    s << StringPrintf("%.1f,%.2f ", p.X(i), p.Y(table[i] / pitch));
  s << "\"/>\n</g>\n";
}

// The panel of sub-camera k on `axis` (0 across, 1 along).
void WritePanel(const LineCalibrationResult& result, int k, int axis, std::ostringstream& s) {
  const double pitch = result.camera.pitch_mm;
  const SubcameraRms& sub = result.subcameras[k];
  const auto& table = axis == 0 ? result.dx_mm : result.dy_mm;
  const auto& sigma = axis == 0 ? result.dx_sigma_mm : result.dy_sigma_mm;
  std::vector<double> samples;
  std::vector<std::pair<double, double>> dots;
  for (const auto& e : result.error_samples)
    if (e.subcamera == k) {
      dots.emplace_back(e.detector, axis == 0 ? e.across_px : e.along_px);
      samples.push_back(dots.back().second);
    }
  Panel p;
  p.x0 = kLeft + axis * (kPanelW + kGapX);
  p.y0 = kTop + k * (kPanelH + kGapY) + kPanelH;
  p.first = sub.first;
  p.last = sub.last;
  ValueRange(table, sigma, sub, samples, pitch, &p);
  WritePanelFrame(p, sub, axis == 0 ? "across" : "along", s);
  WritePanelData(p, table, sigma, dots, pitch, s);
}

}  // namespace

std::string LineCalibrationSvg(const LineCalibrationResult& result, const std::string& title) {
  const int rows = int(result.subcameras.size());
  std::ostringstream s;
  s << StringPrintf(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%.0f\" height=\"%.0f\" "
      "font-family=\"sans-serif\" font-size=\"12\">\n<title>%s</title>\n"
      "<text x=\"10\" y=\"18\">%s: reprojection error without the detector calibration (dots), "
      "fitted table (line) and its 1-sigma band, px (pitches)</text>\n",
      kLeft + 2 * kPanelW + kGapX + 20,
      kTop + rows * (kPanelH + kGapY),
      SvgEscape(title).c_str(),
      SvgEscape(title).c_str());
  for (int k = 0; k < rows; ++k)
    for (int axis = 0; axis < 2; ++axis) WritePanel(result, k, axis, s);
  s << "</svg>\n";
  return s.str();
}

}  // namespace aerocal::triangulation
