// A real photograph cut into a 2 x 3 multi-CCD frame with a known truth, for the matching tests:
// img_4880.jpg of the Boruszyn kite set (Photos: Andrew Zaborowski, on CC-BY license with
// attribution to OpenStreetMap-PL), grey, full resolution 4608 x 3456 px (EXIF orientation
// ignored), as the virtual image of a 3-row x 2-column grid camera with 200 px overlaps. The true
// mappings are the nominal ones with sub-pixel affine misplacements (seeded); sub-images get a
// gain/offset, Gaussian noise of 1.5 DN and 8-bit quantisation. Reference points sit near the
// outer corners of the CCDs (GridLayout kOuterCorners).
#pragma once

#include "stitch/image_io/image_io.h"
#include "stitch/image_io/subimage_cutter.h"
#include "stitch/layout/grid_layout.h"
#include "stitch/simulation/stitch_simulator.h"
#include "tests/support/test_support.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <random>
#include <string>
#include <vector>

namespace aerocal::stitch::testing {

struct MatchScene {
  calib::Camera nominal, truth;
  std::vector<GrayImage> images;  // camera order
};

/// `frame` enlarged `scale` times by bilinear interpolation (pixel centres aligned).
inline GrayImage Enlarged(const GrayImage& frame, int scale) {
  GrayImage out(frame.rows() * scale, frame.cols() * scale);
  const Eigen::Index last_r = frame.rows() - 1, last_c = frame.cols() - 1;
  for (Eigen::Index r = 0; r < out.rows(); ++r) {
    const double y = std::clamp((r + 0.5) / scale - 0.5, 0.0, double(last_r));
    const Eigen::Index r0 = std::min<Eigen::Index>(static_cast<Eigen::Index>(y), last_r - 1);
    const float fy = static_cast<float>(y - r0);
    for (Eigen::Index c = 0; c < out.cols(); ++c) {
      const double x = std::clamp((c + 0.5) / scale - 0.5, 0.0, double(last_c));
      const Eigen::Index c0 = std::min<Eigen::Index>(static_cast<Eigen::Index>(x), last_c - 1);
      const float fx = static_cast<float>(x - c0);
      out(r, c) = (1 - fy) * ((1 - fx) * frame(r0, c0) + fx * frame(r0, c0 + 1)) +
                  fy * ((1 - fx) * frame(r0 + 1, c0) + fx * frame(r0 + 1, c0 + 1));
    }
  }
  return out;
}

/// The scene with the photograph enlarged `scale` times (bilinear; the overlaps stay 200 px), or
/// nullopt when the shared data set is absent. Scale 3 gives a 13,824 x 10,368 px frame of six
/// 7,012 x 3,589 px sub-images: the production size of issue 35's matching target.
inline std::optional<MatchScene> MakeBoruszynScene(int scale) {
  const std::string dir = aerocal::testing::SharedDataDir("odm_boruszyn_kap_frames");
  if (dir.empty()) return std::nullopt;
  GrayImage frame = ReadGrayImage(dir + "/images/img_4880.jpg");
  if (scale > 1) frame = Enlarged(frame, scale);
  GridLayoutOptions layout;
  layout.rows = 3;
  layout.cols = 2;
  layout.virtual_width_px = static_cast<int>(frame.cols());
  layout.virtual_height_px = static_cast<int>(frame.rows());
  layout.overlap_px = 200;
  layout.model = calib::MappingModel::kAffine;
  layout.reference_placement = ReferencePlacement::kOuterCorners;
  MatchScene s;
  s.nominal = MakeGridCamera(layout);
  MisplacementOptions misplacement;  // sub-pixel: 0.5 px shifts, 1e-4 rotation/scale/shear
  misplacement.shift_sigma_px = 0.5;
  misplacement.rotation_sigma_rad = 1e-4;
  misplacement.scale_sigma = 1e-4;
  misplacement.shear = 1e-4;
  std::mt19937_64 rng(4880);
  s.truth = MakeMisplacedCamera(s.nominal, {}, misplacement, rng);
  CutOptions cut;
  cut.gains = {1.0, 0.93, 1.06, 0.97, 1.04, 0.95};
  cut.offsets = {0.0, 4.0, -3.0, 2.0, -5.0, 3.0};
  cut.noise_dn = 1.5;
  cut.seed = 11;
  s.images = CutSubimages(frame, s.truth, cut);
  for (GrayImage& image : s.images) image = image.array().round().max(0.0f).min(255.0f).matrix();
  return s;
}

/// The full-resolution scene (scale 1), built once per test binary.
inline const std::optional<MatchScene>& BoruszynScene() {
  static const std::optional<MatchScene> scene = MakeBoruszynScene(1);
  return scene;
}

struct TieAgreement {
  int ties = 0;
  double rms_px = 0;  // per coordinate, of VirtualFromSub_true(a) - VirtualFromSub_true(b)
  double max_px = 0;  // largest 2D discrepancy
};

/// Maps both rays of every two-ray tie through the TRUE mappings and compares.
inline TieAgreement AgreementThroughTruth(const calib::Camera& truth,
                                          const std::vector<StitchObservation>& rows) {
  TieAgreement out;
  double sum = 0;
  for (std::size_t i = 0; i + 1 < rows.size(); i += 2) {
    const StitchObservation& a = rows[i];
    const StitchObservation& b = rows[i + 1];
    if (a.point != b.point) continue;
    const auto& sa = truth.subimages[truth.SubimageIndex(a.subimage)];
    const auto& sb = truth.subimages[truth.SubimageIndex(b.subimage)];
    const Eigen::Vector2d d = sa.VirtualFromSub({a.u, a.v}) - sb.VirtualFromSub({b.u, b.v});
    sum += d.squaredNorm();
    out.max_px = std::max(out.max_px, d.norm());
    ++out.ties;
  }
  out.rms_px = out.ties > 0 ? std::sqrt(sum / (2.0 * out.ties)) : 0.0;
  return out;
}

}  // namespace aerocal::stitch::testing
