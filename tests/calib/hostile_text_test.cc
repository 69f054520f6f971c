// Issue 37 class 5: a user's text never changes the structure of a file we write. Names and ids
// holding a line break, YAML and CSV punctuation, markup and quotes go through the camera, rig and
// line-camera writers (CameraToYaml, RigToYaml, LineCameraToYaml) and read back as the same text
// and the same number of sub-images / heads / sub-cameras. (The other tools' camera formats:
// CameraFormats.AHostileNameNeverBreaksAFile in camera_formats_test.)
#include "calib/camera/camera_io.h"
#include "calib/camera/line_camera_io.h"
#include "calib/camera/rig_io.h"
#include "calib/core/yaml_util.h"

#include <gtest/gtest.h>

#include <string>

namespace aerocal::calib {
namespace {

// A line break that starts a new YAML key and a new list item, a comment sign, a CSV comma,
// markup and both quotes; each writer must quote or escape all of it.
std::string Hostile(const std::string& tag) {
  return tag + " A&B <x> \"q\" 'p', c\nsecond: line\n- item # not a comment";
}

std::string Config(const std::string& name) {
  return std::string(AEROCAL_CONFIGS_DIR) + "/" + name;
}

TEST(HostileText, CameraNamesSubimageAndReferencePointIdsRoundTrip) {
  Camera camera = ReadCamera(Config("camera_2x3.yaml"));
  ASSERT_FALSE(camera.subimages.empty());
  ASSERT_FALSE(camera.reference_points.empty());
  camera.name = Hostile("camera");
  for (size_t i = 0; i < camera.subimages.size(); ++i) {
    const std::string id = Hostile("sub" + std::to_string(i));
    for (auto& r : camera.reference_points)
      if (r.subimage == camera.subimages[i].id) r.subimage = id;
    camera.subimages[i].id = id;
  }
  camera.reference_points[0].id = Hostile("ref");
  const Camera back = ParseCamera(LoadYamlText(CameraToYaml(camera), "back.yaml"), "back.yaml");
  EXPECT_EQ(back.name, camera.name);
  ASSERT_EQ(back.subimages.size(), camera.subimages.size());
  for (size_t i = 0; i < camera.subimages.size(); ++i)
    EXPECT_EQ(back.subimages[i].id, camera.subimages[i].id);
  ASSERT_EQ(back.reference_points.size(), camera.reference_points.size());
  EXPECT_EQ(back.reference_points[0].id, camera.reference_points[0].id);
  EXPECT_EQ(back.reference_points[0].subimage, camera.reference_points[0].subimage);
}

TEST(HostileText, RigNameAndHeadIdsRoundTrip) {
  Rig rig = ReadRig(Config("rig_dual_lens.yaml"));
  ASSERT_GE(rig.heads.size(), 2u);
  rig.name = Hostile("rig");
  for (size_t i = 0; i < rig.heads.size(); ++i) {
    const std::string id = Hostile("head" + std::to_string(i));
    if (rig.reference_head == rig.heads[i].id) rig.reference_head = id;
    rig.heads[i].id = id;
  }
  const Rig back = ParseRig(LoadYamlText(RigToYaml(rig), "back.yaml"), "back.yaml");
  EXPECT_EQ(back.name, rig.name);
  ASSERT_EQ(back.heads.size(), rig.heads.size());
  for (size_t i = 0; i < rig.heads.size(); ++i) EXPECT_EQ(back.heads[i].id, rig.heads[i].id);
  EXPECT_EQ(back.reference_head, rig.reference_head);
}

TEST(HostileText, LineCameraNameAndSubcameraIdsRoundTrip) {
  LineCamera camera = ReadLineCamera(Config("line_camera_three.yaml"));
  ASSERT_GE(camera.subcameras.size(), 2u);
  camera.name = Hostile("line");
  for (size_t i = 0; i < camera.subcameras.size(); ++i)
    camera.subcameras[i].id = Hostile("s" + std::to_string(i));
  const LineCamera back =
      ParseLineCamera(LoadYamlText(LineCameraToYaml(camera), "back.yaml"), "back.yaml");
  EXPECT_EQ(back.name, camera.name);
  ASSERT_EQ(back.subcameras.size(), camera.subcameras.size());
  for (size_t i = 0; i < camera.subcameras.size(); ++i)
    EXPECT_EQ(back.subcameras[i].id, camera.subcameras[i].id);
}

}  // namespace
}  // namespace aerocal::calib
