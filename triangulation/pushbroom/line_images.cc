#include "triangulation/pushbroom/line_images.h"

#include "calib/camera/camera_io.h"
#include "calib/camera/rotation.h"
#include "calib/core/error.h"
#include "stitch/image_io/image_io.h"
#include "triangulation/adjustment/forward_intersection.h"
#include "triangulation/block/block_io.h"
#include "triangulation/pushbroom/line_rectification.h"
#include "triangulation/simulation/textured_ground.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <random>

namespace aerocal::triangulation {
namespace {

// Sub-samples per pixel side of the area integration (kPixelSamples^2 per pixel).
constexpr int kPixelSamples = 4;

// Grey values of an image whose pixel (r, c) sees the ground point ground(r, c) (NaN: no
// ground), each the mean of the texture over the pixel's footprint, as a real detector
// integrates over its pixel: kPixelSamples^2 samples on a regular grid over the square
// [-1/2, 1/2]^2 pixel, mapped onto the ground by the local Jacobian (central differences of the
// neighbouring pixels' ground points; one-sided at an edge). Point sampling at the pixel centre
// instead aliases the texture (0.3 line spacings per texel) and biased the image-mode
// calibration smoothly in the detector index (module README "Measured").
template <typename Noise>
stitch::GrayImage IntegrateOverPixels(const TexturedGround& texture,
                                      const Eigen::MatrixXd& ground_x,
                                      const Eigen::MatrixXd& ground_y,
                                      Noise&& noise) {
  const int rows = int(ground_x.rows()), cols = int(ground_x.cols());
  stitch::GrayImage image(rows, cols);
  auto valid = [&](int r, int c) {
    return r >= 0 && c >= 0 && r < rows && c < cols && !std::isnan(ground_x(r, c));
  };
  // d ground / d (pixel step) along one image axis at (r, c): central, else one-sided, else 0.
  auto derivative = [&](int r, int c, int dr, int dc) -> Eigen::Vector2d {
    const bool ahead = valid(r + dr, c + dc), behind = valid(r - dr, c - dc);
    if (!ahead && !behind) return Eigen::Vector2d(0, 0);
    const int r1 = ahead ? r + dr : r, c1 = ahead ? c + dc : c;
    const int r0 = behind ? r - dr : r, c0 = behind ? c - dc : c;
    const double steps = (ahead ? 1.0 : 0.0) + (behind ? 1.0 : 0.0);
    return Eigen::Vector2d(ground_x(r1, c1) - ground_x(r0, c0),
                           ground_y(r1, c1) - ground_y(r0, c0)) /
           steps;
  };
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      if (!valid(r, c)) {
        image(r, c) = 0.0f;
        continue;
      }
      const Eigen::Vector2d g(ground_x(r, c), ground_y(r, c));
      const Eigen::Vector2d along_c = derivative(r, c, 0, 1), along_r = derivative(r, c, 1, 0);
      double sum = 0;
      for (int a = 0; a < kPixelSamples; ++a)
        for (int b = 0; b < kPixelSamples; ++b) {
          const double fc = (b + 0.5) / kPixelSamples - 0.5, fr = (a + 0.5) / kPixelSamples - 0.5;
          const Eigen::Vector2d q = g + fc * along_c + fr * along_r;
          sum += texture.At(q.x(), q.y());
        }
      image(r, c) = float(sum / (kPixelSamples * kPixelSamples) + noise());
    }
  return image;
}

using Terrain = std::function<double(double, double)>;
using GreyNoise = std::function<double()>;

// Scene extent: the footprint of the first and last lines and of the outer detectors (`lo`,
// `hi`, m); returns the mean terrain height there.
double SceneExtent(const calib::LineCamera& cam,
                   const PosTrajectory& truth,
                   int lines,
                   const Terrain& terrain,
                   Eigen::Vector2d* lo,
                   Eigen::Vector2d* hi) {
  *lo = Eigen::Vector2d::Constant(1e300);
  *hi = -*lo;
  double height_sum = 0;
  int height_n = 0;
  for (int k = 0; k <= 32; ++k) {
    const double line = (lines - 1) * k / 32.0;
    for (double i : {0.0, 0.5 * (cam.detectors - 1), cam.detectors - 1.0}) {
      const auto g = GroundOfDetector(cam, truth, i, line, terrain);
      if (!g) throw Error("image mode: a detector ray misses the terrain");
      *lo = lo->cwiseMin(g->head<2>());
      *hi = hi->cwiseMax(g->head<2>());
      height_sum += g->z(), ++height_n;
    }
  }
  return height_sum / height_n;
}

// The line image through the true camera and poses: the ground point of every pixel, then the
// texture integrated over each pixel's footprint (one line period along track).
stitch::GrayImage RenderLineImage(const calib::LineCamera& cam,
                                  const PosTrajectory& truth,
                                  int lines,
                                  const Terrain& terrain,
                                  const TexturedGround& texture,
                                  const GreyNoise& grey_noise) {
  Eigen::MatrixXd ground_x(lines, cam.detectors), ground_y(lines, cam.detectors);
  std::vector<Eigen::Vector3d> in_camera(cam.detectors);
  const Eigen::Matrix3d mount = calib::RotationFromOpk(cam.mount_rad);
  for (int i = 0; i < cam.detectors; ++i) {
    const Eigen::Vector2d xy = cam.DetectorPosition(i);
    in_camera[i] = mount * Eigen::Vector3d(xy.x(), xy.y(), -cam.c_mm);
  }
  for (int l = 0; l < lines; ++l) {
    Eigen::Vector3d center, opk;
    truth.PoseAtLine(l, &center, &opk);
    const Eigen::Matrix3d body = calib::RotationFromOpk(opk);
    const Eigen::Vector3d origin = center + body * cam.lever_arm_m;
    for (int i = 0; i < cam.detectors; ++i) {
      const auto g = IntersectSurface(origin, body * in_camera[i], terrain);
      if (!g) throw Error("image mode: a detector ray misses the terrain");
      ground_x(l, i) = g->x();
      ground_y(l, i) = g->y();
    }
  }
  return IntegrateOverPixels(texture, ground_x, ground_y, grey_noise);
}

// The reference frame camera: distortion-free, c for the reference GSD at the flying height.
calib::Camera ReferenceCamera(const LineSimulationOptions& o,
                              const LineImageOptions& io,
                              double reference_gsd) {
  calib::Camera ref;
  ref.name = "pushbroom-sim reference frame camera";
  ref.pixel_size_mm = io.reference_pixel_mm;
  ref.width_px = io.reference_width_px;
  ref.height_px = io.reference_height_px;
  std::fill(ref.interior.begin(), ref.interior.end(), 0.0);
  ref.interior[calib::Camera::Model::kC] = io.reference_pixel_mm * o.height_m / reference_gsd;
  return ref;
}

// Reference exposure k at along-track position y near the mean track (x_mean, z_mean), with
// small smooth position and attitude wobbles.
Exposure ReferenceExposure(int k, double x_mean, double y, double z_mean) {
  Exposure e;
  e.image = "ref" + std::to_string(k + 1);
  e.camera = "reference";
  e.center_m =
      Eigen::Vector3d(x_mean + 2.0 * std::sin(0.7 * k), y, z_mean + 1.5 * std::cos(0.9 * k));
  e.opk_rad =
      Eigen::Vector3d(0.3 * std::sin(1.3 * k), -0.2 * std::cos(0.8 * k), 0.4 * std::sin(0.5 * k)) *
      (M_PI / 180.0);
  e.line = k + 2;
  return e;
}

// The image of reference exposure e: the ground point of every pixel, then the texture.
stitch::GrayImage RenderReferenceFrame(const calib::Camera& ref,
                                       const Exposure& e,
                                       const Terrain& terrain,
                                       const TexturedGround& texture,
                                       const GreyNoise& grey_noise) {
  Eigen::MatrixXd frame_x(ref.height_px, ref.width_px), frame_y(ref.height_px, ref.width_px);
  for (int r = 0; r < ref.height_px; ++r)
    for (int c = 0; c < ref.width_px; ++c) {
      const ImageRay ray = RayFromPixel(ref, e.opk_rad, e.center_m, Eigen::Vector2d(c, r));
      const auto g = IntersectSurface(ray.center_m, ray.direction, terrain);
      frame_x(r, c) = g ? g->x() : std::nan("");
      frame_y(r, c) = g ? g->y() : std::nan("");
    }
  return IntegrateOverPixels(texture, frame_x, frame_y, grey_noise);
}

// The reference strip: nadir frames along the flight's mean track at the flying height, covering
// the scene (lo.y .. hi.y) with a quarter frame beyond each end.
void RenderReferenceStrip(const LineSimulation& sim,
                          const LineImageOptions& io,
                          double reference_gsd,
                          const Eigen::Vector2d& lo,
                          const Eigen::Vector2d& hi,
                          const Terrain& terrain,
                          const TexturedGround& texture,
                          const GreyNoise& grey_noise,
                          LineImageSimulation* out) {
  const int lines = int(sim.pos_truth.size());
  double x_mean = 0, z_mean = 0;
  for (const auto& r : sim.pos_truth) x_mean += r.center_m.x(), z_mean += r.center_m.z();
  x_mean /= lines, z_mean /= lines;
  const double along_m = io.reference_height_px * reference_gsd;  // image rows along Y
  const double base_m = (1 - io.forward_overlap) * along_m;
  int k = 0;
  for (double y = lo.y() - 0.25 * along_m; y <= hi.y() + 0.25 * along_m + base_m;
       y += base_m, ++k) {
    out->reference_exposures.push_back(ReferenceExposure(k, x_mean, y, z_mean));
    out->reference_images.push_back(RenderReferenceFrame(
        out->reference_camera, out->reference_exposures.back(), terrain, texture, grey_noise));
  }
}

}  // namespace

