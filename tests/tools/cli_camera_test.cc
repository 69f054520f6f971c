// aerocal camera convert / show (issue 15): every format through the command line, the OpenCV
// format against OpenCV itself (the published chessboard calibration projected by
// cv::projectPoints, the DJI DewarpData records undistorted by cv::undistortPoints), --report,
// --max-residual-px,
// --model, the distortion plot.
#include "calib/camera/convert_camera.h"
#include "tests/support/test_support.h"
#include "tools/camera_formats.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace aerocal {
namespace {

namespace fs = std::filesystem;
using calib::CameraFile;
using calib::CameraModelId;
using calib::ModelCamera;
using calib::OpenCvModel;
using testing::RunAerocal;
using testing::TempDir;

std::string Read(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// OpenCV pixel of a point in OpenCV camera coordinates through any registry camera.
cv::Point2d Project(const ModelCamera& camera, const cv::Point3d& q) {
  const double c = camera.PrincipalDistanceMm();
  Eigen::Vector2d pixel;
  EXPECT_TRUE(camera.PixelFromIdeal(Eigen::Vector2d(c * q.x / q.z, -c * q.y / q.z), &pixel));
  return {pixel.x(), pixel.y()};
}

// OpenCV's calibration sample output (samples/cpp/calibration.cpp saveCameraParams:
// calibration_time, nframes, image_width, image_height, board size, flags, camera_matrix,
// distortion_coefficients, avg_reprojection_error, per_view_reprojection_errors,
// extrinsic_parameters, image_points) as cv::FileStorage writes it in XML and JSON, and the
// published YAML output cut short (its first 30 lines: a copy that stops inside
// per_view_reprojection_errors' data).
TEST(CameraFormatsOpenCv, SampleOutputAsXmlJsonAndCutShort) {
  TempDir tmp("aerocal_cli_camera");
  const cv::Mat k =
      (cv::Mat_<double>(3, 3) << 535.9157, 0, 342.2832, 0, 535.9157, 235.5708, 0, 0, 1);
  const cv::Mat d =
      (cv::Mat_<double>(5, 1) << -0.266373, -0.0385889, 0.00178319, -0.000281221, 0.238392);
  for (const char* extension : {".xml", ".json"}) {
    SCOPED_TRACE(extension);
    const std::string path = tmp.File(std::string("out_camera_data") + extension);
    {
      cv::FileStorage fs(path, cv::FileStorage::WRITE);
      fs << "calibration_time"
         << "Fri Nov 27 10:00:00 2026"
         << "nframes" << 13 << "image_width" << 640 << "image_height" << 480 << "board_width" << 9
         << "board_height" << 6 << "square_size" << 0.025 << "flags" << 0 << "camera_matrix" << k
         << "distortion_coefficients" << d << "avg_reprojection_error" << 0.3926
         << "extrinsic_parameters" << cv::Mat(13, 6, CV_64F, cv::Scalar(0.1)) << "image_points"
         << cv::Mat(13, 54, CV_32FC2, cv::Scalar(1, 2));
    }
    EXPECT_EQ(calib::DetectCameraFormats(path), std::vector<std::string>{"opencv"});
    const CameraFile f = calib::ReadCameraFileAs("auto", path, {});
    EXPECT_EQ(f.camera.params[OpenCvModel::kFx], 535.9157);
    EXPECT_EQ(f.camera.params[OpenCvModel::kK3], 0.238392);
    EXPECT_EQ(f.camera.frame.height_px, 480);
  }
  const std::string dir = testing::SharedDataDir("opencv_stereo_chessboard_9x6");
  if (dir.empty()) GTEST_SKIP() << "../shared/data absent: the cut-short file is not tried";
  const std::string full = Read(dir + "/left_intrinsics.yml");
  std::string cut;
  std::istringstream in(full);
  int n = 0;
  for (std::string line; n < 30 && std::getline(in, line); ++n) cut += line + "\n";
  const std::string path = tmp.File("left_cut.yml");
  std::ofstream(path) << cut;
  EXPECT_EQ(calib::DetectCameraFormats(path), std::vector<std::string>{"opencv"});
  const CameraFile f = calib::ReadCameraFileAs("auto", path, {});
  const CameraFile whole = tools::ReadOpenCvCamera(dir + "/left_intrinsics.yml", {});
  EXPECT_EQ(f.camera.params, whole.camera.params);
  ASSERT_FALSE(f.notes.empty());
  EXPECT_NE(f.notes[0].find("cut short"), std::string::npos) << f.notes[0];
}

TEST(CameraFormatsOpenCv, PublishedChessboardCalibrationThroughEveryFormatProjectsLikeOpenCv) {
  const std::string dir = testing::SharedDataDir("opencv_stereo_chessboard_9x6");
  if (dir.empty()) GTEST_SKIP() << "../shared/data absent";
  const std::string file = dir + "/left_intrinsics.yml";
  CameraFile cam = tools::ReadOpenCvCamera(file, {});
  // PROVENANCE.md: fx = fy = 535.9157, cx = 342.2832, cy = 235.5708, dist (k1, k2, p1, p2, k3) =
  // (-0.266373, -0.0385889, 0.00178319, -0.000281221, 0.238392), 640 x 480.
  const std::vector<double>& p = cam.camera.params;
  EXPECT_NEAR(p[OpenCvModel::kFx], 535.9157, 5e-5);
  EXPECT_NEAR(p[OpenCvModel::kCy], 235.5708, 5e-5);
  EXPECT_NEAR(p[OpenCvModel::kK3], 0.238392, 5e-7);
  EXPECT_NEAR(p[OpenCvModel::kP2], -0.000281221, 5e-10);
  EXPECT_EQ(cam.camera.frame.width_px, 640);
  EXPECT_FALSE(cam.pixel_size_known);
  cam.camera.frame.pixel_size_mm = 0.006;  // for the mm formats; pixels do not depend on it
  cam.pixel_size_known = true;
  // The board in every view: 9 x 6 corners of 25 mm, the published rvec / tvec per view.
  cv::FileStorage fs(file, cv::FileStorage::READ);
  cv::Mat k, d, extrinsics;
  fs["camera_matrix"] >> k;
  fs["distortion_coefficients"] >> d;
  fs["extrinsic_parameters"] >> extrinsics;
  ASSERT_EQ(extrinsics.rows, 13);
  std::vector<cv::Point3d> board;
  for (int j = 0; j < 6; ++j)
    for (int i = 0; i < 9; ++i) board.emplace_back(0.025 * i, 0.025 * j, 0.0);
  TempDir tmp("aerocal_cli_camera");
  for (const tools::CameraFormat& format : tools::CameraFormats()) {
    SCOPED_TRACE(format.name);
    const calib::FileConversion out = calib::ConvertCameraFile(cam, format.target(cam.camera));
    const std::string path = tmp.File("left." + format.name);
    format.write(path, out.file);
    calib::CameraReadOptions options;
    options.width_px = format.writes_size ? 0 : 640;
    options.height_px = format.writes_size ? 0 : 480;
    options.pixel_size_mm = format.writes_pixel_size ? 0 : 0.006;
    const CameraFile read = format.read(path, options);
    const calib::FileConversion back = calib::ConvertCameraFile(read, {CameraModelId::kOpenCv, {}});
    double worst = 0, worst_back = 0;
    for (int v = 0; v < extrinsics.rows; ++v) {
      const cv::Vec3d rvec(
          extrinsics.at<double>(v, 0), extrinsics.at<double>(v, 1), extrinsics.at<double>(v, 2));
      const cv::Vec3d tvec(
          extrinsics.at<double>(v, 3), extrinsics.at<double>(v, 4), extrinsics.at<double>(v, 5));
      std::vector<cv::Point2d> expected;
      cv::projectPoints(board, rvec, tvec, k, d, expected);
      cv::Matx33d r;
      cv::Rodrigues(rvec, r);
      for (size_t i = 0; i < board.size(); ++i) {
        const cv::Vec3d q = r * cv::Vec3d(board[i].x, board[i].y, board[i].z) + tvec;
        const cv::Point3d qc(q[0], q[1], q[2]);
        worst = std::max(worst, cv::norm(Project(read.camera, qc) - expected[i]));
        worst_back = std::max(worst_back, cv::norm(Project(back.file.camera, qc) - expected[i]));
      }
    }
    std::printf(
        "left_intrinsics.yml -> %-9s (%s, %s): board max %.3g px; back in opencv %.3g px "
        "(stated max %.3g px)\n",
        format.name.c_str(),
        std::string(calib::CameraModelName(read.camera.model)).c_str(),
        out.result.exact ? "exact" : "fit",
        worst,
        worst_back,
        out.result.residual.max_px);
    if (out.result.exact) {
      EXPECT_LT(worst, 1e-9);
      EXPECT_LT(worst_back, 1e-9);
    } else {  // fitted: within the residual the conversion states (plus the fit back)
      EXPECT_LT(worst, out.result.residual.max_px + 1e-9);
      EXPECT_LT(worst_back, 2 * out.result.residual.max_px + 1e-9);
    }
  }
}

TEST(CameraFormatsOpenCv, DjiDewarpDataUndistortedLikeOpenCvWithinTheRefitResidual) {
  // Record A of ../shared/data/dji_dewarpdata_documented (the string verbatim), 5472 x 3648.
  const ModelCamera dji = calib::DjiDewarpDataCamera(
      "2018-09-06;3684.480000000000,3677.570000000000,2.240000000000,22.050000000000,"
      "-0.263482000000,0.106788000000,0.000037110700,-0.000327247000,-0.030078300000",
      {"record A", 1},
      5472,
      3648);
  ModelCamera with_pixel = dji;
  with_pixel.frame.pixel_size_mm = 0.0024;
  const calib::ConversionResult ours =
      calib::ConvertCamera(with_pixel, CameraModelId::kBrownFraser10);
  const std::vector<double>& p = dji.params;
  const cv::Matx33d k(p[0], 0, p[2], 0, p[1], p[3], 0, 0, 1);
  const std::vector<double> d = {p[4], p[5], p[6], p[7], p[8]};
  std::vector<cv::Point2d> pixels, undistorted;
  for (const Eigen::Vector2d& q : calib::FormatGrid(dji.frame, 21))
    pixels.emplace_back(q.x(), q.y());
  cv::undistortPoints(
      pixels,
      undistorted,
      k,
      d,
      cv::noArray(),
      cv::noArray(),
      cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 200, 1e-15));
  // Compared where the refit residual is defined, in measured pixels (OpenCV's undistorted ray
  // re-imaged by our refit), and printed also in undistorted pixels (ideal / c * fy), where the
  // corners are stretched by the undistortion (about 2.3 x at this lens's corners).
  double worst_model = 0, worst_ours = 0, worst_inner = 0, worst_measured = 0;
  const double inner = 0.8 * 0.5 * std::hypot(5472.0, 3648.0);
  for (size_t i = 0; i < pixels.size(); ++i) {
    const Eigen::Vector2d pixel(pixels[i].x, pixels[i].y);
    Eigen::Vector2d ideal_opencv, ideal_ours;
    ASSERT_TRUE(with_pixel.IdealFromPixel(pixel, &ideal_opencv));
    ASSERT_TRUE(ours.camera.IdealFromPixel(pixel, &ideal_ours));
    const Eigen::Vector2d cv_n(undistorted[i].x, -undistorted[i].y);  // y up
    const double fy = p[1];
    const double e_model = (ideal_opencv / with_pixel.PrincipalDistanceMm() - cv_n).norm() * fy;
    const double e_ours = (ideal_ours / ours.camera.PrincipalDistanceMm() - cv_n).norm() * fy;
    worst_model = std::max(worst_model, e_model);
    Eigen::Vector2d reimaged;
    ASSERT_TRUE(ours.camera.PixelFromIdeal(cv_n * ours.camera.PrincipalDistanceMm(), &reimaged));
    worst_measured = std::max(worst_measured, (reimaged - pixel).norm());
    worst_ours = std::max(worst_ours, e_ours);
    if ((pixel - Eigen::Vector2d(2735.5, 1823.5)).norm() <= inner)
      worst_inner = std::max(worst_inner, e_ours);
  }
  std::printf(
      "DJI record A: our opencv model vs cv::undistortPoints %.3g px; our 10-parameter "
      "refit: %.3g px measured (refit residual max %.3g px), %.3g px undistorted (within "
      "80 %%: %.3g px)\n",
      worst_model,
      worst_measured,
      ours.residual.max_px,
      worst_ours,
      worst_inner);
  EXPECT_LT(worst_model, 1e-6);  // the same model: agreement to the iterations' tolerance
  EXPECT_LT(worst_measured, ours.residual.max_px + 1e-6);
  EXPECT_LT(worst_inner, 2.5 * ours.residual.max_inner80_px);
}

// ---- the command line ----

void WriteAerialCamera(const std::string& path) {
  std::ofstream(path)
      << "name: aerial\npixel_size_mm: 0.009\nformat_px: [14000, 12000]\n"
         "interior: {c: 170.038, x0: -0.0024, y0: 0.0015, K1: 3.0e-8, K2: -2.0e-12, "
         "K3: 1.0e-16, P1: 2.0e-7, P2: -1.5e-7, B1: 1.0e-5, B2: -8.0e-6}\n"
         "interior_sigma: {c: 0.002, x0: 0.001}\n";
}

TEST(CliCamera, ConvertsOursIntoEveryFormatAndBackWithAReport) {
  TempDir tmp("aerocal_cli_camera");
  const std::string ours = tmp.File("cam.yaml");
  WriteAerialCamera(ours);
  for (const tools::CameraFormat& format : tools::CameraFormats()) {
    SCOPED_TRACE(format.name);
    const std::string out = tmp.File("cam." + format.name),
                      report = tmp.File(format.name + ".json");
    auto r = RunAerocal("camera convert --from aerocal --to " + format.name + " " + ours + " " +
                        out + " --report " + report);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find("residual over the format"), std::string::npos) << r.output;
    const auto json = nlohmann::json::parse(Read(report));
    for (const char* key : {"exact", "acceptable", "model", "residual_px", "notes"})
      EXPECT_TRUE(json.contains(key)) << key;
    for (const char* key : {"max", "rms", "max_inner80", "max_at"})
      EXPECT_TRUE(json["residual_px"].contains(key)) << key;
    // Ours and Australis are the same model (exact); PhotoModeler and DBAT lack B1, B2 (a fit).
    EXPECT_EQ(json["exact"].get<bool>(), format.name == "aerocal" || format.name == "australis");
    EXPECT_LT(json["residual_px"]["max"].get<double>(), 0.1);
    // Covariance: kept as interior_sigma in ours, carried into Metashape, said when dropped.
    const std::string notes = json["notes"].dump();
    if (format.name != "aerocal" && format.name != "metashape" && format.name != "australis") {
      EXPECT_NE(notes.find("covariance dropped"), std::string::npos) << notes;
    }
    if (format.name == "metashape") {
      EXPECT_NE(Read(out).find("<covariance>"), std::string::npos);
    }
    const std::string extra = !format.writes_size        ? " --width 14000 --height 12000"
                              : format.writes_pixel_size ? ""
                                                         : " --pixel-size-mm 0.009";
    // Back with --from auto: every file we write is detected as its own format.
    r = RunAerocal("camera convert --from auto --to aerocal --model brown10 " + out + " " +
                   tmp.File("back_" + format.name + ".yaml") + extra);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find("read as " + format.name + " (--from auto)"), std::string::npos)
        << r.output;
  }
}

