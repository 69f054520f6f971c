// Deterministic (seeded) simulation of a flight with a multi-head rig (CONVENTIONS.md "Multi-head
// rigs", FORMATS.md "Multi-head rig"): the truth behind the rig bundle's synthetic tests and the
// `aerocal simulate --rig` files.
//
// The flight plan, the GNSS/IMU-measured exposures and the ground points are those of the
// frame-camera simulator (flight_simulator.h, the same options and the same seeded streams); the
// exposures are the rig's (virtual centre O and rig attitude R), the footprint is the virtual
// camera's. Each head k of each exposure sees the object through R_k = R M_k E_k,
// O_k = O + R t_k + v dT_k (calib/camera/rig.h HeadPose) with its own true interior; its
// measurements are pixels of that head (observations.csv with a `head` column).
//
// Presets: `dual-lens` is configs/rig_dual_lens.yaml (two 10000 x 10000 px heads of 6 um,
// c = 150 mm, head B 0.15 m along x converging by 1 deg). `uav4` is configs/rig_uav4.yaml (four
// 24.5 mm full-frame heads tilted 24 deg along and 37 deg across track, issue 16).
//
// Stitching ties (issue 16): per exposure, ground points on the terrain seen by two or more heads
// of that ONE exposure and measured there only: around given standard positions of the virtual
// image (stitch::DesignRig computes them; the caller passes them, triangulation does not use
// stitch beyond sub-image mappings), at random places of the overlap zones (dense ties), and
// check ties (points.csv role `check` without coordinates). Each exposure also gets `z_ref`, the
// mean terrain height under the virtual image.
//
// Image mode (`simulate --rig uav4 --render-images --texture PHOTO`): every head image of every
// exposure rendered through the TRUE head pose of that exposure (ground calibration + increments
// E_k + offsets dT_k with the velocity; calib::HeadPose) and the head's true interior onto the
// terrain textured with a real photograph (textured_ground.h), plus Gaussian grey-value noise. Each
// pixel integrates the texture over its footprint, as a sensor integrates over its pixel area: the
// rays through the pixel's four corners are intersected with the terrain exactly (bisection to
// 1e-10 m), the points inside bilinear in them, n x n samples (n = the footprint's longer
// diagonal in texels, rounded up, within 2..8) averaged with equal weights (a box filter). The
// texture is finer than the head pixels (2 texels per nadir pixel by default), so one sample per
// pixel (`point_sampling`, the former renderer) aliases it differently in heads of different GSD:
// tests/stitch/rig_stitched_image_test.cc measures both. `format_scale` shrinks every format (pixel
// size grown by the same factor, same field of view) so that tests render small images of the
// same geometry.
#pragma once

#include "calib/camera/rig.h"
#include "stitch/image_io/gray_image.h"
#include "triangulation/block/block.h"
#include "triangulation/simulation/flight_simulator.h"
#include "triangulation/simulation/textured_ground.h"

#include <Eigen/Core>

#include <cmath>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace aerocal::triangulation {

enum class RigPreset { kDualLens, kUav4 };

/// "dual-lens" | "uav4" -> preset; nullopt for any other name.
std::optional<RigPreset> ParseRigPreset(const std::string& name);

/// The nominal rig of a preset (a maker's design values). ConfigError for a preset not built yet.
calib::Rig MakeNominalRig(RigPreset preset);

struct RigFlightSimulationOptions {
  /// Flight geometry, points, image noise, GNSS/IMU: as the frame simulator. The camera fields
  /// (layout, misplacement, stitching, interior_correction) are not used.
  FlightSimulationOptions flight = DefaultRigFlight();
  RigPreset preset = RigPreset::kDualLens;
  /// truth - nominal of every non-reference head's mount angles (rad) and lever arm (m)
  Eigen::Vector3d mount_error_rad = Eigen::Vector3d(15.0, -25.0, 10.0) * M_PI / (180.0 * 3600.0);
  Eigen::Vector3d lever_arm_error_m = Eigen::Vector3d(1.5e-3, -1.0e-3, 2.0e-3);
  /// truth - nominal interior of head k (k-th entry; the last one serves the heads beyond)
  std::vector<calib::InteriorParams> interior_correction = DefaultHeadInteriorCorrections();
  double increment_sigma_rad = 0.0;  // per-exposure E_k of non-reference heads (sigma), >= 0
  double time_offset_s = 0.0;        // dT_k of every non-reference head, |dT| <= 1 s
  double speed_mps = 0.0;            // platform speed along the strips, >= 0; > 0: exposures.csv
                                     // carries the velocity vX, vY, vZ
  /// Every head's and the virtual camera's format x format_scale (rounded), pixel sizes / scale:
  /// the same geometry in fewer pixels (rendered images for tests), (0, 1].
  double format_scale = 1.0;
  /// dT_k per head (s, k-th entry; the reference head's is ignored, |dT| <= 1 s); empty: every
  /// non-reference head has time_offset_s.
  std::vector<double> head_time_offsets_s;

