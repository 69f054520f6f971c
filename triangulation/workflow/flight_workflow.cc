#include "triangulation/workflow/flight_workflow.h"

#include "calib/camera/camera_io.h"
#include "calib/camera/camera_model_json.h"
#include "calib/core/error.h"
#include "calib/core/file_digest.h"
#include "calib/core/progress.h"
#include "stitch/adjustment/flight_stability.h"
#include "stitch/adjustment/frame_measurements.h"
#include "stitch/io/stitch_result_json.h"
#include "stitch/simulation/stitch_simulator.h"
#include "triangulation/adjustment/block_adjustment.h"
#include "triangulation/adjustment/conventional_reference.h"
#include "triangulation/adjustment/self_calibration_choice.h"
#include "triangulation/block/block_io.h"
#include "triangulation/georef/object_frame.h"
#include "triangulation/joint/joint_adjustment.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>

namespace aerocal::triangulation {
namespace {

namespace fs = std::filesystem;

// The project with every exposure using `camera` (a flight of one camera).
Project WithCamera(Project project, const calib::Camera& camera, const std::string& camera_file) {
  if (project.cameras.size() != 1)
    ThrowInputError({project.path, 0},
                    "the flight workflow takes a block of one camera (found " +
                        std::to_string(project.cameras.size()) + ")");
  const std::string id = project.cameras.begin()->first;
  project.cameras[id] = camera;
  project.camera_files[id] = camera_file;
  return project;
}

// Records every reason why `r` is not a valid result of `step`.
void CheckStep(const std::string& step, const AdjustmentResult& r, FlightWorkflowResult* out) {
  for (const auto& reason : r.invalid_reasons) {
    out->valid = false;
    out->failures.emplace_back(step, reason);
  }
}

std::string Line(const char* format, double a, double b, double c) {
  char buffer[256];
  std::snprintf(buffer, sizeof(buffer), format, a, b, c);
  return buffer;
}

// One terminal line per warning of an adjustment, naming it.
void AddWarnings(const std::string& name,
                 const AdjustmentResult& result,
                 FlightWorkflowResult* out) {
  for (const auto& w : result.warnings)
    out->summary.push_back("warning (" + name + "): " + w.message);
}

std::string VirtualProjectPath(const FlightWorkflowOptions& options) {
  const std::string path = (fs::path(options.data_folder) / "project.yaml").string();
  if (!fs::exists(path))
    throw InputError(options.data_folder +
                     ": no project.yaml (the block with virtual-image observations)");
  return path;
}

bool HasStitching(const Project& project, const calib::Camera& camera) {
  return !project.stitching_file.empty() && !camera.subimages.empty();
}

// Step 1 from the frames adjusted elsewhere, checked against the measurements they must come from.
stitch::BatchResult CollectStitchedFrames(const Project& project,
                                          const FlightWorkflowOptions& options,
                                          const stitch::BatchOptions& batch) {
  const ExposureMeasurements m = ReadExposureMeasurements(project, options.stitch_sigma_px);
  const std::vector<stitch::FrameRun>& runs = *options.stitched_frames;
  bool same = runs.size() == m.frames.size();
  for (size_t i = 0; same && i < runs.size(); ++i)
    same = runs[i].adjustment.frame == m.frames[i].frame;
  if (!same)
    throw InputError(project.stitching_file + ": the frames adjusted apart (" +
                     std::to_string(runs.size()) + ") are not the flight's " +
                     std::to_string(m.frames.size()) + " frames in order");
  return stitch::CollectBatch(runs, batch);
}

}  // namespace

stitch::BatchOptions FlightStitchingOptions(const FlightWorkflowOptions& options) {
  stitch::BatchOptions batch;
  batch.stitch.base_ids = options.base_ids;
  return batch;
}

FlightStitching ReadFlightStitching(const FlightWorkflowOptions& options) {
  FlightStitching out;
  out.options = FlightStitchingOptions(options);
  const calib::Camera camera = calib::ReadCamera(options.camera_file);
  const Project project =
      WithCamera(ReadProject(VirtualProjectPath(options)), camera, options.camera_file);
  if (!HasStitching(project, camera)) return out;
  ExposureMeasurements m = ReadExposureMeasurements(project, options.stitch_sigma_px);
  out.camera = std::move(m.camera);
  out.rows = std::move(m.rows);
  out.frames = std::move(m.frames);
  return out;
}

namespace {

// What the steps share: the block in the adjustment frame, how results map back, the progress.
struct FlightContext {
  const FlightWorkflowOptions& options;
  const calib::Camera& camera;
  const ObjectFrame& object_frame;
  const Project& project;  // in the adjustment frame
  Progress* progress;      // may be null
  void Stage(const char* name) const {
    if (progress) progress->Stage(name);
  }
  void Advance() const {
    if (progress) progress->Advance();
  }
};

// Geodetic blocks are adjusted in a metric frame and their results written back (georef/).
AdjustmentResult AdjustInFrame(const FlightContext& c, const AdjustOptions& o) {
  AdjustmentResult r =
      c.options.choose_free_set ? AdjustWithChosenFreeSet(c.project, o) : Adjust(c.project, o);
  ToInputFrame(c.object_frame, &r);
  return r;
}

// The document's description of the flight: camera, data, frame and the files read.
void WriteFlightHeader(const FlightContext& c, const Project& input, nlohmann::json* doc) {
  nlohmann::json& d = *doc;
  d["kind"] = "flight";
  d["camera"] = c.options.camera_file;
  d["camera_name"] = c.camera.name;
  d["camera_model"] = calib::CameraModelTableToJson(c.camera.model);
  d["data"] = c.options.data_folder;
  d["camera_format"] = {{"width_px", c.camera.width_px},
                        {"height_px", c.camera.height_px},
                        {"pixel_size_mm", c.camera.pixel_size_mm}};
  d["base_subimages"] = c.options.base_ids;
  d["frame"] = c.object_frame.Description();
  // The files read, with their checksums: a lab verifies a re-run read the same data.
  // (The joint step adds the sub-image project's files.)
  d["inputs"] = InputFilesToJson(ProjectFiles(input));
}

// 1. Stitching of every exposure, model chosen per frame by the F test, and stability.
std::optional<stitch::BatchResult> RunStitchingStep(const FlightContext& c,
                                                    const stitch::BatchOptions& batch,
                                                    FlightWorkflowResult* out) {
  if (!HasStitching(c.project, c.camera)) {
    out->summary.push_back("stitching: no stitching measurements in the project");
    return std::nullopt;
  }
  std::optional<stitch::BatchResult> stitching =
      c.options.stitched_frames
          ? CollectStitchedFrames(c.project, c.options, batch)
          : StitchExposures(c.project, batch, c.options.stitch_sigma_px, nullptr);
  nlohmann::json& doc = out->document;
  doc["stitching"] = stitch::StitchResultToJson(*stitching, batch);
  char line[256];
  std::snprintf(line,
                sizeof(line),
                "stitching: %zu exposures, sigma0 %.3f px, model %s",
                stitching->frames.size(),
                doc["stitching"].value("sigma0_px", 0.0),
                doc["stitching"].value("model", std::string("?")).c_str());
  out->summary.push_back(line);
  return stitching;
}

// The two adjustments of the virtual-image observations, and the options the joint inherits.
struct FrameAdjustments {
  AdjustOptions self_options;  // with the chosen free set
  AdjustmentResult self_calibration;
  AdjustmentResult conventional;
};

// 2. Conventional and self-calibrating triangulation on the virtual-image observations.
FrameAdjustments RunFrameAdjustments(const FlightContext& c) {
  FrameAdjustments a;
  a.self_options.free_interior = c.options.free_interior;
  a.self_options.suspect_effect_limit = c.options.suspect_effect_limit;
  a.self_calibration = AdjustInFrame(c, a.self_options);
  a.self_options.free_interior = a.self_calibration.free_interior;  // the chosen set, for the joint
  c.Advance();
  c.Stage("conventional");
  // The conventional reference: same observations (gross errors decided by the full model).
  AdjustOptions conventional_options;
  conventional_options.suspect_effect_limit = c.options.suspect_effect_limit;
  a.conventional = AdjustConventionalReference(c.project, conventional_options, a.self_calibration);
  ToInputFrame(c.object_frame, &a.conventional);
  return a;
}

// The two adjustments into the document, the validity, the camera and the terminal lines.
void RecordFrameAdjustments(FrameAdjustments* a,
                            nlohmann::json* adjustments,
                            FlightWorkflowResult* out) {
  const AdjustmentResult& conventional = a->conventional;
  AdjustmentResult& self_calibration = a->self_calibration;
  // A self-calibrated camera that makes the check points significantly worse is not a calibration
  // (self_calibration_choice.h): not written, the result not valid, with the test.
  const CheckPointComparison check_test = CompareCheckPoints(conventional, self_calibration);
  out->document["check_point_test"] = {{"tested", check_test.tested},
                                       {"n", check_test.n},
                                       {"f", check_test.f},
                                       {"f_critical", check_test.f_critical},
                                       {"alpha", check_test.alpha},
                                       {"worse", check_test.worse},
                                       {"message", check_test.message}};
  if (check_test.worse) self_calibration.Invalidate(check_test.message);
  out->summary.push_back(check_test.message);
  nlohmann::json c = AdjustmentToJson(conventional);
  c["name"] = "conventional";
  adjustments->push_back(c);
  nlohmann::json s = AdjustmentToJson(self_calibration);
  s["name"] = "self_calibration";
  adjustments->push_back(s);
  out->document["comparison"] = ComparisonToJson(conventional, self_calibration);
  out->converged = conventional.converged() && self_calibration.converged();
  CheckStep("conventional", conventional, out);
  CheckStep("self-calibration", self_calibration, out);
  out->camera_from = "self_calibration";
  out->camera_from_reason = "the self-calibrating adjustment of the virtual-image observations";
  for (const AdjustmentResult* r :
       {&conventional, static_cast<const AdjustmentResult*>(&self_calibration)}) {
    const std::string name = r == &conventional ? "conventional" : "self-calibration";
    out->summary.push_back(name + Line(": sigma0 %.3f px, check RMSE spatial %.3f m (n=%.0f)",
                                       r->sigma0_px,
                                       r->check.spatial_rmse_m,
                                       r->check.n));
    AddWarnings(name, *r, out);
  }
}

// The sub-image project's files that the virtual-image project did not name, into `inputs`.
void AddJointInputs(const Project& raw, nlohmann::json* doc) {
  for (const auto& file : InputFilesToJson(ProjectFiles(raw)))
    if (std::none_of((*doc)["inputs"].begin(),
                     (*doc)["inputs"].end(),
                     [&](const nlohmann::json& f) { return f["path"] == file["path"]; }))
      (*doc)["inputs"].push_back(file);
}

// A joint sigma0 far above the self-calibration's: its mapping model does not fit the sub-images.
void WarnOnJointSigma0(const AdjustmentResult& self_calibration, JointResult* joint) {
  const double ratio = joint->adjustment.sigma0 / self_calibration.sigma0;
  if (ratio <= kJointSigma0RatioLimit) return;
  joint->adjustment.warnings.push_back(
      {kWarningJointSigma0Ratio,
       "joint",
       ratio,
       kJointSigma0RatioLimit,
       Line("sigma0 %.3f px against %.3f px of the self-calibration (ratio %.2f): ",
            joint->adjustment.sigma0_px,
            self_calibration.sigma0_px,
            ratio) +
           "the joint's mapping model (" + joint->mapping_model + ") does not fit the sub-images"});
}

// 3. Joint stitching + triangulation on the raw sub-image observations.
void RunJointStep(const FlightContext& c,
                  const std::string& subimage_project,
                  const stitch::BatchResult* stitching,
                  const stitch::BatchOptions& batch,
                  const FrameAdjustments& frame,
                  nlohmann::json* adjustments,
                  FlightWorkflowResult* out) {
  JointOptions joint_options;
  joint_options.adjust = frame.self_options;
  joint_options.base_ids = c.options.base_ids;
  joint_options.stitch_sigma_px = c.options.stitch_sigma_px;
  // The control survey's part of the certified interior's covariance (the certificate's type-B
  // component "control coordinates", as a test field's).
  joint_options.control_cofactor = true;
  // The mapping model the flight's stitching chose (or the one given), from its flight means.
  const calib::Camera start =
      JointMappingsFromStitching(c.camera, stitching, batch, c.options.joint_model, &joint_options);
  const Project raw = ToAdjustmentFrame(
      WithCamera(ReadProject(subimage_project), start, c.options.camera_file), c.object_frame);
  AddJointInputs(raw, &out->document);
  JointResult joint = AdjustJoint(raw, joint_options);
  ToInputFrame(c.object_frame, &joint.adjustment);
  WarnOnJointSigma0(frame.self_calibration, &joint);
  nlohmann::json j = JointResultToJson(joint);
  j["name"] = "joint";
  adjustments->push_back(j);
  out->converged = out->converged && joint.adjustment.converged();
  CheckStep("joint", joint.adjustment, out);
  out->calibrated_camera = JointUpdatedCamera(c.camera, raw.cameras.begin()->first, joint);
  out->camera_from = "joint";
  out->camera_from_reason =
      "the joint stitching + triangulation adjustment (interior and the sub-image mappings "
      "refined together)";
  out->summary.push_back("joint: mappings " + joint.mapping_model + " (" +
                         joint.mapping_model_reason + ")");
  out->summary.push_back(Line("joint: sigma0 %.3f px, check RMSE spatial %.3f m (n=%.0f)",
                              joint.adjustment.sigma0_px,
                              joint.adjustment.check.spatial_rmse_m,
                              joint.adjustment.check.n));
  AddWarnings("joint", joint.adjustment, out);
}

// The adjustments, their warnings, the validity and the written camera's origin.
void FinishFlightDocument(const nlohmann::json& adjustments, FlightWorkflowResult* out) {
  nlohmann::json& doc = out->document;
  doc["adjustments"] = adjustments;
  // Every adjustment's warnings in one list, each naming its adjustment.
  doc["warnings"] = nlohmann::json::array();
  for (const auto& a : adjustments)
    for (auto w : a.value("warnings", nlohmann::json::array())) {
      w["adjustment"] = a["name"];
      doc["warnings"].push_back(w);
    }
  doc["converged"] = out->converged;
  doc["valid"] = out->valid;
  // Which adjustment the written camera comes from; null when none is written (not valid).
  doc["camera_written_from"] = out->valid ? nlohmann::json{{"adjustment", out->camera_from},
                                                           {"reason", out->camera_from_reason}}
                                          : nlohmann::json();
  doc["failures"] = nlohmann::json::array();
  for (const auto& [step, reason] : out->failures) {
    doc["failures"].push_back({{"step", step}, {"reason", reason}});
    out->summary.push_back("NOT VALID: " + step + ": " + reason);
  }
}

}  // namespace

FlightWorkflowResult RunFlightWorkflow(const FlightWorkflowOptions& options, Progress* progress) {
  FlightWorkflowResult out;
  const calib::Camera camera = calib::ReadCamera(options.camera_file);
  const std::string virtual_project = VirtualProjectPath(options);
  const std::string subimage_project =
      (fs::path(options.data_folder) / "project_subimage.yaml").string();
  const Project input = WithCamera(ReadProject(virtual_project), camera, options.camera_file);
  const ObjectFrame object_frame(input.frame);
  const Project project = ToAdjustmentFrame(input, object_frame);
  const FlightContext c{options, camera, object_frame, project, progress};
  WriteFlightHeader(c, input, &out.document);

  c.Stage("stitching");
  const stitch::BatchOptions batch = FlightStitchingOptions(options);
  const std::optional<stitch::BatchResult> stitching = RunStitchingStep(c, batch, &out);
  c.Advance();
  c.Stage("self-calibration");
  nlohmann::json adjustments = nlohmann::json::array();
  FrameAdjustments frame = RunFrameAdjustments(c);
  c.Advance();
  c.Stage("joint");
  RecordFrameAdjustments(&frame, &adjustments, &out);
  out.calibrated_camera = UpdatedCamera(camera, frame.self_calibration.cameras.at(0));
  if (options.joint && fs::exists(subimage_project) && !camera.subimages.empty())
    RunJointStep(
        c, subimage_project, stitching ? &*stitching : nullptr, batch, frame, &adjustments, &out);
  c.Advance();
  c.Stage("result");
  FinishFlightDocument(adjustments, &out);
  c.Advance();
  return out;
}

}  // namespace aerocal::triangulation
