#include "stitch/rig/rig_convert.h"

#include "calib/core/csv.h"
#include "calib/core/error.h"

#include <Eigen/Geometry>
#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

namespace aerocal::stitch {

Eigen::Matrix3d HeadFromVirtualHomography(const RigConverter& converter, int head) {
  const calib::Rig& rig = converter.rig();
  const calib::Camera& v = rig.virtual_camera.camera;
  const calib::Camera& camera = rig.heads[head].camera;
  // Virtual pixel -> ray in the virtual camera frame: (x - x0, y - y0, -c) of its pinhole part
  // (the virtual camera's distortion, like a head's, is left to the correction grid).
  const Eigen::Vector2d v0 = v.PrincipalPointMm();
  Eigen::Matrix3d virtual_ray;
  virtual_ray << v.pixel_size_mm, 0, -0.5 * (v.width_px - 1) * v.pixel_size_mm - v0.x(),  //
      0, -v.pixel_size_mm, 0.5 * (v.height_px - 1) * v.pixel_size_mm - v0.y(),            //
      0, 0, -v.c_mm();
  // Ray d (object frame) from O -> G = O + (h / n.d) d; in head space
  // u = R_k^T (G - O_k) ~ R_k^T ((O - O_k) n^T + h I) d.
  const Eigen::Vector3d n = converter.Plane().normal;
  const double h = converter.Plane().offset - n.dot(converter.VirtualCenter());
  const Eigen::Matrix3d head_space =
      converter.ObjectFromHead(head).transpose() *
      ((converter.VirtualCenter() - converter.HeadCenter(head)) * n.transpose() +
       h * Eigen::Matrix3d::Identity()) *
      converter.ObjectFromVirtual() * virtual_ray;
  // Head space u -> measured pixel: x = -c u_x / u_z + x0 -> (c u_x - x0 u_z, c u_y - y0 u_z,
  // -u_z), then col = x / p + (W - 1) / 2, row = -y / p + (H - 1) / 2.
  const double c = camera.c_mm(), p = camera.pixel_size_mm;
  const Eigen::Vector2d principal = camera.PrincipalPointMm();
  Eigen::Matrix3d photo;
  photo << c, 0, -principal.x(),  //
      0, c, -principal.y(),       //
      0, 0, -1;
  Eigen::Matrix3d pixel;
  pixel << 1 / p, 0, 0.5 * (camera.width_px - 1),  //
      0, -1 / p, 0.5 * (camera.height_px - 1),     //
      0, 0, 1;
  return pixel * photo * head_space;
}

calib::Camera RigExposureAsSubimageCamera(const RigConverter& converter) {
  const calib::Rig& rig = converter.rig();
  calib::Camera camera = rig.virtual_camera.camera;  // its model, interior and format
  camera.name = rig.name;
  for (int k = 0; k < static_cast<int>(rig.heads.size()); ++k) {
    const calib::RigHead& head = rig.heads[k];
    Eigen::Matrix3d virtual_from_head = HeadFromVirtualHomography(converter, k).inverse();
    if (!virtual_from_head.allFinite() || std::abs(virtual_from_head(2, 2)) < 1e-300)
      throw InputError("head " + head.id + ": its image does not map onto the rectification plane");
    virtual_from_head /= virtual_from_head(2, 2);
    calib::SubimageMapping mapping;
    mapping.id = head.id;
    mapping.width_px = head.camera.width_px;
    mapping.height_px = head.camera.height_px;
    mapping.model = calib::MappingModel::kProjective;
    mapping.params = calib::ParamsFromHomography(mapping.model, virtual_from_head);
    camera.subimages.push_back(mapping);
  }
  return camera;
}

namespace {

// Distortion: the head's model is not the pinhole (c, principal point) the homography uses, at
// the image's corners and centre (in any registered model, without naming its terms).
bool HasDistortion(const calib::Camera& camera) {
  const Eigen::Vector2d principal = camera.PrincipalPointMm();
  const double w = camera.width_px - 1, h = camera.height_px - 1;
  for (const Eigen::Vector2d& pixel : {Eigen::Vector2d(0, 0),
                                       Eigen::Vector2d(w, 0),
                                       Eigen::Vector2d(0, h),
                                       Eigen::Vector2d(w, h),
                                       Eigen::Vector2d(w / 2, h / 2)}) {
    Eigen::Vector2d ideal;
    if (!camera.IdealFromPixel(pixel, &ideal)) return true;
    const Eigen::Vector2d pinhole = camera.PhotoFromPixel(pixel) - principal;
    if ((ideal - pinhole).norm() > 1e-9 * camera.pixel_size_mm) return true;
  }
  return false;
}

// The exact head pixel of a virtual pixel: over the plane, or over the DEM when given.
std::optional<Eigen::Vector2d> ExactHeadPixel(const RigConverter& converter,
                                              const DemGrid* dem,
                                              int head,
                                              const Eigen::Vector2d& virtual_px) {
  if (!dem) return converter.HeadFromVirtual(head, virtual_px);
  const std::optional<Eigen::Vector3d> ray =
      converter.rig().virtual_camera.RayFromPixel(virtual_px);
  if (!ray) return std::nullopt;
  const auto g =
      IntersectDem(*dem, converter.VirtualCenter(), converter.ObjectFromVirtual() * *ray);
  if (!g) return converter.HeadFromVirtual(head, virtual_px);
  return converter.HeadPixelOfPoint(head, *g);
}

// Exact head pixel minus the homography's at virtual pixel (U, V), where the correction grid is
// defined: the exact map exists (the ray meets the plane or DEM, the point lies in front of the
// head, the correction inverts) and lands inside the head's format widened by half its larger
// side on every side. Elsewhere nullopt: beyond the head's horizon (a tilted head, e.g. B and D of
// the uav4 rig, sees the far side of the level virtual image only at grazing angles) the map
// diverges and changes sign, so a grid node there holds values that are no correction at all,
// and bilinear interpolation between such a node and its neighbour can land a virtual pixel far
// outside the head inside its format (a spurious overlap zone).
std::optional<Eigen::Vector2d> MapDifference(const RigConverter& converter,
                                             const DemGrid* dem,
                                             int head,
                                             const Eigen::Matrix3d& h,
                                             const Eigen::Vector2d& virtual_px) {
  const auto exact = ExactHeadPixel(converter, dem, head, virtual_px);
  if (!exact) return std::nullopt;
  const calib::Camera& camera = converter.rig().heads[head].camera;
  const double margin = 0.5 * std::max(camera.width_px, camera.height_px);
  if (exact->x() < -margin || exact->y() < -margin || exact->x() > camera.width_px - 1 + margin ||
      exact->y() > camera.height_px - 1 + margin)
    return std::nullopt;
  const Eigen::Vector2d linear = (h * virtual_px.homogeneous()).hnormalized();
  return *exact - linear;
}

MapCorrectionGrid MakeGrid(const RigConverter& converter,
                           const DemGrid* dem,
                           int head,
                           const Eigen::Matrix3d& h,
                           int step) {
  const calib::Camera& v = converter.rig().virtual_camera.camera;
  MapCorrectionGrid g;
  g.step_px = step;
  g.cols = std::max((v.width_px - 1 + step - 1) / step + 1, 2);
  g.rows = std::max((v.height_px - 1 + step - 1) / step + 1, 2);
  g.duv.resize(2 * static_cast<size_t>(g.cols) * g.rows);
  for (int j = 0; j < g.rows; ++j)
    for (int i = 0; i < g.cols; ++i) {
      // Outside the defined region the node holds NaN: the interpolated (u, v) of every virtual
      // pixel of its cells is NaN, which the resampler's per-pixel format test rejects.
      const auto d = MapDifference(converter, dem, head, h, Eigen::Vector2d(i * step, j * step));
      const size_t at = 2 * (static_cast<size_t>(j) * g.cols + i);
      g.duv[at] = d ? static_cast<float>(d->x()) : std::numeric_limits<float>::quiet_NaN();
      g.duv[at + 1] = d ? static_cast<float>(d->y()) : std::numeric_limits<float>::quiet_NaN();
      if (d) g.max_abs_px = std::max(g.max_abs_px, static_cast<float>(d->cwiseAbs().maxCoeff()));
    }
  return g;
}

// Largest |interpolated - exact| (px) at the cell centres whose exact head pixel lies inside the
// head's format.
double GridError(const RigConverter& converter,
                 const DemGrid* dem,
                 int head,
                 const Eigen::Matrix3d& h,
                 const MapCorrectionGrid& g) {
  double worst = 0.0;
  for (int j = 0; j + 1 < g.rows; ++j)
    for (int i = 0; i + 1 < g.cols; ++i) {
      const Eigen::Vector2d centre((i + 0.5) * g.step_px, (j + 0.5) * g.step_px);
      const auto exact = ExactHeadPixel(converter, dem, head, centre);
      if (!exact || !converter.InHeadFormat(head, *exact)) continue;
      Eigen::Vector2d interpolated = Eigen::Vector2d::Zero();
      for (int dj = 0; dj < 2; ++dj)
        for (int di = 0; di < 2; ++di) {
          const size_t at = 2 * (static_cast<size_t>(j + dj) * g.cols + i + di);
          interpolated += 0.25 * Eigen::Vector2d(g.duv[at], g.duv[at + 1]);
        }
      const Eigen::Vector2d mapped = (h * centre.homogeneous()).hnormalized() + interpolated;
      // A cell inside the head that touches an undefined node: refine (NaN would pass std::max).
      if (!mapped.allFinite()) return std::numeric_limits<double>::infinity();
      worst = std::max(worst, (mapped - *exact).cwiseAbs().maxCoeff());
    }
  return worst;
}

}  // namespace

HeadMapCorrections MakeHeadMapCorrections(const RigConverter& converter,
                                          double tolerance_px,
                                          const DemGrid* dem) {
  AEROCAL_CHECK(tolerance_px > 0) << tolerance_px;
  HeadMapCorrections out;
  const calib::Rig& rig = converter.rig();
  out.grids.resize(rig.heads.size());
  for (int k = 0; k < static_cast<int>(rig.heads.size()); ++k) {
    // The homography is exact between two pinholes over the plane: a grid where the head or the
    // virtual camera has distortion, or a DEM is the surface.
    if (!dem && !HasDistortion(rig.heads[k].camera) && !HasDistortion(rig.virtual_camera.camera))
      continue;
    const Eigen::Matrix3d h = HeadFromVirtualHomography(converter, k);
    double error = 0.0;
    int step = 64;
    for (;; step /= 2) {
      out.grids[k] = MakeGrid(converter, dem, k, h, step);
      error = GridError(converter, dem, k, h, out.grids[k]);
      if (error <= tolerance_px || step <= 2) break;
    }
    out.max_error_px = std::max(out.max_error_px, error);
    out.finest_step_px = out.finest_step_px == 0 ? step : std::min(out.finest_step_px, step);
  }
  return out;
}

ResampleReport ConvertRigExposure(const RigConverter& converter,
                                  const std::vector<RasterSource*>& sources,
                                  RasterSink* sink,
                                  const ResampleOptions& options,
                                  HeadMapCorrections* corrections,
                                  const DemGrid* dem) {
  HeadMapCorrections grids = MakeHeadMapCorrections(converter, 0.01, dem);
  const ResampleReport report = ResampleVirtualImage(
      RigExposureAsSubimageCamera(converter), sources, sink, options, grids.grids);
  if (corrections) *corrections = std::move(grids);
  return report;
}

}  // namespace aerocal::stitch
