#include "triangulation/adjustment/nadir_start.h"

#include "calib/core/error.h"

#include <algorithm>
#include <complex>
#include <map>

namespace aerocal::triangulation {

std::vector<Exposure> NadirStartFromControl(const Project& project, const std::string& camera_id) {
  const calib::Camera& camera = project.cameras.at(camera_id);
  struct Pair {
    std::complex<double> photo, ground;
    double z;
  };
  std::map<std::string, std::vector<Pair>> pairs;
  const Eigen::Vector2d principal_point = camera.PrincipalPointMm();
  for (const auto& o : project.observations) {
    const GroundPoint* p = project.FindPoint(o.point);
    if (!p || !p->xyz_m) continue;
    const Eigen::Vector2d xy = camera.PhotoFromPixel(o.pixel) - principal_point;
    pairs[o.image].push_back({{xy.x(), xy.y()}, {p->xyz_m->x(), p->xyz_m->y()}, p->xyz_m->z()});
  }
  std::vector<Exposure> out;
  for (auto& [image, list] : pairs) {
    if (list.size() < 2)
      throw InputError("image " + image +
                       " sees fewer than two surveyed points: no starting orientation");
    std::complex<double> a, t;
    for (;;) {
      std::complex<double> mp, mg;
      for (const auto& q : list) {
        mp += q.photo;
        mg += q.ground;
      }
      mp /= double(list.size());
      mg /= double(list.size());
      std::complex<double> num;
      double den = 0;
      for (const auto& q : list) {
        num += (q.ground - mg) * std::conj(q.photo - mp);
        den += std::norm(q.photo - mp);
      }
      a = num / den;
      t = mg - a * mp;
      std::vector<double> residuals;
      for (const auto& q : list) residuals.push_back(std::abs(a * q.photo + t - q.ground));
      std::vector<double> sorted = residuals;
      std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
      const auto worst = std::max_element(residuals.begin(), residuals.end()) - residuals.begin();
      if (list.size() <= 3 || residuals[worst] <= 5.0 * sorted[sorted.size() / 2]) break;
      list.erase(list.begin() + worst);
    }
    double z = 0;
    for (const auto& q : list) z += q.z;
    Exposure e;
    e.image = image;
    e.camera = camera_id;
    e.center_m = {t.real(), t.imag(), z / list.size() + std::abs(a) * camera.c_mm()};
    e.opk_rad = {0.0, 0.0, std::arg(a)};
    out.push_back(e);
  }
  return out;
}

}  // namespace aerocal::triangulation
