#include "calib/camera/camera_io.h"

#include "calib/core/atomic_file.h"
#include "calib/core/error.h"
#include "tests/support/test_support.h"

#include <gtest/gtest.h>

#include <fstream>

namespace aerocal::calib {
namespace {

Camera ExampleCamera() {
  Camera c;
  c.name = "DMZ-1";
  c.pixel_size_mm = 0.009;
  c.width_px = 14000;
  c.height_px = 12000;
  c.interior = {170.038, -0.1757, 0.3930, 3e-8, -2e-12, 1e-16, 2e-7, -1.5e-7, 1e-5, -8e-6};
  c.interior_sigma[BrownFraser10Model::kC] = 0.01;
  c.interior_sigma[BrownFraser10Model::kK1] = 1e-9;
  c.subimages.push_back(
      {"I", 7100, 4134, MappingModel::kAffine, {1.0001, 2e-5, 0.5, -1e-5, 0.9999, 3.25}});
  c.subimages.push_back({"II", 7100, 4134, MappingModel::kConformal, {1.0, 1e-5, 6900.0, -0.5}});
  c.subimages.push_back(
      {"III", 7100, 4134, MappingModel::kProjective, {1, 0, 1, 0, 1, 7933, 1e-9, -2e-9}});
  c.subimages.push_back({"IV", 7100, 4134, MappingModel::kTranslation, {6900, 7933}});
  c.reference_points.push_back({"A", "I", 12.0, 8.0, 12.5, 11.25, 0.05});
  return c;
}

void WriteText(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

TEST(CameraIo, WriteThenReadGivesTheSameCamera) {
  testing::TempDir dir;
  const Camera a = ExampleCamera();
  WriteCamera(dir.File("cam.yaml"), a);
  const Camera b = ReadCamera(dir.File("cam.yaml"));
  EXPECT_EQ(b.name, a.name);
  EXPECT_EQ(b.pixel_size_mm, a.pixel_size_mm);
  EXPECT_FALSE(b.pixel_size_tolerance_mm.has_value());
  // The pitch's tolerance (a type-B component of calibrate's budget) is kept when stated.
  Camera with_tolerance = a;
  with_tolerance.pixel_size_tolerance_mm = 2.5e-5;
  WriteCamera(dir.File("tol.yaml"), with_tolerance);
  EXPECT_EQ(ReadCamera(dir.File("tol.yaml")).pixel_size_tolerance_mm, 2.5e-5);
  EXPECT_EQ(b.width_px, a.width_px);
  EXPECT_EQ(b.height_px, a.height_px);
  for (int i = 0; i < BrownFraser10Model::kNumParams; ++i) {
    EXPECT_EQ(b.interior[i], a.interior[i]) << BrownFraser10Model::kParams[i].name;
    EXPECT_EQ(b.interior_sigma[i], a.interior_sigma[i]);
  }
  ASSERT_EQ(b.subimages.size(), a.subimages.size());
  for (size_t k = 0; k < a.subimages.size(); ++k) {
    EXPECT_EQ(b.subimages[k].id, a.subimages[k].id);
    EXPECT_EQ(b.subimages[k].model, a.subimages[k].model);
    EXPECT_EQ(b.subimages[k].params, a.subimages[k].params);
    EXPECT_EQ(b.subimages[k].width_px, a.subimages[k].width_px);
  }
  ASSERT_EQ(b.reference_points.size(), 1u);
  EXPECT_EQ(b.reference_points[0].U, 12.5);
  EXPECT_EQ(b.reference_points[0].sigma_px, 0.05);
  // Written twice, byte for byte the same.
  EXPECT_EQ(CameraToYaml(b), CameraToYaml(a));
}

TEST(CameraIo, ReadsTheFormatsExample) {
  testing::TempDir dir;
  WriteText(dir.File("c.yaml"),
            "name: DMZ-1\npixel_size_mm: 0.009\nformat_px: [14000, 12000]\ninterior:\n  c: 170.0\n"
            "  x0: -0.1757\n  y0: 0.3930\ninterior_sigma:\n  c: 0.01\nsubimages:\n  - id: I\n"
            "    format_px: [7000, 4000]\n    model: affine\n    params: [1, 0, 0, 0, 1, 0]\n"
            "reference_points:\n  - {id: A, subimage: I, u: 12.0, v: 8.0, U: 12.0, V: 8.0, "
            "sigma_px: 0.05}\n");
  const Camera c = ReadCamera(dir.File("c.yaml"));
  EXPECT_EQ(c.interior[BrownFraser10Model::kK1], 0.0) << "omitted terms are 0";
  EXPECT_DOUBLE_EQ(c.interior[BrownFraser10Model::kX0], -0.1757);
  EXPECT_EQ(*c.interior_sigma[0], 0.01);
  EXPECT_FALSE(c.interior_sigma[1].has_value());
}

// Each bad file must be refused with FILE:LINE and what is wrong.
TEST(CameraIo, BadFilesNameFileAndLine) {
  testing::TempDir dir;
  const std::string base = "pixel_size_mm: 0.009\nformat_px: [100, 100]\ninterior:\n  c: 50\n";
  struct Case {
    std::string text, expected;
  } cases[] = {
      {"pixel_size_mm: -1\nformat_px: [100, 100]\ninterior: {c: 50}\n",
       ":1: pixel_size_mm out of range (got -1"},
      {base + "colour: red\n", ":5: unknown key 'colour'"},
      {base + "  K9: 1\n", ":5: unknown key 'K9'"},
      {base + "subimages:\n  - id: I\n    format_px: [10, 10]\n    model: affine\n    params: [1, "
              "0, 0]\n",
       ":9: sub-image I: model affine needs 6 params"},
      {base + "subimages:\n  - id: I\n    format_px: [10, 10]\n    model: spline\n",
       ":8: unknown mapping model 'spline'"},
      {base + "subimages:\n  - {id: I, format_px: [10, 10]}\nreference_points:\n  - {id: A, "
              "subimage: II, u: 1, v: 1, U: 1, V: 1}\n",
       ":8: reference point A names unknown sub-image 'II'"},
      {base + "interior_sigma: {c: 0}\n", ":5: interior_sigma.c must be > 0"},
      {base + "pixel_size_tolerance_mm: 0.01\n",
       ":5: pixel_size_tolerance_mm out of range (got 0.01"},
      {"pixel_size_mm: [0.009\n", ":2: invalid YAML"},
  };
  for (const auto& c : cases) {
    WriteText(dir.File("bad.yaml"), c.text);
    try {
      ReadCamera(dir.File("bad.yaml"));
      ADD_FAILURE() << "accepted: " << c.text;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(dir.File("bad.yaml") + c.expected), std::string::npos)
          << "got: " << e.what() << "\nexpected: " << c.expected;
    }
  }
  EXPECT_THROW(ReadCamera(dir.File("missing.yaml")), InputError);
}

}  // namespace
}  // namespace aerocal::calib

