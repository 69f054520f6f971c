// PhotoModeler's camera: the calibration of a PhotoModeler "Bundle Soln" text export (lines 1-5 of
// the file; the photos that follow are not read). Layout, as the export of the DBAT camcal demo
// (../shared/data/dbat_camcal_olympus_c4040z/photomodeler/camcal-pmexport.txt, PhotoModeler
// Scanner 2016) shows it:
//   1  Bundle Soln <project title>
//   2  <tolerance> <last photo index> <image width px> <image height px>
//   3  nine a-priori weights of the adjustment (not read)
//   4  f  ppx  ppy  format-width  format-height  K1  K2  K3  P1  P2     (mm, mm^-2 .. mm^-6, mm^-1)
//   5  the a-priori sigmas of line 4 (not read: they are settings, not results)
// The parameters are those of PhotoModeler's Camera Viewer dialog, with the conventions of its
// online help (photomodeler.com/downloads/OnlineHelp/pages/camera-parameters.html,
// lens-distortion-formulation.html, radial-lens-distortion.html, decentering-lens-distortion.html):
//   - the principal point is "relative to the upper-left corner of the image", in mm;
//   - the correction is applied to the MARKED point (x, y) in mm from the principal point:
//       xc = x + x (K1 r^2 + K2 r^4 + K3 r^6) + P1 (r^2 + 2 x^2) + 2 P2 x y
//       yc = y + y (K1 r^2 + K2 r^4 + K3 r^6) + P2 (r^2 + 2 y^2) + 2 P1 x y
//     (the "unbalanced" form), i.e. our correction form (brown_fraser_10) without B1, B2.
// The help does not say which way y points in those formulas; y up is DBAT's reading (its model 3
// reproduces PhotoModeler's projects, DBAT's PROVENANCE above), and with the principal point from
// the upper-left corner: x0 = ppx - W p / 2, y0 = H p / 2 - ppy. The pixel size is the format
// height over the image height (square pixels, as DBAT reads it); a format width that disagrees
// (PhotoModeler's x scale, what DBAT calls the aspect) is reported as a note, not modelled.
// Also read: a PhotoModeler calibration / project status report's camera block ("Camera1: ...",
// then "Focal Length", "Xp - principal point x", "Yp", "Fw - format width", "Fh", "K1"-"P2" title
// lines with "Value: X mm" and "Deviation: Name: Y mm"; report_camera.cc), the same conventions.
// Writing gives lines 1-5 with no photos: the camera as PhotoModeler's export holds it; that
// PhotoModeler imports such a file is not verified (no PhotoModeler here).
#include "calib/camera/formats/camera_formats.h"
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"

#include <cmath>
#include <filesystem>
#include <sstream>

