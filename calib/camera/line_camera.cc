#include "calib/camera/line_camera.h"

#include "calib/camera/rotation.h"
#include "calib/core/csv.h"
#include "calib/core/error.h"

#include <cmath>

namespace aerocal::calib {

int LineCamera::SubcameraOf(double i) const {
  const long nearest = std::lround(i);
  if (!(nearest >= 0 && nearest < detectors)) return -1;
  if (!subcameras.empty()) {
    for (size_t k = 0; k < subcameras.size(); ++k)
      if (nearest >= subcameras[k].first && nearest <= subcameras[k].last) return int(k);
    return -1;
  }
  if (!calibration.empty()) {
    for (size_t k = 0; k < calibration.size(); ++k)
      if (nearest >= calibration[k].first && nearest <= calibration[k].last) return int(k);
    return -1;
  }
  return 0;
}

std::vector<std::pair<int, int>> LineCamera::Ranges() const {
  std::vector<std::pair<int, int>> ranges;
  if (!subcameras.empty()) {
    for (const auto& s : subcameras) ranges.emplace_back(s.first, s.last);
  } else if (!calibration.empty()) {
    for (const auto& p : calibration) ranges.emplace_back(p.first, p.last);
  } else {
    ranges.emplace_back(0, detectors - 1);
  }
  return ranges;
}

Eigen::Vector2d LineCamera::DesignPosition(double i) const {
  if (subcameras.empty()) return {(i - 0.5 * (detectors - 1)) * pitch_mm, 0.0};
  int k = SubcameraOf(i);
  if (k < 0) k = i < 0 ? 0 : int(subcameras.size()) - 1;  // extrapolate the outer sub-camera
  const LineSubcamera& s = subcameras[k];
  const double j = i - s.first;
  const Eigen::Vector3d ray_in_sub((j - 0.5 * (s.Count() - 1)) * s.pitch_mm, 0.0, -s.c_mm);
  const Eigen::Vector3d d = RotationFromOpk(s.mount_rad) * ray_in_sub;
  return {-c_mm * d.x() / d.z(), -c_mm * d.y() / d.z()};
}

Eigen::Vector2d LineCamera::Correction(double i) const {
  if (!calibration.empty()) {
    int k = SubcameraOf(i);
    if (k < 0) k = i < 0 ? 0 : int(calibration.size()) - 1;
    // With sub-cameras, the polynomial of the range that holds i.
    if (!subcameras.empty()) {
      const long nearest = std::lround(std::max(0.0, std::min<double>(i, detectors - 1)));
      for (size_t r = 0; r < calibration.size(); ++r)
        if (nearest >= calibration[r].first && nearest <= calibration[r].last) k = int(r);
    }
    const LinePolynomial& p = calibration[k];
    const double u = p.Normalised(i);
    return {EvaluatePolynomial(p.dx.data(), int(p.dx.size()), u),
            EvaluatePolynomial(p.dy.data(), int(p.dy.size()), u)};
  }
  if (dx_mm.empty()) return Eigen::Vector2d::Zero();
  const double clamped = std::max(0.0, std::min<double>(i, detectors - 1));
  const int i0 = std::min(int(std::floor(clamped)), detectors - 1);
  const int i1 = std::min(i0 + 1, detectors - 1);
  const double w = clamped - i0;
  return {(1 - w) * dx_mm[i0] + w * dx_mm[i1], (1 - w) * dy_mm[i0] + w * dy_mm[i1]};
}

void LineCamera::Validate(const std::string& file) const {
  const SourceRef where{file, 0};
  if (detectors <= 0) ThrowInputError(where, "line.detectors must be > 0");
  if (!(pitch_mm > 0)) ThrowInputError(where, "line.pitch_mm must be > 0");
  if (!(c_mm > 0)) ThrowInputError(where, "line.c must be > 0");
  if (!dx_mm.empty() && !calibration.empty())
    ThrowInputError(where,
                    "line: give either dx_mm/dy_mm tables or calibration polynomials, not both");
  if (dx_mm.size() != dy_mm.size() || (!dx_mm.empty() && int(dx_mm.size()) != detectors))
    ThrowInputError(where,
                    "line.dx_mm and line.dy_mm must both hold line.detectors (" +
                        std::to_string(detectors) + ") values (got " +
                        std::to_string(dx_mm.size()) + " and " + std::to_string(dy_mm.size()) +
                        ")");
  // Ranges: contiguous, in order, covering 0 .. N-1.
  auto check_ranges = [&](const std::vector<std::pair<int, int>>& ranges, const std::string& what) {
    int next = 0;
    for (const auto& [first, last] : ranges) {
      if (first != next || last < first)
        ThrowInputError(where,
                        what + " ranges must be contiguous from detector 0, in order (range [" +
                            std::to_string(first) + ", " + std::to_string(last) +
                            "] should start at " + std::to_string(next) + ")");
      next = last + 1;
    }
    if (next != detectors)
      ThrowInputError(where,
                      what + " ranges end at detector " + std::to_string(next - 1) +
                          ", expected line.detectors - 1 = " + std::to_string(detectors - 1));
  };
  if (!subcameras.empty()) {
    std::vector<std::pair<int, int>> r;
    for (const auto& s : subcameras) {
      if (!(s.c_mm > 0) || !(s.pitch_mm > 0))
        ThrowInputError(where, "sub-camera " + s.id + ": c and pitch_mm must be > 0");
      r.emplace_back(s.first, s.last);
    }
    check_ranges(r, "line.subcameras");
  }
  if (!calibration.empty()) {
    std::vector<std::pair<int, int>> r;
    for (const auto& p : calibration) r.emplace_back(p.first, p.last);
    check_ranges(r, "line.calibration");
    if (!subcameras.empty()) {
      // Each polynomial range lies within one sub-camera (jumps only at seams).
      for (const auto& p : calibration)
        if (SubcameraOf(p.first) != SubcameraOf(p.last))
          ThrowInputError(where,
                          "line.calibration range [" + std::to_string(p.first) + ", " +
                              std::to_string(p.last) + "] spans a sub-camera seam");
    }
  }
  // The design must put every detector in front of the virtual camera.
  for (const auto& s : subcameras)
    for (int i : {s.first, s.last}) {
      const Eigen::Vector3d d =
          RotationFromOpk(s.mount_rad) *
          Eigen::Vector3d((i - s.first - 0.5 * (s.Count() - 1)) * s.pitch_mm, 0.0, -s.c_mm);
      if (!(d.z() < -1e-3 * d.norm()))
        ThrowInputError(where,
                        "sub-camera " + s.id + ": detector " + std::to_string(i) +
                            " looks sideways or backwards in the virtual camera (mount " +
                            FormatNumber(s.mount_rad.x() * 180 / M_PI) + ", " +
                            FormatNumber(s.mount_rad.y() * 180 / M_PI) + ", " +
                            FormatNumber(s.mount_rad.z() * 180 / M_PI) + " deg)");
    }
}

LineCamera CombineLineCameras(const std::string& name,
                              std::vector<LineSubcamera> subcameras,
                              double c_mm,
                              double pitch_mm) {
  LineCamera camera;
  camera.name = name;
  camera.c_mm = c_mm;
  camera.pitch_mm = pitch_mm;
  int next = 0;
  for (auto& s : subcameras) {
    const int n = s.Count();
    AEROCAL_CHECK(n > 0) << "sub-camera " << s.id << " has no detectors";
    s.first = next;
    s.last = next + n - 1;
    next += n;
  }
  camera.detectors = next;
  camera.subcameras = std::move(subcameras);
  return camera;
}

}  // namespace aerocal::calib
