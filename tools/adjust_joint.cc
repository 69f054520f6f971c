#include "tools/adjust_joint.h"

#include "calib/camera/camera_io.h"
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"
#include "calib/core/error.h"
#include "calib/core/result_file.h"
#include "tools/command_registry.h"
#include "tools/option_ranges.h"
#include "triangulation/block/block_io.h"
#include "triangulation/georef/object_frame.h"
#include "triangulation/joint/joint_adjustment.h"

#include <cstdio>
#include <filesystem>
#include <optional>

namespace aerocal::tools {

std::string CameraOutputPath(const std::string& out, const std::string& id, bool several) {
  if (!several) return out;
  const std::filesystem::path p(out);
  return (p.parent_path() / (p.stem().string() + "_" + id + p.extension().string())).string();
}

int FinishAdjust(const triangulation::AdjustmentResult& result,
                 nlohmann::json json,
                 const std::string& out,
                 const std::string& write_camera,
                 const std::string& camera_kind,
                 const std::function<void()>& write_cameras) {
  WriteResult(out, "adjust", std::move(json));  // no copy: the document is most of the peak
  const bool ok = result.valid;
  for (const auto& reason : result.invalid_reasons)
    std::fprintf(stderr, "adjust: not valid: %s\n", reason.c_str());
  if (!write_camera.empty()) {
    if (ok)
      write_cameras();
    else
      std::fprintf(stderr, "%s not written: the result is not valid\n", camera_kind.c_str());
  }
  std::printf("result -> %s\n", out.c_str());
  return ok ? kExitOk : kExitNotConverged;
}

void AddJointAdjustOptions(CLI::App& app, JointAdjustArgs* args) {
  CLI::Option* joint = app.add_option(
      "--joint-stitching",
      args->stitching,
      "Joint stitching + triangulation adjustment of a project measured in raw sub-image pixels: "
      "per-flight (one mapping per sub-image) or per-exposure");
  app.add_option("--joint-model",
                 args->model,
                 "Mapping model of the joint adjustment: translation | conformal | affine | "
                 "projective | auto "
                 "(the model the stitching F test chooses for the flight, as `aerocal stitch "
                 "--model auto`)")
      ->needs(joint);
  app.add_option("--base",
                 args->base,
                 "Joint adjustment: comma-separated sub-images keeping the camera file's mapping "
                 "(the focal "
                 "plane's datum; default: the camera's reference points)")
      ->needs(joint);
  app.add_option("--stitch-sigma-px",
                 args->stitch_sigma_px,
                 "Joint adjustment: stitching sigma where the stitching file has none, px")
      ->check(PositiveUpTo(100))
      ->needs(joint);
}

int RunJointAdjust(const JointAdjustArgs& joint,
                   const triangulation::AdjustOptions& options,
                   const triangulation::Project& input,
                   const std::string& project_path,
                   const std::string& out,
                   const std::string& write_camera) {
  triangulation::JointOptions joint_options;
  joint_options.adjust = options;
  joint_options.scope = triangulation::ParseMappingScope(joint.stitching);
  joint_options.base_ids = SplitCommaList(joint.base);
  joint_options.stitch_sigma_px = joint.stitch_sigma_px;
  const std::optional<calib::MappingModel> forced = triangulation::ParseJointModel(joint.model);
  if (options.robust_start)
    throw ConfigError(
        "--robust-start is not available with --joint-stitching (start from a plain adjustment)");

  if (!input.rigs.empty())
    throw ConfigError(
        "--joint-stitching: " + project_path + ": camera '" + input.rigs.begin()->first +
        "' is a rig: the joint adjustment estimates the sub-image mappings of a frame "
        "camera, a rig's heads have none (adjust the rig without --joint-stitching)");
  const triangulation::ObjectFrame frame(input.frame);
  triangulation::Project project = triangulation::ToAdjustmentFrame(input, frame);
  joint_options.Validate(project);
  if (!forced && project.stitching_file.empty())
    throw ConfigError(
        project_path +
        ": --joint-model auto needs the project's stitching measurements (stitching:) to choose "
        "the model; name them or give the model");

  // The flight's stitching: the model (F test per exposure, the flight's choice) and the starting
  // mappings (its flight means).
  if (!project.stitching_file.empty()) {
    stitch::BatchOptions batch;
    batch.model = forced;
    batch.stitch.base_ids = joint_options.base_ids;
    batch.stitch.data_snooping = options.data_snooping;
    const stitch::BatchResult stitching =
        triangulation::StitchExposures(project, batch, joint_options.stitch_sigma_px, nullptr);
    for (auto& [id, camera] : project.cameras)
      if (!camera.subimages.empty())
        camera = triangulation::JointMappingsFromStitching(
            camera, &stitching, batch, forced, &joint_options);
  } else {
    triangulation::JointMappingsFromStitching(calib::Camera{}, nullptr, {}, forced, &joint_options);
  }

  triangulation::JointResult result = triangulation::AdjustJoint(project, joint_options);
  triangulation::ToInputFrame(frame, &result.adjustment);
  std::printf("%s%s",
              triangulation::FormatSummary(result.adjustment).c_str(),
              triangulation::FormatJointSummary(result).c_str());
  nlohmann::json json = triangulation::JointResultToJson(result);
  json["project"] = project_path;
  AddProjectFacts(input, &json);
  // As the plain adjustment: exit 3 and no camera when the result is not valid.
  return FinishAdjust(result.adjustment, std::move(json), out, write_camera, "camera", [&] {
    const auto& cameras = result.adjustment.cameras;
    for (const auto& estimate : cameras) {
      const std::string path = CameraOutputPath(write_camera, estimate.id, cameras.size() > 1);
      calib::WriteCamera(
          path,
          triangulation::JointUpdatedCamera(input.cameras.at(estimate.id), estimate.id, result));
      std::printf("camera %s -> %s%s\n",
                  estimate.id.c_str(),
                  path.c_str(),
                  joint_options.scope == triangulation::MappingScope::kPerExposure
                      ? " (interior; the per-exposure mappings are in the result only)"
                      : "");
    }
  });
}

}  // namespace aerocal::tools
