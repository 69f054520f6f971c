#include "triangulation/calibration/resection.h"

#include "calib/camera/rotation.h"
#include "calib/core/error.h"
#include "triangulation/adjustment/forward_intersection.h"

#include <Eigen/Dense>

#include <cmath>
#include <map>
#include <set>

namespace aerocal::triangulation {
namespace {

// Relative smallest principal extent below which a point set is treated as planar.
constexpr double kPlanarRatio = 0.02;

const Eigen::Matrix3d kForwardFromImage = Eigen::Vector3d(1, -1, -1).asDiagonal();

// Similarity that moves the points' centroid to 0 and their mean distance to sqrt(dim) (Hartley).
template <int Dim>
Eigen::Matrix<double, Dim + 1, Dim + 1> Normalizer(
    const std::vector<Eigen::Matrix<double, Dim, 1>>& points) {
  Eigen::Matrix<double, Dim, 1> mean = Eigen::Matrix<double, Dim, 1>::Zero();
  for (const auto& p : points) mean += p;
  mean /= static_cast<double>(points.size());
  double distance = 0;
  for (const auto& p : points) distance += (p - mean).norm();
  distance /= static_cast<double>(points.size());
  const double s = distance > 0 ? std::sqrt(static_cast<double>(Dim)) / distance : 1.0;
  Eigen::Matrix<double, Dim + 1, Dim + 1> t = Eigen::Matrix<double, Dim + 1, Dim + 1>::Identity();
  t.template topLeftCorner<Dim, Dim>() *= s;
  t.template topRightCorner<Dim, 1>() = -s * mean;
  return t;
}

// Homography dst ~ H src by the normalised DLT; false when degenerate.
bool FitHomography(const std::vector<Eigen::Vector2d>& src,
                   const std::vector<Eigen::Vector2d>& dst,
                   Eigen::Matrix3d* h) {
  const int n = static_cast<int>(src.size());
  if (n < 4) return false;
  const Eigen::Matrix3d ts = Normalizer<2>(src), td = Normalizer<2>(dst);
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(2 * n, 9);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d s = ts * src[i].homogeneous();
    const Eigen::Vector3d d = td * dst[i].homogeneous();
    a.block<1, 3>(2 * i, 0) = s.transpose();
    a.block<1, 3>(2 * i, 6) = -d.x() * s.transpose();
    a.block<1, 3>(2 * i + 1, 3) = s.transpose();
    a.block<1, 3>(2 * i + 1, 6) = -d.y() * s.transpose();
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(a, Eigen::ComputeFullV);
  const Eigen::VectorXd v = svd.matrixV().col(8);
  Eigen::Matrix3d hn;
  hn << v(0), v(1), v(2), v(3), v(4), v(5), v(6), v(7), v(8);
  *h = td.inverse() * hn * ts;
  return std::isfinite(h->norm()) && std::abs(h->determinant()) > 1e-300;
}

Eigen::Matrix3d NearestRotation(const Eigen::Matrix3d& m) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(m, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d r = svd.matrixU() * svd.matrixV().transpose();
  if (r.determinant() < 0) {
    Eigen::Matrix3d u = svd.matrixU();
    u.col(2) *= -1;
    r = u * svd.matrixV().transpose();
  }
  return r;
}

// Plane frame of a point set: centroid and principal axes (columns e1, e2, n = e1 x e2) with
// the singular values of the centred coordinates.
struct PlaneFrame {
  Eigen::Vector3d centroid;
  Eigen::Matrix3d axes;
  Eigen::Vector3d extent;
};

PlaneFrame FitPlane(const std::vector<Eigen::Vector3d>& points) {
  PlaneFrame f;
  f.centroid.setZero();
  for (const auto& p : points) f.centroid += p;
  f.centroid /= static_cast<double>(points.size());
  Eigen::MatrixXd centred(points.size(), 3);
  for (size_t i = 0; i < points.size(); ++i) centred.row(i) = (points[i] - f.centroid).transpose();
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(centred, Eigen::ComputeFullV);
  f.axes = svd.matrixV();
  f.axes.col(2) = f.axes.col(0).cross(f.axes.col(1));
  f.extent = svd.singularValues().head<3>();
  if (points.size() < 3) f.extent.tail<2>().setZero();
  return f;
}

Eigen::Vector2d Normalised(const calib::Camera& camera, const Eigen::Vector2d& pixel) {
  // The pinhole part of the camera's model (principal point and distance), distortion ignored.
  const Eigen::Vector2d xy = camera.PhotoFromPixel(pixel) - camera.PrincipalPointMm();
  const double c = camera.c_mm();
  return {xy.x() / c, -xy.y() / c};
}

Exposure ExposureFromForward(const Eigen::Matrix3d& forward_from_object,
                             const Eigen::Vector3d& center_m) {
  Exposure e;
  const Eigen::Matrix3d object_from_image = forward_from_object.transpose() * kForwardFromImage;
  e.opk_rad = calib::OpkFromRotation(object_from_image);
  e.center_m = center_m;
  return e;
}

}  // namespace

std::optional<ResectionStart> ResectImage(const calib::Camera& camera,
                                          const std::vector<Eigen::Vector2d>& pixels,
                                          const std::vector<Eigen::Vector3d>& points_m,
                                          std::string* why) {
  const int n = static_cast<int>(points_m.size());
  if (n < 4) {
    *why = "sees " + std::to_string(n) + " points of known coordinates (needs 4)";
    return std::nullopt;
  }
  std::vector<Eigen::Vector2d> uv;
  for (const auto& p : pixels) uv.push_back(Normalised(camera, p));
  const PlaneFrame plane = FitPlane(points_m);
  ResectionStart out;
  out.n_points = n;
  if (plane.extent(1) <= kPlanarRatio * plane.extent(0)) {
    *why = "its points of known coordinates lie on a line";
    return std::nullopt;
  }
  const bool planar = plane.extent(2) <= kPlanarRatio * plane.extent(0) || n < 6;
  if (planar) {
    std::vector<Eigen::Vector2d> ab;
    for (const auto& p : points_m)
      ab.push_back((plane.axes.transpose() * (p - plane.centroid)).head<2>());
    Eigen::Matrix3d h;
    if (!FitHomography(ab, uv, &h)) {
      *why = "degenerate homography";
      return std::nullopt;
    }
    double lambda = 2.0 / (h.col(0).norm() + h.col(1).norm());
    if (lambda * h(2, 2) < 0) lambda = -lambda;  // the target in front of the camera
    Eigen::Matrix3d q;
    q.col(0) = lambda * h.col(0);
    q.col(1) = lambda * h.col(1);
    q.col(2) = q.col(0).cross(q.col(1));
    const Eigen::Matrix3d forward_from_object = NearestRotation(q) * plane.axes.transpose();
    const Eigen::Vector3d t = lambda * h.col(2);
    out.exposure = ExposureFromForward(forward_from_object,
                                       plane.centroid - forward_from_object.transpose() * t);
    out.method = "homography";
  } else {
    std::vector<Eigen::Vector3d> xyz = points_m;
    const Eigen::Matrix4d ts = Normalizer<3>(xyz);
    const Eigen::Matrix3d td = Normalizer<2>(uv);
    Eigen::MatrixXd a = Eigen::MatrixXd::Zero(2 * n, 12);
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector4d s = ts * xyz[i].homogeneous();
      const Eigen::Vector3d d = td * uv[i].homogeneous();
      a.block<1, 4>(2 * i, 0) = s.transpose();
      a.block<1, 4>(2 * i, 8) = -d.x() * s.transpose();
      a.block<1, 4>(2 * i + 1, 4) = s.transpose();
      a.block<1, 4>(2 * i + 1, 8) = -d.y() * s.transpose();
    }
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(a, Eigen::ComputeFullV);
    const Eigen::VectorXd v = svd.matrixV().col(11);
    Eigen::Matrix<double, 3, 4> pn;
    pn << v(0), v(1), v(2), v(3), v(4), v(5), v(6), v(7), v(8), v(9), v(10), v(11);
    Eigen::Matrix<double, 3, 4> p = td.inverse() * pn * ts;
    if (p.leftCols<3>().determinant() < 0) p = -p;
    const Eigen::Matrix3d m = p.leftCols<3>();
    const Eigen::Vector3d center = -m.inverse() * p.col(3);
    out.exposure = ExposureFromForward(NearestRotation(m), center);
    out.method = "dlt";
  }
  // Check: every point in front of the camera, and the reprojection RMS.
  double sum = 0;
  for (int i = 0; i < n; ++i) {
    Eigen::Vector2d projected;
    if (!camera.ProjectToPixel(
            out.exposure.opk_rad, out.exposure.center_m, points_m[i], &projected)) {
      *why = "a point of known coordinates lies behind the resected camera (" + out.method + ")";
      return std::nullopt;
    }
    sum += (projected - pixels[i]).squaredNorm();
  }
  out.rms_px = std::sqrt(sum / n);
  return out;
}

