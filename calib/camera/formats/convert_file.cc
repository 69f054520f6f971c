// A camera file expressed in a format's model (camera_formats.h ConvertCameraFile): ConvertCamera
// with the parameters the format cannot hold at 0, and the covariance carried through the
// conversion's Jacobian.
#include "calib/camera/formats/camera_formats.h"
#include "calib/core/numeric_jacobian.h"

#include <cmath>
#include <cstdio>
#include <limits>

namespace aerocal::calib {

FileConversion ConvertCameraFile(const CameraFile& from,
                                 const FormatTarget& target,
                                 const ConvertOptions& options) {
  if (target.needs_pixel_size && !from.pixel_size_known)
    throw ConfigError(
        "--pixel-size-mm: the target holds millimetres and the source gives no pixel "
        "size");
  FileConversion out;
  ConvertOptions o = options;
  o.zero.insert(o.zero.end(), target.zero_params.begin(), target.zero_params.end());
  out.result = ConvertCamera(from.camera, target.model, o);
  out.file.name = from.name;
  out.file.camera = out.result.camera;
  out.file.pixel_size_known = from.pixel_size_known;
  if (from.covariance) {
    // Linear propagation: C_to = J C_from J^T, J = d(target params)/d(source params) by central
    // differences of the whole conversion (closed form or fit; the fit converges far below the
    // step, see convert_file_test). The residual check of the perturbed conversions is skipped.
    ConvertOptions quick = o;
    quick.check_grid = 2;
    const Eigen::MatrixXd jacobian = NumericJacobian(
        [&](const std::vector<double>& params) {
          ModelCamera perturbed = from.camera;
          perturbed.params = params;
          const ConversionResult r = ConvertCamera(perturbed, target.model, quick);
          return Eigen::VectorXd(
              Eigen::Map<const Eigen::VectorXd>(r.camera.params.data(), r.camera.params.size()));
        },
        from.camera.params);
    out.file.covariance = jacobian * *from.covariance * jacobian.transpose();
    out.notes.push_back("covariance propagated through the conversion's Jacobian (J C J^T)");
  }
  return out;
}

FileConversion ConvertCameraFileSimplest(const CameraFile& from,
                                         const FormatTarget& target,
                                         const ConvertOptions& options,
                                         int max_coefficients,
                                         std::vector<std::string>* tried) {
  if (!target.coefficient_choice) return ConvertCameraFile(from, target, options);
  if (max_coefficients < 4) throw ConfigError("--max-coefficients must be >= 4 (k1 k2 p1 p2)");
  struct Choice {
    int n;
    const char* terms;
    std::vector<std::string> zero;
  };
  const Choice choices[] = {{4, "k1 k2 p1 p2", {"k3", "k4", "k5", "k6"}},
                            {5, "k1 k2 p1 p2 k3", {"k4", "k5", "k6"}},
                            {8, "k1 k2 p1 p2 k3 k4 k5 k6", {}}};
  const bool colmap = target.model == CameraModelId::kColmapOpenCv ||
                      target.model == CameraModelId::kColmapFullOpenCv;
  ConvertOptions ungated = options;
  ungated.max_residual_px = std::numeric_limits<double>::infinity();
  std::vector<std::pair<int, FileConversion>> results;
  for (const Choice& c : choices) {
    if (c.n > max_coefficients) break;
    FormatTarget t = target;
    t.zero_params = c.zero;
    if (colmap) {  // COLMAP's OPENCV holds exactly 4; FULL_OPENCV the rest
      t.model = c.n == 4 ? CameraModelId::kColmapOpenCv : CameraModelId::kColmapFullOpenCv;
      if (c.n == 4) t.zero_params.clear();
    }
    results.emplace_back(c.n, ConvertCameraFile(from, t, ungated));
    const ConversionResidual& r = results.back().second.result.residual;
    char line[200];
    std::snprintf(line,
                  sizeof(line),
                  "%d coefficients (%s): residual max %.3g px, rms %.3g px%s",
                  c.n,
                  c.terms,
                  r.max_px,
                  r.rms_px,
                  r.failed_points ? " (points not invertible)" : "");
    if (tried) tried->push_back(line);
  }
  double best = std::numeric_limits<double>::infinity();
  for (const auto& [n, conversion] : results)
    if (conversion.result.residual.failed_points == 0)
      best = std::min(best, conversion.result.residual.max_px);
  const bool gated = std::isfinite(options.max_residual_px);
  size_t pick = results.size() - 1;
  for (size_t k = 0; k < results.size(); ++k) {
    const ConversionResidual& r = results[k].second.result.residual;
    if (r.failed_points == 0 && r.max_px <= (gated ? options.max_residual_px : best + 0.01)) {
      pick = k;
      break;
    }
  }
  FileConversion chosen = results[pick].second;
  chosen.result.acceptable = chosen.result.residual.failed_points == 0 &&
                             chosen.result.residual.max_px <= options.max_residual_px;
  chosen.notes.push_back(
      std::to_string(results[pick].first) + " distortion coefficients written " +
      (gated ? "(the fewest meeting --max-residual-px)"
             : "(the fewest within 0.01 px of the best tried; --max-coefficients " +
                   std::to_string(max_coefficients) + ")"));
  return chosen;
}

}  // namespace aerocal::calib
