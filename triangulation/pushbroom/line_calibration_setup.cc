// Set-up of a line-camera calibration (line_calibration_run.h): the sensor kind and its blocks,
// the control points, the image observations and what they cover, the held polynomial entries.
#include "calib/core/csv.h"
#include "calib/core/error.h"
#include "calib/residuals/prior.h"
#include "triangulation/pushbroom/line_calibration_run.h"

#include <algorithm>

namespace aerocal::triangulation::internal {
namespace {

using calib::BlockId;
using calib::kLineMaxTerms;

// The sub-camera carrying the datum: the option, -1 the middle one; ConfigError beyond the last.
int ReferenceSubcamera(const LineCalibrationOptions& options, int n_sub) {
  const int reference = options.reference_subcamera >= 0 ? options.reference_subcamera : n_sub / 2;
  if (reference >= n_sub)
    throw ConfigError("--reference must be a sub-camera index within 0 .. " +
                      std::to_string(n_sub - 1));
  return reference;
}

// The kind's options from the calibration's: the POS sigmas from pos.csv where it gives them.
LineScanOptions KindOptions(const LineCalibrationOptions& options, const PosTrajectory& pos) {
  LineScanOptions line_options;
  line_options.node_spacing_lines = options.node_spacing_lines;
  line_options.free_c = options.free_c;
  line_options.pos_prior = options.pos_prior;
  line_options.pos_sigma_center_m =
      pos.MedianCenterSigma().value_or(Eigen::Vector3d::Constant(options.pos_sigma_m));
  line_options.pos_sigma_opk_rad = pos.MedianOpkSigma().value_or(
      Eigen::Vector3d::Constant(options.pos_sigma_deg * M_PI / 180.0));
  line_options.boresight = options.boresight;
  line_options.boresight_sigma_rad = options.boresight_sigma_rad;
  line_options.lever_arm = options.lever_arm;
  line_options.lever_arm_sigma_m = options.lever_arm_sigma_m;
  line_options.time_offset = options.time_offset;
  return line_options;
}

Project StripProject(const std::string& observations_file) {
  Project strip;
  strip.observations_file = observations_file;
  return strip;
}

}  // namespace

LineRun::LineRun(const calib::LineCamera& camera_in,
                 const PosTrajectory& pos_in,
                 const LineCalibrationOptions& options_in,
                 const std::string& observations_file_in)
    : camera(camera_in),
      pos(pos_in),
      options(options_in),
      observations_file(observations_file_in),
      ranges(camera_in.Ranges()),
      n_sub(int(ranges.size())),
      reference(ReferenceSubcamera(options_in, n_sub)),
      first_line(pos_in.first_line()),
      last_line(pos_in.last_line()),
      spacing(options_in.node_spacing_lines),
      n_nodes(calib::SplineNodeCount(last_line - first_line, spacing)),
      start_degree(options_in.degree.value_or(options_in.max_degree)),
      strip(StripProject(observations_file_in)),
      dense_index(strip),
      sensor(camera_in, pos_in, KindOptions(options_in, pos_in)),
      context{strip, adjust_options, builder, dense_index, no_poses, no_frame},
      fixed_entries(n_sub),
      datum_entries(n_sub) {
  for (int s = 0; s < n_sub; ++s)
    sub_ids.push_back(camera.subcameras.empty() ? std::to_string(s) : camera.subcameras[s].id);
}

std::map<std::string, BlockId> AddControlPoints(LineRun& run,
                                                const std::vector<GroundPoint>& points) {
  std::vector<const GroundPoint*> control;
  for (const auto& g : points)
    if (g.role == PointRole::kControl && g.xyz_m) control.push_back(&g);
  run.point_values.resize(control.size());  // sized once: the blocks point into it
  for (size_t k = 0; k < control.size(); ++k) run.point_values[k] = *control[k]->xyz_m;
  std::map<std::string, BlockId> blocks;
  for (size_t k = 0; k < control.size(); ++k) {
    const BlockId block = run.builder.AddBlock("point_" + control[k]->id,
                                               run.point_values[k].data(),
                                               3,
                                               calib::BlockKind::kGroundPoint,
                                               {"X", "Y", "Z"});
    blocks[control[k]->id] = block;  // a repeated id: its last point
    const Eigen::Vector3d& v = *control[k]->xyz_m;
    const Eigen::Vector3d& s = control[k]->sigma_m;
    run.builder.AddResidual(
        calib::kGroupControl,
        calib::PriorCostFunction::Create({v.x(), v.y(), v.z()}, {s.x(), s.y(), s.z()}),
        {block},
        "control " + control[k]->id);
  }
  run.result.n_control = int(control.size());
  return blocks;
}

LineCoverage AddImageObservations(LineRun& run,
                                  const std::vector<LineObservation>& observations,
                                  const std::map<std::string, BlockId>& control) {
  LineCoverage coverage{std::vector<int>(run.n_nodes, 0), std::vector<int>(run.n_nodes, 0)};
  auto& b = run.builder;
  for (const auto& o : observations) {
    const auto it = control.find(o.point);
    if (it == control.end()) {
      ++run.result.n_ignored;
      continue;
    }
    ImageObservation observation;
    observation.image = kLineStripImage;
    observation.point = o.point;
    observation.pixel = Eigen::Vector2d(o.detector, o.line);
    observation.sigma_px = o.sigma_px;
    observation.line = o.source_line;
    ObservationTerm term = run.sensor.Observe(run.context, observation, it->second);
    const int j = run.sensor.Terms().back().segment;
    ++coverage.per_segment[j];
    for (int m = 0; m < 4; ++m) ++coverage.per_node[j + m];
    const auto id =
        b.AddResidual(term.group, std::move(term.cost), term.blocks, "point " + o.point);
    run.image_residuals.push_back(id);
    // The start must be a valid geometry (the point in front of the camera).
    if (b.EvaluateResidual(id).empty())
      ThrowInputError({run.observations_file, o.source_line},
                      "point " + o.point + " lies behind the camera at line " +
                          FormatNumber(o.line) + " with the POS and the file's camera");
  }
  run.result.n_observations = int(run.image_residuals.size());
  if (run.image_residuals.empty())
    throw InputError(run.observations_file + ": no observation of a control point (" +
                     std::to_string(run.result.n_ignored) +
                     " observations of other points ignored)");
  return coverage;
}

// Too few points per line: per spline segment; a node no observation reaches is undetermined
// without the POS prior (it is then fixed at 0 and the result is not valid).
void CheckCoverage(LineRun& run, const LineCoverage& coverage) {
  const int minimum = run.options.min_observations_per_segment;
  for (int j = 0; j + 3 < run.n_nodes; ++j) {
    const double a = run.first_line + j * run.spacing;
    const double z = std::min(run.last_line, a + run.spacing - 1);
    if (a > run.last_line) break;
    if (coverage.per_segment[j] < minimum)
      run.result.warnings.push_back({"few_points_per_line",
                                     "lines " + FormatNumber(a) + " .. " + FormatNumber(z),
                                     double(coverage.per_segment[j]),
                                     double(minimum),
                                     "only " + std::to_string(coverage.per_segment[j]) +
                                         " observations between two spline nodes: the per-line "
                                         "corrections there rest on the POS prior"});
  }
  for (int j = 0; j < run.n_nodes; ++j)
    if (coverage.per_node[j] == 0 && !run.options.pos_prior) {
      run.builder.FixBlock(run.sensor.NodeBlocks()[j]);
      run.result.valid = false;
      run.result.warnings.push_back(
          {"few_points_per_line",
           "node " + std::to_string(j),
           0,
           1,
           "no observation reaches spline node " + std::to_string(j) +
               " and there is no POS prior: its correction is not determined"});
    }
}

// Fixed detector entries: above the degree. The reference datum (module README "Datum"): the
// reference sub-camera's Legendre mean and slope per axis are zero (LineDatumResidual), which holds
// the same whatever degree the test leaves; its constant and linear entries follow the higher
// terms (a_0 = -a_2/3 - a_4/5, a_1 = -3 a_3/5 - 3 a_5/7) and do not enter the test.
void HoldEntriesAboveStartDegree(LineRun& run) {
  for (int s = 0; s < run.n_sub; ++s) {
    for (int k = run.start_degree + 1; k < kLineMaxTerms; ++k) {
      run.fixed_entries[s].insert(k);
      run.fixed_entries[s].insert(kLineMaxTerms + k);
    }
    if (run.options.datum == LineDatum::kReference && s == run.reference)
      run.datum_entries[s] = {0, 1, kLineMaxTerms, kLineMaxTerms + 1};
  }
}

void ApplyFixedEntries(LineRun& run) {
  for (int s = 0; s < run.n_sub; ++s)
    run.sensor.SetFixedDetectorEntries(
        run.builder, s, std::vector<int>(run.fixed_entries[s].begin(), run.fixed_entries[s].end()));
}

}  // namespace aerocal::triangulation::internal