std::vector<ResectionStart> StartFromResections(const Project& project,
                                                const std::string& camera_id) {
  const calib::Camera& camera = project.cameras.at(camera_id);
  std::map<std::string, Eigen::Vector3d> known;
  for (const auto& p : project.points)
    if (p.role == PointRole::kControl && p.xyz_m) known[p.id] = *p.xyz_m;
  std::map<std::string, std::vector<const ImageObservation*>> by_image;
  for (const auto& o : project.observations) by_image[o.image].push_back(&o);
  std::map<std::string, ResectionStart> started;
  std::map<std::string, std::string> reasons;
  for (bool progress = true; progress;) {
    progress = false;
    for (const auto& [image, list] : by_image) {
      if (started.count(image)) continue;
      std::vector<Eigen::Vector2d> pixels;
      std::vector<Eigen::Vector3d> points;
      for (const ImageObservation* o : list) {
        const auto k = known.find(o->point);
        if (k == known.end()) continue;
        pixels.push_back(o->pixel);
        points.push_back(k->second);
      }
      std::string why;
      auto start = ResectImage(camera, pixels, points, &why);
      if (!start) {
        reasons[image] = why;
        continue;
      }
      start->exposure.image = image;
      start->exposure.camera = camera_id;
      started[image] = *start;
      progress = true;
    }
    if (!progress) break;
    // Tie points seen from two or more started images become known (starting values only).
    std::map<std::string, std::vector<ImageRay>> rays;
    for (const auto& o : project.observations) {
      if (known.count(o.point) || !started.count(o.image)) continue;
      const Exposure& e = started.at(o.image).exposure;
      rays[o.point].push_back(RayFromPixel(camera, e.opk_rad, e.center_m, o.pixel));
    }
    for (const auto& [point, list] : rays)
      if (auto xyz = IntersectRays(list)) known[point] = *xyz;
  }
  std::string missing;
  for (const auto& [image, list] : by_image)
    if (!started.count(image))
      missing += (missing.empty() ? "" : "; ") + image + ": " + reasons[image];
  if (!missing.empty())
    throw InputError(project.observations_file + ": no starting orientation by resection for " +
                     missing);
  std::vector<ResectionStart> out;
  for (auto& [image, start] : started) out.push_back(start);
  return out;
}

