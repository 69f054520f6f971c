#include "triangulation/pushbroom/cloud_control.h"

#include "calib/core/error.h"
#include "triangulation/adjustment/forward_intersection.h"
#include "triangulation/calibration/calibration.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <Eigen/QR>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <functional>
#include <optional>

namespace aerocal::triangulation {
namespace {

struct Ray2 {
  int frame = 0;
  Eigen::Vector2d pixel;
  Eigen::Matrix2d weight;  // inverse covariance, px^-2
};

// Normalised cross-correlation search: the template of `l1` at p against the reference image
// resampled through the affine t0 + a0 x; returns the best integer shift (L1 cells) and its
// correlation.
bool SearchCorrelation(const stitch::GrayImage& l1,
                       const Eigen::Vector2i& p,
                       const stitch::GrayImage& b,
                       const Eigen::Vector2d& t0,
                       const Eigen::Matrix2d& a0,
                       int h,
                       int s,
                       Eigen::Vector2i* shift,
                       double* best) {
  const int n = 2 * (h + s) + 1, m = 2 * h + 1;
  Eigen::MatrixXd window(n, n);
  for (int v = 0; v < n; ++v)
    for (int u = 0; u < n; ++u) {
      const Eigen::Vector2d q = t0 + a0 * Eigen::Vector2d(u - h - s, v - h - s);
      const float g = SampleBilinear(b, q.x(), q.y());
      if (std::isnan(g)) return false;
      window(v, u) = g;
    }
  Eigen::MatrixXd tmpl(m, m);
  for (int y = 0; y < m; ++y)
    for (int x = 0; x < m; ++x) tmpl(y, x) = l1(p.y() + y - h, p.x() + x - h);
  tmpl.array() -= tmpl.mean();
  const double t_norm = tmpl.norm();
  if (!(t_norm > 0)) return false;
  *best = -2;
  for (int sy = 0; sy <= 2 * s; ++sy)
    for (int sx = 0; sx <= 2 * s; ++sx) {
      const auto patch = window.block(sy, sx, m, m);
      const double mean = patch.mean();
      const double norm = std::sqrt(std::max(0.0, patch.squaredNorm() - m * m * mean * mean));
      if (!(norm > 0)) continue;
      const double r = (patch.array() * tmpl.array()).sum() / (norm * t_norm);
      if (r > *best) *best = r, *shift = Eigen::Vector2i(sx - s, sy - s);
    }
  return *best > -2;
}

// Weighted intersection of the rays (Gauss-Newton on the pixel misclosures from a least-squares
// ray intersection); returns v^T P v and N^-1 and the per-ray v^T P v.
bool Intersect(const calib::Camera& camera,
               const std::vector<ReferenceFrame>& frames,
               const std::vector<Ray2>& rays,
               Eigen::Vector3d* point,
               Eigen::Matrix3d* cov,
               double* vtpv,
               std::vector<double>* per_ray) {
  std::vector<ImageRay> lines;
  for (const auto& r : rays)
    lines.push_back(
        RayFromPixel(camera, frames[r.frame].opk_rad, frames[r.frame].center_m, r.pixel));
  const auto start = IntersectRays(lines);
  if (!start) return false;
  Eigen::Vector3d x = *start;
  Eigen::Matrix3d n;
  for (int iteration = 0; iteration < 10; ++iteration) {
    n.setZero();
    Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
    for (const auto& r : rays) {
      const auto& f = frames[r.frame];
      Eigen::Vector2d p0;
      if (!camera.ProjectToPixel(f.opk_rad, f.center_m, x, &p0)) return false;
      Eigen::Matrix<double, 2, 3> j;
      for (int a = 0; a < 3; ++a) {
        Eigen::Vector3d xa = x;
        xa[a] += 1e-3;
        Eigen::Vector2d pa;
        if (!camera.ProjectToPixel(f.opk_rad, f.center_m, xa, &pa)) return false;
        j.col(a) = (pa - p0) / 1e-3;
      }
      n += j.transpose() * r.weight * j;
      rhs += j.transpose() * r.weight * (r.pixel - p0);
    }
    const Eigen::Vector3d dx = n.ldlt().solve(rhs);
    if (!dx.allFinite()) return false;
    x += dx;
    if (dx.norm() < 1e-6) break;
  }
  *vtpv = 0;
  per_ray->clear();
  for (const auto& r : rays) {
    const auto& f = frames[r.frame];
    Eigen::Vector2d p0;
    if (!camera.ProjectToPixel(f.opk_rad, f.center_m, x, &p0)) return false;
    const Eigen::Vector2d v = r.pixel - p0;
    per_ray->push_back(v.dot(r.weight * v));
    *vtpv += per_ray->back();
  }
  *point = x;
  *cov = n.inverse();
  return cov->allFinite();
}

// Gross errors of the line-image side: the misclosure (observation - projection of the point
// through the nominal camera and the POS, px) is smooth in the detector index (the calibration;
// the POS error adds ~ its own size), so per sub-camera and axis a degree-5 polynomial in the
// normalised index is fitted robustly (3 rounds: least squares, then drop |v| > k 1.4826 MAD,
// at least min_px); returns the indices to keep.
std::vector<bool> SmoothMisclosureInliers(const calib::LineCamera& camera,
                                          const PosTrajectory& pos,
                                          const std::vector<LineObservation>& obs,
                                          const std::vector<GroundPoint>& points,
                                          double k,
                                          double min_px,
                                          int* rejected) {
  std::vector<bool> keep(obs.size(), true);
  std::vector<Eigen::Vector2d> v(obs.size());
  for (size_t n = 0; n < obs.size(); ++n) {
    Eigen::Vector2d xy;
    if (!ProjectAtLine(camera, pos, obs[n].line, *points[n].xyz_m, &xy)) {
      keep[n] = false;
      continue;
    }
    // Across: focal-plane x against the detector's design x; along: y against 0 (mm -> px).
    v[n] = (camera.DetectorPosition(obs[n].detector) - xy) / camera.pitch_mm;
  }
  const auto ranges = camera.Ranges();
  for (size_t s = 0; s < ranges.size(); ++s) {
    const double first = ranges[s].first, last = ranges[s].second;
    std::vector<size_t> mine;
    for (size_t n = 0; n < obs.size(); ++n)
      if (keep[n] && camera.SubcameraOf(obs[n].detector) == int(s)) mine.push_back(n);
    for (int axis = 0; axis < 2; ++axis)
      for (int round = 0; round < 3; ++round) {
        std::vector<size_t> in;
        for (size_t n : mine)
          if (keep[n]) in.push_back(n);
        const int terms = std::min<int>(6, int(in.size()) / 4);
        if (terms < 1) break;
        Eigen::MatrixXd a(in.size(), terms);
        Eigen::VectorXd b(in.size());
        for (size_t r = 0; r < in.size(); ++r) {
          const double u =
              last > first ? (2 * obs[in[r]].detector - first - last) / (last - first) : 0;
          for (int t = 0; t < terms; ++t) a(r, t) = std::pow(u, t);
          b[r] = v[in[r]][axis];
        }
        const Eigen::VectorXd coef = a.colPivHouseholderQr().solve(b);
        const Eigen::VectorXd res = b - a * coef;
        std::vector<double> abs_res(res.size());
        for (int r = 0; r < res.size(); ++r) abs_res[r] = std::abs(res[r]);
        std::nth_element(abs_res.begin(), abs_res.begin() + abs_res.size() / 2, abs_res.end());
        const double limit = std::max(min_px, k * 1.4826 * abs_res[abs_res.size() / 2]);
        bool changed = false;
        for (size_t r = 0; r < in.size(); ++r)
          if (std::abs(res[r]) > limit) keep[in[r]] = false, changed = true, ++*rejected;
        if (!changed) break;
      }
  }
  return keep;
}

// What the matching of every interest point shares.
struct CloudContext {
  const calib::LineCamera& camera;
  const PosTrajectory& pos;
  const stitch::GrayImage& line_image;
  const calib::Camera& ref_camera;
  const std::vector<ReferenceFrame>& frames;
  const CloudControlOptions& o;
  const L1Image& l1;
  stitch::LsmOptions lsm;                       // with the template half size
  std::function<double(double, double)> plane;  // Z = the mean terrain height
  std::vector<std::pair<int, int>> ranges;      // detector range per sub-camera
};

// An interest point of the L1 image and the line-image template that observes it.
struct CellTemplate {
  Eigen::Vector2i p;                               // L1 cell
  Eigen::Vector2d cell_in_line;                    // the cell's (detector, line) position
  Eigen::Vector2i q;                               // the template's centre pixel in the line image
  Eigen::Vector3d q_ground, qx_ground, qy_ground;  // q, q + (1, 0), q + (0, 1) on the plane
};

void CheckCloudControlInputs(const calib::LineCamera& camera,
                             const stitch::GrayImage& line_image,
                             const calib::Camera& ref_camera,
                             const std::vector<ReferenceFrame>& frames) {
  if (line_image.cols() != camera.detectors)
    throw InputError("the line image has " + std::to_string(line_image.cols()) +
                     " columns, the camera " + std::to_string(camera.detectors) + " detectors");
  for (const auto& f : frames)
    if (f.image.cols() != ref_camera.width_px || f.image.rows() != ref_camera.height_px)
      throw InputError(f.id + ": image is " + std::to_string(f.image.cols()) + " x " +
                       std::to_string(f.image.rows()) + " px, the reference camera " +
                       std::to_string(ref_camera.width_px) + " x " +
                       std::to_string(ref_camera.height_px));
}

// The template of an interest point, or nullopt where it cannot be matched.
std::optional<CellTemplate> TemplateOfInterest(const CloudContext& c,
                                               const stitch::InterestPoint& ip) {
  const L1Image& l1 = c.l1;
  const int h = c.o.template_half_px;
  CellTemplate t;
  t.p = Eigen::Vector2i(int(std::lround(ip.position.x())), int(std::lround(ip.position.y())));
  const Eigen::Vector2i& p = t.p;
  // The template and a margin must lie on valid cells.
  const int r = h + 2;
  if (p.x() < r || p.y() < r || p.x() >= l1.grid.width - r || p.y() >= l1.grid.height - r)
    return std::nullopt;
  bool valid = true;
  for (int y = -r; y <= r && valid; ++y)
    for (int x = -r; x <= r && valid; ++x) valid = l1.Valid(p.x() + x, p.y() + y);
  if (!valid) return std::nullopt;
  // The line-image template: centred on the integer pixel q nearest to the cell's line-image
  // position, moved inside the cell's sub-camera (the template must not cross a seam). The
  // observation is q itself, so no interpolated grey value of the line image enters it.
  t.cell_in_line = Eigen::Vector2d(l1.detector_map(p.y(), p.x()), l1.line_map(p.y(), p.x()));
  const auto [first, last] = c.ranges[c.camera.SubcameraOf(t.cell_in_line.x())];
  if (last - first < 2 * h + 2) return std::nullopt;
  t.q = Eigen::Vector2i(
      std::clamp<int>(int(std::lround(t.cell_in_line.x())), first + h + 1, last - h - 1),
      int(std::lround(t.cell_in_line.y())));
  if (t.q.y() < h + 1 || t.q.y() > c.line_image.rows() - h - 2) return std::nullopt;
  const auto q_ground = GroundOfDetector(c.camera, c.pos, t.q.x(), t.q.y(), c.plane);
  const auto qx_ground = GroundOfDetector(c.camera, c.pos, t.q.x() + 1, t.q.y(), c.plane);
  const auto qy_ground = GroundOfDetector(c.camera, c.pos, t.q.x(), t.q.y() + 1, c.plane);
  if (!q_ground || !qx_ground || !qy_ground) return std::nullopt;
  t.q_ground = *q_ground;
  t.qx_ground = *qx_ground;
  t.qy_ground = *qy_ground;
  return t;
}

// The reference pixel of the L1 cell in frame f, by correlation then least squares on L1.
std::optional<Eigen::Vector2d> MatchOnL1(const CloudContext& c,
                                         const ReferenceFrame& f,
                                         const Eigen::Vector2i& p) {
  const L1Image& l1 = c.l1;
  const int h = c.o.template_half_px;
  const Eigen::Vector3d g0 = l1.grid.Ground(p.x(), p.y());
  Eigen::Vector2d t0, tx, ty;
  if (!c.ref_camera.ProjectToPixel(f.opk_rad, f.center_m, g0, &t0) ||
      !c.ref_camera.ProjectToPixel(
          f.opk_rad, f.center_m, g0 + Eigen::Vector3d(l1.grid.gsd_m, 0, 0), &tx) ||
      !c.ref_camera.ProjectToPixel(
          f.opk_rad, f.center_m, g0 + Eigen::Vector3d(0, l1.grid.gsd_m, 0), &ty))
    return std::nullopt;
  Eigen::Matrix2d a0;
  a0.col(0) = tx - t0;
  a0.col(1) = ty - t0;
  const double reach = (h + c.o.search_px + 3) * a0.cwiseAbs().rowwise().sum().maxCoeff();
  if (!(t0.x() > reach && t0.y() > reach && t0.x() < f.image.cols() - 1 - reach &&
        t0.y() < f.image.rows() - 1 - reach))
    return std::nullopt;
  Eigen::Vector2i shift = Eigen::Vector2i::Zero();
  double ncc = 0;
  if (!SearchCorrelation(l1.image, p, f.image, t0, a0, h, c.o.search_px, &shift, &ncc))
    return std::nullopt;
  if (ncc < c.o.min_correlation) return std::nullopt;
  const auto m_l1 =
      stitch::MatchLeastSquares(l1.image, p, f.image, t0 + a0 * shift.cast<double>(), a0, c.lsm);
  if (!m_l1.ok()) return std::nullopt;
  return m_l1.position_in_b;
}

// The mean reference pixel of the template's plane points in frame f; nullopt if one fails.
std::optional<Eigen::Vector2d> MeanMappedTemplate(const CloudContext& c,
                                                  const ReferenceFrame& f,
                                                  const Eigen::Vector2i& q) {
  const int h = c.o.template_half_px;
  Eigen::Vector2d mean_mapped = Eigen::Vector2d::Zero();
  for (int y = -h; y <= h; ++y)
    for (int x = -h; x <= h; ++x) {
      const auto g = GroundOfDetector(c.camera, c.pos, q.x() + x, q.y() + y, c.plane);
      Eigen::Vector2d pixel;
      if (!(g && c.ref_camera.ProjectToPixel(f.opk_rad, f.center_m, *g, &pixel)))
        return std::nullopt;
      mean_mapped += pixel;
    }
  return Eigen::Vector2d(mean_mapped / double((2 * h + 1) * (2 * h + 1)));
}

// The ray of the template into reference frame k, or nullopt; appends the match sigma.
std::optional<Ray2> MatchInFrame(const CloudContext& c,
                                 const CellTemplate& t,
                                 int k,
                                 std::vector<double>* match_sigmas) {
  const ReferenceFrame& f = c.frames[k];
  const int h = c.o.template_half_px;
  const auto on_l1 = MatchOnL1(c, f, t.p);
  if (!on_l1) return std::nullopt;
  // Refined from the line image itself: the L1 grey values are interpolated at fractional
  // line-image positions whose fraction drifts slowly over the L1 grid (its cells are not
  // the detectors), and interpolation shifts fine texture towards the nearest sample: a
  // smooth bias of the L1 position (module README "Cloud control").
  Eigen::Vector2d pq, pqx, pqy;
  if (!c.ref_camera.ProjectToPixel(f.opk_rad, f.center_m, t.q_ground, &pq) ||
      !c.ref_camera.ProjectToPixel(f.opk_rad, f.center_m, t.qx_ground, &pqx) ||
      !c.ref_camera.ProjectToPixel(f.opk_rad, f.center_m, t.qy_ground, &pqy))
    return std::nullopt;
  Eigen::Matrix2d a_line;
  a_line.col(0) = pqx - pq;
  a_line.col(1) = pqy - pq;
  const Eigen::Vector2d start = *on_l1 + a_line * (t.q.cast<double>() - t.cell_in_line);
  const double margin = (h + 3) * a_line.cwiseAbs().rowwise().sum().maxCoeff();
  if (!(start.x() > margin && start.y() > margin && start.x() < f.image.cols() - 1 - margin &&
        start.y() < f.image.rows() - 1 - margin))
    return std::nullopt;
  const auto m = stitch::MatchLeastSquares(c.line_image, t.q, f.image, start, a_line, c.lsm);
  if (!m.ok()) return std::nullopt;
  // The affine of the match stands for the exact mapping line pixel -> plane point ->
  // reference pixel, which a tilted sub-camera's perspective curves (ground sampling ~ sec^2
  // of the look angle). Over the symmetric template the least-squares affine's centre is the
  // template's MEAN mapped position, not the centre's: off by mean_o F(o) - F(0) ~ k h^2 / 3
  // (k = tan(look) pitch / c per px), a smooth across-track bias in the detector index
  // (measured: 0.013-0.019 px table error, 7-11 sigma; module README "Measured"). Removed.
  const auto mean_mapped = MeanMappedTemplate(c, f, t.q);
  if (!mean_mapped) return std::nullopt;
  match_sigmas->push_back(m.SigmaMaxPx());
  Ray2 ray;
  ray.frame = k;
  ray.pixel = m.position_in_b - (*mean_mapped - pq);
  const double s = c.o.min_match_sigma_px;
  ray.weight = (m.cov_px2 + s * s * Eigen::Matrix2d::Identity()).inverse();
  return ray;
}

// Intersects the rays, removing the worst one while the misclosure fails the chi-square test at
// gross_error_alpha; false when fewer than two rays remain (or the intersection fails).
bool IntersectWithoutGrossErrors(const CloudContext& c,
                                 std::vector<Ray2>* rays,
                                 Eigen::Vector3d* x,
                                 Eigen::Matrix3d* cov,
                                 int* n_rays_removed) {
  double vtpv = 0;
  std::vector<double> per_ray;
  while (rays->size() >= 2) {
    if (!Intersect(c.ref_camera, c.frames, *rays, x, cov, &vtpv, &per_ray)) return false;
    const int dof = 2 * int(rays->size()) - 3;
    if (vtpv <= ChiSquareQuantile(1.0 - c.o.gross_error_alpha, dof)) return true;
    rays->erase(rays->begin() +
                (std::max_element(per_ray.begin(), per_ray.end()) - per_ray.begin()));
    ++*n_rays_removed;
  }
  return false;
}

// The control point of one interest point (matched, intersected, precise enough), counted by
// why it was not made otherwise.
void AddCloudPoint(const CloudContext& c,
                   const stitch::InterestPoint& ip,
                   std::vector<double>* match_sigmas,
                   CloudControlResult* out) {
  const auto t = TemplateOfInterest(c, ip);
  if (!t) return;
  ++out->n_interest;
  std::vector<Ray2> rays;
  for (size_t k = 0; k < c.frames.size(); ++k)
    if (const auto ray = MatchInFrame(c, *t, int(k), match_sigmas)) {
      rays.push_back(*ray);
      ++out->n_rays;
    }
  if (rays.size() < 2) {
    ++out->n_no_match;
    return;
  }
  Eigen::Vector3d x;
  Eigen::Matrix3d cov;
  if (!IntersectWithoutGrossErrors(c, &rays, &x, &cov, &out->n_rays_removed)) {
    ++out->n_gross;
    return;
  }
  const Eigen::Vector3d sigma = cov.diagonal().cwiseSqrt();
  if (!(sigma.maxCoeff() <= c.o.max_point_sigma_m)) {
    ++out->n_imprecise;
    return;
  }
  GroundPoint point;
  point.id = "cc" + std::to_string(out->points.size() + 1);
  point.role = PointRole::kControl;
  point.xyz_m = x;
  point.sigma_m = sigma;
  LineObservation obs;
  obs.point = point.id;
  obs.detector = t->q.x();
  obs.line = t->q.y();
  obs.sigma_px = c.o.line_sigma_px;
  obs.source_line = int(out->observations.size()) + 2;
  out->points.push_back(point);
  out->observations.push_back(obs);
}

// Drops the points whose line-image misclosure is not smooth in the detector index.
void DropLineOutliers(const CloudContext& c, CloudControlResult* out) {
  const auto keep = SmoothMisclosureInliers(c.camera,
                                            c.pos,
                                            out->observations,
                                            out->points,
                                            c.o.line_outlier_k,
                                            c.o.line_outlier_min_px,
                                            &out->n_line_outliers);
  std::vector<LineObservation> observations;
  std::vector<GroundPoint> points;
  for (size_t n = 0; n < keep.size(); ++n)
    if (keep[n]) {
      observations.push_back(out->observations[n]);
      points.push_back(out->points[n]);
    }
  out->observations = std::move(observations);
  out->points = std::move(points);
}

}  // namespace

void CloudControlOptions::Validate() const {
  auto require = [](bool ok, const std::string& message) {
    if (!ok) throw ConfigError(message);
  };
  require(gsd_m >= 0, "--gsd-m must be >= 0 (0: the line spacing)");
  require(map_step_px >= 1 && map_step_px <= 64, "--map-step must be within 1 .. 64");
  require(template_half_px >= 3 && template_half_px <= 30,
          "--template-half must be within 3 .. 30");
  require(search_px >= 0 && search_px <= 100, "--search-px must be within 0 .. 100");
  require(min_correlation >= 0 && min_correlation <= 1, "--min-correlation must be within 0 .. 1");
  require(min_match_sigma_px > 0, "--min-match-sigma-px must be > 0");
  require(line_sigma_px > 0, "--line-sigma-px must be > 0");
  require(gross_error_alpha > 0 && gross_error_alpha < 0.5,
          "--gross-error-alpha must be within (0, 0.5)");
  require(max_point_sigma_m > 0, "--max-point-sigma-m must be > 0");
  require(line_outlier_k > 0 && line_outlier_min_px > 0,
          "--line-outlier-k and --line-outlier-min-px must be > 0");
  foerstner.Validate();
  lsm.Validate();
}

CloudControlResult MakeCloudControl(const calib::LineCamera& camera,
                                    const PosTrajectory& pos,
                                    const stitch::GrayImage& line_image,
                                    const calib::Camera& ref_camera,
                                    const std::vector<ReferenceFrame>& frames,
                                    const CloudControlOptions& o) {
  o.Validate();
  CheckCloudControlInputs(camera, line_image, ref_camera, frames);
  CloudControlResult out;
  out.l1 = RectifyLineImage(camera, pos, line_image, o.mean_height_m, o.gsd_m, o.map_step_px);
  CloudContext c{
      camera, pos, line_image, ref_camera, frames, o, out.l1, o.lsm, nullptr, camera.Ranges()};
  c.lsm.half_size_px = o.template_half_px;
  c.plane = [&o](double, double) { return o.mean_height_m; };
  std::vector<double> match_sigmas;
  for (const auto& ip : stitch::DetectFoerstner(out.l1.image, o.foerstner))
    AddCloudPoint(c, ip, &match_sigmas, &out);
  DropLineOutliers(c, &out);
  if (!match_sigmas.empty()) {
    std::nth_element(
        match_sigmas.begin(), match_sigmas.begin() + match_sigmas.size() / 2, match_sigmas.end());
    out.median_match_sigma_px = match_sigmas[match_sigmas.size() / 2];
  }
  return out;
}

nlohmann::json CloudControlToJson(const CloudControlResult& r, const CloudControlOptions& o) {
  nlohmann::json j;
  j["kind"] = "pushbroom_control";
  j["l1"] = {{"width", r.l1.grid.width},
             {"height", r.l1.grid.height},
             {"gsd_m", r.l1.grid.gsd_m},
             {"z_m", r.l1.grid.z_m},
             {"x0_m", r.l1.grid.x0_m},
             {"y0_m", r.l1.grid.y0_m}};
  j["n_interest"] = r.n_interest;
  j["n_rays"] = r.n_rays;
  j["n_points"] = r.points.size();
  j["rejected"] = {{"fewer_than_two_matches", r.n_no_match},
                   {"gross_error", r.n_gross},
                   {"imprecise", r.n_imprecise},
                   {"rays_removed", r.n_rays_removed},
                   {"line_outliers", r.n_line_outliers}};
  j["median_match_sigma_px"] = r.median_match_sigma_px;
  j["options"] = {{"mean_height_m", o.mean_height_m},
                  {"map_step_px", o.map_step_px},
                  {"template_half_px", o.template_half_px},
                  {"search_px", o.search_px},
                  {"min_correlation", o.min_correlation},
                  {"min_match_sigma_px", o.min_match_sigma_px},
                  {"line_sigma_px", o.line_sigma_px},
                  {"gross_error_alpha", o.gross_error_alpha},
                  {"max_point_sigma_m", o.max_point_sigma_m}};
  return j;
}

}  // namespace aerocal::triangulation