void LineImageOptions::Validate() const {
  auto require = [](bool ok, const std::string& message) {
    if (!ok) throw ConfigError(message);
  };
  require(!texture_path.empty(),
          "--texture: the photograph of the scene is required with --render-images");
  require(texture_gsd_m >= 0, "--texture-gsd-m must be >= 0");
  require(reference_width_px >= 100 && reference_width_px <= 20000 && reference_height_px >= 100 &&
              reference_height_px <= 20000,
          "the reference image format must be within 100 .. 20000 px");
  // Each reference frame holds two double grids of its format (16 bytes a pixel) while rendered.
  require(double(reference_width_px) * reference_height_px <= kMaxReferencePixels,
          "--reference-size: " + std::to_string(reference_width_px) + "x" +
              std::to_string(reference_height_px) +
              " px is more than the 2.5e7 px a reference frame may have");
  require(reference_pixel_mm > 0 && reference_gsd_m >= 0, "reference pixel > 0, GSD >= 0");
  require(forward_overlap >= 0.5 && forward_overlap <= 0.9,
          "--reference-overlap must be within 0.5 .. 0.9");
  require(grey_noise_dn >= 0, "--grey-noise-dn must be >= 0");
}

LineImageSimulation RenderLineImages(const LineSimulation& sim,
                                     const LineSimulationOptions& o,
                                     const LineImageOptions& io) {
  io.Validate();
  const Terrain terrain = [&o](double x, double y) { return SimulatedTerrainHeight(o, x, y); };
  const PosTrajectory truth = PosTrajectory::FromRecords(sim.pos_truth, "pos_truth.csv");
  const calib::LineCamera& cam = sim.truth;
  const int lines = int(sim.pos_truth.size());
  std::mt19937_64 rng(io.seed * 7919 + 13);
  std::normal_distribution<double> noise(0.0, 1.0);
  LineImageSimulation out;
  Eigen::Vector2d lo, hi;
  out.mean_height_m = SceneExtent(cam, truth, lines, terrain, &lo, &hi);
  const double line_spacing_m =
      (sim.pos_truth.back().center_m - sim.pos_truth.front().center_m).head<2>().norm() /
      std::max(1, lines - 1);
  const double reference_gsd = io.reference_gsd_m > 0 ? io.reference_gsd_m : 0.6 * line_spacing_m;

  TexturedGround texture;
  ReadGroundTexture(io.texture_path, &texture);
  texture.gsd_m =
      io.texture_gsd_m > 0 ? io.texture_gsd_m : 0.5 * std::min(line_spacing_m, reference_gsd);
  texture.x_c = 0.5 * (lo.x() + hi.x());
  texture.y_c = 0.5 * (lo.y() + hi.y());
  out.texture_gsd_m = texture.gsd_m;
  const GreyNoise grey_noise = [&]() { return io.grey_noise_dn * noise(rng); };
  out.line_image = RenderLineImage(cam, truth, lines, terrain, texture, grey_noise);
  out.reference_camera = ReferenceCamera(o, io, reference_gsd);
  RenderReferenceStrip(sim, io, reference_gsd, lo, hi, terrain, texture, grey_noise, &out);
  return out;
}

void WriteLineImages(const LineImageSimulation& images, const std::string& folder) {
  namespace fs = std::filesystem;
  fs::create_directories(fs::path(folder) / "reference");
  stitch::WriteGrayImage((fs::path(folder) / "line_image.png").string(), images.line_image);
  calib::WriteCamera((fs::path(folder) / "reference" / "camera.yaml").string(),
                     images.reference_camera);
  WriteExposures((fs::path(folder) / "reference" / "exposures.csv").string(),
                 images.reference_exposures);
  for (size_t k = 0; k < images.reference_images.size(); ++k)
    stitch::WriteGrayImage(
        (fs::path(folder) / "reference" / (images.reference_exposures[k].image + ".png")).string(),
        images.reference_images[k]);
}

}  // namespace aerocal::triangulation