TEST(CliCamera, ShowPrintsOurConventionAndWritesThePlot) {
  TempDir tmp("aerocal_cli_camera");
  const std::string dji = tmp.File("dji.txt");
  std::ofstream(dji) << "2018-09-06;3684.48,3677.57,2.24,22.05,-0.263482,0.106788,3.71107e-5,"
                        "-3.27247e-4,-0.0300783\n";
  const auto r = RunAerocal("camera show --from dji " + dji +
                            " --width 5472 --height 3648 "
                            "--pixel-size-mm 0.0024 --plot " +
                            tmp.File("d.svg"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("our convention"), std::string::npos) << r.output;
  // x0 = (2738.24 - 2735.5) px = 2.74 px from the centre.
  EXPECT_NE(r.output.find("2.74 px from the centre"), std::string::npos) << r.output;
  const std::string svg = Read(tmp.File("d.svg"));
  EXPECT_NE(svg.find("<svg"), std::string::npos);
  // Readable without a caption: both panels on axes, the vectors with a scale bar.
  for (const char* text : {"|distortion| (px)", "column (px)", "row (px)", "px of distortion"})
    EXPECT_NE(svg.find(text), std::string::npos) << text;
  // The stereo file's second camera.
  const std::string data = testing::SharedDataDir("opencv_stereo_chessboard_9x6");
  if (!data.empty()) {
    const auto s = RunAerocal("camera show --from opencv " + data +
                              "/intrinsics.yml --camera 2 "
                              "--width 640 --height 480");
    EXPECT_EQ(s.exit_code, 0) << s.output;
    EXPECT_NE(s.output.find("334.557445279"), std::string::npos) << s.output;
  }
}

TEST(CliCamera, MaxResidualTurnsABadFitIntoExit3AndWritesNothing) {
  TempDir tmp("aerocal_cli_camera");
  const std::string dji = tmp.File("dji.txt");
  std::ofstream(dji)
      << "3684.48,3677.57,2.24,22.05,-0.263482,0.106788,3.71107e-5,-3.27247e-4,-0.0300783\n";
  const auto r = RunAerocal("camera convert --from dji --to aerocal --model brown10 " + dji + " " +
                            tmp.File("ours.yaml") +
                            " --width 5472 --height 3648 --pixel-size-mm 0.0024 "
                            "--max-residual-px 5 --report " +
                            tmp.File("r.json"));
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find("conversion_residual"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(tmp.File("ours.yaml")));
  const auto json = nlohmann::json::parse(Read(tmp.File("r.json")));
  EXPECT_FALSE(json["acceptable"].get<bool>());
  EXPECT_GT(json["residual_px"]["max"].get<double>(), 5.0);
  // Kept in its own model (no --model) it is exact.
  const auto exact =
      RunAerocal("camera convert --from dji --to aerocal " + dji + " " + tmp.File("dji.yaml") +
                 " --width 5472 --height 3648 --pixel-size-mm 0.0024");
  EXPECT_EQ(exact.exit_code, 0) << exact.output;
  EXPECT_NE(exact.output.find("exact (closed form)"), std::string::npos) << exact.output;
  EXPECT_NE(Read(tmp.File("dji.yaml")).find("model: opencv"), std::string::npos);
}

// Issue 30 item 1: --model picks one of the models the --to format's registry row lists (COLMAP's
// RADIAL here: exact from a camera already in it); a model the format does not write is exit 2
// naming the option, the format and the model, and OUT is left as it was.
TEST(CliCamera, ModelMustBeOneTheFormatWrites) {
  TempDir tmp("aerocal_cli_camera_model");
  const std::string colmap = tmp.File("cameras.txt"), out = tmp.File("out.txt");
  std::ofstream(colmap) << "1 RADIAL 640 480 500 320 240 -0.1 0.01\n";
  const auto radial = RunAerocal("camera convert --from colmap --to colmap --model colmap_radial " +
                                 colmap + " " + out + " --pixel-size-mm 0.006");
  ASSERT_EQ(radial.exit_code, 0) << radial.output;
  EXPECT_NE(Read(out).find("RADIAL 640 480"), std::string::npos) << Read(out);
  const std::string kalibr = tmp.File("camchain.yaml");
  std::ofstream(kalibr) << "previous\n";
  const auto refused = RunAerocal("camera convert --from colmap --to kalibr --model brown10 " +
                                  colmap + " " + kalibr + " --pixel-size-mm 0.006");
  EXPECT_EQ(refused.exit_code, 2) << refused.output;
  EXPECT_NE(refused.output.find("--model brown10: the kalibr format cannot hold a brown_fraser_10 "
                                "camera (it writes opencv, opencv_fisheye)"),
            std::string::npos)
      << refused.output;
  EXPECT_EQ(Read(kalibr), "previous\n");
}

// Issue 37 class 3: the same fit (max > 5 px) without --max-residual-px is refused by the default
// limit of 1 px (a camera missing by more is not the one read); a larger limit, given, accepts it.
TEST(CliCamera, AFitMissingByMoreThanAPixelIsExit3WithoutAGate) {
  TempDir tmp("aerocal_cli_camera_default_limit");
  const std::string dji = tmp.File("dji.txt");
  std::ofstream(dji)
      << "3684.48,3677.57,2.24,22.05,-0.263482,0.106788,3.71107e-5,-3.27247e-4,-0.0300783\n";
  const std::string args = "camera convert --from dji --to aerocal --model brown10 " + dji + " " +
                           tmp.File("ours.yaml") +
                           " --width 5472 --height 3648 --pixel-size-mm 0.0024 --report " +
                           tmp.File("r.json");
  const auto refused = RunAerocal(args);
  EXPECT_EQ(refused.exit_code, 3) << refused.output;
  EXPECT_NE(refused.output.find("conversion_residual"), std::string::npos) << refused.output;
  EXPECT_NE(refused.output.find("exceeds the default limit 1 px"), std::string::npos)
      << refused.output;
  EXPECT_FALSE(fs::exists(tmp.File("ours.yaml")));
  EXPECT_FALSE(nlohmann::json::parse(Read(tmp.File("r.json")))["acceptable"].get<bool>());
  const auto accepted = RunAerocal(args + " --max-residual-px 1000");
  EXPECT_EQ(accepted.exit_code, 0) << accepted.output;
  EXPECT_TRUE(fs::exists(tmp.File("ours.yaml")));
  const auto json = nlohmann::json::parse(Read(tmp.File("r.json")));
  EXPECT_TRUE(json["acceptable"].get<bool>());
  EXPECT_GT(json["residual_px"]["max"].get<double>(), 1.0);
}

}  // namespace
}  // namespace aerocal