std::optional<double> ClosedFormPrincipalDistance(const Project& project,
                                                  const std::string& camera_id) {
  const calib::Camera& camera = project.cameras.at(camera_id);
  std::map<std::string, Eigen::Vector3d> control;
  std::vector<Eigen::Vector3d> all;
  for (const auto& p : project.points)
    if (p.role == PointRole::kControl && p.xyz_m) {
      control[p.id] = *p.xyz_m;
      all.push_back(*p.xyz_m);
    }
  if (all.size() < 4) return std::nullopt;
  const PlaneFrame plane = FitPlane(all);
  if (plane.extent(2) > kPlanarRatio * plane.extent(0)) return std::nullopt;
  std::map<std::string, std::pair<std::vector<Eigen::Vector2d>, std::vector<Eigen::Vector2d>>>
      views;
  const Eigen::Vector2d principal_point = camera.PrincipalPointMm();
  for (const auto& o : project.observations) {
    const auto k = control.find(o.point);
    if (k == control.end()) continue;
    const Eigen::Vector2d xy = camera.PhotoFromPixel(o.pixel) - principal_point;
    views[o.image].first.push_back(
        (plane.axes.transpose() * (k->second - plane.centroid)).head<2>());
    views[o.image].second.push_back({xy.x(), -xy.y()});
  }
  double ata = 0, atb = 0;
  for (const auto& [image, view] : views) {
    Eigen::Matrix3d h;
    if (!FitHomography(view.first, view.second, &h)) continue;
    h /= h.norm();
    const double a1 = h(0, 0) * h(0, 1) + h(1, 0) * h(1, 1), b1 = -h(2, 0) * h(2, 1);
    const double a2 = h(0, 0) * h(0, 0) + h(1, 0) * h(1, 0) - h(0, 1) * h(0, 1) - h(1, 1) * h(1, 1);
    const double b2 = -(h(2, 0) * h(2, 0) - h(2, 1) * h(2, 1));
    ata += a1 * a1 + a2 * a2;
    atb += a1 * b1 + a2 * b2;
  }
  if (ata <= 0) return std::nullopt;
  const double w = atb / ata;
  if (!(w > 0)) return std::nullopt;
  return 1.0 / std::sqrt(w);
}

}  // namespace aerocal::triangulation
