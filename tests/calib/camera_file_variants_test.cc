// Camera files as other tools really write them (issue 29): one reader test per variant, on a file
// in the exact layout of that tool (small numeric records; where each layout comes from is said at
// each test), plus the registry's detection (`--from auto`) and what a wrong --from says.
#include "calib/camera/formats/camera_formats.h"
#include "calib/core/error.h"
#include "tests/support/test_support.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

namespace aerocal::calib {
namespace {

using testing::TempDir;

std::string Write(const TempDir& dir, const std::string& name, const std::string& text) {
  const std::string path = dir.File(name);
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

std::string Data(const std::string& name) {
  return std::string(AEROCAL_TEST_DATA_DIR) + "/camera_files/" + name;
}

// The InputError message of reading `path` as `format` ("" when it reads).
std::string ReadError(const std::string& format,
                      const std::string& path,
                      const CameraReadOptions& options = {}) {
  try {
    ReadCameraFileAs(format, path, options);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

double P(const CameraFile& f, const char* name) { return internal::Param(f.camera, name); }

bool HasNote(const CameraFile& f, const std::string& part) {
  for (const auto& n : f.notes)
    if (n.find(part) != std::string::npos) return true;
  return false;
}

// ---- the registry ----

TEST(CameraFileRegistry, EveryWrittenFileIsDetectedAsItsOwnFormatOnly) {
  TempDir dir("aerocal_variants");
  const ModelCamera drone = {CameraModelId::kOpenCv,
                             {3684.48,
                              3677.57,
                              2738.24,
                              1846.05,
                              -0.263482,
                              0.106788,
                              3.71107e-5,
                              -3.27247e-4,
                              -0.0300783,
                              0,
                              0,
                              0},
                             {0.0024, 5472, 3648}};
  for (const CameraFormat& f : CameraFormats()) {
    SCOPED_TRACE(f.name);
    CameraFile source;
    source.name = "cam";
    source.camera = drone;
    const FileConversion in_model = ConvertCameraFile(source, f.target(drone));
    const std::string path = dir.File("written_" + f.name + f.extension);
    f.write(path, in_model.file);
    EXPECT_EQ(DetectCameraFormats(path), std::vector<std::string>{f.name});
  }
}

TEST(CameraFileRegistry, AWrongFromNamesWhatTheFileLooksLike) {
  TempDir dir("aerocal_variants");
  const std::string kalibr = Write(dir,
                                   "camchain.yaml",
                                   "cam0:\n  camera_model: pinhole\n  intrinsics: [458.654, "
                                   "457.296, 367.215, 248.375]\n  distortion_model: radtan\n"
                                   "  distortion_coeffs: [-0.28340811, 0.07395907, 0.00019359, "
                                   "1.76187114e-05]\n  resolution: [752, 480]\n");
  const std::string message = ReadError("colmap", kalibr);
  EXPECT_NE(message.find("looks like kalibr: --from kalibr"), std::string::npos) << message;
  EXPECT_EQ(ReadError("auto", kalibr), "");
  const std::string nothing = Write(dir, "notes.txt", "just some words\n");
  EXPECT_NE(ReadError("auto", nothing).find("looks like none of the camera formats"),
            std::string::npos);
}

// ---- ROS camera_info ----

// Layout: camera_calibration_parsers (github.com/ros-perception/image_common,
// camera_calibration_parsers/src/parse_yml.cpp writeCalibrationYml). Values: a ROS calibration of
// a Point Grey camera, github.com/ahoarau/mekabot m3qa/ros_config/cameras/pg2_800x600_calib.yml.iss
// (written before distortion_model existed: the parsers' plumb_bob rule applies, said).
TEST(CameraFileVariants, RosCameraInfoOfARealCalibration) {
  TempDir dir("aerocal_variants");
  const std::string path = Write(
      dir,
      "pg2_800x600_calib.yml",
      "image_width: 800\nimage_height: 600\ncamera_name: 00b09d0100990bb6\ncamera_matrix:\n"
      "  rows: 3\n  cols: 3\n  data: [538.63, 0, 457.698, 0, 539.723, 297.003, 0, 0, 1]\n"
      "distortion_coefficients:\n  rows: 1\n  cols: 5\n  data: [-0.30678, 0.0825017, 0.0028784, "
      "-0.00015829, 0]\nrectification_matrix:\n  rows: 3\n  cols: 3\n  data: [1, 0, 0, 0, 1, 0, "
      "0, 0, 1]\nprojection_matrix:\n  rows: 3\n  cols: 4\n  data: [538.63, 0, 457.698, 0, 0, "
      "539.723, 297.003, 0, 0, 0, 1, 0]\n");
  EXPECT_EQ(DetectCameraFormats(path), std::vector<std::string>{"ros"});
  const CameraFile f = ReadCameraFileAs("auto", path, {});
  EXPECT_EQ(f.name, "00b09d0100990bb6");
  EXPECT_EQ(f.camera.model, CameraModelId::kOpenCv);
  EXPECT_EQ(P(f, "fx"), 538.63);
  EXPECT_EQ(P(f, "cy"), 297.003);
  EXPECT_EQ(P(f, "k1"), -0.30678);
  EXPECT_EQ(P(f, "p2"), -0.00015829);
  EXPECT_EQ(f.camera.frame.width_px, 800);
  EXPECT_TRUE(HasNote(f, "plumb_bob"));
}

TEST(CameraFileVariants, RosCameraInfoRejectsWhatItCannotHold) {
  TempDir dir("aerocal_variants");
  const std::string head =
      "image_width: 640\nimage_height: 480\ncamera_matrix:\n  rows: 3\n  cols: 3\n  data: [500, "
      "0, 320, 0, 500, 240, 0, 0, 1]\ndistortion_model: plumb_bob\ndistortion_coefficients:\n"
      "  rows: 1\n  cols: 5\n";
  EXPECT_NE(ReadError("ros", Write(dir, "a.yaml", head + "  data: [.nan, 0, 0, 0, 0]\n"))
                .find("a.yaml:11"),
            std::string::npos);
  EXPECT_NE(
      ReadError("ros", Write(dir, "b.yaml", head + "  data: [0, 0, 0, 0]\n")).find("rows x cols"),
      std::string::npos);
  EXPECT_NE(ReadError("ros",
                      Write(dir,
                            "c.yaml",
                            head + "  data: [0, 0, 0, 0, 0]\n"
                                   "image_width: 640\n"))
                .find("c.yaml"),
            std::string::npos);  // a duplicated key is an error, not the first one taken
}

// ---- camodocal / VINS ----

// VINS-Fusion's EuRoC camera, verbatim: github.com/HKUST-Aerial-Robotics/VINS-Fusion
// config/euroc/cam0_pinhole.yaml (camodocal's PinholeCamera layout, cv::FileStorage's %YAML:1.0).
TEST(CameraFileVariants, CamodocalPinholeOfVinsFusionEuroc) {
  TempDir dir("aerocal_variants");
  const std::string path = Write(
      dir,
      "cam0_pinhole.yaml",
      "%YAML:1.0\n---\nmodel_type: PINHOLE\ncamera_name: camera\nimage_width: 752\n"
      "image_height: 480\ndistortion_parameters:\n   k1: -2.9250563288482467e-01\n"
      "   k2: 8.3305380138632271e-02\n   p1: 2.4650824570721693e-05\n"
      "   p2: -1.1770093773613896e-04\nprojection_parameters:\n   fx: 4.6170381623421628e+02\n"
      "   fy: 4.6043378588777085e+02\n   cx: 3.6322379726457223e+02\n"
      "   cy: 2.4818637846327383e+02\n");
  EXPECT_EQ(DetectCameraFormats(path), std::vector<std::string>{"camodocal"});
  const CameraFile f = ReadCameraFileAs("auto", path, {});
  EXPECT_EQ(P(f, "fx"), 4.6170381623421628e+02);
  EXPECT_EQ(P(f, "cx"), 3.6322379726457223e+02);
  EXPECT_EQ(P(f, "k1"), -2.9250563288482467e-01);
  EXPECT_EQ(P(f, "p2"), -1.1770093773613896e-04);
  EXPECT_EQ(f.camera.frame.height_px, 480);
  // ours -> camodocal -> ours: exact, numbers in their shortest form.
  const std::string out = dir.File("back.yaml");
  WriteCamodocalCamera(out, f);
  const CameraFile back = ReadCamodocalCamera(out, {});
  EXPECT_EQ(back.camera.params, f.camera.params);
  std::ifstream in(out);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("k1: -0.2925056328848247\n"), std::string::npos) << text;
}

// ---- Agisoft Metashape / PhotoScan ----

// A Metashape (1.5+) cameras export's <sensors>, as EasyIDP's tests hold it
// (github.com/UTokyo-FieldPhenomics-Lab/EasyIDP tests/test_metashape.py, a DJI camera): a sensor
// without a calibration, then one whose <covariance> is beside the <calibration>.
TEST(CameraFileVariants, MetashapeSensorsWithCovarianceBesideTheCalibration) {
  TempDir dir("aerocal_variants");
  const std::string path =
      Write(dir,
            "sensors.xml",
            "<sensors>\n<sensor id=\"0\" label=\"Test_Pro (10.26mm)\" type=\"frame\">\n"
            "<resolution width=\"5472\" height=\"3648\"/>\n</sensor>\n"
            "<sensor id=\"1\" label=\"Test_Pro (10.26mm)\" type=\"frame\">\n"
            "<resolution width=\"5472\" height=\"3648\"/>\n"
            "<property name=\"pixel_width\" value=\"0.0024107142857142856\"/>\n"
            "<property name=\"pixel_height\" value=\"0.0024107142857142856\"/>\n"
            "<calibration type=\"frame\" class=\"adjusted\">\n<resolution width=\"5472\" "
            "height=\"3648\"/>\n"
            "<f>3239.2350850187408</f>\n<cx>-17.266617222361305</cx>\n<cy>51.627079230267093</cy>\n"
            "<k1>-0.0061748904544724733</k1>\n<k2>0.0085312948846406767</k2>\n"
            "<k3>-0.0059426077261182687</k3>\n<p1>0.0038636434570336977</p1>\n"
            "<p2>0.00036559169480901107</p2>\n</calibration>\n<covariance>\n<params>f cx</params>\n"
            "<coeffs>1.3198921426619455e+02 -3.6441406803097598e-01 -3.6441406803097598e-01 "
            "8.8492784732170038e-01</coeffs>\n</covariance>\n</sensor>\n</sensors>\n");
  EXPECT_EQ(DetectCameraFormats(path), std::vector<std::string>{"metashape"});
  const std::string listing = ReadError("metashape", path);
  EXPECT_NE(listing.find("name one with --camera (0 (Test_Pro (10.26mm)), 1 ("), std::string::npos)
      << listing;
  CameraReadOptions options;
  options.camera_id = "7";
  EXPECT_NE(ReadError("metashape", path, options).find("no sensor id 7"), std::string::npos);
  options.camera_id = "1";
  const CameraFile f = ReadCameraFileAs("metashape", path, options);
  EXPECT_EQ(f.name, "Test_Pro (10.26mm)");
  EXPECT_EQ(P(f, "f"), 3239.2350850187408);
  EXPECT_EQ(P(f, "p2"), 0.00036559169480901107);
  EXPECT_EQ(f.camera.frame.pixel_size_mm, 0.0024107142857142856);
  ASSERT_TRUE(f.covariance.has_value());
  EXPECT_EQ((*f.covariance)(0, 1), -3.6441406803097598e-01);
  options.camera_id = "0";
  EXPECT_NE(ReadError("metashape", path, options).find("has no <calibration>"), std::string::npos);
}

// PhotoScan <= 1.2's form (fx, fy, absolute cx, cy): MeshLab's "Agisoft xml" camera export as the
// CTU MRS documentation shows it (ctu-mrs.github.io docs, 3d_model_processing, MeshLab section).
TEST(CameraFileVariants, PhotoScanFxFyAbsoluteCentreForm) {
  TempDir dir("aerocal_variants");
  const std::string path = Write(
      dir,
      "cameras.xml",
      "<sensor id=\"keep the original\" label=\"keep the original\" type=\"frame\">\n"
      "  <resolution width=\"2048\" height=\"2048\"/>\n"
      "  <property name=\"pixel_width\" value=\"0.01\"/>\n"
      "  <property name=\"pixel_height\" value=\"0.01\"/>\n"
      "  <property name=\"focal_length\" value=\"10.235\"/>\n"
      "  <property name=\"fixed\" value=\"false\"/>\n"
      "  <calibration type=\"frame\" class=\"adjusted\">\n"
      "    <resolution width=\"2048\" height=\"2048\"/>\n    <fx>1023.5</fx>\n    <fy>1023.5</fy>\n"
      "    <cx>1024</cx>\n    <cy>1024</cy>\n    <k1>0</k1>\n    <k2>0</k2>\n    <p1>0</p1>\n"
      "    <p2>0</p2>\n  </calibration>\n</sensor>\n");
  const CameraFile f = ReadCameraFileAs("auto", path, {});
  EXPECT_EQ(P(f, "f"), 1023.5);
  EXPECT_EQ(P(f, "b1"), 0.0);
  EXPECT_EQ(P(f, "cx"), 0.0);  // the image centre
  EXPECT_EQ(P(f, "cy"), 0.0);
  EXPECT_TRUE(HasNote(f, "PhotoScan <= 1.2"));
}

// A PhotoScan project archive (.psz: doc.xml inside, its chunk inline) with an initial and an
// adjusted calibration in the fx/fy form; made here with Python's zipfile (deflate), the values
// illustrative (tests/data/camera_files/photoscan12_project.psz).
TEST(CameraFileVariants, PhotoScanProjectArchiveAdjustedPreferredAndSaid) {
  const std::string path = Data("photoscan12_project.psz");
  EXPECT_EQ(DetectCameraFormats(path), std::vector<std::string>{"metashape"});
  const CameraFile f = ReadCameraFileAs("auto", path, {});
  EXPECT_EQ(f.name, "FC330 (3.61mm)");
  EXPECT_DOUBLE_EQ(P(f, "f"), 2354.9);
  EXPECT_NEAR(P(f, "b1"), 0.8, 1e-9);  // fx - fy
  EXPECT_EQ(P(f, "b2"), 0.31);         // skew
  EXPECT_EQ(P(f, "cx"), 12.25);        // 2012.25 - 4000 / 2
  EXPECT_EQ(P(f, "cy"), -10.5);
  EXPECT_EQ(P(f, "k3"), -0.0061);
  EXPECT_TRUE(HasNote(f, "the adjusted calibration read"));
  EXPECT_EQ(f.camera.frame.pixel_size_mm, 0.00156);
}

// A Metashape >= 1.3 project: project.psx whose chunk is project.files/0/chunk.zip holding doc.xml
// (the layout EasyIDP's Metashape reader opens); two sensors, --camera picks one. The first
// sensor's values: a real M3M calibration quoted by geograypher's tests
// (github.com/open-forest-observatory/geograypher, "Example portion of a real camera file").
TEST(CameraFileVariants, MetashapePsxProjectFolder) {
  const std::string path = Data("metashape_project.psx");
  EXPECT_EQ(DetectCameraFormats(path), std::vector<std::string>{"metashape"});
  EXPECT_NE(ReadError("auto", path).find("holds 2 sensors"), std::string::npos);
  CameraReadOptions options;
  options.camera_id = "0";
  const CameraFile f = ReadCameraFileAs("auto", path, options);
  EXPECT_EQ(f.name, "M3M (12.29mm)");
  EXPECT_EQ(P(f, "f"), 3705.4728792737214);
  EXPECT_EQ(P(f, "b2"), -0.3058334293);
  EXPECT_EQ(P(f, "k4"), -0.0761413904);
  EXPECT_EQ(f.camera.frame.width_px, 5280);
}

TEST(CameraFileVariants, MetashapeNoSilentSubstitution) {
  TempDir dir("aerocal_variants");
  const auto calibration = [&](const std::string& name, const std::string& body) {
    return Write(dir,
                 name,
                 "<calibration>\n<projection>frame</projection>\n<width>100</width>\n"
                 "<height>80</height>\n<f>90</f>\n" +
                     body + "</calibration>\n");
  };
  EXPECT_NE(ReadError("metashape", calibration("dup.xml", "<k1>0.1</k1>\n<k1>0.2</k1>\n"))
                .find("dup.xml:7: <k1> occurs twice"),
            std::string::npos);
  EXPECT_NE(ReadError("metashape", calibration("empty.xml", "<k1></k1>\n")).find("empty.xml:6"),
            std::string::npos);
  EXPECT_NE(ReadError("metashape", calibration("nan.xml", "<k2>nan</k2>\n")).find("nan.xml:6"),
            std::string::npos);
  const std::string zero_pixel = Write(
      dir,
      "pixel.xml",
      "<sensor id=\"0\">\n<resolution width=\"100\" height=\"80\"/>\n<property "
      "name=\"pixel_width\" value=\"0\"/>\n<calibration><f>90</f></calibration>\n</sensor>\n");
  EXPECT_NE(ReadError("metashape", zero_pixel).find("pixel.xml:3: pixel_width must be > 0"),
            std::string::npos);
  const std::string two_adjusted =
      Write(dir,
            "two.xml",
            "<sensor id=\"0\">\n<resolution width=\"100\" height=\"80\"/>\n<calibration "
            "class=\"adjusted\"><f>90</f></calibration>\n<calibration "
            "class=\"adjusted\"><f>91</f></calibration>\n</sensor>\n");
  EXPECT_NE(ReadError("metashape", two_adjusted).find("two.xml:4"), std::string::npos);
}

// ---- Pix4D ----

// A project's calibrated_camera_parameters.txt: the 7 header lines and two image records of a
// Pix4Dmapper project as quoted in public code (images P1000852 / P1000853, "from the dataset of
// Francesco"; a stereo-rectification sample), and a third record of another camera (DSC_0157,
// quoted in a public labelme-projection script); layout as EasyIDP's Pix4D reader documents it.
TEST(CameraFileVariants, Pix4dCalibratedCameraParametersPerImage) {
  TempDir dir("aerocal_variants");
  const std::string header =
      "fileName imageWidth imageHeight \ncamera matrix K [3x3]\nradial distortion [3x1]\n"
      "tangential distortion [2x1]\ncamera position t [3x1]\ncamera rotation R [3x3]\n"
      "camera model m = K [R|-Rt] X\n\n";
  const std::string p852 =
      "P1000852_1400496954965.JPG 4592 3448\n\n"
      "3837.04710692373510028119 0 2287.77960528229596093297\n"
      "0 3837.04710692373510028119 1742.83970496531173921539\n0 0 1\n"
      "-0.04930618424089858870 0.04239222797251372687 -0.02928533838596112174\n"
      "0.00028446432839522286 -0.00085023797648524325\n"
      "53.81054947407682931271 2.73450993122391761148 109.15739203396617540420\n"
      "-0.30242406816031625061 -0.95203343934820727767 0.04660486412583432492\n"
      "-0.95061868820348527365 0.30483019730717991758 0.05833232764043053825\n"
      "-0.06974089643565797858 -0.02666235496892283355 -0.99720876760679444395\n\n";
  const std::string p853 =
      "P1000853_1400496954965.JPG 4592 3448\n\n"
      "3837.04710692373510028119 0 2287.77960528229596093297\n"
      "0 3837.04710692373510028119 1742.83970496531173921539\n0 0 1\n"
      "-0.04930618424089858870 0.04239222797251372687 -0.02928533838596112174\n"
      "0.00028446432839522286 -0.00085023797648524325\n"
      "63.77929108604634222957 21.54632894130132925170 109.22231512122060337333\n"
      "-0.30039254188295805292 -0.94706188642182642656 0.11330535763249140191\n"
      "-0.94827780856518950614 0.30931607093561647170 0.07136361848837562138\n"
      "-0.10263293118632564604 -0.08600785747874520326 -0.99099401102530326746\n\n";
  const std::string dsc157 =
      "DSC_0157.JPG 7360 4912\n7363.51850023951465118444 0 3686.33719996831450771424\n"
      "0 7363.51850023951465118444 2439.04083412635009153746\n0 0 1\n"
      "-0.09005921067656787182 0.10773972435740564180 -0.01257054987797603419\n"
      "-0.00029570539858373248 -0.00027422056492206067\n"
      "114.12600004808672338186 378.81985574952466322429 -2.31159761431545440757\n"
      "-0.49632901575943477734 0.86794436424468834890 -0.01816834310427051929\n"
      "0.86649900151927328196 0.49400145706385401034 -0.07170802455019638366\n"
      "-0.05326338781351704077 -0.05133362440616233424 -0.99726018196053234366\n";
  const std::string same = Write(dir, "p_calibrated_camera_parameters.txt", header + p852 + p853);
  EXPECT_EQ(DetectCameraFormats(same), std::vector<std::string>{"pix4d"});
  const CameraFile f = ReadCameraFileAs("auto", same, {});
  EXPECT_EQ(f.name, "P1000852_1400496954965.JPG");
  EXPECT_TRUE(HasNote(f, "all 2 images share K and distortion"));
  const FileConversion cv = ConvertCameraFile(f, {CameraModelId::kOpenCv, {}});
  EXPECT_TRUE(cv.result.exact);
  EXPECT_NEAR(P(cv.file, "fx"), 3837.04710692373510028119, 1e-9);
  EXPECT_NEAR(P(cv.file, "cx"), 2287.77960528229596093297 - 0.5, 1e-9);  // corner origin
  EXPECT_EQ(P(cv.file, "k3"), -0.02928533838596112174);
  EXPECT_EQ(P(cv.file, "p1"), 0.00028446432839522286);  // T1
  const std::string mixed =
      Write(dir, "m_calibrated_camera_parameters.txt", header + p852 + p853 + dsc157);
  CameraReadOptions options;
  options.camera_id = "DSC_0157.JPG";
  const CameraFile g = ReadCameraFileAs("pix4d", mixed, options);
  EXPECT_EQ(g.camera.frame.width_px, 7360);
  EXPECT_TRUE(HasNote(g, "2 of 3 images have another K"));
  options.camera_id = "nope.JPG";
  EXPECT_NE(ReadError("pix4d", mixed, options).find("images: P1000852"), std::string::npos);
  const std::string cut =
      Write(dir, "c_calibrated_camera_parameters.txt", header + p852.substr(0, p852.size() / 2));
  EXPECT_NE(ReadError("pix4d", cut).find("c_calibrated_camera_parameters.txt:9: image "),
            std::string::npos);
}

// ---- DJI ----

// exiftool's default output of two DJI images (records A and B of
// ../shared/data/dji_dewarpdata_documented: A an exiftool dump in the Agisoft forum, topic 10220;
// B Stack Overflow 53511464), in the layout `exiftool -ImageWidth -ImageHeight
// -CalibratedFocalLength -CalibratedOpticalCenterX -CalibratedOpticalCenterY -DewarpData *.JPG`
// prints: "======== FILE" blocks, print names padded to a column, " : ".
TEST(CameraFileVariants, DjiExiftoolListingOfSeveralImages) {
  TempDir dir("aerocal_variants");
  const std::string path = Write(
      dir,
      "exiftool.txt",
      "======== DJI_0001.JPG\nImage Width                     : 5472\n"
      "Image Height                    : 3648\nCalibrated Focal Length         : 3666.666504\n"
      "Calibrated Optical Center X     : 2736.000000\nCalibrated Optical Center Y     : "
      "1824.000000\n"
      "Dewarp Data                     : 2018-09-06;3684.480000000000,3677.570000000000,"
      "2.240000000000,22.050000000000,-0.263482000000,0.106788000000,0.000037110700,"
      "-0.000327247000,-0.030078300000\n"
      "======== DJI_0002.JPG\nImage Width                     : 4864\n"
      "Image Height                    : 3648\n"
      "Dewarp Data                     : 2018-03-13;3659.780000000000,3653.170000000000,"
      "-7.710000000000,45.900000000000,-0.269478000000,0.115681000000,-0.000087561900,"
      "-0.000306177000,-0.035762800000\n    2 image files read\n");
  EXPECT_EQ(DetectCameraFormats(path), std::vector<std::string>{"dji"});
  EXPECT_NE(
      ReadError("auto", path).find("name one with --camera (1 (DJI_0001.JPG), 2 (DJI_0002.JPG))"),
      std::string::npos)
      << ReadError("auto", path);
  CameraReadOptions options;
  options.camera_id = "DJI_0002.JPG";
  const CameraFile b = ReadCameraFileAs("auto", path, options);
  EXPECT_EQ(b.name, "2018-03-13");  // the record's date
  EXPECT_EQ(b.camera.frame.width_px, 4864);
  EXPECT_NEAR(P(b, "cx"), 2432 - 7.71, 1e-9);
  options.camera_id = "2018-09-06";
  const CameraFile a = ReadCameraFileAs("dji", path, options);
  EXPECT_NEAR(P(a, "cy"), 1824 + 22.05, 1e-9);
  EXPECT_TRUE(HasNote(a, "Calibrated Focal Length = 3666.666504"));
  // ours -> DJI sidecar -> ours keeps the date and the numbers, written in their shortest form.
  const std::string out = dir.File("a.xmp");
  WriteDjiDewarpData(out, a);
  const CameraFile back = ReadDjiDewarpData(out, {});
  EXPECT_EQ(back.name, "2018-09-06");
  for (size_t i = 0; i < a.camera.params.size(); ++i)
    EXPECT_NEAR(
        back.camera.params[i], a.camera.params[i], 1e-12 * (1 + std::abs(a.camera.params[i])));
  std::ifstream in(out);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("2018-09-06;3684.48,3677.57,"), std::string::npos) << text;
}

TEST(CameraFileVariants, DjiTagNamesWithoutSizeNameBothOptions) {
  TempDir dir("aerocal_variants");
  const std::string path =
      Write(dir,
            "dewarp_s.txt",
            "DewarpData                      : 2018-09-06;3684.48,3677.57,"
            "2.24,22.05,-0.263482,0.106788,3.71107e-5,-3.27247e-4,-0.0300783\n");
  EXPECT_NE(ReadError("auto", path).find("pass --width and --height"), std::string::npos);
  CameraReadOptions options;
  options.width_px = 5472;
  options.height_px = 3648;
  EXPECT_EQ(P(ReadCameraFileAs("auto", path, options), "fx"), 3684.48);
  const std::string junk = Write(dir, "junk.txt", "DewarpData: 1,2,3,4,5,6,7,8,9\nnot a tag\n");
  EXPECT_NE(ReadError("dji", junk, options).find("junk.txt:2"), std::string::npos);
}

// ---- Kalibr ----

// A camchain-imucam with two cameras, T_cam_imu, T_cn_cnm1, cam_overlaps and keys Kalibr does not
// write (flip_camera): github.com/ethz-asl/voxblox voxblox_ros/cfg/calibrations/euroc_camchain.yaml
// (the EuRoC equidistant calibration), with a comment after a value as hand-edited files have.
TEST(CameraFileVariants, KalibrCamchainImucamOfEuroc) {
  TempDir dir("aerocal_variants");
  const std::string path = Write(
      dir,
      "euroc_camchain.yaml",
      "cam0:\n  T_cam_imu:\n"
      "  - [0.014067833389924844, 0.9996023098557362, -0.024440094001271714, 0.0657094717307726]\n"
      "  - [-0.9998997399258257, 0.014103075047756597, 0.0012701852087405128, "
      "-0.01662153508680676]\n"
      "  - [0.0016143605484757653, 0.0244197748817434, 0.9997004893640622, 0.0014868599890966905]\n"
      "  - [0.0, 0.0, 0.0, 1.0]\n  cam_overlaps: [1]\n  camera_model: pinhole\n"
      "  distortion_coeffs: [-0.011602611404146694, 0.05399058892805103, -0.07542693754837938,\n"
      "    0.03666365316319072]\n  distortion_model: equidistant\n"
      "  intrinsics: [461.3418503026154, 460.13885656354387, 366.4281018364134, "
      "248.8415565479774]\n"
      "  resolution: [752, 480]  # width, height\n  rostopic: /cam0/image_raw\n  flip_camera: "
      "true\n"
      "cam1:\n  T_cam_imu:\n"
      "  - [0.011810542390279122, 0.9995951714398011, -0.02588444171084584, -0.04439379107435547]\n"
      "  - [-0.9998052969172723, 0.01221433647773218, 0.015497685006934178, "
      "-0.016235309745499065]\n"
      "  - [0.01580757238202092, 0.025696365864524458, 0.9995448051171812, 0.0012030335279962774]\n"
      "  - [0.0, 0.0, 0.0, 1.0]\n  T_cn_cnm1:\n"
      "  - [0.9999964092230391, 0.0022551294207702314, -0.0014477335121195142, "
      "-0.11006339056724425]\n"
      "  - [-0.002234380261272062, 0.9998970009983116, 0.014177268405057909, "
      "0.000510253673254922]\n"
      "  - [0.0014795559720994585, -0.014173982710466103, 0.9998984494078623, "
      "-0.0006164896618526655]\n"
      "  - [0.0, 0.0, 0.0, 1.0]\n  cam_overlaps: [0]\n  camera_model: pinhole\n"
      "  distortion_coeffs: [0.005730625619095735, -0.009587210461496316, 0.01921165649877144,\n"
      "    -0.010717188529046507]\n  distortion_model: equidistant\n"
      "  intrinsics: [459.6820431465863, 458.37659300282706, 380.01198798196646, "
      "255.55347731935623]\n"
      "  resolution: [752, 480]\n  rostopic: /cam1/image_raw\n  flip_camera: true\n");
  EXPECT_EQ(DetectCameraFormats(path), std::vector<std::string>{"kalibr"});
  EXPECT_NE(ReadError("auto", path).find("name one with --camera (cam0, cam1)"), std::string::npos);
  CameraReadOptions options;
  options.camera_id = "cam1";
  const CameraFile f = ReadCameraFileAs("auto", path, options);
  EXPECT_EQ(f.name, "cam1");
  EXPECT_EQ(f.camera.model, CameraModelId::kOpenCvFisheye);
  EXPECT_EQ(f.camera.params[0], 459.6820431465863);
  EXPECT_EQ(f.camera.params[7], -0.010717188529046507);
  EXPECT_EQ(f.camera.frame.width_px, 752);
  // Written back under its key, every number in its shortest exact form.
  const std::string out = dir.File("back.yaml");
  WriteKalibrCamchain(out, f);
  std::ifstream in(out);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(text.rfind("cam1:\n", 0), 0u) << text;
  EXPECT_NE(text.find("-0.010717188529046507]"), std::string::npos) << text;
  EXPECT_EQ(ReadKalibrCamchain(out, {}).camera.params, f.camera.params);
}

// ---- COLMAP ----

// cameras.txt as COLMAP writes it (colmap.github.io/format.html "Text format", its three-camera
// example) with the ids from 0, as pycolmap / nerfstudio exports number them; and cameras.bin in
// the layout of COLMAP's WriteCamerasBinary (src/colmap/scene/reconstruction_io.cc).
TEST(CameraFileVariants, ColmapIdsFromZeroAndTheBinaryFile) {
  TempDir dir("aerocal_variants");
  const std::string text =
      Write(dir,
            "cameras.txt",
            "# Camera list with one line of data per camera:\n#   CAMERA_ID, MODEL, WIDTH, HEIGHT, "
            "PARAMS[]\n# Number of cameras: 3\n0 SIMPLE_PINHOLE 3072 2304 2559.81 1536 1152\n"
            "1 PINHOLE 3072 2304 2560.56 2560.56 1536 1152\n"
            "2 SIMPLE_RADIAL 3072 2304 2559.69 1536 1152 -0.0218531\n");
  EXPECT_EQ(DetectCameraFormats(text), std::vector<std::string>{"colmap"});
  CameraReadOptions options;
  options.camera_id = "0";
  const CameraFile zero = ReadCameraFileAs("auto", text, options);
  EXPECT_EQ(zero.name, "0");
  EXPECT_EQ(zero.camera.params[0], 2559.81);
  options.camera_id = "2";
  const CameraFile two = ReadCameraFileAs("auto", text, options);
  EXPECT_EQ(two.camera.params[3], -0.0218531);
  // The id survives: written back as camera 2, in text and in binary.
  const std::string bin = dir.File("cameras.bin");
  WriteColmapCameras(bin, two);
  EXPECT_EQ(DetectCameraFormats(bin), std::vector<std::string>{"colmap"});
  options.camera_id = "";
  const CameraFile back = ReadCameraFileAs("auto", bin, options);
  EXPECT_EQ(back.name, "2");
  EXPECT_EQ(back.camera.params, two.camera.params);
  EXPECT_EQ(back.camera.model, two.camera.model);
  // A cut binary file: an error naming the file, never a crash.
  std::ifstream in(bin, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string cut = Write(dir, "cut.bin", bytes.substr(0, bytes.size() - 3));
  EXPECT_NE(ReadError("colmap", cut).find("cut.bin"), std::string::npos);
  const std::string dup =
      Write(dir, "dup.txt", "0 PINHOLE 10 10 5 5 5 5\n0 PINHOLE 10 10 6 6 5 5\n");
  options.camera_id = "0";
  EXPECT_NE(ReadError("colmap", dup, options).find("dup.txt:2: camera id 0 occurs twice"),
            std::string::npos);
}

// ---- DBAT ----

// A DBAT camera XML fragment (a <camera> without <document>), the c4040z result camera of DBAT's
// camcal demo (../shared/data/dbat_camcal_olympus_c4040z/result/c4040z.xml, DBAT 0.9.2.0), and a
// <cameras> list of two (the second the same camera under id 2): --camera picks.
TEST(CameraFileVariants, DbatFragmentsAndTheAspectAsB1) {
  TempDir dir("aerocal_variants");
  const std::string camera =
      "<camera>\n<id>1</id>\n<name>Olympus Camedia C4040Z</name>\n<unit>mm</unit>\n"
      "<calibrated>yes</calibrated>\n<sensor>7.25301132255482273,5.43764000000000003</sensor>\n"
      "<image>2272,1704</image>\n<aspect>0.999610402322309577</aspect>\n<focal>7.5</focal>\n"
      "<model>3</model>\n<nK>3</nK>\n<nP>2</nP>\n<cc>7.45699532273933752</cc>\n"
      "<pp>3.61546239970888994,2.61329279848268081</pp>\n<skew>0</skew>\n"
      "<K>0.00458860662755811253,-4.51350997187018702e-05,-2.05253370760761127e-06</K>\n"
      "<P>-6.12803065099492536e-05,-4.41170561685059337e-05</P>\n</camera>\n";
  const std::string one = Write(dir, "camera.xml", camera);
  EXPECT_EQ(DetectCameraFormats(one), std::vector<std::string>{"dbat"});
  const CameraFile f = ReadCameraFileAs("auto", one, {});
  EXPECT_EQ(f.name, "Olympus Camedia C4040Z");
  EXPECT_NEAR(P(f, "B1"), 1.0 - 0.999610402322309577, 1e-9);  // as = 1 - aspect
  EXPECT_TRUE(HasNote(f, "not exact"));
  std::string second = camera;
  second.replace(second.find("<id>1</id>"), 10, "<id>2</id>");
  const std::string two =
      Write(dir, "cameras.xml", "<cameras>\n" + camera + second + "</cameras>\n");
  EXPECT_NE(ReadError("auto", two).find("name one with --camera (1, 2)"), std::string::npos);
  CameraReadOptions options;
  options.camera_id = "2";
  EXPECT_EQ(ReadCameraFileAs("auto", two, options).camera.params, f.camera.params);
  // Written back with the aspect and read again: the same camera.
  const std::string out = dir.File("back.xml");
  WriteDbatCameraXml(out, f);
  const CameraFile back = ReadDbatCameraXml(out, {});
  for (size_t i = 0; i < f.camera.params.size(); ++i)
    EXPECT_NEAR(
        back.camera.params[i], f.camera.params[i], 1e-14 * (1 + std::abs(f.camera.params[i])));
}

// DBAT's text report (DBAT 0.9.2.0 report.txt of its camcal demo and of the Roma EOS 5D project,
// ../shared/data/dbat_*/result/report.txt): the same camera as the XML DBAT wrote beside it, to the
// report's 6 significant digits, with the deviations as sigmas.
TEST(CameraFileVariants, DbatTextReportAgainstItsXml) {
  const std::string dir = testing::SharedDataDir("dbat_camcal_olympus_c4040z");
  if (dir.empty()) GTEST_SKIP() << "../shared/data absent";
  const std::string report = dir + "/result/report.txt";
  EXPECT_EQ(DetectCameraFormats(report), std::vector<std::string>{"dbat"});
  const CameraFile r = ReadCameraFileAs("auto", report, {});
  const CameraFile x = ReadDbatCameraXml(dir + "/result/c4040z.xml", {});
  EXPECT_EQ(r.name, "Camera1");
  for (size_t i = 0; i < x.camera.params.size(); ++i)
    EXPECT_NEAR(r.camera.params[i],
                x.camera.params[i],
                6e-6 * std::abs(x.camera.params[i]) + (i == 1 || i == 2 ? 5e-6 : 1e-9))
        << i;  // x0, y0: px, py printed to 5e-6 mm
  EXPECT_LT(CompareCameras(x.camera, r.camera, 21).max_px, 0.05);  // 6 digits printed
  ASSERT_TRUE(r.covariance.has_value());
  EXPECT_NEAR(std::sqrt((*r.covariance)(0, 0)), 0.00105, 1e-12);  // c
  const std::string roma = testing::SharedDataDir("dbat_roma_canon_eos5d");
  if (roma.empty()) return;
  const CameraFile e = ReadCameraFileAs("dbat", roma + "/result/report.txt", {});
  EXPECT_EQ(e.camera.frame.width_px, 5616);
  EXPECT_EQ(P(e, "c"), 24.5425);
  EXPECT_EQ(P(e, "K2"), -1.86985e-07);
  EXPECT_EQ(P(e, "B1"), 0.0);
}

// ---- PhotoModeler ----

// A PhotoModeler report's camera block: the heading and value lines of PhotoModeler's project
// status report (../shared/data/dbat_camcal_olympus_c4040z/photomodeler/
// weighted-with-orient-pmreport.txt: "Camera1: <name>", indented title lines, "Value: X unit",
// "Deviation: Name: Y unit", CRLF line ends) with the calibration headings of PhotoModeler's
// calibration report as DBAT's PhotoModeler-style report writer lists them ("Focal Length",
// "Xp - principal point x", ..., "Iw - image width"). No PhotoModeler calibration report itself
// was available: the values are PhotoModeler's own calibration of the same images, line 4 of its
// Bundle Soln export (camcal-pmexport.txt), which must read as the same camera.
TEST(CameraFileVariants, PhotoModelerReportBlockIsItsBundleSolnCamera) {
  const std::string dir = testing::SharedDataDir("dbat_camcal_olympus_c4040z");
  if (dir.empty()) GTEST_SKIP() << "../shared/data absent";
  TempDir tmp("aerocal_variants");
  const auto entry = [](const std::string& title,
                        const std::string& name,
                        const std::string& value,
                        const std::string& deviation,
                        const std::string& unit) {
    return "            " + title + "\r\n                 Value: " + value + " " + unit +
           "\r\n                 Deviation: " + name + ": " + deviation + " " + unit + "\r\n";
  };
  const std::string report =
      "\r\nStatus Report Tree\r\n   Project Name: camcal.pmr\r\n"
      "      Camera Calibration Standard Deviations\r\n"
      "         Camera1: Olympus C4040Z 2272x1704 inf focus\r\n" +
      entry("Focal Length", "Focal", "7.4653", "0.0011", "mm") +
      entry("Xp - principal point x", "Xp", "3.6173", "0.0008", "mm") +
      entry("Yp - principal point y", "Yp", "2.6128", "0.0009", "mm") +
      "            Fw - format width\r\n                 Value: 7.25319 mm\r\n"
      "            Fh - format height\r\n                 Value: 5.43764 mm\r\n" +
      entry("K1 - radial distortion 1", "K1", "0.00498", "2.2e-005", "mm^-2") +
      entry("K2 - radial distortion 2", "K2", "-0.00010", "2.7e-006", "mm^-4") +
      entry("K3 - radial distortion 3", "K3", "0.00000", "0", "mm^-6") +
      entry("P1 - decentering distortion 1", "P1", "-0.00006", "3.5e-006", "mm^-1") +
      entry("P2 - decentering distortion 2", "P2", "-0.00004", "3.9e-006", "mm^-1") +
      "            Iw - image width\r\n                 Value: 2272 px\r\n"
      "            Ih - image height\r\n                 Value: 1704 px\r\n"
      "      Cameras\r\n         Camera1: Olympus C4040Z 2272x1704 inf focus\r\n"
      "            Calibration: yes\r\n            Number of photos using camera: 21\r\n";
  const std::string path = Write(tmp, "camcal-report.txt", report);
  EXPECT_EQ(DetectCameraFormats(path), std::vector<std::string>{"photomodeler"});
  const CameraFile r = ReadCameraFileAs("auto", path, {});
  const CameraFile b = ReadPhotoModelerCamera(dir + "/photomodeler/camcal-pmexport.txt", {});
  EXPECT_EQ(r.name, "Camera1");
  for (size_t i = 0; i < b.camera.params.size(); ++i)
    EXPECT_NEAR(r.camera.params[i], b.camera.params[i], 1e-12) << i;
  EXPECT_EQ(r.camera.frame.width_px, 2272);
  ASSERT_TRUE(r.covariance.has_value());
  EXPECT_NEAR(std::sqrt((*r.covariance)(0, 0)), 0.0011, 1e-15);
  EXPECT_TRUE(HasNote(r, "Format width"));  // 7.25319 mm against 2272 square pixels: said
  EXPECT_EQ(P(r, "B1"), 0.0);               // not modelled, as in the Bundle Soln reader
}

// ---- every reader on damaged files (what the camera_formats fuzzer does, in the unit build) ----

// Each seed of the fuzzer and the project archives, cut at 8 lengths and with bytes overwritten at
// 4 places, through every reader of the registry: a camera or an aerocal::Error, nothing else (a
// crash or another exception fails the test).
TEST(CameraFileRegistry, EveryReaderRefusesDamagedFilesWithAnError) {
  namespace fs = std::filesystem;
  TempDir dir("aerocal_variants");
  std::vector<std::string> inputs;
  const fs::path seeds =
      fs::path(AEROCAL_TEST_DATA_DIR) / ".." / "fuzz" / "seeds" / "camera_formats";
  for (const auto& entry : fs::directory_iterator(seeds)) inputs.push_back(entry.path().string());
  inputs.push_back(Data("photoscan12_project.psz"));
  inputs.push_back(Data("metashape_project.files/0/chunk.zip"));
  int reads = 0, errors = 0;
  for (const std::string& input : inputs) {
    std::ifstream in(input, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::vector<std::string> damaged;
    for (int k = 0; k < 8; ++k) damaged.push_back(bytes.substr(0, bytes.size() * k / 8));
    for (int k = 1; k < 5; ++k) {
      std::string flipped = bytes;
      for (size_t i = flipped.size() * k / 5; i < flipped.size() && i < flipped.size() * k / 5 + 3;
           ++i)
        flipped[i] = static_cast<char>(flipped[i] ^ 0x5a);
      damaged.push_back(flipped);
    }
    for (const std::string& text : damaged)
      for (const CameraFormat& f : CameraFormats()) {
        const std::string path = Write(dir, "damaged_" + f.name + f.extension, text);
        try {
          f.read(path, {});
          ++reads;
        } catch (const aerocal::Error&) {
          ++errors;
        }
      }
  }
  std::printf("damaged inputs: %d read, %d refused with an error\n", reads, errors);
  EXPECT_GT(errors, 0);
}

}  // namespace
}  // namespace aerocal::calib
