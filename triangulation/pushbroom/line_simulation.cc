#include "triangulation/pushbroom/line_simulation.h"

#include "calib/camera/line_camera_io.h"
#include "calib/camera/rotation.h"
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"
#include "calib/core/error.h"
#include "calib/residuals/line_collinearity.h"
#include "triangulation/pushbroom/line_rectification.h"
#include "triangulation/sensor/line_scan_camera.h"

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <random>
#include <sstream>

namespace aerocal::triangulation {
namespace {

constexpr double kDeg = M_PI / 180.0;
using Vector6d = Eigen::Matrix<double, 6, 1>;

}  // namespace

double SimulatedTerrainHeight(const LineSimulationOptions& o, double x_m, double y_m) {
  return 0.5 * o.relief_m * std::sin(x_m / 170.0 + 0.3) * std::cos(y_m / 230.0 - 0.2);
}

void LineSimulationOptions::Validate() const {
  auto require = [](bool ok, const std::string& message) {
    if (!ok) throw ConfigError(message);
  };
  require(detectors_per_camera >= 10 && detectors_per_camera <= 100000,
          "--detectors must be within 10 .. 100000 per camera");
  require(tilt_deg >= 0 && tilt_deg <= 40, "--tilt-deg must be within 0 .. 40");
  require(pitch_mm > 0 && pitch_mm <= 1, "--pitch-mm must be within (0, 1]");
  require(overlap >= 0 && overlap < 0.5, "--overlap must be within 0 .. 0.5");
  // pos.csv and its truth hold two records of ~140 bytes a line: 1e6 lines is ~0.3 GB.
  require(lines >= 20 && lines <= 1000000, "--lines must be within 20 .. 1e6");
  require(height_m > 0 && speed_m_s > 0 && relief_m >= 0, "--height-m, speed > 0, --relief-m >= 0");
  require(relief_m < 0.5 * height_m, "--relief-m must be below half the flying height");
  require(control_points >= 0, "--control must be >= 0");
  require(image_noise_px >= 0 && image_sigma_px > 0, "--image-noise-px >= 0, --image-sigma-px > 0");
  require(control_noise_m >= 0 && control_sigma_m > 0,
          "--control-noise-m >= 0, --control-sigma-m > 0");
  require(pos_error_m >= 0 && pos_error_deg >= 0, "--pos-error-m and --pos-error-deg must be >= 0");
  require(node_spacing_lines >= 1, "--node-spacing must be >= 1");
  require(detector_error_px >= 0, "--detector-error-px must be >= 0");
  require(subcamera_error_px >= 0, "--subcamera-error-px must be >= 0");
  require(std::abs(time_offset_s) <= 1.0, "--time-offset-s must be within -1 .. 1 s");
  require(pos_bias_m >= 0 && pos_bias_deg >= 0 && pos_drift_m >= 0 && pos_drift_deg >= 0,
          "--pos-bias-m, --pos-bias-deg, --pos-drift-m and --pos-drift-deg must be >= 0");
}

namespace {

// The simulation's random numbers, one generator and one distribution each, shared by the steps
// in their order (the same seed gives the same files).
struct SimulationRandom {
  explicit SimulationRandom(std::uint64_t seed) : rng(seed) {}
  std::mt19937_64 rng;
  std::normal_distribution<double> normal{0.0, 1.0};
  std::uniform_real_distribution<double> uniform{0.0, 1.0};
};

// The nominal camera: three sub-cameras, c so that each covers tilt (1 + overlap) across.
calib::LineCamera NominalLineCamera(const LineSimulationOptions& o, double half_field_rad) {
  const int n = o.detectors_per_camera;
  const double c = 0.5 * n * o.pitch_mm / std::tan(half_field_rad);
  std::vector<calib::LineSubcamera> subs(3);
  const char* ids[] = {"L", "N", "R"};
  for (int k = 0; k < 3; ++k) {
    subs[k].id = ids[k];
    subs[k].last = n - 1;
    subs[k].c_mm = c;
    subs[k].pitch_mm = o.pitch_mm;
    // Look angle (k - 1) tilt towards +x: a rotation about y by minus that angle.
    subs[k].mount_rad = Eigen::Vector3d(0, -(k - 1) * o.tilt_deg * kDeg, 0);
  }
  calib::LineCamera cam = calib::CombineLineCameras("pushbroom-sim", subs, c, o.pitch_mm);
  if (o.linear_layout) {
    // One straight virtual CCD; the sub-cameras are its polynomial ranges.
    cam.subcameras.clear();
    for (int k = 0; k < 3; ++k) cam.calibration.push_back({k * n, k * n + n - 1, {}, {}});
  }
  cam.mount_rad = Eigen::Vector3d(0.1, -0.05, 0.2) * kDeg;  // a known boresight
  cam.lever_arm_m = Eigen::Vector3d(0.2, 0.1, -0.3);
  return cam;
}

// Smooth per-detector errors: a cubic in u per sub-camera and axis.
std::vector<calib::LinePolynomial> TruthPolynomials(const LineSimulationOptions& o,
                                                    int reference_subcamera,
                                                    SimulationRandom* random) {
  auto& [rng, normal, uniform] = *random;
  const int n = o.detectors_per_camera;
  const double amp = o.detector_error_px * o.pitch_mm;
  const double sub_amp = o.subcamera_error_px * o.pitch_mm;
  std::vector<calib::LinePolynomial> truth_polynomials;
  for (int k = 0; k < 3; ++k) {
    calib::LinePolynomial p;
    p.first = k * n;
    p.last = k * n + n - 1;
    const bool reference = k == reference_subcamera && sub_amp == 0;
    for (auto* axis : {&p.dx, &p.dy}) {
      *axis = {reference ? 0.0 : amp * normal(rng),
               reference ? 0.0 : amp * normal(rng),
               0.5 * amp * normal(rng),
               0.5 * amp * normal(rng)};
      // The reference's errors satisfy the calibration's datum (zero Legendre mean and slope,
      // LineDatumResidual): a_0 = -a_2 / 3, a_1 = -3 a_3 / 5.
      if (reference) {
        double mean = 0, slope = 0;
        LegendreMeanAndSlope(axis->data(), int(axis->size()), &mean, &slope);
        (*axis)[0] -= mean;
        (*axis)[1] -= slope;
      }
    }
    if (sub_amp > 0) {
      p.dx[0] += sub_amp * normal(rng);  // offset across
      p.dy[0] += sub_amp * normal(rng);  // offset along
      p.dx[1] += sub_amp * normal(rng);  // scale
      p.dy[1] += sub_amp * normal(rng);  // rotation in the focal plane
      p.dy[2] += sub_amp * normal(rng);  // curvature of the line
    }
    truth_polynomials.push_back(p);
  }
  return truth_polynomials;
}

// The true poses (sim->pos_truth) and the error-free POS rows (returned) of every line: along +Y,
// kappa 0 (the line along X, across track).
std::vector<PosRecord> SimulateTrajectory(const LineSimulationOptions& o,
                                          double spacing_m,
                                          double dt,
                                          SimulationRandom* random,
                                          LineSimulation* sim) {
  auto& [rng, normal, uniform] = *random;
  const double ph[6] = {uniform(rng) * 6.28,
                        uniform(rng) * 6.28,
                        uniform(rng) * 6.28,
                        uniform(rng) * 6.28,
                        uniform(rng) * 6.28,
                        uniform(rng) * 6.28};
  const double a = o.attitude_variation_deg * kDeg, q = o.position_variation_m;
  // The body's trajectory at a (fractional) line index.
  auto trajectory = [&](double l, PosRecord* r) {
    const double s = l / double(o.lines);  // 0 .. 1 along the strip
    r->center_m = {q * std::sin(2 * M_PI * 1.3 * s + ph[0]),
                   l * spacing_m + 0.3 * q * std::sin(2 * M_PI * 0.7 * s + ph[1]),
                   o.height_m + q * std::sin(2 * M_PI * 0.9 * s + ph[2])};
    r->opk_rad = {a * std::sin(2 * M_PI * 2.1 * s + ph[3]),
                  a * std::sin(2 * M_PI * 1.7 * s + ph[4]),
                  0.5 * a * std::sin(2 * M_PI * 1.1 * s + ph[5])};
  };
  // A time offset: line l is exposed at its time stamp plus time_offset_s, so its true pose is
  // the trajectory there, while the POS row of line l is the trajectory at the stamp.
  std::vector<PosRecord> pos_rows;
  for (int l = 0; l < o.lines; ++l) {
    PosRecord r;
    r.line = l;
    r.source_line = l + 2;
    r.time_s = 1000.0 + l * dt;
    trajectory(l + o.time_offset_s / dt, &r);
    sim->pos_truth.push_back(r);
    trajectory(l, &r);
    pos_rows.push_back(r);
  }
  return pos_rows;
}

// POS error: a cubic B-spline with random node values, plus bias and drift.
std::vector<Vector6d> PosErrorNodes(const LineSimulationOptions& o, SimulationRandom* random) {
  auto& [rng, normal, uniform] = *random;
  const int nodes = calib::SplineNodeCount(o.lines - 1, o.node_spacing_lines);
  std::vector<Vector6d> error_nodes(nodes);
  for (auto& e : error_nodes)
    for (int k = 0; k < 6; ++k)
      e[k] = (k < 3 ? o.pos_error_m : o.pos_error_deg * kDeg) * normal(rng);
  // Bias and drift: constant and linear in the line index, which the cubic B-spline holds exactly
  // (node j is centred on line (j - 1) spacing).
  if (o.pos_bias_m > 0 || o.pos_bias_deg > 0 || o.pos_drift_m > 0 || o.pos_drift_deg > 0) {
    Vector6d bias, drift;
    for (int k = 0; k < 6; ++k) {
      bias[k] = (k < 3 ? o.pos_bias_m : o.pos_bias_deg * kDeg) * normal(rng);
      drift[k] = (k < 3 ? o.pos_drift_m : o.pos_drift_deg * kDeg) * normal(rng);
    }
    for (int j = 0; j < nodes; ++j)
      error_nodes[j] += bias + drift * ((j - 1) * double(o.node_spacing_lines) / (o.lines - 1));
  }
  return error_nodes;
}

// The POS (rows plus the spline's error, with sigmas) and the corrections that undo the error.
void AddPosErrors(const LineSimulationOptions& o,
                  const std::vector<PosRecord>& pos_rows,
                  const std::vector<Vector6d>& error_nodes,
                  LineSimulation* sim) {
  const int nodes = int(error_nodes.size());
  for (int l = 0; l < o.lines; ++l) {
    const calib::SplineSpan span = calib::CubicBSplineWeights(l, o.node_spacing_lines);
    const int j = std::min(span.first_node, nodes - 4);
    Vector6d e = Vector6d::Zero();
    for (int m = 0; m < 4; ++m) e += span.weights[m] * error_nodes[j + m];
    PosRecord r = pos_rows[l];
    r.center_m += e.head<3>();
    r.opk_rad += e.tail<3>();
    if (o.pos_error_m > 0) r.center_sigma_m = Eigen::Vector3d::Constant(o.pos_error_m);
    if (o.pos_error_deg > 0) r.opk_sigma_rad = Eigen::Vector3d::Constant(o.pos_error_deg * kDeg);
    if (!r.center_sigma_m || !r.opk_sigma_rad) r.center_sigma_m.reset(), r.opk_sigma_rad.reset();
    sim->pos.push_back(r);
    sim->true_corrections.push_back(-e);
  }
}

// The noisy observations of `ground` by the sub-cameras that see it (near line t0).
std::vector<LineObservation> ObserveControlPoint(const LineSimulationOptions& o,
                                                 const LineSimulation& sim,
                                                 const PosTrajectory& truth,
                                                 const Eigen::Vector3d& ground,
                                                 double t0,
                                                 SimulationRandom* random) {
  auto& [rng, normal, uniform] = *random;
  const int n = o.detectors_per_camera;
  std::vector<LineObservation> seen;
  for (int s = 0; s < 3; ++s) {
    double i = 0, t = 0;
    const int first = s * n, last = s * n + n - 1;
    if (!SubcameraPixelOfPoint(sim.truth, truth, s, t0, ground, &i, &t)) continue;
    if (!(i >= first - 0.5 && i <= last + 0.5)) continue;
    if (!(t >= 1 && t <= o.lines - 2)) continue;
    LineObservation obs;
    obs.detector = i + o.image_noise_px * normal(rng);
    obs.line = t + o.image_noise_px * normal(rng);
    obs.sigma_px = o.image_sigma_px;
    // A measurement lies on one of its sub-camera's detectors (a column of the line image
    // belongs to one sub-camera): a point that noise carries past the sub-camera's edge would
    // be read as the neighbour's detector, so it is not measured (and, at the outer edges,
    // beyond the line).
    const long column = std::lround(obs.detector);
    if (!(obs.detector >= -0.5 && column >= first && column <= last)) continue;
    seen.push_back(obs);
  }
  return seen;
}

// Terrain and cloud control points in the swath, each with its observations.
void PlaceControlPoints(const LineSimulationOptions& o,
                        double spacing_m,
                        double half_field_rad,
                        SimulationRandom* random,
                        LineSimulation* sim) {
  auto& [rng, normal, uniform] = *random;
  const PosTrajectory truth = PosTrajectory::FromRecords(sim->pos_truth, "pos_truth.csv");
  const double length = o.lines * spacing_m;
  const double half_swath = o.height_m * std::tan(1.5 * o.tilt_deg * kDeg + half_field_rad * 0.3);
  auto terrain = [&](double x, double y) { return SimulatedTerrainHeight(o, x, y); };
  int placed = 0;
  for (int attempt = 0; placed < o.control_points && attempt < 20 * o.control_points + 100;
       ++attempt) {
    const double y = (0.02 + 0.96 * uniform(rng)) * length;
    const double x = (2 * uniform(rng) - 1) * half_swath;
    const Eigen::Vector3d ground(x, y, terrain(x, y));
    std::vector<LineObservation> seen =
        ObserveControlPoint(o, *sim, truth, ground, y / spacing_m, random);
    if (seen.empty()) continue;
    GroundPoint g;
    g.id = "c" + std::to_string(placed + 1);
    g.role = PointRole::kControl;
    g.sigma_m = Eigen::Vector3d::Constant(o.control_sigma_m);
    g.xyz_m = ground;
    sim->points_truth.push_back(g);
    g.xyz_m = ground + o.control_noise_m * Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
    sim->points.push_back(g);
    for (auto& obs : seen) {
      obs.point = g.id;
      obs.source_line = int(sim->observations.size()) + 2;
      sim->observations.push_back(obs);
    }
    ++placed;
  }
}

}  // namespace

LineSimulation SimulateLineFlight(const LineSimulationOptions& o) {
  o.Validate();
  SimulationRandom random(o.seed);
  LineSimulation sim;
  const double half_field_rad = std::max(0.5 * o.tilt_deg * (1 + o.overlap), 5.0) * kDeg;
  calib::LineCamera cam = NominalLineCamera(o, half_field_rad);
  const double c = cam.c_mm;
  sim.nominal = cam;
  sim.nominal.name = "pushbroom-sim nominal";
  sim.reference_subcamera = 1;
  cam.calibration = TruthPolynomials(o, sim.reference_subcamera, &random);
  sim.truth = cam;
  sim.truth.name = "pushbroom-sim truth";

  const double spacing_m = o.pitch_mm / c * o.height_m;  // along-track ground spacing of a line
  const double dt = spacing_m / o.speed_m_s;
  const std::vector<PosRecord> pos_rows = SimulateTrajectory(o, spacing_m, dt, &random, &sim);
  AddPosErrors(o, pos_rows, PosErrorNodes(o, &random), &sim);
  PlaceControlPoints(o, spacing_m, half_field_rad, &random, &sim);
  return sim;
}

void WriteLineSimulation(const LineSimulation& sim, const std::string& folder) {
  std::filesystem::create_directories(folder);
  auto path = [&](const std::string& name) {
    return (std::filesystem::path(folder) / name).string();
  };
  calib::WriteLineCamera(path("camera_nominal.yaml"), sim.nominal);
  calib::WriteLineCamera(path("camera_truth.yaml"), sim.truth);
  WritePos(path("pos.csv"), sim.pos);
  WritePos(path("pos_truth.csv"), sim.pos_truth);
  WriteLineObservations(path("observations.csv"), sim.observations);
  for (int truth = 0; truth < 2; ++truth) {
    std::ostringstream out;
    out << "point,X,Y,Z,sX,sY,sZ,role\n";
    for (const auto& g : truth ? sim.points_truth : sim.points)
      out << g.id << "," << FormatNumber(g.xyz_m->x(), 17) << "," << FormatNumber(g.xyz_m->y(), 17)
          << "," << FormatNumber(g.xyz_m->z(), 17) << "," << FormatNumber(g.sigma_m.x()) << ","
          << FormatNumber(g.sigma_m.y()) << "," << FormatNumber(g.sigma_m.z()) << ",control\n";
    WriteFileAtomically(path(truth ? "points_truth.csv" : "points.csv"), out.str());
  }
  {
    std::ostringstream out;
    out << "i,subcamera,dx_mm,dy_mm\n";
    for (int i = 0; i < sim.truth.detectors; ++i) {
      const Eigen::Vector2d d = sim.truth.Correction(i);
      const int k = sim.truth.SubcameraOf(i);
      out << i << ","
          << (sim.truth.subcameras.empty() ? std::to_string(k) : sim.truth.subcameras[k].id) << ","
          << FormatNumber(d.x(), 17) << "," << FormatNumber(d.y(), 17) << "\n";
    }
    WriteFileAtomically(path("truth_detectors.csv"), out.str());
  }
  {
    std::ostringstream out;
    out << "line,dX,dY,dZ,domega,dphi,dkappa\n";
    for (size_t l = 0; l < sim.true_corrections.size(); ++l) {
      out << l;
      for (int a = 0; a < 6; ++a)
        out << "," << FormatNumber(sim.true_corrections[l][a] * (a < 3 ? 1.0 : 180.0 / M_PI), 17);
      out << "\n";
    }
    WriteFileAtomically(path("truth_trajectory.csv"), out.str());
  }
}

}  // namespace aerocal::triangulation
