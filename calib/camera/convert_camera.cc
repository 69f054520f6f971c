#include "calib/camera/convert_camera.h"

#include "calib/problem/problem_builder.h"
#include "calib/residuals/autodiff_residual.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace aerocal::calib {
namespace {

/// One grid point of a conversion fit: the source's ideal ray `direction` (ideal mm / c) seen at
/// the measured photo coordinates `measured_mm`. Residual in px (whitened with 1 px), in the
/// target's closed-form direction. blocks: params[Model::kNumParams].
template <typename Model>
struct ConversionFitResidual
    : AutoDiffResidual<ConversionFitResidual<Model>, 2, Model::kNumParams> {
  ConversionFitResidual(const PixelFrame& frame,
                        const Eigen::Vector2d& measured_mm,
                        const Eigen::Vector2d& direction)
      : frame_(frame), measured_mm_(measured_mm), direction_(direction) {}
  template <typename T>
  bool operator()(const T* params, T* r) const {
    const T c = Model::PrincipalDistanceMm(params, frame_);
    const T inverse_pixel = T(1.0 / frame_.pixel_size_mm);
    if constexpr (Model::kCorrectionForm) {
      const T measured[2] = {T(measured_mm_.x()), T(measured_mm_.y())};
      T ideal[2];
      if (!Model::IdealFromMeasured(params, frame_, measured, ideal)) return false;
      r[0] = (ideal[0] - c * direction_.x()) * inverse_pixel;
      r[1] = (ideal[1] - c * direction_.y()) * inverse_pixel;
    } else {
      const T ideal[2] = {c * direction_.x(), c * direction_.y()};
      T measured[2];
      if (!Model::MeasuredFromIdeal(params, frame_, ideal, measured)) return false;
      r[0] = (measured[0] - measured_mm_.x()) * inverse_pixel;
      r[1] = (measured[1] - measured_mm_.y()) * inverse_pixel;
    }
    return true;
  }

 private:
  PixelFrame frame_;
  Eigen::Vector2d measured_mm_, direction_;
};

template <typename Model>
int FitParameters(const ModelCamera& from,
                  const ConvertOptions& options,
                  std::vector<double>* params) {
  ProblemBuilder builder;
  std::vector<std::string> names;
  for (const auto& info : Model::kParams) names.emplace_back(info.name);
  const BlockId block =
      builder.AddBlock("camera", params->data(), Model::kNumParams, BlockKind::kInterior, names);
  std::vector<int> fixed;
  std::vector<std::string> held = options.fixed;
  held.insert(held.end(), options.zero.begin(), options.zero.end());
  for (const auto& name : held) {
    const int index = IndexOfParam(Model::kParams, name);
    if (index < 0)
      throw ConfigError("ConvertCamera: " + std::string(Model::kName) + " has no parameter '" +
                        name + "'");
    fixed.push_back(index);
  }
  std::sort(fixed.begin(), fixed.end());
  fixed.erase(std::unique(fixed.begin(), fixed.end()), fixed.end());
  if (!fixed.empty()) builder.FixEntries(block, fixed);
  const double c_from = from.PrincipalDistanceMm();
  for (const Eigen::Vector2d& pixel : FormatGrid(from.frame, options.fit_grid)) {
    Eigen::Vector2d ideal;
    if (!from.IdealFromPixel(pixel, &ideal)) continue;
    builder.AddResidual(
        "conversion",
        ConversionFitResidual<Model>::Create(
            from.frame, from.frame.PhotoFromPixel(pixel), Eigen::Vector2d(ideal / c_from)),
        {block});
  }
  SolverOptions solver;
  solver.max_iterations = 200;
  solver.num_threads = 1;
  const SolveReport report = builder.Solve(solver);
  if (!report.usable)
    throw Error("ConvertCamera into " + std::string(Model::kName) + ": the fit failed (" +
                report.message + ")");
  return report.iterations;
}

}  // namespace

std::vector<Eigen::Vector2d> FormatGrid(const PixelFrame& frame, int n) {
  std::vector<Eigen::Vector2d> grid;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      grid.emplace_back((frame.width_px - 1) * double(i) / (n - 1),
                        (frame.height_px - 1) * double(j) / (n - 1));
  return grid;
}

