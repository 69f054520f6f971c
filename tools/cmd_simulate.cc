// aerocal simulate: writes the deterministic example flight (triangulation/simulation).
#include "calib/core/atomic_file.h"
#include "calib/core/error.h"
#include "stitch/rig/rig_design.h"
#include "tools/command_registry.h"
#include "tools/option_ranges.h"
#include "triangulation/pushbroom/line_images.h"
#include "triangulation/pushbroom/line_simulation.h"
#include "triangulation/simulation/flight_edge_targets.h"
#include "triangulation/simulation/flight_simulator.h"
#include "triangulation/simulation/rig_flight_simulator.h"
#include "triangulation/simulation/test_field_simulator.h"

#include <cmath>
#include <cstdio>
#include <set>
#include <sstream>

namespace aerocal::tools {
namespace {

struct SimulateArgs {
  std::string out;
  std::string layout = "3x2";
  std::string nominal_mapping = "affine";
  triangulation::FlightSimulationOptions options;
  std::uint64_t seed = 1;
  std::string rig;
  double increment_arcsec = 0.0, time_offset_ms = 0.0, speed_mps = 0.0, format_scale = 1.0;
  std::vector<double> lever_arm_m, boresight_deg;  // planted platform (frame flight)
  double gnss_time_offset_ms = 0.0;
  bool pushbroom = false;
  triangulation::LineSimulationOptions line;
  bool pushbroom_images = false;
  std::string reference_size = "2000x1500";
  triangulation::LineImageOptions line_images;
  bool test_field = false;
  triangulation::TestFieldOptions field;
  bool edge_targets = false;  // frame flight: resolution targets and their image patches
  triangulation::FlightEdgeTargetOptions edge;
};

// `simulate --test-field`: the calibration test field (triangulation/simulation/
// test_field_simulator.h); the flight options that mean the same here are taken when given.
int RunTestFieldSimulation(const CLI::App& app, SimulateArgs& args) {
  auto& t = args.field;
  t.seed = args.seed;
  const auto given = [&](const char* name) { return app.count(name) > 0; };
  if (given("--survey-sigma-m")) t.survey_sigma_m = args.options.survey_sigma_m;
  if (given("--image-noise-px")) t.image_noise_px = args.options.image_noise_px;
  if (given("--image-sigma-px")) t.image_sigma_px = args.options.image_sigma_px;
  // Every other option (flight, rig, pushbroom) is refused by name, never silently ignored.
  const std::set<std::string> field_options = {"--out",
                                               "--seed",
                                               "--test-field",
                                               "--planar",
                                               "--groups",
                                               "--images-per-group",
                                               "--distance-m",
                                               "--survey-sigma-m",
                                               "--image-noise-px",
                                               "--image-sigma-px",
                                               "--help"};
  for (const CLI::Option* option : app.get_options())
    if (option->count() > 0 && !field_options.count(option->get_name()))
      throw ConfigError(option->get_name() + " does not apply to --test-field");
  const auto field = triangulation::SimulateTestField(t);
  triangulation::WriteSimulatedTestField(field, args.out);
  std::printf(
      "simulated a %s test field: %zu targets, %zu images in %d groups, %zu image "
      "observations -> %s\n",
      t.planar ? "planar" : "3-D",
      field.points_truth.size(),
      field.exposures_truth.size(),
      t.groups,
      field.observations.size(),
      args.out.c_str());
  return kExitOk;
}

using FlightIntOption = std::pair<std::string, int triangulation::FlightSimulationOptions::*>;
using FlightDoubleOption = std::pair<std::string, double triangulation::FlightSimulationOptions::*>;

// `simulate --rig NAME`: the rig flight, with the flight options the user gave over the rig's
// defaults; the frame camera's options are refused by name.
int RunRigSimulation(const CLI::App& app,
                     const SimulateArgs& args,
                     const std::vector<FlightIntOption>& int_options,
                     const std::vector<FlightDoubleOption>& double_options) {
  const auto preset = triangulation::ParseRigPreset(args.rig);
  if (!preset) throw ConfigError("--rig must be dual-lens or uav4 (got '" + args.rig + "')");
  for (const char* frame_only :
       {"--layout", "--nominal-mapping", "--ccd-shear", "--stitch-noise-px", "--stitch-ties"})
    if (app.get_option(frame_only)->count() > 0)
      throw ConfigError(std::string(frame_only) + " applies to the frame camera, not to --rig");
  triangulation::RigFlightSimulationOptions options;
  if (*preset == triangulation::RigPreset::kUav4)
    options = triangulation::RigFlightSimulationOptions::DefaultUav4();
  options.preset = *preset;
  for (const auto& [name, member] : int_options)
    if (app.get_option(name)->count() > 0) options.flight.*member = args.options.*member;
  for (const auto& [name, member] : double_options)
    if (app.get_option(name)->count() > 0) options.flight.*member = args.options.*member;
  options.flight.seed = args.seed;
  if (options.flight.control_points > options.flight.ground_points)
    throw ConfigError("--control (" + std::to_string(options.flight.control_points) +
                      ") must not exceed --surveyed-points (" +
                      std::to_string(options.flight.ground_points) + ")");
  const auto given = [&](const char* name) { return app.get_option(name)->count() > 0; };
  if (*preset != triangulation::RigPreset::kUav4 || given("--head-increment-arcsec"))
    options.increment_sigma_rad = args.increment_arcsec * M_PI / (180.0 * 3600.0);
  if (*preset != triangulation::RigPreset::kUav4 || given("--head-time-offset-ms")) {
    options.time_offset_s = args.time_offset_ms * 1e-3;
    options.head_time_offsets_s.clear();
  }
  if (*preset != triangulation::RigPreset::kUav4 || given("--speed-mps"))
    options.speed_mps = args.speed_mps;
  if (*preset == triangulation::RigPreset::kUav4) {
    // The stitching ties around the standard positions of the rig's design (stitch/rig).
    const stitch::RigDesign design = stitch::DesignRig(
        triangulation::ScaleRigFormats(triangulation::MakeNominalRig(*preset), args.format_scale),
        options.flight.flying_height_m,
        200);
    for (const auto& s : design.standard_positions)
      options.stitch_ties.standard_positions.push_back({s.name, s.virtual_px});
    options.stitch_ties.jitter_px *= args.format_scale;  // the same ground radius
  }
  if (options.time_offset_s != 0.0 && options.speed_mps == 0.0)
    std::fprintf(stderr, "warning: --head-time-offset-ms without --speed-mps moves no head\n");
  options.format_scale = args.format_scale;
  for (const char* pushbroom_only : {"--reference-size", "--reference-overlap"})
    if (app.get_option(pushbroom_only)->count() > 0)
      throw ConfigError(std::string(pushbroom_only) +
                        " applies to --pushbroom --render-images only");
  triangulation::RigImageOptions image_options;
  image_options.texture_path = args.line_images.texture_path;
  image_options.texture_gsd_m = args.line_images.texture_gsd_m;
  image_options.grey_noise_dn = args.line_images.grey_noise_dn;
  image_options.seed = args.seed;
  if (args.pushbroom_images) image_options.Validate();
  const auto flight = triangulation::SimulateRigFlight(options);
  // The photograph is read before anything is written: a bad one leaves no partial output.
  if (args.pushbroom_images) triangulation::MakeRigGroundTexture(flight, image_options);
  triangulation::WriteSimulatedRigFlight(flight, args.out);
  if (args.pushbroom_images) {
    const double gsd = triangulation::WriteRigHeadImages(flight, image_options, args.out);
    std::printf("rendered %zu head images (texture %.3f m per texel) -> %s/images\n",
                flight.exposures_truth.size() * flight.truth.heads.size(),
                gsd,
                args.out.c_str());
  }
  std::printf(
      "simulated rig %s: %zu exposures x %zu heads, %zu ground points, %zu head "
      "observations -> %s\n",
      flight.nominal.name.c_str(),
      flight.exposures_truth.size(),
      flight.nominal.heads.size(),
      flight.points_truth.size(),
      flight.observations.size(),
      args.out.c_str());
  return kExitOk;
}

// `simulate --edge-targets`: the flight's resolution targets and their patches in OUT/edge_targets
// (triangulation/simulation/flight_edge_targets.h).
void WriteEdgeTargets(const triangulation::SimulatedFlight& flight,
                      triangulation::FlightEdgeTargetOptions options,
                      std::uint64_t seed,
                      const std::string& out) {
  options.seed = seed;
  const auto edges = triangulation::LayOutEdgeTargets(flight, options);
  const auto patches = triangulation::RenderEdgeTargetPatches(flight, edges, options);
  triangulation::WriteEdgeTargetPatches(patches, edges, options, out + "/edge_targets");
  std::printf(
      "rendered %zu edge target patches of %zu edges (PSF sigma %.2f px) -> %s/edge_targets\n",
      patches.size(),
      edges.size(),
      options.psf_sigma_px,
      out.c_str());
}

// `simulate --help` grouped by mode (issue 33 item 4): the options each mode adds, under its
// name; the flight options (the default mode) are shared by the others where they say so.
void GroupOptionsByMode(CLI::App& app) {
  const std::vector<std::pair<std::string, std::set<std::string>>> groups = {
      {"Output", {"--out", "--seed"}},
      {"Multi-head rig flight (--rig)",
       {"--rig", "--head-increment-arcsec", "--head-time-offset-ms", "--format-scale"}},
      {"Calibration test field (--test-field)",
       {"--test-field", "--planar", "--groups", "--images-per-group", "--distance-m"}},
      {"Pushbroom line camera (--pushbroom)",
       {"--pushbroom",
        "--detectors",
        "--lines",
        "--tilt-deg",
        "--pos-error-m",
        "--pos-error-deg",
        "--detector-error-px",
        "--subcamera-error-px",
        "--linear-layout",
        "--pos-bias-m",
        "--pos-bias-deg",
        "--pos-drift-m",
        "--pos-drift-deg",
        "--time-offset-s",
        "--node-spacing",
        "--control-noise-m"}},
      {"Rendered images (--render-images, with --rig or --pushbroom)",
       {"--render-images",
        "--texture",
        "--texture-gsd-m",
        "--reference-size",
        "--reference-overlap",
        "--grey-noise-dn"}}};
  for (CLI::Option* option : app.get_options()) {
    if (option->get_name() == "--help") continue;
    std::string group =
        "Frame-camera flight (the default; --rig, --pushbroom and --test-field take "
        "those they name)";
    for (const auto& [name, members] : groups)
      if (members.count(option->get_name())) group = name;
    option->group(group);
  }
}

// The frame-camera flight: block, points, noise, sigmas, the multi-CCD layout.
void AddFlightOptions(CLI::App& app, SimulateArgs* args) {
  auto& o = args->options;
  app.add_option("--out", args->out, "Output folder (created; files replaced atomically)")
      ->required();
  app.add_option("--seed", args->seed, "Random seed (the same seed gives the same files)")
      ->check(SeedCheck());
  app.add_option(
         "--exposures", o.exposures, "Number of exposures (spread over the strips), 2..20000")
      ->check(FiniteRange(2, 20000));
  app.add_option("--strips", o.strips, "Number of east-west strips, 1..1000")
      ->check(FiniteRange(1, 1000));
  app.add_option(
         "--height-m", o.flying_height_m, "Flying height above the mean terrain, 1..100000 m")
      ->check(FiniteRange(1.0, 1e5));
  app.add_option("--forward-overlap", o.forward_overlap, "Forward overlap, 0..1")
      ->check(FiniteRange(0.0, 0.95));
  app.add_option("--side-overlap", o.side_overlap, "Side overlap, 0..1")
      ->check(FiniteRange(0.0, 0.95));
  app.add_option("--relief-m", o.terrain_relief_m, "Terrain relief (peak to peak), 0..10000 m")
      ->check(FiniteRange(0.0, 1e4));
  app.add_option("--surveyed-points",
                 o.ground_points,
                 "Surveyed ground points (control + check), 0..100000")
      ->check(FiniteRange(0, 100000));
  app.add_option(
         "--control", o.control_points, "Control points among them (corners and centre first)")
      ->check(FiniteRange(0, 100000));
  app.add_option("--tie-points", o.tie_points, "Unsurveyed tie points, 0..1000000")
      ->check(FiniteRange(0, 1000000));
  app.add_option(
         "--image-noise-px", o.image_noise_px, "Image measurement noise (sigma), 0..1000 px")
      ->check(FiniteRange(0.0, 1e3));
  app.add_option("--image-sigma-px",
                 o.image_sigma_px,
                 "A-priori image sigma written to the files, (0, 1000] px")
      ->check(PositiveUpTo(1e3));
  app.add_option("--stitch-noise-px",
                 o.stitching.noise_px,
                 "Stitching tie-point matching noise, 0..1000 px")
      ->check(FiniteRange(0.0, 1e3));
  app.add_option(
         "--stitch-ties", o.stitching.ties_per_frame, "Stitching tie points per exposure, 0..10000")
      ->check(FiniteRange(0, 10000));
  app.add_option("--survey-sigma-m",
                 o.survey_sigma_m,
                 "Noise and sigma of control/check coordinates, (0, 1000] m")
      ->check(PositiveUpTo(1e3));
  app.add_option("--gnss-sigma-m",
                 o.gnss_sigma_m,
                 "GNSS camera-centre sigma, 0..1000 m (0: no GNSS, approximate centres)")
      ->check(FiniteRange(0.0, 1e3));
  app.add_option("--imu-sigma-deg", o.imu_sigma_deg, "IMU attitude sigma, 0..90 deg (0: no IMU)")
      ->check(FiniteRange(0.0, 90.0));
  app.add_option("--start-offset-m",
                 o.start_position_error_m,
                 "Error of approximate centres without GNSS, 0..100000 m")
      ->check(FiniteRange(0.0, 1e5));
  app.add_option("--start-offset-deg",
                 o.start_angle_error_deg,
                 "Error of approximate angles without IMU, 0..180 deg")
      ->check(FiniteRange(0.0, 180.0));
  app.add_option("--layout",
                 args->layout,
                 "Sub-image grid ROWSxCOLS of the camera, 1..10 each (default 3x2: six CCDs)");
  app.add_option(
      "--nominal-mapping",
      args->nominal_mapping,
      "Mapping model of the nominal camera's sub-images: translation (a maker's design: nominal "
      "offsets only) | conformal | affine | projective; the truth keeps a richer model where its "
      "misplacements need one");
  app.add_option("--ccd-shear",
                 o.misplacement.shear,
                 "Affine part of the true CCD misplacements (x-scale minus y-scale and skew, each "
                 "+-this), 0..0.1")
      ->check(FiniteRange(0.0, 0.1));
}

// The options a frame-camera flight refuses (they apply to --rig only).
struct RigOptions {
  CLI::Option *increment = nullptr, *time_offset = nullptr, *format_scale = nullptr;
};

// --rig and its options.
RigOptions AddRigOptions(CLI::App& app, SimulateArgs* args) {
  app.add_option(
      "--rig",
      args->rig,
      "Simulate a multi-head rig flight instead: dual-lens (configs/rig_dual_lens.yaml; "
      "flight defaults 1200 m, 30 exposures, 100 m relief, 40 surveyed and 300 tie "
      "points) | uav4 (configs/rig_uav4.yaml; one line of 8 exposures at 300 m over 30 m "
      "relief, 10 m/s, increments 0.025 deg, shutter offsets ~3 ms, stitching ties at "
      "the 12 standard positions, dense and check ties per exposure); the flight "
      "options above override the defaults");
  RigOptions rig;
  rig.increment = app.add_option("--head-increment-arcsec",
                                 args->increment_arcsec,
                                 "--rig: sigma of the per-exposure attitude increments E_k of the "
                                 "non-reference heads, 0..3600 arcsec")
                      ->check(FiniteRange(0.0, 3600.0));
  rig.time_offset = app.add_option("--head-time-offset-ms",
                                   args->time_offset_ms,
                                   "--rig: exposure time offset dT_k of the non-reference heads, "
                                   "-1000..1000 ms (with --speed-mps)")
                        ->check(FiniteRange(-1000.0, 1000.0));
  rig.format_scale = app.add_option("--format-scale",
                                    args->format_scale,
                                    "--rig: every format (heads, virtual image) x this, pixel "
                                    "sizes / this: the same geometry in "
                                    "fewer pixels (small rendered images), (0, 1]")
                         ->check(FiniteRange(0, 1, true));
  return rig;
}

// The platform: speed, GNSS lever arm, IMU boresight, GNSS time offset.
void AddPlatformOptions(CLI::App& app, SimulateArgs* args) {
  app.add_option("--speed-mps",
                 args->speed_mps,
                 "Platform speed along the strips, 0..1000 m/s (> 0: exposures.csv carries vX, vY, "
                 "vZ)")
      ->check(FiniteRange(0.0, 1000.0));
  app.add_option("--lever-arm-m",
                 args->lever_arm_m,
                 "GNSS lever arm a planted in the GNSS centres (X0 + R a), camera frame, m, "
                 "\"X,Y,Z\" (with --gnss-sigma-m)")
      ->check(FiniteRange(-1000, 1000))
      ->delimiter(',')
      ->expected(3);
  app.add_option("--boresight-deg",
                 args->boresight_deg,
                 "Boresight misalignment M planted in the IMU angles (R M^T), omega,phi,kappa deg "
                 "(with --imu-sigma-deg)")
      ->check(FiniteRange(-360, 360))
      ->delimiter(',')
      ->expected(3);
  app.add_option("--gnss-time-offset-ms",
                 args->gnss_time_offset_ms,
                 "GNSS time offset dt planted in the GNSS centres (+ v dt), -10000..10000 ms (with "
                 "--gnss-sigma-m and --speed-mps)")
      ->check(FiniteRange(-1e4, 1e4));
}

// --edge-targets and its patches' PSF and noise.
void AddEdgeTargetOptions(CLI::App& app, SimulateArgs* args) {
  auto* edge_targets = app.add_flag(
      "--edge-targets",
      args->edge_targets,
      "Also lay out square edge targets (both directions) on the ground and write "
      "OUT/edge_targets/: raw sub-image patches of every exposure that sees an edge, rendered "
      "through the true camera and a Gaussian PSF, and the virtual image's patches resampled "
      "from them (bilinear), as mosaics for `aerocal quality mtf` with patches.csv");
  app.add_option("--psf-sigma-px",
                 args->edge.psf_sigma_px,
                 "--edge-targets: sigma of the Gaussian PSF of the raw sub-images, 0.3..3 px")
      ->needs(edge_targets)
      ->check(FiniteRange(0.3, 3.0));
  app.add_option("--edge-noise-dn",
                 args->edge.noise_dn,
                 "--edge-targets: Gaussian noise of the patches' pixels (16-bit, a 32000 DN step), "
                 "0..2000 DN")
      ->needs(edge_targets)
      ->check(FiniteRange(0.0, 2000.0));
}

// --test-field: a camera-calibration test field instead of a flight.
void AddTestFieldOptions(CLI::App& app, SimulateArgs* args) {
  app.add_flag(
      "--test-field",
      args->test_field,
      "A camera-calibration test field instead of a flight: targets on a facade with depth "
      "layers, convergent images in groups (calibrate --observations --points --groups)");
  app.add_flag("--planar", args->field.planar, "Test field: all targets on one plane");
  app.add_option("--groups", args->field.groups, "Test field: image groups, 1..26")
      ->check(FiniteRange(1, 26));
  app.add_option("--images-per-group",
                 args->field.images_per_group,
                 "Test field: images per group, 4..1000")
      ->check(FiniteRange(4, 1000));
  app.add_option(
         "--distance-m", args->field.distance_m, "Test field: camera distance from the wall, m")
      ->check(FiniteRange(1.0, 1000.0));
}

// Line camera (pushbroom) flight: its own options; the shared flight options apply when given.
void AddLineOptions(CLI::App& app, SimulateArgs* args) {
  auto& l = args->line;
  app.add_flag(
      "--pushbroom",
      args->pushbroom,
      "Simulate a combined line camera (three tilted line cameras) instead: camera files, "
      "pos.csv, observations, control points and truth (triangulation/pushbroom/README.md)");
  app.add_option(
         "--detectors", l.detectors_per_camera, "Pushbroom: detectors per line camera, 10..100000")
      ->check(FiniteRange(10, 100000));
  app.add_option("--lines",
                 l.lines,
                 "Pushbroom: scan lines, 20..1000000 (with --render-images: lines x 3 x detectors "
                 "at most 5e7 px)")
      ->check(FiniteRange(20, 1000000));
  app.add_option("--tilt-deg",
                 l.tilt_deg,
                 "Pushbroom: look angle of the outer cameras across track, 0..40 deg")
      ->check(FiniteRange(0.0, 40.0));
  app.add_option("--pos-error-m",
                 l.pos_error_m,
                 "Pushbroom: sigma of the smooth POS position error, 0..100 m")
      ->check(FiniteRange(0.0, 100.0));
  app.add_option("--pos-error-deg",
                 l.pos_error_deg,
                 "Pushbroom: sigma of the smooth POS attitude error, 0..10 deg")
      ->check(FiniteRange(0.0, 10.0));
  app.add_option("--detector-error-px",
                 l.detector_error_px,
                 "Pushbroom: size of the smooth per-detector errors, 0..100 px")
      ->check(FiniteRange(0.0, 100.0));
  app.add_option("--subcamera-error-px",
                 l.subcamera_error_px,
                 "Pushbroom: sigma of every sub-camera's own offset, scale, rotation and curvature "
                 "errors (the reference's too), 0..100 px")
      ->check(FiniteRange(0.0, 100.0));
  app.add_flag("--linear-layout",
               l.linear_layout,
               "Pushbroom: the sub-cameras stitched onto one straight virtual CCD (the camera "
               "file's calibration ranges, no subcameras section)");
  app.add_option("--pos-bias-m",
                 l.pos_bias_m,
                 "Pushbroom: sigma of a constant POS position error, 0..100 m")
      ->check(FiniteRange(0.0, 100.0));
  app.add_option("--pos-bias-deg",
                 l.pos_bias_deg,
                 "Pushbroom: sigma of a constant POS attitude error, 0..10 deg")
      ->check(FiniteRange(0.0, 10.0));
  app.add_option("--pos-drift-m",
                 l.pos_drift_m,
                 "Pushbroom: sigma of a linear POS position drift (at the end), 0..100 m")
      ->check(FiniteRange(0.0, 100.0));
  app.add_option("--pos-drift-deg",
                 l.pos_drift_deg,
                 "Pushbroom: sigma of a linear POS attitude drift (at the end), 0..10 deg")
      ->check(FiniteRange(0.0, 10.0));
  app.add_option("--time-offset-s",
                 l.time_offset_s,
                 "Pushbroom: shutter / POS latency, s: each line exposed this long after its "
                 "pos.csv time stamp, -1..1")
      ->check(FiniteRange(-1.0, 1.0));
  app.add_option("--node-spacing",
                 l.node_spacing_lines,
                 "Pushbroom: node spacing of the POS error spline, lines")
      ->check(FiniteRange(1, 1000000));
  app.add_option("--control-noise-m",
                 l.control_noise_m,
                 "Pushbroom: control-point coordinate noise, 0..1000 m")
      ->check(FiniteRange(0.0, 1e3));
}

// --render-images (--pushbroom or --rig) and its texture, reference frames and noise.
void AddLineImageOptions(CLI::App& app, SimulateArgs* args) {
  auto* images = app.add_flag(
      "--render-images",
      args->pushbroom_images,
      "Pushbroom: also render the line image and a reference frame strip of a scene "
      "textured with --texture (image mode of `pushbroom control`); --rig: render every "
      "head image of every exposure (images/<image>_<head>.tif)");
  app.add_option("--texture",
                 args->line_images.texture_path,
                 "--render-images: the photograph laid on the terrain as its texture")
      ->needs(images);
  app.add_option("--texture-gsd-m",
                 args->line_images.texture_gsd_m,
                 "--render-images: ground size of a texel (2 x 2 photo pixels), m; 0: automatic")
      ->needs(images)
      ->check(FiniteRange(0.0, 100.0));
  app.add_option("--reference-size",
                 args->reference_size,
                 "Pushbroom --render-images: reference frame format WIDTHxHEIGHT px")
      ->needs(images);
  app.add_option("--reference-overlap",
                 args->line_images.forward_overlap,
                 "Pushbroom --render-images: forward overlap of the reference strip, 0.5..0.9")
      ->needs(images)
      ->check(FiniteRange(0.5, 0.9));
  app.add_option("--grey-noise-dn",
                 args->line_images.grey_noise_dn,
                 "--render-images: Gaussian grey-value noise of the rendered images, DN")
      ->needs(images)
      ->check(FiniteRange(0.0, 100.0));
}

// `simulate --pushbroom`: the line camera flight (the shared flight options where given), its
// rendered images with --render-images.
int RunLineSimulation(const CLI::App& app, SimulateArgs& args, const CLI::Option* format_scale) {
  if (!args.rig.empty()) throw ConfigError("--pushbroom and --rig: choose one");
  if (format_scale->count() > 0) throw ConfigError("--format-scale applies to --rig only");
  auto& l = args.line;
  l.seed = args.seed;
  auto given = [&](const char* name) { return app.count(name) > 0; };
  if (given("--height-m")) l.height_m = args.options.flying_height_m;
  if (given("--relief-m")) l.relief_m = args.options.terrain_relief_m;
  if (given("--image-noise-px")) l.image_noise_px = args.options.image_noise_px;
  if (given("--image-sigma-px")) l.image_sigma_px = args.options.image_sigma_px;
  if (given("--survey-sigma-m")) {
    l.control_sigma_m = args.options.survey_sigma_m;
    if (!given("--control-noise-m")) l.control_noise_m = args.options.survey_sigma_m;
  }
  if (given("--control")) l.control_points = args.options.control_points;
  if (args.pushbroom_images && !given("--relief-m")) l.relief_m = 20.0;
  auto& io = args.line_images;
  if (args.pushbroom_images) {
    io.seed = args.seed;
    char x = 0;
    std::istringstream in(args.reference_size);
    std::string rest;
    if (!(in >> io.reference_width_px >> x >> io.reference_height_px) || x != 'x' || (in >> rest))
      throw ConfigError("--reference-size must be WIDTHxHEIGHT (got '" + args.reference_size +
                        "')");
    io.Validate();
    // The line image is rendered through two double grids of lines x all detectors: the
    // product is bounded before anything is allocated.
    const double pixels = double(l.lines) * 3 * l.detectors_per_camera;
    if (pixels > triangulation::kMaxLineImagePixels)
      throw ConfigError("--lines x --detectors: a line image of " + std::to_string(l.lines) +
                        " lines x 3 x " + std::to_string(l.detectors_per_camera) +
                        " detectors is " + FormatNumber(pixels) +
                        " px, more than the 5e7 px --render-images renders");
  }
  const auto sim = triangulation::SimulateLineFlight(l);
  if (args.pushbroom_images) {
    // Rendered before anything is written: a bad photograph leaves no partial output.
    const auto rendered = triangulation::RenderLineImages(sim, l, io);
    triangulation::WriteLineSimulation(sim, args.out);
    triangulation::WriteLineImages(rendered, args.out);
    std::printf(
        "rendered a line image of %d x %zu px and %zu reference frames of %d x %d px "
        "(texture %.3f m per texel, mean terrain height %.2f m)\n",
        sim.truth.detectors,
        sim.pos.size(),
        rendered.reference_images.size(),
        io.reference_width_px,
        io.reference_height_px,
        rendered.texture_gsd_m,
        rendered.mean_height_m);
  } else {
    triangulation::WriteLineSimulation(sim, args.out);
  }
  std::printf(
      "simulated a line camera of %d detectors (3 x %d), %d lines, %zu control points, "
      "%zu observations -> %s\n",
      sim.truth.detectors,
      l.detectors_per_camera,
      l.lines,
      sim.points.size(),
      sim.observations.size(),
      args.out.c_str());
  return kExitOk;
}

// `simulate` of a frame-camera flight (multi-CCD layout, platform, edge targets).
int RunFrameFlightSimulation(SimulateArgs& args) {
  auto& o = args.options;
  o.seed = args.seed;
  o.speed_mps = args.speed_mps;
  if (!args.lever_arm_m.empty()) {
    if (o.gnss_sigma_m <= 0) throw ConfigError("--lever-arm-m needs --gnss-sigma-m > 0");
    for (double v : args.lever_arm_m)
      if (!(std::abs(v) <= 1000.0)) throw ConfigError("--lever-arm-m must be within +-1000 m");
    o.lever_arm_m = Eigen::Vector3d(args.lever_arm_m[0], args.lever_arm_m[1], args.lever_arm_m[2]);
  }
  if (!args.boresight_deg.empty()) {
    if (o.imu_sigma_deg <= 0) throw ConfigError("--boresight-deg needs --imu-sigma-deg > 0");
    for (double v : args.boresight_deg)
      if (!(std::abs(v) <= 180.0)) throw ConfigError("--boresight-deg must be within +-180 deg");
    o.boresight_rad =
        Eigen::Vector3d(args.boresight_deg[0], args.boresight_deg[1], args.boresight_deg[2]) *
        (M_PI / 180.0);
  }
  o.gnss_time_offset_s = args.gnss_time_offset_ms * 1e-3;
  if (o.gnss_time_offset_s != 0.0 && (o.gnss_sigma_m <= 0 || o.speed_mps <= 0))
    throw ConfigError("--gnss-time-offset-ms needs --gnss-sigma-m > 0 and --speed-mps > 0");
  int rows = 0, cols = 0;
  char x = 0;
  std::istringstream in(args.layout);
  std::string rest;
  if (!(in >> rows >> x >> cols) || x != 'x' || (in >> rest) || rows < 1 || cols < 1 || rows > 10 ||
      cols > 10 || rows * cols < 2)
    throw ConfigError(
        "--layout must be ROWSxCOLS, 1..10 each, with at least two sub-images (got '" +
        args.layout + "')");
  if (rows != o.layout.rows || cols != o.layout.cols) {
    o.layout.rows = rows;
    o.layout.cols = cols;
    // Base CCDs: the one or two sub-images at the centre of the grid.
    o.layout.base_ids.clear();
    const int r = (rows - 1) / 2;
    for (int c = (cols - 1) / 2; c <= cols / 2; ++c)
      o.layout.base_ids.push_back(stitch::RomanNumeral(r * cols + c + 1));
  }
  const auto nominal_mapping = calib::ParseMappingModel(args.nominal_mapping);
  if (!nominal_mapping)
    throw ConfigError(
        "--nominal-mapping must be translation, conformal, affine or projective (got '" +
        args.nominal_mapping + "')");
  o.layout.model = *nominal_mapping;
  if (o.control_points > o.ground_points)
    throw ConfigError("--control (" + std::to_string(o.control_points) +
                      ") must not exceed --surveyed-points (" + std::to_string(o.ground_points) +
                      "): control points are among the surveyed points");
  const auto flight = triangulation::SimulateFlight(o);
  triangulation::WriteSimulatedFlight(flight, args.out);
  if (args.edge_targets) WriteEdgeTargets(flight, args.edge, args.seed, args.out);
  // Points are placed only where enough images see them: say when fewer than asked fit.
  int control = 0, check = 0, tie = 0;
  for (const auto& p : flight.points_truth)
    (p.role == triangulation::PointRole::kControl ? control
     : p.role == triangulation::PointRole::kCheck ? check
                                                  : tie)++;
  const int asked_check = o.ground_points - o.control_points;
  if (control < o.control_points || check < asked_check || tie < o.tie_points)
    std::fprintf(stderr,
                 "warning: placed %d of %d control, %d of %d check and %d of %d tie points (the "
                 "others found no place seen by enough images)\n",
                 control,
                 o.control_points,
                 check,
                 asked_check,
                 tie,
                 o.tie_points);
  std::printf(
      "simulated %zu exposures, %zu ground points, %zu image observations, %zu stitching "
      "measurements -> %s\n",
      flight.exposures_truth.size(),
      flight.points_truth.size(),
      flight.observations.size(),
      flight.stitching.size(),
      args.out.c_str());
  return kExitOk;
}

CommandRun SetupSimulate(CLI::App& app) {
  auto args = std::make_shared<SimulateArgs>();
  AddFlightOptions(app, args.get());
  const RigOptions rig = AddRigOptions(app, args.get());
  AddPlatformOptions(app, args.get());
  AddEdgeTargetOptions(app, args.get());
  AddTestFieldOptions(app, args.get());
  AddLineOptions(app, args.get());
  AddLineImageOptions(app, args.get());
  CLI::Option *increment = rig.increment, *time_offset = rig.time_offset,
              *format_scale = rig.format_scale;
  // Flight options a rig flight takes over when given (the rig's defaults otherwise).
  using Flight = triangulation::FlightSimulationOptions;
  const std::vector<std::pair<std::string, int Flight::*>> int_options = {
      {"--exposures", &Flight::exposures},
      {"--strips", &Flight::strips},
      {"--surveyed-points", &Flight::ground_points},
      {"--control", &Flight::control_points},
      {"--tie-points", &Flight::tie_points}};
  const std::vector<std::pair<std::string, double Flight::*>> double_options = {
      {"--height-m", &Flight::flying_height_m},
      {"--forward-overlap", &Flight::forward_overlap},
      {"--side-overlap", &Flight::side_overlap},
      {"--relief-m", &Flight::terrain_relief_m},
      {"--image-noise-px", &Flight::image_noise_px},
      {"--image-sigma-px", &Flight::image_sigma_px},
      {"--survey-sigma-m", &Flight::survey_sigma_m},
      {"--gnss-sigma-m", &Flight::gnss_sigma_m},
      {"--imu-sigma-deg", &Flight::imu_sigma_deg},
      {"--start-offset-m", &Flight::start_position_error_m},
      {"--start-offset-deg", &Flight::start_angle_error_deg}};
  GroupOptionsByMode(app);
  return [args, &app, int_options, double_options, increment, time_offset, format_scale]() {
    CheckOutputFolder(args->out, "--out");
    if (args->edge_targets && (args->test_field || args->pushbroom || !args->rig.empty()))
      throw ConfigError("--edge-targets applies to a frame-camera flight only");
    if (args->test_field) return RunTestFieldSimulation(app, *args);
    for (const char* field_only : {"--planar", "--groups", "--images-per-group", "--distance-m"})
      if (app.count(field_only) > 0)
        throw ConfigError(std::string(field_only) + " applies to --test-field only");
    if (args->pushbroom_images && !args->pushbroom && args->rig.empty())
      throw ConfigError("--render-images applies to --pushbroom or --rig only");
    if (args->pushbroom) return RunLineSimulation(app, *args, format_scale);
    if (!args->rig.empty()) return RunRigSimulation(app, *args, int_options, double_options);
    for (const CLI::Option* rig_only : {increment, time_offset, format_scale})
      if (rig_only->count() > 0)
        throw ConfigError(rig_only->get_name() + " applies to a rig flight (--rig) only");
    return RunFrameFlightSimulation(*args);
  };
}

}  // namespace

AEROCAL_REGISTER_COMMAND(
    simulate,
    "simulate",
    "Write a simulated flight of a multi-CCD camera (FORMATS.md files + truth)",
    SetupSimulate);

}  // namespace aerocal::tools
