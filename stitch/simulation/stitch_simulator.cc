#include "stitch/simulation/stitch_simulator.h"

#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

namespace aerocal::stitch {
namespace {

struct Box {
  double u0, v0, u1, v1;  // virtual-image bounding box
  double Area() const { return std::max(0.0, u1 - u0) * std::max(0.0, v1 - v0); }
};

Box Footprint(const calib::SubimageMapping& s) {
  Box b{1e300, 1e300, -1e300, -1e300};
  for (double u : {0.0, s.width_px - 1.0})
    for (double v : {0.0, s.height_px - 1.0}) {
      const Eigen::Vector2d p = s.VirtualFromSub({u, v});
      b.u0 = std::min(b.u0, p.x());
      b.v0 = std::min(b.v0, p.y());
      b.u1 = std::max(b.u1, p.x());
      b.v1 = std::max(b.v1, p.y());
    }
  return b;
}

}  // namespace

calib::Camera MakeMisplacedCamera(const calib::Camera& nominal,
                                  const std::vector<std::string>& base_ids,
                                  const MisplacementOptions& o,
                                  std::mt19937_64& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  calib::Camera truth = nominal;
  for (auto& s : truth.subimages) {
    if (std::find(base_ids.begin(), base_ids.end(), s.id) != base_ids.end()) continue;
    // Misplacement about the sub-image centre: rotation, scale, optional affine part, shift.
    const double angle = o.rotation_sigma_rad * normal(rng);
    const double scale = 1.0 + o.scale_sigma * normal(rng);
    const double dscale = o.shear * (normal(rng) > 0 ? 1.0 : -1.0);
    const double skew = o.shear * (normal(rng) > 0 ? 1.0 : -1.0);
    Eigen::Matrix3d a = Eigen::Matrix3d::Identity();
    a(0, 0) = scale * std::cos(angle) + 0.5 * dscale;
    a(0, 1) = -scale * std::sin(angle) + skew;
    a(1, 0) = scale * std::sin(angle);
    a(1, 1) = scale * std::cos(angle) - 0.5 * dscale;
    Eigen::Matrix3d to_centre = Eigen::Matrix3d::Identity(),
                    from_centre = Eigen::Matrix3d::Identity();
    const double cu = 0.5 * (s.width_px - 1), cv = 0.5 * (s.height_px - 1);
    to_centre(0, 2) = -cu;
    to_centre(1, 2) = -cv;
    from_centre(0, 2) = cu + o.shift_sigma_px * normal(rng);
    from_centre(1, 2) = cv + o.shift_sigma_px * normal(rng);
    const Eigen::Matrix3d h =
        calib::HomographyFromParams(s.model, s.params.data()) * from_centre * a * to_centre;
    // Keep the nominal model unless the misplacement needs a richer one.
    calib::MappingModel needed = calib::MappingModel::kTranslation;
    if (o.rotation_sigma_rad != 0.0 || o.scale_sigma != 0.0)
      needed = calib::MappingModel::kConformal;
    if (o.shear != 0.0) needed = calib::MappingModel::kAffine;
    if (static_cast<int>(s.model) < static_cast<int>(needed)) s.model = needed;
    s.params = calib::ParamsFromHomography(s.model, h);
  }
  return truth;
}

std::vector<StitchObservation> SimulateFrame(const calib::Camera& truth,
                                             const std::string& frame,
                                             const FrameSimulationOptions& o,
                                             std::mt19937_64& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::vector<StitchObservation> rows;
  for (const auto& ref : truth.reference_points) {
    const int k = truth.SubimageIndex(ref.subimage);
    const Eigen::Vector2d uv = truth.subimages[k].SubFromVirtual({ref.U, ref.V});
    rows.push_back({frame,
                    ref.id,
                    ref.subimage,
                    uv.x() + o.reference_noise_px * normal(rng),
                    uv.y() + o.reference_noise_px * normal(rng),
                    ref.sigma_px});
  }
  // Overlap strips: pairwise intersections of sub-image footprints.
  struct Strip {
    Box box;
  };
  std::vector<Strip> strips;
  double total_area = 0.0;
  const size_t n = truth.subimages.size();
  for (size_t a = 0; a < n; ++a)
    for (size_t b = a + 1; b < n; ++b) {
      const Box fa = Footprint(truth.subimages[a]), fb = Footprint(truth.subimages[b]);
      const Box overlap{std::max(fa.u0, fb.u0),
                        std::max(fa.v0, fb.v0),
                        std::min(fa.u1, fb.u1),
                        std::min(fa.v1, fb.v1)};
      if (overlap.Area() <= 0) continue;
      strips.push_back({overlap});
      total_area += overlap.Area();
    }
  int tie = 0;
  for (const auto& strip : strips) {
    const int count =
        static_cast<int>(std::round(o.ties_per_frame * strip.box.Area() / total_area));
    int made = 0;
    for (int attempt = 0; made < count && attempt < 20 * count + 100; ++attempt) {
      const Eigen::Vector2d p(strip.box.u0 + uniform(rng) * (strip.box.u1 - strip.box.u0),
                              strip.box.v0 + uniform(rng) * (strip.box.v1 - strip.box.v0));
      std::vector<StitchObservation> seen;
      for (const auto& s : truth.subimages) {
        const Eigen::Vector2d uv = s.SubFromVirtual(p);
        if (!s.Contains(uv, -o.edge_margin_px)) continue;
        seen.push_back({frame, "", s.id, uv.x(), uv.y(), o.sigma_px});
      }
      if (seen.size() < 2) continue;
      const std::string id = "t" + std::to_string(++tie);
      for (auto& obs : seen) {
        obs.point = id;
        obs.u += o.noise_px * normal(rng);
        obs.v += o.noise_px * normal(rng);
        rows.push_back(obs);
      }
      ++made;
    }
  }
  return rows;
}

void WriteStitchObservations(const std::string& path,
                             const std::vector<StitchObservation>& rows,
                             bool exact) {
  WriteFileAtomically(path, [&](std::ostream& out) {
    out << "frame,point,subimage,u,v,sigma_px\n";
    const char* format = exact ? "%.17g,%.17g,%.17g\n" : "%.4f,%.4f,%.4g\n";
    char numbers[128];
    for (const auto& r : rows) {
      std::snprintf(numbers, sizeof(numbers), format, r.u, r.v, r.sigma_px);
      out << r.frame << ',' << r.point << ',' << r.subimage << ',' << numbers;
    }
  });
}

std::vector<StitchObservation> ReadStitchObservations(const std::string& path,
                                                      double default_sigma_px) {
  const CsvTable table = CsvTable::Read(path);
  table.RequireColumns({"frame", "point", "subimage", "u", "v"});
  table.RejectUnknownColumns({"frame", "point", "subimage", "u", "v", "sigma_px"});
  std::vector<StitchObservation> rows;
  rows.reserve(table.rows().size());
  for (const auto& row : table.rows()) {
    StitchObservation obs;
    obs.frame = table.String(row, "frame");
    obs.point = table.String(row, "point");
    obs.subimage = table.String(row, "subimage");
    if (obs.frame.empty() || obs.point.empty() || obs.subimage.empty())
      ThrowInputError(table.Where(row), "frame, point and subimage must not be empty");
    obs.line = row.line;
    // Bounds (stitch/README.md): |u|, |v| <= 1e7 px, 0 < sigma_px <= 1e4 px.
    obs.u = table.Bounded(row, "u", -1e7, 1e7);
    obs.v = table.Bounded(row, "v", -1e7, 1e7);
    obs.sigma_px = table.OptionalNumber(row, "sigma_px").value_or(default_sigma_px);
    if (!(obs.sigma_px > 0 && obs.sigma_px <= 1e4))
      ThrowInputError(table.Where(row),
                      "sigma_px must be > 0 and <= 1e4 (got " + FormatNumber(obs.sigma_px) + ")");
    rows.push_back(obs);
  }
  return rows;
}

}  // namespace aerocal::stitch