ConversionResidual CompareCameras(const ModelCamera& a, const ModelCamera& b, int grid) {
  AEROCAL_CHECK(grid >= 2) << "grid " << grid;
  ConversionResidual out;
  const double ca = a.PrincipalDistanceMm(), cb = b.PrincipalDistanceMm();
  const Eigen::Vector2d centre(0.5 * (a.frame.width_px - 1), 0.5 * (a.frame.height_px - 1));
  const double inner = 0.8 * 0.5 * std::hypot(a.frame.width_px, a.frame.height_px);
  double sum2 = 0.0;
  int n = 0;
  for (const Eigen::Vector2d& pixel : FormatGrid(a.frame, grid)) {
    ++out.points;
    Eigen::Vector2d ideal, back;
    if (!a.IdealFromPixel(pixel, &ideal) || !b.PixelFromIdeal(ideal * (cb / ca), &back) ||
        !back.allFinite()) {
      ++out.failed_points;
      continue;
    }
    const double e = (back - pixel).norm();
    sum2 += e * e;
    ++n;
    if (e > out.max_px) {
      out.max_px = e;
      out.max_at_px = pixel;
    }
    if ((pixel - centre).norm() <= inner) out.max_inner80_px = std::max(out.max_inner80_px, e);
  }
  out.rms_px = n > 0 ? std::sqrt(sum2 / n) : 0.0;
  return out;
}

ConversionResult ConvertCamera(const ModelCamera& from,
                               CameraModelId to,
                               const ConvertOptions& options) {
  AEROCAL_CHECK(static_cast<int>(from.params.size()) == CameraModelParamCount(from.model))
      << CameraModelName(from.model) << " needs " << CameraModelParamCount(from.model)
      << " parameters, got " << from.params.size();
  if (options.fit_grid < 5 || options.check_grid < 2)
    throw ConfigError("ConvertCamera: fit_grid must be >= 5 and check_grid >= 2");
  ConversionResult result;
  result.camera.model = to;
  result.camera.frame = from.frame;
  result.camera.params.assign(CameraModelParamCount(to), 0.0);
  if (from.model == to) {
    result.camera.params = from.params;
    result.exact = true;
  } else {
    OpenCvParams cv;
    const bool exact_out = VisitCameraModel(from.model, [&](auto m) {
      return decltype(m)::ToOpenCv(from.params.data(), from.frame, &cv);
    });
    const bool exact_in = VisitCameraModel(to, [&](auto m) {
      return decltype(m)::FromOpenCv(cv, from.frame, result.camera.params.data());
    });
    result.exact = exact_out && exact_in;
  }
  const std::vector<ParamInfo> table = CameraModelParams(to);
  for (const std::string& name : options.zero) {
    int index = -1;
    for (size_t i = 0; i < table.size(); ++i)
      if (table[i].name == name) index = static_cast<int>(i);
    if (index < 0)
      throw ConfigError("ConvertCamera: " + std::string(CameraModelName(to)) +
                        " has no parameter '" + name + "'");
    if (result.camera.params[index] != 0.0) result.exact = false;
    result.camera.params[index] = 0.0;
  }
  if (!result.exact)
    result.fit_iterations = VisitCameraModel(to, [&](auto m) {
      return FitParameters<decltype(m)>(from, options, &result.camera.params);
    });
  result.residual = CompareCameras(from, result.camera, options.check_grid);
  result.acceptable =
      result.residual.failed_points == 0 && result.residual.max_px <= options.max_residual_px;
  return result;
}

std::string ConversionResult::Summary() const {
  char buffer[320];
  std::snprintf(
      buffer,
      sizeof(buffer),
      "%s %s: residual rms %.3g px, max %.3g px at pixel (%.0f, %.0f), max within 80 %% "
      "of the half-diagonal %.3g px%s",
      std::string(CameraModelName(camera.model)).c_str(),
      exact ? "(exact)" : "(least-squares fit)",
      residual.rms_px,
      residual.max_px,
      residual.max_at_px.x(),
      residual.max_at_px.y(),
      residual.max_inner80_px,
      residual.failed_points
          ? (", " + std::to_string(residual.failed_points) + " points not invertible").c_str()
          : "");
  return buffer;
}

}  // namespace aerocal::calib
