#include "triangulation/sensor/line_scan_camera.h"

#include "calib/camera/rotation.h"
#include "calib/core/csv.h"
#include "calib/core/error.h"
#include "calib/problem/mounted_block.h"
#include "calib/residuals/prior.h"

#include <algorithm>
#include <cmath>

namespace aerocal::triangulation {

bool ProjectAtLine(const calib::LineCamera& camera,
                   const PosTrajectory& pos,
                   double line,
                   const Eigen::Vector3d& point,
                   Eigen::Vector2d* xy) {
  Eigen::Vector3d center, opk;
  pos.PoseAtLine(line, &center, &opk);
  const Eigen::Matrix3d body = calib::RotationFromOpk(opk);
  const Eigen::Vector3d v = calib::RotationFromOpk(camera.mount_rad).transpose() *
                            body.transpose() * (point - center - body * camera.lever_arm_m);
  if (!(v.z() < 0)) return false;
  *xy = Eigen::Vector2d(-camera.c_mm * v.x() / v.z(), -camera.c_mm * v.y() / v.z());
  return true;
}

LineScanCamera::LineScanCamera(const calib::LineCamera& camera,
                               const PosTrajectory& pos,
                               const LineScanOptions& options)
    : camera_(camera), pos_(pos), options_(options), ranges_(camera.Ranges()) {}

bool LineScanCamera::Measures(const ImageObservation& observation) const {
  return observation.image == kLineStripImage;
}

void LineScanCamera::RegisterBlocks(const SensorContext& context) {
  calib::ProblemBuilder& b = context.builder;
  const int n_sub = static_cast<int>(ranges_.size());
  const int n_nodes =
      calib::SplineNodeCount(pos_.last_line() - pos_.first_line(), options_.node_spacing_lines);
  nodes_.assign(n_nodes, Vector6d::Zero());
  detector_.assign(n_sub, {});
  for (auto& d : detector_) d.fill(0.0);
  c_ = camera_.c_mm;
  mount_ = camera_.mount_rad;
  lever_ = camera_.lever_arm_m;
  const char* entry_names[] = {"dX", "dY", "dZ", "domega", "dphi", "dkappa"};
  for (int j = 0; j < n_nodes; ++j)
    node_blocks_.push_back(b.AddBlock("node" + std::to_string(j),
                                      nodes_[j].data(),
                                      calib::kLineNodeSize,
                                      calib::BlockKind::kOther,
                                      {entry_names, entry_names + 6}));
  for (int s = 0; s < n_sub; ++s) {
    std::vector<std::string> names;
    for (int k = 0; k < calib::kLineMaxTerms; ++k) names.push_back("dx" + std::to_string(k));
    for (int k = 0; k < calib::kLineMaxTerms; ++k) names.push_back("dy" + std::to_string(k));
    const std::string id =
        camera_.subcameras.empty() ? std::to_string(s) : camera_.subcameras[s].id;
    detector_blocks_.push_back(b.AddBlock("detector_" + id,
                                          detector_[s].data(),
                                          2 * calib::kLineMaxTerms,
                                          calib::BlockKind::kInterior,
                                          names));
  }
  c_block_ = b.AddBlock("c", &c_, 1, calib::BlockKind::kInterior, {"c"});
  mount_block_ =
      b.AddBlock("mount", mount_.data(), 3, calib::BlockKind::kOther, {"omega", "phi", "kappa"});
  lever_block_ =
      b.AddBlock("lever_arm", lever_.data(), 3, calib::BlockKind::kOther, {"x", "y", "z"});
  time_offset_s_ = 0.0;
  time_block_ = b.AddBlock("time_offset", &time_offset_s_, 1, calib::BlockKind::kOther, {"dt"});
  if (!options_.time_offset) b.FixBlock(time_block_);
  if (!options_.free_c) b.FixBlock(c_block_);
  calib::ApplyBlockMode(b, mount_block_, options_.boresight);
  calib::ApplyBlockMode(b, lever_block_, options_.lever_arm);
}

LineDetectorSite LineScanCamera::DetectorSite(double detector) const {
  LineDetectorSite site;
  const int n_sub = static_cast<int>(ranges_.size());
  const long nearest =
      std::lround(std::max(0.0, std::min<double>(detector, camera_.detectors - 1)));
  for (int r = 0; r < n_sub; ++r)
    if (nearest >= ranges_[r].first && nearest <= ranges_[r].second) site.subcamera = r;
  const auto& range = ranges_[site.subcamera];
  site.u = range.second > range.first
               ? (2.0 * detector - range.first - range.second) / double(range.second - range.first)
               : 0.0;
  return site;
}

void LineScanCamera::PoseAtLine(double line,
                                Eigen::Vector3d* center_m,
                                Eigen::Vector3d* opk_rad) const {
  pos_.PoseAtLine(line, center_m, opk_rad);
  const calib::SplineSpan span = calib::CubicBSplineWeights(std::max(0.0, line - pos_.first_line()),
                                                            options_.node_spacing_lines);
  const int j = std::min(span.first_node, NumNodes() - 4);
  for (int m = 0; m < 4; ++m) {
    *center_m += span.weights[m] * nodes_[j + m].head<3>();
    *opk_rad += span.weights[m] * nodes_[j + m].tail<3>();
  }
}

ImageRay LineScanCamera::StartingRay(const SensorContext& context,
                                     const ImageObservation& observation) const {
  (void)context;
  const double detector = observation.pixel.x(), line = observation.pixel.y();
  Eigen::Vector3d center, opk;
  PoseAtLine(line, &center, &opk);
  const LineDetectorSite site = DetectorSite(detector);
  const double* poly = detector_[site.subcamera].data();
  const Eigen::Vector2d xy =
      camera_.DetectorPosition(detector) +
      Eigen::Vector2d(
          calib::EvaluatePolynomial(poly, calib::kLineMaxTerms, site.u),
          calib::EvaluatePolynomial(poly + calib::kLineMaxTerms, calib::kLineMaxTerms, site.u));
  const Eigen::Matrix3d body = calib::RotationFromOpk(opk);
  ImageRay ray;
  ray.center_m = center + body * lever_;
  ray.direction =
      (body * calib::RotationFromOpk(mount_) * Eigen::Vector3d(xy.x(), xy.y(), -c_)).normalized();
  return ray;
}

namespace {

void CheckLineObservation(const calib::LineCamera& camera,
                          const PosTrajectory& pos,
                          const SourceRef& where,
                          double detector,
                          double line) {
  if (!(detector >= -0.5 && detector <= camera.detectors - 0.5))
    ThrowInputError(where,
                    "col (detector) must be within -0.5 .. " +
                        FormatNumber(camera.detectors - 0.5) + " (got " + FormatNumber(detector) +
                        ")");
  if (!pos.CoversLine(line))
    ThrowInputError(where,
                    "row (scan line) " + FormatNumber(line) +
                        " is outside the POS trajectory (lines " + FormatNumber(pos.first_line()) +
                        " .. " + FormatNumber(pos.last_line()) + ")");
}

// The detector index where the slope of sub-camera `range` is taken by central differences of
// +- kSlopeStep (inside the range).
constexpr double kSlopeStep = 0.01;
double SlopeSite(const std::pair<int, int>& range, double detector) {
  return std::max(range.first + kSlopeStep, std::min(range.second - kSlopeStep, detector));
}

// Whitening in detectors and lines: the local detector spacing in the virtual focal plane and
// the image motion of one line (at the POS pose, the file's camera and the point's current
// values); the observation's sigma in mm, x and y.
Eigen::Vector2d LineSigmaMm(const calib::LineCamera& camera,
                            const PosTrajectory& pos,
                            const std::pair<int, int>& range,
                            double detector,
                            double line,
                            const Eigen::Vector3d& xyz,
                            double sigma_px) {
  const double h = kSlopeStep;
  const double ic = SlopeSite(range, detector);
  const double dx_di =
      range.second > range.first
          ? std::abs(camera.DesignPosition(ic + h).x() - camera.DesignPosition(ic - h).x()) /
                (2 * h)
          : camera.pitch_mm;
  double dy_dt = 0;
  {
    const double t0 = pos.CoversLine(line - 0.5) ? line - 0.5 : line;
    const double t1 = pos.CoversLine(line + 0.5) ? line + 0.5 : line;
    Eigen::Vector2d y0, y1;
    if (t1 > t0 && ProjectAtLine(camera, pos, t0, xyz, &y0) &&
        ProjectAtLine(camera, pos, t1, xyz, &y1))
      dy_dt = std::abs(y1.y() - y0.y()) / (t1 - t0);
  }
  if (!(dy_dt > 1e-3 * camera.pitch_mm)) dy_dt = camera.pitch_mm;
  return Eigen::Vector2d(sigma_px * std::max(dx_di, 1e-3 * camera.pitch_mm), sigma_px * dy_dt);
}

// The POS velocity and attitude rate at the line (the time offset's lever): central
// differences of the interpolated POS over +- 1 ms.
void PosRatesAtLine(const PosTrajectory& pos,
                    double line,
                    Eigen::Vector3d* velocity,
                    Eigen::Vector3d* opk_rate) {
  const double time = pos.LineTime(line);
  const double t0 = std::max(pos.records().front().time_s, time - 1e-3);
  const double t1 = std::min(pos.records().back().time_s, time + 1e-3);
  Eigen::Vector3d c0, c1, o0, o1;
  pos.PoseAtTime(t0, &c0, &o0);
  pos.PoseAtTime(t1, &c1, &o1);
  *velocity = Eigen::Vector3d((c1 - c0) / (t1 - t0));
  *opk_rate = Eigen::Vector3d((o1 - o0) / (t1 - t0));
}

// The table at its start values: the measured position, the line direction there (the ray
// angle's frame) and c, at which the angle is weighted (line_ray_angle.h).
calib::LineDetectorGeometry DetectorGeometry(const calib::LineCamera& camera,
                                             const std::pair<int, int>& range,
                                             double detector,
                                             double u,
                                             const Eigen::Vector3d& range_m) {
  const double h = kSlopeStep;
  const double ic = SlopeSite(range, detector);
  calib::LineDetectorGeometry geometry;
  geometry.xy_mm = camera.DetectorPosition(detector);
  geometry.slope_mm =
      range.second > range.first
          ? Eigen::Vector2d((camera.DetectorPosition(ic + h) - camera.DetectorPosition(ic - h)) /
                            (2 * h))
          : Eigen::Vector2d(camera.pitch_mm, 0.0);
  geometry.u = u;
  geometry.du_di = range.second > range.first ? 2.0 / double(range.second - range.first) : 0;
  geometry.nominal_c_mm = camera.c_mm;
  geometry.nominal_range_m = range_m.norm();
  return geometry;
}

}  // namespace

ObservationTerm LineScanCamera::Observe(const SensorContext& context,
                                        const ImageObservation& observation,
                                        calib::BlockId point) {
  const SourceRef where{context.project.observations_file, observation.line};
  const double detector = observation.pixel.x(), line = observation.pixel.y();
  CheckLineObservation(camera_, pos_, where, detector, line);
  const LineDetectorSite site = DetectorSite(detector);
  const int s = site.subcamera;
  Eigen::Vector3d pos_center, pos_opk;
  pos_.PoseAtLine(line, &pos_center, &pos_opk);
  const Eigen::Vector3d xyz = Eigen::Map<const Eigen::Vector3d>(context.builder.BlockValues(point));
  const Eigen::Vector2d sigma_xy_mm =
      LineSigmaMm(camera_, pos_, ranges_[s], detector, line, xyz, observation.sigma_px);
  const double t = std::max(0.0, line - pos_.first_line());
  const calib::SplineSpan span = calib::CubicBSplineWeights(t, options_.node_spacing_lines);
  const int j = std::min(span.first_node, NumNodes() - 4);
  terms_.push_back({s, detector, site.u, sigma_xy_mm, j});
  ObservationTerm term;
  term.group = kGroupLineImage;
  Eigen::Vector3d velocity, opk_rate;
  PosRatesAtLine(pos_, line, &velocity, &opk_rate);
  const calib::LineDetectorGeometry geometry = DetectorGeometry(
      camera_,
      ranges_[s],
      detector,
      site.u,
      Eigen::Vector3d(xyz - pos_center - calib::RotationFromOpk(pos_opk) * camera_.lever_arm_m));
  term.cost = calib::LineCollinearityResidual::Create(
      geometry, span, pos_opk, pos_center, sigma_xy_mm, velocity, opk_rate);
  term.blocks = {node_blocks_[j],
                 node_blocks_[j + 1],
                 node_blocks_[j + 2],
                 node_blocks_[j + 3],
                 detector_blocks_[s],
                 c_block_,
                 mount_block_,
                 lever_block_,
                 time_block_,
                 point};
  return term;
}

void LineScanCamera::AddOwnResiduals(const SensorContext& context) {
  calib::ProblemBuilder& b = context.builder;
  const Eigen::Vector3d& sc = options_.pos_sigma_center_m;
  const Eigen::Vector3d& so = options_.pos_sigma_opk_rad;
  if (options_.pos_prior)
    for (int j = 0; j < NumNodes(); ++j)
      b.AddResidual(kGroupPosPrior,
                    calib::PriorCostFunction::Create(
                        {0, 0, 0, 0, 0, 0}, {sc.x(), sc.y(), sc.z(), so.x(), so.y(), so.z()}),
                    {node_blocks_[j]},
                    "pos node " + std::to_string(j));
  // The weighted boresight and lever arm around the camera file's values (group line_prior).
  const double sb = options_.boresight_sigma_rad, sl = options_.lever_arm_sigma_m;
  const Eigen::Vector3d& m = camera_.mount_rad;
  const Eigen::Vector3d& a = camera_.lever_arm_m;
  calib::AddBlockPrior(b,
                       mount_block_,
                       options_.boresight,
                       {m.x(), m.y(), m.z()},
                       {sb, sb, sb},
                       kLineOwner,
                       "boresight");
  calib::AddBlockPrior(b,
                       lever_block_,
                       options_.lever_arm,
                       {a.x(), a.y(), a.z()},
                       {sl, sl, sl},
                       kLineOwner,
                       "lever arm");
}

void LineScanCamera::SetFixedDetectorEntries(calib::ProblemBuilder& builder,
                                             int s,
                                             const std::vector<int>& fixed) {
  for (int e : fixed) detector_[s][e] = 0.0;
  builder.FreeBlock(detector_blocks_[s]);
  if (!fixed.empty()) builder.FixEntries(detector_blocks_[s], fixed);
}

}  // namespace aerocal::triangulation