namespace aerocal::calib {
namespace {

using Model = BrownFraser10Model;

std::vector<double> Numbers(const std::vector<std::string>& lines,
                            int index,
                            size_t count,
                            const std::string& path,
                            const std::string& what) {
  const SourceRef where{path, index + 1};
  if (index >= static_cast<int>(lines.size()))
    ThrowInputError(where, "missing line " + std::to_string(index + 1) + " (" + what + ")");
  std::istringstream in(lines[index]);
  std::vector<double> out;
  for (std::string token; in >> token;)
    out.push_back(internal::ParseNumber(token, where, what, 1e6));
  if (out.size() < count)
    ThrowInputError(where,
                    what + " needs " + std::to_string(count) + " numbers (got " +
                        std::to_string(out.size()) + ")");
  return out;
}

}  // namespace

bool IsPhotoModelerReport(const std::string& head) {
  return head.find("Xp - principal point x") != std::string::npos &&
         head.find("Focal Length") != std::string::npos;
}

CameraFile ReadPhotoModelerCamera(const std::string& path, const CameraReadOptions& options) {
  const std::string text = ReadTextFile(path);
  const std::vector<std::string> lines = SplitLines(text);
  if (IsPhotoModelerReport(text))
    return internal::ReadReportCamera(path, lines, options, "PhotoModeler");
  if (lines.empty() || lines[0].rfind("Bundle Soln", 0) != 0)
    ThrowInputError({path, 1},
                    "not a PhotoModeler Bundle Soln export (line 1 must start with "
                    "'Bundle Soln')");
  if (!options.camera_id.empty())
    ThrowInputError({path, 1}, "--camera: a Bundle Soln export holds one project camera");
  const std::vector<double> size = Numbers(lines, 1, 4, path, "tolerance, photos, width, height");
  const std::vector<double> cam = Numbers(lines, 3, 10, path, "f ppx ppy fw fh K1 K2 K3 P1 P2");
  const SourceRef where_size{path, 2}, where_cam{path, 4};
  const double w = size[2], h = size[3];
  if (!(w >= 1 && h >= 1 && w == std::floor(w) && h == std::floor(h) && w <= 1e6 && h <= 1e6))
    ThrowInputError(where_size, "image width and height must be positive integers (px)");
  const double f = cam[0], ppx = cam[1], ppy = cam[2], fw = cam[3], fh = cam[4];
  if (!(f > 0)) ThrowInputError(where_cam, "focal length must be > 0 mm");
  if (!(fw > 0 && fh > 0)) ThrowInputError(where_cam, "format size must be > 0 mm");
  for (int i = 5; i < 10; ++i)
    if (!(std::abs(cam[i]) <= 1.0))
      ThrowInputError(where_cam,
                      "K1-K3, P1, P2 must be within +-1 (got " + FormatNumber(cam[i]) + ")");
  CameraFile file;
  file.name =
      lines[0].size() > 11 ? lines[0].substr(12) : std::filesystem::path(path).stem().string();
  const double pixel = fh / h;  // square pixels from the format height
  internal::ResolveFormat(
      &file, options, where_size, static_cast<int>(w), static_cast<int>(h), pixel);
  const double p = file.camera.frame.pixel_size_mm;
  const double x_scale = fw / w;  // PhotoModeler's mm per pixel along x
  if (std::abs(x_scale / p - 1.0) > 1e-6)
    file.notes.push_back("PhotoModeler format width " + FormatNumber(fw) + " mm is " +
                         FormatNumber(w * p) +
                         " mm at the square pixel of the format height: x "
                         "scale " +
                         FormatNumber(x_scale / p - 1.0) +
                         " not modelled (the "
                         "principal point is kept in pixels)");
  file.camera.model = Model::kId;
  file.camera.params.assign(Model::kNumParams, 0.0);
  std::vector<double>& q = file.camera.params;
  q[Model::kC] = f;
  q[Model::kX0] = (ppx / x_scale - 0.5 * w) * p;
  q[Model::kY0] = (0.5 * h - ppy / p) * p;
  q[Model::kK1] = cam[5];
  q[Model::kK2] = cam[6];
  q[Model::kK3] = cam[7];
  q[Model::kP1] = cam[8];
  q[Model::kP2] = cam[9];
  file.notes.push_back(
      "PhotoModeler's y direction in its distortion formulas is not stated by its "
      "help: y up as DBAT reads it");
  return file;
}

void WritePhotoModelerCamera(const std::string& path, const CameraFile& file) {
  AEROCAL_CHECK(file.camera.model == Model::kId) << "not brown_fraser_10";
  const PixelFrame& f = file.camera.frame;
  const std::vector<double>& q = file.camera.params;
  const double w_mm = f.width_px * f.pixel_size_mm, h_mm = f.height_px * f.pixel_size_mm;
  const auto n = [](double v) { return internal::ShortestNumber(v); };
  std::ostringstream out;
  out << "Bundle Soln " << (file.name.empty() ? "aerocal camera" : internal::OneLine(file.name))
      << "\n"
      << " 0 -1 " << f.width_px << " " << f.height_px << "\n"
      << " 1 0 0 0 0 0 0 0 0\n"
      << " " << n(q[Model::kC]) << " " << n(q[Model::kX0] + 0.5 * w_mm) << " "
      << n(0.5 * h_mm - q[Model::kY0]) << " " << n(w_mm) << " " << n(h_mm) << " "
      << n(q[Model::kK1]) << " " << n(q[Model::kK2]) << " " << n(q[Model::kK3]) << " "
      << n(q[Model::kP1]) << " " << n(q[Model::kP2]) << "\n 0 0 0 0 0 0 0 0 0 0\n";
  WriteFileAtomically(path, out.str());
}

}  // namespace aerocal::calib
