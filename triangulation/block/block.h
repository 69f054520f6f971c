// A block for aerial triangulation as FORMATS.md "Block" defines it: cameras, exposures
// (approximate or GNSS/IMU-measured exterior orientation), image observations (virtual-image
// pixels, or raw sub-image pixels of a multi-CCD camera) and ground points with roles control /
// check / tie. Angles are radians in memory, degrees in files (CONVENTIONS.md "Exterior
// orientation").
#pragma once

#include "calib/camera/camera.h"
#include "calib/camera/rig.h"
#include "calib/problem/mounted_block.h"

#include <Eigen/Core>

#include <map>
#include <optional>
#include <string>
#include <vector>

namespace aerocal::triangulation {

struct Exposure {
  std::string image, camera;
  Eigen::Vector3d center_m = Eigen::Vector3d::Zero();  // X0, Y0, Z0 in the object frame
  Eigen::Vector3d opk_rad = Eigen::Vector3d::Zero();   // omega, phi, kappa
  std::optional<Eigen::Vector3d> center_sigma_m;       // GNSS prior when present
  std::optional<Eigen::Vector3d> opk_sigma_rad;        // IMU prior when present
  std::optional<Eigen::Vector3d> velocity_mps;         // platform velocity (rig blocks: vX,vY,vZ)
  std::optional<double> z_ref_m;  // rig blocks: height Z of the rectification plane (z_ref)
  int line = 0;                   // source line in exposures.csv
};

enum class PointRole { kControl, kCheck, kTie };
std::string PointRoleName(PointRole role);

struct GroundPoint {
  std::string id;
  std::optional<Eigen::Vector3d> xyz_m;  // surveyed (control/check) or approximate (tie);
                                         // a check point without it is a check tie (rig stitch)
  Eigen::Vector3d sigma_m = Eigen::Vector3d::Constant(0.05);  // survey sigma, control/check
  PointRole role = PointRole::kTie;
  int line = 0;
};

struct ImageObservation {
  std::string image, point;
  std::string subimage;  // empty: virtual-image pixel (col, row); else raw (u, v)
  std::string head;      // rig head id (observations.csv `head` column); empty: no rig
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();
  double sigma_px = 0.5;
  int line = 0;
};

/// The object frame of the project (FORMATS.md `frame:`). kCrs: the files' coordinates are in a
/// CRS PROJ reads (triangulation/georef/crs.h); the adjustment runs in the local tangent plane
/// about `origin` (lat_deg, lon_deg, h_m on the datum of `crs`) or, without one, about the block
/// centre. The legacy kinds keep their meaning (triangulation/README.md "Frames").
struct FrameSpec {
  enum class Kind { kProjected, kLocal, kUtm, kGeodeticToLocal, kCrs };
  Kind kind = Kind::kProjected;
  std::string description = "as given";
  double lat_deg = 0, lon_deg = 0, h_m = 0;  // local tangent plane origin
  std::string utm_zone;                      // e.g. "48N"
  std::string source;                        // "project.yaml:LINE" of `frame:`, named in errors
  // kCrs only:
  std::string crs;            // EPSG code, compound "EPSG:2056+5728", WKT or PROJ string
  std::string vertical;       // optional separate vertical CRS ("EPSG:5783")
  std::string geoid_grid;     // optional grid file: heights orthometric above it (h = H + N)
  std::string points_crs;     // optional: points.csv in another CRS than `crs`
  std::string exposures_crs;  // optional: exposures.csv in another CRS than `crs`
  bool has_origin = false;    // lat_deg, lon_deg, h_m given (`origin:`)
};

/// How a platform parameter (lever arm, boresight, GNSS time offset) enters the adjustment: the
/// one mounted-block mode (calib/problem/mounted_block.h). The pushbroom module still spells it
/// PlatformParamMode; the alias goes when it moves onto the helper.
using PlatformParamMode = calib::BlockMode;
/// The mode's name (calib::BlockModeName), for the pushbroom module's writers.
inline std::string PlatformParamModeName(PlatformParamMode mode) {
  return std::string(calib::BlockModeName(mode));
}

/// The GNSS/IMU platform of the block (triangulation/README.md "GNSS/IMU priors on the
/// platform"): the GNSS antenna records X0 + R a + v dt, the IMU records the attitude R M^T.
/// From the project YAML's `platform:` (FORMATS.md keys below) or `aerocal adjust` options.
struct PlatformSpec {
  Eigen::Vector3d lever_arm_m = Eigen::Vector3d::Zero();  // a: centre -> antenna, camera frame
  PlatformParamMode lever_arm = PlatformParamMode::kFixed;
  double lever_arm_sigma_m = 0.0;                           // > 0 when weighted, per axis
  Eigen::Vector3d boresight_rad = Eigen::Vector3d::Zero();  // M (imu_from_image) omega, phi, kappa
  PlatformParamMode boresight = PlatformParamMode::kFixed;
  double boresight_sigma_rad = 0.0;  // > 0 when weighted, per angle
  double time_offset_s = 0.0;        // dt: GNSS time - exposure time
  PlatformParamMode time_offset = PlatformParamMode::kFixed;
  double time_offset_sigma_s = 0.0;  // > 0 when weighted
  std::string source;  // "project.yaml:LINE" of `platform:` (or the options), named in errors
};

struct Project {
  std::string path;  // the project YAML, or the folder
  std::map<std::string, calib::Camera> cameras;
  std::map<std::string, std::string> camera_files;
  /// Cameras whose file has a `rig` section (FORMATS.md "Multi-head rig"), by camera id. Such a
  /// camera is also in `cameras` as its reference head (the frame camera's interior block of that
  /// id is the reference head's); its exposures are measured in head pixels (`head` column).
  std::map<std::string, calib::Rig> rigs;
  std::vector<Exposure> exposures;
  std::vector<ImageObservation> observations;
  std::vector<GroundPoint> points;
  std::string exposures_file, observations_file, points_file;
  std::string stitching_file;  // optional per-exposure stitching measurements
  FrameSpec frame;
  PlatformSpec platform;  // lever arm, boresight, GNSS time offset (all fixed at 0 by default)

  const Exposure* FindExposure(const std::string& image) const;
  const GroundPoint* FindPoint(const std::string& id) const;
};

}  // namespace aerocal::triangulation