  struct StandardPosition {
    std::string name;            // "AB-1"
    Eigen::Vector2d virtual_px;  // in the level virtual image of the nadir design
  };
  /// Stitching ties per exposure (see the header comment); all zero: none.
  struct StitchTies {
    std::vector<StandardPosition> standard_positions;
    int per_standard_position = 0;  // ties around each standard position, >= 0
    double jitter_px = 40.0;        // radius around a standard position (virtual px), >= 0
    int dense = 0;                  // ties at random places seen by >= 2 heads, >= 0
    int check = 0;                  // check ties, >= 0
  } stitch_ties;

  /// The frame simulator's defaults at the dual-lens camera's relative flying height (1200 m)
  /// with terrain relief of 100 m.
  static FlightSimulationOptions DefaultRigFlight();
  static std::vector<calib::InteriorParams> DefaultHeadInteriorCorrections();
  /// The four-head stitching flight of issue 16 (preset uav4): one line of 8 exposures at 300 m
  /// over 30 m of relief, 10 m/s, per-exposure increments of 0.025 deg (sigma per angle), shutter
  /// offsets B +3, C -2.5, D +3.5 ms, GNSS 0.05 m / IMU 0.01 deg, tie noise 0.3 px, no surveyed
  /// points; ties: 3 per standard position, 40 dense, 10 check per exposure (the positions are the
  /// caller's).
  static RigFlightSimulationOptions DefaultUav4();
};

/// Truth of one head in one exposure: the attitude increment E_k (rad) and time offset dT_k (s).
struct RigExposureTruth {
  std::string image, head;
  Eigen::Vector3d increment_rad = Eigen::Vector3d::Zero();
  double dt_s = 0.0;
};

struct SimulatedRigFlight {
  RigFlightSimulationOptions options;
  calib::Rig nominal, truth;
  std::vector<Exposure> exposures_truth, exposures_file;
  std::vector<GroundPoint> points_truth, points_file;
  std::vector<ImageObservation> observations;   // head pixels, `head` set
  std::vector<RigExposureTruth> rig_exposures;  // every exposure and head
  /// Stitching tie id -> the standard position it was placed around ("" for dense / check ties).
  std::map<std::string, std::string> tie_position;
};

/// The true head pixel of an object point in one exposure; false when it lies behind the head.
bool ProjectRigHead(const calib::RigHead& head,
                    const Exposure& exposure,
                    const RigExposureTruth& increment,
                    const Eigen::Vector3d& point_m,
                    Eigen::Vector2d* pixel);

SimulatedRigFlight SimulateRigFlight(const RigFlightSimulationOptions& options);

/// The rig with every format (heads and virtual image) x `scale` (rounded, >= 16 px) and every
/// pixel size / scale (the principal distances and the fields of view stay). ConfigError unless
/// 0 < scale <= 1.
calib::Rig ScaleRigFormats(const calib::Rig& rig, double scale);

/// Image mode (header comment).
struct RigImageOptions {
  std::string texture_path;    // the photograph (any format ReadGrayImage reads), required
  double texture_gsd_m = 0.0;  // ground size of a texel (2 x 2 photo pixels); 0: half the
                               // virtual image's nadir GSD at the flying height, >= 0
  double grey_noise_dn = 1.0;  // Gaussian noise added to every rendered grey value (DN), >= 0
  std::uint64_t seed = 1;
  bool point_sampling = false;  // true: one texture sample at each pixel centre (the renderer
                                // before area integration; kept for the comparison in
                                // tests/stitch/rig_stitched_image_test.cc)
  void Validate() const;        // ConfigError naming the option
};

/// The photograph laid on the ground under the flight (centred on the mean exposure centre) with
/// the options' texel size.
TexturedGround MakeRigGroundTexture(const SimulatedRigFlight& flight,
                                    const RigImageOptions& options);

/// The image of head `head` in exposure `exposure` (indices into the flight) through its true
/// pose and interior, grey values of `ground` plus the options' noise (seeded by options.seed,
/// exposure and head). Error when a pixel's ray does not point down.
stitch::GrayImage RenderRigHeadImage(const SimulatedRigFlight& flight,
                                     const TexturedGround& ground,
                                     const RigImageOptions& options,
                                     int exposure,
                                     int head);

/// The file of one head image under a folder: `images/<image>_<head>.tif` (8 bit).
std::string RigHeadImagePath(const std::string& folder,
                             const std::string& image,
                             const std::string& head);

/// Renders and writes every head image of every exposure (RigHeadImagePath, 8 bit, rounded and
/// clamped); returns the texel size used (m).
double WriteRigHeadImages(const SimulatedRigFlight& flight,
                          const RigImageOptions& options,
                          const std::string& folder);

/// Writes rig_nominal.yaml, rig_truth.yaml (FORMATS.md "Multi-head rig"), exposures.csv,
/// observations.csv (`image,head,point,col,row,sigma_px`), points.csv, project.yaml and
/// truth/exposures.csv, truth/points.csv, truth/rig_exposures.csv
/// (`image,head,domega,dphi,dkappa,dT_ms`, degrees and ms). Every file is written atomically.
void WriteSimulatedRigFlight(const SimulatedRigFlight& flight, const std::string& folder);

}  // namespace aerocal::triangulation
