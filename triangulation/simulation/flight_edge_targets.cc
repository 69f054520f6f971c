#include "triangulation/simulation/flight_edge_targets.h"

#include "calib/core/atomic_file.h"
#include "calib/core/error.h"
#include "stitch/image_io/image_io.h"
#include "stitch/resample/raster.h"
#include "stitch/resample/virtual_image.h"
#include "stitch/simulation/rendered_edge.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <random>
#include <sstream>
#include <utility>

namespace aerocal::triangulation {
namespace {

constexpr double kDegToRad = 3.14159265358979323846 / 180.0;

void ValidateOptions(const FlightEdgeTargetOptions& o) {
  auto require = [](bool ok, const char* name, double value, const char* rule) {
    if (ok) return;
    std::ostringstream message;
    message << "edge targets: " << name << " must be " << rule << " (got " << value << ")";
    throw ConfigError(message.str());
  };
  require(o.targets_x >= 1, "targets_x", o.targets_x, ">= 1");
  require(o.targets_y >= 1, "targets_y", o.targets_y, ">= 1");
  require(o.edge_length_m > 0.0, "edge_length_m", o.edge_length_m, "> 0");
  require(o.slant_deg >= 2.0 && o.slant_deg <= 10.0, "slant_deg", o.slant_deg, "in 2..10");
  require(o.psf_sigma_px >= 0.3 && o.psf_sigma_px <= 3.0, "psf_sigma_px", o.psf_sigma_px, "0.3..3");
  require(o.bright_dn > o.dark_dn && o.dark_dn >= 0.0 && o.bright_dn <= 65535.0,
          "bright_dn",
          o.bright_dn,
          "> dark_dn >= 0 and <= 65535");
  require(o.noise_dn >= 0.0, "noise_dn", o.noise_dn, ">= 0");
  require(o.patch_px >= 48, "patch_px", o.patch_px, ">= 48");
  require(o.region_px >= 32 && o.region_px <= o.patch_px - 8,
          "region_px",
          o.region_px,
          ">= 32 and <= patch_px - 8");
}

// The two windows of one edge seen by one exposure: the virtual window centred on the edge's
// middle and the raw window of the one sub-image that covers it (with a 2 px margin for the
// bilinear neighbours); false when none or several sub-images cover it or it leaves the image.
struct PatchWindows {
  int subimage = -1;
  Eigen::Vector2i virtual_origin = Eigen::Vector2i::Zero(), raw_origin = Eigen::Vector2i::Zero(),
                  raw_size = Eigen::Vector2i::Zero();
};
bool FindWindows(const calib::Camera& camera,
                 const Eigen::Vector2d& middle_px,
                 int patch_px,
                 PatchWindows* w) {
  w->virtual_origin = Eigen::Vector2i(static_cast<int>(std::lround(middle_px.x())) - patch_px / 2,
                                      static_cast<int>(std::lround(middle_px.y())) - patch_px / 2);
  if (w->virtual_origin.minCoeff() < 0 || w->virtual_origin.x() + patch_px > camera.width_px ||
      w->virtual_origin.y() + patch_px > camera.height_px)
    return false;
  const double last = patch_px - 1.0;
  const Eigen::Vector2d corners[4] = {{0, 0}, {last, 0}, {0, last}, {last, last}};
  int covering = 0;
  for (int k = 0; k < static_cast<int>(camera.subimages.size()); ++k) {
    const calib::SubimageMapping& sub = camera.subimages[k];
    Eigen::Vector2d lo(1e300, 1e300), hi(-1e300, -1e300);
    int inside = 0;
    for (const Eigen::Vector2d& c : corners) {
      const Eigen::Vector2d uv = sub.SubFromVirtual(w->virtual_origin.cast<double>() + c);
      inside += sub.Contains(uv, -2.0) ? 1 : 0;
      lo = lo.cwiseMin(uv), hi = hi.cwiseMax(uv);
    }
    if (inside == 0) continue;
    if (inside < 4 || ++covering > 1) return false;  // across a sub-image border: an overlap
    w->subimage = k;
    w->raw_origin = Eigen::Vector2i(static_cast<int>(std::floor(lo.x())) - 2,
                                    static_cast<int>(std::floor(lo.y())) - 2);
    w->raw_size = Eigen::Vector2i(static_cast<int>(std::ceil(hi.x())) + 3,
                                  static_cast<int>(std::ceil(hi.y())) + 3) -
                  w->raw_origin;
  }
  return covering == 1;
}

// The raw window rendered: the edge through the raw pixels a and b (window coordinates), bright
// on the side of `bright`, through the PSF and each pixel's area, plus noise, 16-bit.
stitch::MemoryRaster RenderRawWindow(const Eigen::Vector2i& size,
                                     const Eigen::Vector2d& a,
                                     const Eigen::Vector2d& b,
                                     const Eigen::Vector2d& bright,
                                     const FlightEdgeTargetOptions& o,
                                     std::mt19937_64& rng,
                                     Eigen::Vector2d* normal) {
  const Eigen::Vector2d d = (b - a).normalized();
  *normal = Eigen::Vector2d(-d.y(), d.x());
  if (normal->dot(bright - a) < 0.0) *normal = -*normal;
  const double angle = std::atan2(normal->y(), normal->x()), offset = normal->dot(a);
  std::normal_distribution<double> noise(0.0, 1.0);
  stitch::MemoryRaster raster({size.x(), size.y(), 1, 16});
  for (int r = 0; r < size.y(); ++r)
    for (int c = 0; c < size.x(); ++c) {
      const double fraction = stitch::EdgePixelFraction(c, r, angle, offset, o.psf_sigma_px);
      raster.Set(
          c, r, 0, o.dark_dn + (o.bright_dn - o.dark_dn) * fraction + o.noise_dn * noise(rng));
    }
  return raster;
}

stitch::GrayImage ToGray(const stitch::MemoryRaster& raster) {
  const stitch::RasterInfo info = raster.Info();
  stitch::GrayImage image(info.height, info.width);
  for (int r = 0; r < info.height; ++r)
    for (int c = 0; c < info.width; ++c) image(r, c) = static_cast<float>(raster.At(c, r));
  return image;
}

// The virtual window resampled from the raw window by the production resampler: a camera of the
// patch's format with the raw window as its one sub-image, mapped by T(-virtual origin) H
// T(raw origin) (H the true mapping, a projectivity of the same model).
stitch::MemoryRaster ResampleWindow(const calib::SubimageMapping& sub,
                                    const PatchWindows& w,
                                    int patch_px,
                                    stitch::MemoryRaster* raw) {
  Eigen::Matrix3d to_virtual = Eigen::Matrix3d::Identity(), from_raw = Eigen::Matrix3d::Identity();
  to_virtual.block<2, 1>(0, 2) = -w.virtual_origin.cast<double>();
  from_raw.block<2, 1>(0, 2) = w.raw_origin.cast<double>();
  const Eigen::Matrix3d h =
      to_virtual * calib::HomographyFromParams(sub.model, sub.params.data()) * from_raw;
  calib::Camera patch;
  patch.width_px = patch.height_px = patch_px;
  patch.pixel_size_mm = 0.01;
  patch.subimages.push_back({sub.id,
                             w.raw_size.x(),
                             w.raw_size.y(),
                             sub.model,
                             calib::ParamsFromHomography(sub.model, h)});
  stitch::MemoryRaster sink({patch_px, patch_px, 1, 16});
  stitch::ResampleOptions options;
  options.interpolation = stitch::Interpolation::kBilinear;
  options.threads = 1;
  stitch::ResampleVirtualImage(patch, {raw}, &sink, options);
  return sink;
}

stitch::PixelRegion CentredRegion(int width, int height, int side) {
  return {(width - side) / 2, (height - side) / 2, side, side};
}

}  // namespace

std::vector<stitch::EdgeTarget> LayOutEdgeTargets(const SimulatedFlight& flight,
                                                  const FlightEdgeTargetOptions& options) {
  ValidateOptions(options);
  Eigen::Vector2d lo(1e300, 1e300), hi(-1e300, -1e300);
  for (const Exposure& e : flight.exposures_truth)
    lo = lo.cwiseMin(e.center_m.head<2>()), hi = hi.cwiseMax(e.center_m.head<2>());
  const Eigen::Vector2d centre = 0.5 * (lo + hi), half_span = 0.25 * (hi - lo);
  const double turn = options.slant_deg * kDegToRad, half = 0.5 * options.edge_length_m;
  const Eigen::Vector2d east(std::cos(turn), std::sin(turn)),
      north(-std::sin(turn), std::cos(turn));
  std::vector<stitch::EdgeTarget> edges;
  for (int j = 0; j < options.targets_y; ++j)
    for (int i = 0; i < options.targets_x; ++i) {
      // Grid over the inner half of the block (exposure centres +- a quarter of their span).
      auto at = [](int k, int n) { return n == 1 ? 0.0 : -1.0 + 2.0 * k / (n - 1); };
      const Eigen::Vector2d c = centre + Eigen::Vector2d(at(i, options.targets_x) * half_span.x(),
                                                         at(j, options.targets_y) * half_span.y());
      const double z = SimulatedTerrainHeight(flight.options, c.x(), c.y());
      auto ground = [&](double e, double n) {
        const Eigen::Vector2d p = c + e * half * east + n * half * north;
        return Eigen::Vector3d(p.x(), p.y(), z);
      };
      const std::string id = "T" + std::to_string(j * options.targets_x + i + 1);
      // Counter-clockwise round the square, so the bright inside is on the left.
      edges.push_back({id + "_x", ground(-1, 1), ground(-1, -1)});  // west edge, north -> south
      edges.push_back({id + "_y", ground(1, 1), ground(-1, 1)});    // north edge, east -> west
    }
  return edges;
}

std::vector<EdgeTargetPatch> RenderEdgeTargetPatches(const SimulatedFlight& flight,
                                                     const std::vector<stitch::EdgeTarget>& edges,
                                                     const FlightEdgeTargetOptions& options) {
  ValidateOptions(options);
  const calib::Camera& camera = flight.truth;
  std::mt19937_64 rng(options.seed);
  std::vector<EdgeTargetPatch> patches;
  for (const Exposure& e : flight.exposures_truth)
    for (const stitch::EdgeTarget& edge : edges) {
      // The edge's middle, two points a quarter of its length to either side and one inside.
      const Eigen::Vector3d middle = 0.5 * (edge.start_m + edge.end_m),
                            along = 0.25 * (edge.end_m - edge.start_m);
      const Eigen::Vector3d inside =
          middle + Eigen::Vector3d(-along.y(), along.x(), 0.0).normalized();
      Eigen::Vector2d m_px, a_px, b_px, in_px;
      if (!camera.ProjectToPixel(e.opk_rad, e.center_m, middle, &m_px) ||
          !camera.ProjectToPixel(e.opk_rad, e.center_m, middle - along, &a_px) ||
          !camera.ProjectToPixel(e.opk_rad, e.center_m, middle + along, &b_px) ||
          !camera.ProjectToPixel(e.opk_rad, e.center_m, inside, &in_px))
        continue;
      PatchWindows w;
      if (!FindWindows(camera, m_px, options.patch_px, &w)) continue;
      const calib::SubimageMapping& sub = camera.subimages[w.subimage];
      const Eigen::Vector2d origin = w.raw_origin.cast<double>();
      EdgeTargetPatch p;
      p.target = edge.id, p.image = e.image, p.subimage = sub.id;
      p.raw_origin_px = w.raw_origin, p.virtual_origin_px = w.virtual_origin;
      stitch::MemoryRaster raw = RenderRawWindow(w.raw_size,
                                                 sub.SubFromVirtual(a_px) - origin,
                                                 sub.SubFromVirtual(b_px) - origin,
                                                 sub.SubFromVirtual(in_px) - origin,
                                                 options,
                                                 rng,
                                                 &p.raw_normal);
      p.virtual_image = ToGray(ResampleWindow(sub, w, options.patch_px, &raw));
      p.raw = ToGray(raw);
      p.raw_region = CentredRegion(w.raw_size.x(), w.raw_size.y(), options.region_px);
      p.virtual_region = CentredRegion(options.patch_px, options.patch_px, options.region_px);
      const Eigen::Vector2d d = (b_px - a_px).normalized();
      p.normal = Eigen::Vector2d(-d.y(), d.x());
      p.axis = std::abs(p.normal.x()) >= std::abs(p.normal.y()) ? stitch::MtfAxis::kX
                                                                : stitch::MtfAxis::kY;
      p.gsd_m = 2.0 * along.norm() / (b_px - a_px).norm();
      const stitch::PixelRegion& vr = p.virtual_region;
      for (int r = vr.row; r < vr.row + vr.height; ++r)
        for (int c = vr.col; c < vr.col + vr.width; ++c) {
          const Eigen::Vector2d uv =
              sub.SubFromVirtual(w.virtual_origin.cast<double>() + Eigen::Vector2d(c, r));
          p.shifts.push_back(uv - uv.array().floor().matrix());
        }
      patches.push_back(std::move(p));
    }
  return patches;
}

namespace {

constexpr int kTilesPerRow = 8;

// A mosaic of patches: tile k at column k % 8, row k / 8 of tiles `tile` px wide.
struct Mosaic {
  std::vector<const stitch::GrayImage*> tiles;
  stitch::PixelRegion Place(const stitch::GrayImage& image,
                            const stitch::PixelRegion& region,
                            int tile) {
    AEROCAL_CHECK(image.rows() <= tile && image.cols() <= tile) << "a patch exceeds its tile";
    const int k = static_cast<int>(tiles.size());
    tiles.push_back(&image);
    return {region.col + (k % kTilesPerRow) * tile,
            region.row + (k / kTilesPerRow) * tile,
            region.width,
            region.height};
  }
  stitch::GrayImage Image(int tile) const {
    const int n = static_cast<int>(tiles.size());
    const int cols = std::min(n, kTilesPerRow), rows = (n + kTilesPerRow - 1) / kTilesPerRow;
    stitch::GrayImage out = stitch::GrayImage::Zero(rows * tile, cols * tile);
    for (int k = 0; k < n; ++k)
      out.block((k / kTilesPerRow) * tile,
                (k % kTilesPerRow) * tile,
                tiles[k]->rows(),
                tiles[k]->cols()) = *tiles[k];
    return out;
  }
};

std::string RoiColumns(const stitch::PixelRegion& r) {
  std::ostringstream out;
  out << r.col << ',' << r.row << ',' << r.width << ',' << r.height;
  return out.str();
}

}  // namespace

void WriteEdgeTargetPatches(const std::vector<EdgeTargetPatch>& patches,
                            const std::vector<stitch::EdgeTarget>& edges,
                            const FlightEdgeTargetOptions& options,
                            const std::string& folder) {
  namespace fs = std::filesystem;
  fs::create_directories(folder);
  const int tile = options.patch_px + 16;
  std::map<std::string, Mosaic> raw;  // by sub-image
  Mosaic virt;
  std::ostringstream csv;
  csv << "# edge target patches of the simulated flight (docs/formats.md); regions in px\n"
      << "target,image,subimage,axis,raw_file,raw_col,raw_row,raw_width,raw_height,virtual_file,"
         "virtual_col,virtual_row,virtual_width,virtual_height,raw_origin_col,raw_origin_row,"
         "virtual_origin_col,virtual_origin_row,shift_x_px,shift_y_px,gsd_m\n";
  csv.precision(10);
  for (const EdgeTargetPatch& p : patches) {
    const std::string raw_file = "raw_" + p.subimage + ".tif";
    Eigen::Vector2d mean_shift = Eigen::Vector2d::Zero();
    for (const Eigen::Vector2d& d : p.shifts)
      mean_shift += d / static_cast<double>(p.shifts.size());
    csv << p.target << ',' << p.image << ',' << p.subimage << ',' << stitch::MtfAxisName(p.axis)
        << ',' << raw_file << ',' << RoiColumns(raw[p.subimage].Place(p.raw, p.raw_region, tile))
        << ",virtual.tif," << RoiColumns(virt.Place(p.virtual_image, p.virtual_region, tile)) << ','
        << p.raw_origin_px.x() << ',' << p.raw_origin_px.y() << ',' << p.virtual_origin_px.x()
        << ',' << p.virtual_origin_px.y() << ',' << mean_shift.x() << ',' << mean_shift.y() << ','
        << p.gsd_m << '\n';
  }
  for (const auto& [sub, mosaic] : raw)
    stitch::WriteGrayImage(
        (fs::path(folder) / ("raw_" + sub + ".tif")).string(), mosaic.Image(tile), 16);
  if (!patches.empty())
    stitch::WriteGrayImage((fs::path(folder) / "virtual.tif").string(), virt.Image(tile), 16);
  std::ostringstream targets;
  targets << "# edge targets: bright on the left of start -> end seen from above (m)\n"
          << "id,start_x,start_y,start_z,end_x,end_y,end_z\n";
  targets.precision(12);
  for (const stitch::EdgeTarget& e : edges)
    targets << e.id << ',' << e.start_m.x() << ',' << e.start_m.y() << ',' << e.start_m.z() << ','
            << e.end_m.x() << ',' << e.end_m.y() << ',' << e.end_m.z() << '\n';
  WriteFileAtomically((fs::path(folder) / "targets.csv").string(), targets.str());
  WriteFileAtomically((fs::path(folder) / "patches.csv").string(), csv.str());
}

}  // namespace aerocal::triangulation