namespace aerocal::calib {
namespace {

TEST(ModelCameraFile, EveryRegisteredModelRoundTripsThroughYaml) {
  ForEachCameraModel([](auto model) {
    using M = decltype(model);
    ModelCamera camera;
    camera.model = M::kId;
    camera.frame = {0.0039, 6000, 4000};
    for (int i = 0; i < M::kNumParams; ++i) camera.params.push_back(1000.0 + 0.123456789 * i);
    const std::string text = ModelCameraToYaml(camera, "cam");
    const ModelCamera back = ParseModelCamera(YAML::Load(text), "mem.yaml");
    EXPECT_EQ(back.model, camera.model) << M::kName;
    EXPECT_EQ(back.params, camera.params) << M::kName;
    EXPECT_EQ(back.frame.width_px, 6000);
    EXPECT_EQ(back.frame.pixel_size_mm, 0.0039);
  });
}

TEST(ModelCameraFile, BadModelOrParameterNamesTheLine) {
  const auto expect_error = [](const std::string& text, const std::string& what) {
    try {
      ParseModelCamera(YAML::Load(text), "cam.yaml");
      ADD_FAILURE() << "no error for " << text;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  expect_error("model: opencv_x\npixel_size_mm: 0.004\nformat_px: [10, 10]\ninterior: {fx: 1}\n",
               "cam.yaml:1: unknown camera model 'opencv_x'");
  expect_error("model: opencv\npixel_size_mm: 0.004\nformat_px: [10, 10]\ninterior: {K1: 1}\n",
               "cam.yaml:4");
  // Values outside the unit-derived bounds (calib/README.md "Camera file bounds") name key and
  // line.
  expect_error(
      "model: opencv\npixel_size_mm: 0.004\nformat_px: [10, 10]\n"
      "interior:\n  fx: 1000\n  k1: 1e300\n",
      "cam.yaml:6: interior.k1 out of range");
  expect_error(
      "model: opencv\npixel_size_mm: 0.004\nformat_px: [10, 10]\n"
      "interior:\n  fx: 1e308\n",
      "cam.yaml:5: interior.fx out of range");
  expect_error(
      "model: metashape_frame\npixel_size_mm: 0.004\nformat_px: [10, 10]\n"
      "interior:\n  f: .nan\n",
      "cam.yaml:5");
  expect_error("model: opencv\npixel_size_mm: 1e-30\nformat_px: [10, 10]\ninterior: {fx: 1}\n",
               "cam.yaml:2: pixel_size_mm out of range");
  // The 10-parameter reader says what to do with another registered model.
  try {
    ParseCamera(YAML::Load("model: metashape_frame\npixel_size_mm: 0.004\nformat_px: [10, 10]\n"
                           "interior: {f: 1}\n"),
                "cam.yaml");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("convert it first"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace aerocal::calib
