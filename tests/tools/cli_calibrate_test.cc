// aerocal calibrate and aerocal certificate on real data (skipped when ../shared/data is absent):
// OpenCV's chessboard images against cv::calibrateCamera on the same corners and the published
// Bouguet / OpenCV results; the DBAT Olympus test field (started from aerocal's own resections)
// against DBAT's published calibration, in three image groups; the certificate from it (JSON,
// HTML, PDF rendered to PNG), deterministic; bad input with exit 2 and nothing written.
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"
#include "tests/support/test_support.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>

namespace aerocal {
namespace {

using testing::RunAerocal;
using testing::RunCommand;
using testing::SharedDataDir;
using testing::TempDir;

nlohmann::json ReadJson(const std::string& path) { return aerocal::testing::ReadJson(path); }

void WriteText(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

TEST(CalibrateCommand, OpenCvModelOnTheChessboardEqualsCalibrateCamera) {
  // Issue 14's acceptance: the camera file in the OpenCV model, the board held (--board-sigma-mm
  // 1e-6: cv::calibrateCamera takes the board as exact), no snooping: aerocal's bundle adjustment
  // in that model and cv::calibrateCamera on the same corners give the same RMS and intrinsics to
  // 1e-4 relative (measured: RMS 1.6e-7, worst parameter k2 9e-5, fx 4e-8).
  const std::string dir = SharedDataDir("opencv_stereo_chessboard_9x6");
  if (dir.empty()) GTEST_SKIP() << "../shared/data/opencv_stereo_chessboard_9x6 is absent";
  TempDir tmp("aerocal_calibrate_cv_model");
  WriteText(tmp.File("camera.yaml"),
            "name: left\nmodel: opencv\npixel_size_mm: 0.006\nformat_px: [640, 480]\n"
            "interior: {fx: 500, fy: 500, cx: 319.5, cy: 239.5}\n");
  const auto r =
      RunAerocal("calibrate --camera " + tmp.File("camera.yaml") + " --images '" + dir +
                 "/left*.jpg' --board chessboard:9x6:25 --board-sigma-mm 1e-6 --self-calibration "
                 "fx,fy,cx,cy,k1,k2,p1,p2,k3 --model opencv --no-snooping --out " +
                 tmp.File("cv.json"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto j = ReadJson(tmp.File("cv.json"));
  EXPECT_EQ(j["cameras"][0]["model"], "opencv");
  const auto& ours = j["cameras"][0]["estimated"];
  const auto& cv = j["calibration"]["opencv"];
  for (const char* p : {"fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3"})
    EXPECT_NEAR(ours[p].get<double>(), cv[p].get<double>(), 1e-4 * std::abs(cv[p].get<double>()))
        << p;
  EXPECT_NEAR(j["calibration"]["rms_px"].get<double>(),
              cv["rms_px"].get<double>(),
              1e-4 * cv["rms_px"].get<double>());

  // Its certificate draws the OpenCV camera's own distortion (computed in its model, not restated
  // by the renderer): this lens's strong barrel distortion (k1 ~ -0.28) is a large outward
  // correction at the corners, not the flat zero curve a 10-parameter formula would draw.
  const auto c =
      RunAerocal("certificate --result " + tmp.File("cv.json") + " --out " + tmp.File("cert"));
  ASSERT_LE(c.exit_code, 3) << c.output;
  const auto cert = ReadJson(tmp.File("cert/certificate.json"));
  // No lab file: a draft, not called a certificate (issue 33 item 2).
  const std::string draft = ReadTextFile(tmp.File("cert/certificate.html"));
  EXPECT_NE(draft.find("<h1>DRAFT calibration report (no laboratory file: not a certificate)</h1>"),
            std::string::npos);
  EXPECT_EQ(draft.find("Calibration certificate"), std::string::npos);
  EXPECT_EQ(draft.find("Signatures"), std::string::npos);
  const auto& d = cert["distortion"];
  ASSERT_TRUE(d.is_object()) << cert.dump().substr(0, 400);
  EXPECT_EQ(d["profile_kind"], "mean over directions");
  EXPECT_EQ(d["grid"].size(), 99u);
  EXPECT_GT(d["profile"].back()[1].get<double>(), 50.0);  // um at the half diagonal
  EXPECT_TRUE(std::filesystem::exists(tmp.File("cert/certificate.pdf")));
}

TEST(CalibrateCommand, OpenCvChessboardAgainstCalibrateCameraAndThePublishedResults) {
  const std::string dir = SharedDataDir("opencv_stereo_chessboard_9x6");
  if (dir.empty()) GTEST_SKIP() << "../shared/data/opencv_stereo_chessboard_9x6 is absent";
  TempDir tmp("aerocal_calibrate_cv");
  WriteText(tmp.File("camera.yaml"),
            "name: left\npixel_size_mm: 0.006\nformat_px: [640, 480]\ninterior: {c: 3.0}\n");
  const auto r =
      RunAerocal("calibrate --camera " + tmp.File("camera.yaml") + " --images '" + dir +
                 "/left*.jpg' --board chessboard:9x6:25 --model opencv --write-marks " +
                 tmp.File("marks") + " --out " + tmp.File("left.json") + " --write-camera " +
                 tmp.File("left_calibrated.yml") + " --camera-format opencv");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto j = ReadJson(tmp.File("left.json"));
  for (const char* key : {"kind",
                          "sigma0",
                          "sigma0_px",
                          "sigma0_um",
                          "redundancy",
                          "iterations",
                          "converged",
                          "cameras",
                          "control",
                          "check",
                          "exposures",
                          "rejected",
                          "calibration"})
    EXPECT_TRUE(j.contains(key)) << key;
  const auto& cal = j["calibration"];
  EXPECT_EQ(cal["method"]["detected"].size(), 13u);  // left01..14 without 10
  EXPECT_EQ(cal["data"]["observations"].get<int>(), 13 * 54);
  EXPECT_TRUE(std::filesystem::exists(tmp.File("marks/observations.csv")));
  // --model opencv --camera-format opencv: the run's OpenCV-model estimate is what is written
  // (issue 29), exactly, not a refit of our 10-parameter camera.
  const auto& written = cal["camera_written"];
  EXPECT_EQ(written["format"].get<std::string>(), "opencv");
  EXPECT_EQ(written["model"].get<std::string>(), "opencv");
  EXPECT_TRUE(written["exact"].get<bool>());
  EXPECT_LT(written["residual_px"]["max"].get<double>(), 1e-6);
  EXPECT_NE(ReadTextFile(tmp.File("left_calibrated.yml")).find("camera_matrix"), std::string::npos);
  const auto& est = j["cameras"][0]["estimated"];
  const double p = 0.006;
  const double f_px = est["c"].get<double>() / p;
  const double cx = est["x0"].get<double>() / p + 319.5, cy = -est["y0"].get<double>() / p + 239.5;
  const auto& cv = cal["opencv"];
  std::printf(
      "aerocal: f %.3f cx %.3f cy %.3f RMS %.4f px | cv::calibrateCamera: fx %.3f fy %.3f cx %.3f "
      "cy %.3f RMS %.4f px\n",
      f_px,
      cx,
      cy,
      cal["rms_px"].get<double>(),
      cv["fx"].get<double>(),
      cv["fy"].get<double>(),
      cv["cx"].get<double>(),
      cv["cy"].get<double>(),
      cv["rms_px"].get<double>());
  // Same corners, different distortion models (correction form vs OpenCV's forward form) and a
  // common c for fx, fy: the principal distance within 0.2 %, the principal point within 1 px,
  // the RMS within 10 %.
  EXPECT_NEAR(f_px / (0.5 * (cv["fx"].get<double>() + cv["fy"].get<double>())), 1.0, 2e-3);
  EXPECT_NEAR(cx, cv["cx"].get<double>(), 1.0);
  EXPECT_NEAR(cy, cv["cy"].get<double>(), 1.0);
  EXPECT_NEAR(cal["rms_px"].get<double>() / cv["rms_px"].get<double>(), 1.0, 0.10);
  // Published: Bouguet fx 533.00, fy 533.15, cx 341.59, cy 234.26 (14 images, his corners);
  // OpenCV's sample fx = fy 535.92, cx 342.28, cy 235.57 (fixed aspect, its corners).
  EXPECT_NEAR(f_px / 533.08, 1.0, 5e-3);
  EXPECT_NEAR(f_px / 535.92, 1.0, 1e-2);
  EXPECT_NEAR(cx, 341.59, 2.0);
  EXPECT_NEAR(cy, 234.26, 2.0);
  // The budget states c with U and k.
  bool stated = false;
  for (const auto& q : cal["uncertainty"])
    stated =
        stated || (q["quantity"] == "c" && q["U"].get<double>() > 0 && q["k"].get<double>() >= 2.0);
  EXPECT_TRUE(stated);
}

class OlympusCalibration : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = SharedDataDir("dbat_camcal_olympus_c4040z");
    if (dir_.empty()) GTEST_SKIP() << "../shared/data/dbat_camcal_olympus_c4040z is absent";
    // The block files from the DBAT marks (the importer needs stations; calibrate ignores them).
    const auto imp = RunAerocal(
        "import dbat --camera-xml " + dir_ + "/c4040z.xml --marks " + dir_ +
        "/measurements/markpts.txt --images " + dir_ + "/images/images.txt --control " + dir_ +
        "/reference/camcal-fixed.txt --control-sigma-m 1e-6 --photomodeler-export " + dir_ +
        "/photomodeler/camcal-pmexport.txt --out " + tmp_.File("oly"));
    ASSERT_EQ(imp.exit_code, 0) << imp.output;
    std::string groups = "image,group\n";
    for (int i = 21; i <= 41; ++i)
      groups += "P82500" + std::to_string(i) + ",G" + std::to_string(i % 3 + 1) + "\n";
    WriteText(tmp_.File("groups.csv"), groups);
  }
  std::string Calibrate(const std::string& extra) {
    return "calibrate --camera " + tmp_.File("oly/camera_cam1.yaml") + " --observations " +
           tmp_.File("oly/observations.csv") + " --points " + tmp_.File("oly/points.csv") +
           " --self-calibration c,x0,y0,K1,K2,K3,P1,P2,B1 --no-snooping " + extra;
  }
  std::string dir_;
  TempDir tmp_{"aerocal_calibrate_oly"};
};

TEST_F(OlympusCalibration, PublishedDbatValuesWithinThreeSigmaAndGroupStability) {
  const auto r = RunAerocal(
      Calibrate("--groups " + tmp_.File("groups.csv") + " --out " + tmp_.File("oly.json")));
  // The three groups of 7 images do not agree within their sigmas (y0, P2, ...): flagged, exit 3.
  ASSERT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find("warning: group_stability"), std::string::npos);
  const auto j = ReadJson(tmp_.File("oly.json"));
  const auto& cal = j["calibration"];
  EXPECT_EQ(cal["start"]["resections"].size(), 21u);
  EXPECT_EQ(cal["groups"].size(), 3u);
  EXPECT_EQ(cal["stability"]["rows"].size(), 9u);
  EXPECT_FALSE(cal["stability"]["agree"].get<bool>());
  // The test's sensitivity per group: the change detected with 80 % power, more than twice the
  // group's own sigma, largest for the least precise group (group_change_power.h).
  EXPECT_EQ(cal["stability"]["power"].get<double>(), 0.8);
  for (const auto& row : cal["stability"]["rows"]) {
    const auto& d = row["detectable_change"];
    const auto& s = row["sigmas"];
    ASSERT_EQ(d.size(), 3u) << row["parameter"];
    int least_precise = 0, largest_change = 0;
    for (int g = 0; g < 3; ++g) {
      EXPECT_GT(d[g].get<double>(), 2 * s[g].get<double>()) << row["parameter"];
      if (s[g].get<double>() > s[least_precise].get<double>()) least_precise = g;
      if (d[g].get<double>() > d[largest_change].get<double>()) largest_change = g;
    }
    EXPECT_EQ(largest_change, least_precise) << row["parameter"];
  }
  const auto& est = j["cameras"][0]["estimated"];
  const auto& sig = j["cameras"][0]["sigma"];
  // DBAT 0.9.2.0 (PROVENANCE.md): c 7.45700, pp 3.61546 / 2.61329 mm from the top-left corner,
  // K1 4.58861e-3, K2 -4.51351e-5, K3 -2.05253e-6, P1 -6.12803e-5, P2 -4.41171e-5.
  const double p = 0.0031911032863849768;
  const std::map<std::string, double> published = {{"c", 7.45700},
                                                   {"x0", 3.61546 - 2272 * p / 2},
                                                   {"y0", 1704 * p / 2 - 2.61329},
                                                   {"K1", 4.58861e-3},
                                                   {"K2", -4.51351e-5},
                                                   {"K3", -2.05253e-6},
                                                   {"P1", -6.12803e-5},
                                                   {"P2", -4.41171e-5}};
  for (const auto& [name, value] : published) {
    SCOPED_TRACE(name);
    EXPECT_LE(std::abs(est[name].get<double>() - value), 3.0 * sig[name].get<double>())
        << est[name].get<double>() << " sigma " << sig[name].get<double>();
  }
  EXPECT_NEAR(j["sigma0_px"].get<double>() / 0.16148, 1.0, 0.10);
}

TEST_F(OlympusCalibration, CertificateJsonHtmlAndPdfDeterministic) {
  // The pitch's tolerance from the budget file: a type-B component of every length (issue 33).
  WriteText(tmp_.File("budget.yaml"), "pixel_size_tolerance_mm: 3.2e-6\n");
  const auto r = RunAerocal(
      Calibrate("--budget " + tmp_.File("budget.yaml") + " --out " + tmp_.File("oly.json")));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  WriteText(tmp_.File("lab.yaml"),
            "lab: {name: Test Lab, address: 1 Road, accreditation: none}\n"
            "certificate: {number: T-1, date: 2026-11-24}\n"
            "camera: {make: Olympus, model: C4040Z, serial: '123'}\n"
            "signatures: {calibrated_by: A, checked_by: B, approved_by: C}\n");
  WriteText(tmp_.File("tol.yaml"), "c: 0.001\nx0: 0.001\n");
  const std::string args = "certificate --result " + tmp_.File("oly.json") + " --lab " +
                           tmp_.File("lab.yaml") + " --previous " + tmp_.File("oly.json") +
                           " --tolerances " + tmp_.File("tol.yaml");
  const auto c1 = RunAerocal(args + " --out " + tmp_.File("cert1"));
  ASSERT_EQ(c1.exit_code, 0) << c1.output;
  EXPECT_NE(c1.output.find("c = 7.457"), std::string::npos) << c1.output;
  const auto cert = ReadJson(tmp_.File("cert1/certificate.json"));
  EXPECT_EQ(cert["kind"], "certificate");
  EXPECT_TRUE(cert["comparison"]["pass"].get<bool>());  // against itself: differences 0
  EXPECT_EQ(cert["comparison"]["rows"][0]["criterion"], "|difference| <= tolerance");
  // The comparison judges the camera; sigma0 (m_0) and the check RMSEs are the run's, not judged.
  for (const auto& row : cert["comparison"]["rows"]) {
    const std::string q = row["quantity"];
    EXPECT_EQ(row["judged"].get<bool>(), q != "m_0" && q != "m_X" && q != "m_Y" && q != "m_Z") << q;
  }
  const std::string html = ReadTextFile(tmp_.File("cert1/certificate.html"));
  for (const char* text : {"Calibration certificate",
                           "T-1",
                           "Uncertainty budget",
                           "<img class=\"figure\" alt=\"figure\" src=\"data:image/svg+xml;base64,",
                           "Stability over image groups",
                           "Check points",
                           "Comparison with the previous certificate",
                           "Signatures",
                           "c = 7.457",
                           // the budget's components and where each comes from
                           "Sources of the components",
                           "Type A (statistical, from this calibration&#x27;s data): image "
                           "measurements",
                           "<td>control coordinates</td><td>B</td>",
                           "survey sigmas of",
                           "<td>pixel pitch</td><td>B</td>",
                           "stated in the budget file"})
    EXPECT_NE(html.find(text), std::string::npos) << text;
  // c's pitch component: c 7.457 mm times 3.2e-6 / 0.00319 / sqrt 3 (0.1 % of the pitch).
  for (const auto& q : cert["results"])
    if (q["quantity"] == "c")
      for (const auto& comp : q["components"])
        if (comp["source"] == "pixel pitch") {  // braces: EXPECT_NEAR is an if/else macro
          EXPECT_NEAR(comp["u"].get<double>(),
                      q["value"].get<double>() * 3.2e-6 / 0.0031911032863849768 / std::sqrt(3.0),
                      1e-9);
        }
  // Deterministic: a second run writes the same bytes.
  const auto c2 = RunAerocal(args + " --out " + tmp_.File("cert2"));
  ASSERT_EQ(c2.exit_code, 0) << c2.output;
  for (const char* f : {"certificate.json", "certificate.html", "certificate.pdf"}) {
    SCOPED_TRACE(f);
    EXPECT_EQ(ReadTextFile(tmp_.File(std::string("cert1/") + f)),
              ReadTextFile(tmp_.File(std::string("cert2/") + f)));
  }
  // Last year's certificate as it was issued (schema 2, before the per-head tables) still
  // compares; an older version is refused by name.
  nlohmann::json issued = cert;
  issued["schema_version"] = 2;
  issued.erase("heads");
  issued.erase("comparison");
  WriteText(tmp_.File("issued.json"), issued.dump(1));
  const std::string against_issued = "certificate --no-render --result " + tmp_.File("oly.json") +
                                     " --lab " + tmp_.File("lab.yaml") + " --previous " +
                                     tmp_.File("issued.json") + " --tolerances " +
                                     tmp_.File("tol.yaml");
  const auto c3 = RunAerocal(against_issued + " --out " + tmp_.File("cert3"));
  ASSERT_EQ(c3.exit_code, 0) << c3.output;
  EXPECT_TRUE(ReadJson(tmp_.File("cert3/certificate.json"))["comparison"]["pass"].get<bool>());
  issued["schema_version"] = 1;
  WriteText(tmp_.File("issued.json"), issued.dump(1));
  const auto c4 = RunAerocal(against_issued + " --out " + tmp_.File("cert4"));
  EXPECT_EQ(c4.exit_code, 2) << c4.output;
  EXPECT_NE(c4.output.find("issued.json: schema_version is 1, expected 3"), std::string::npos)
      << c4.output;
  // Every PDF page rendered to PNG (poppler's pdftoppm).
  if (RunCommand("command -v pdftoppm").exit_code != 0)
    GTEST_SKIP()
        << "pdftoppm is absent (Debian package poppler-utils): the PDF pages are not rendered";
  const auto png = RunCommand("pdftoppm -r 40 -png " + tmp_.File("cert1/certificate.pdf") + " " +
                              tmp_.File("page"));
  ASSERT_EQ(png.exit_code, 0) << png.output;
  int pages = 0;
  for (const auto& e : std::filesystem::directory_iterator(tmp_.path()))
    if (e.path().extension() == ".png" && std::filesystem::file_size(e.path()) > 1000) ++pages;
  EXPECT_GE(
      pages,
      5);  // identification + results + budget, distortion, residuals, stability .. signatures
}

TEST_F(OlympusCalibration, StatedImageSigmaScaleIsAbsorbedBySigma0) {
  // Issue 33 (the a-priori image sigma in the budget, tools/certificate/README.md): every stated
  // image sigma times 3 gives sigma0 / 3 and the same image component and U of every certified
  // quantity: the scale cancels in sigma0^2 Q N_image Q, so no type B component counts it. Exact
  // with the images the only weights; here the control (1e-6 m) mixes in at 1.3e-4 relative
  // (seen), hence 1e-3.
  constexpr double kMixing = 1e-3;
  const CsvTable obs = CsvTable::Read(tmp_.File("oly/observations.csv"));
  std::ofstream out(tmp_.File("oly/observations_x3.csv"));
  for (size_t i = 0; i < obs.header().size(); ++i) out << (i ? "," : "") << obs.header()[i];
  out << "\n";
  for (const auto& row : obs.rows())
    for (size_t i = 0; i < obs.header().size(); ++i) {
      const std::string& key = obs.header()[i];
      out << (i ? "," : "")
          << (key == "sigma_px" ? FormatNumber(3 * obs.Number(row, key)) : obs.String(row, key))
          << (i + 1 == obs.header().size() ? "\n" : "");
    }
  out.close();
  nlohmann::json results[2];
  const char* files[2] = {"oly/observations.csv", "oly/observations_x3.csv"};
  for (int k = 0; k < 2; ++k) {
    const auto r =
        RunAerocal("calibrate --camera " + tmp_.File("oly/camera_cam1.yaml") + " --observations " +
                   tmp_.File(files[k]) + " --points " + tmp_.File("oly/points.csv") +
                   " --self-calibration c,x0,y0,K1,K2,K3,P1,P2,B1 --no-snooping --out " +
                   tmp_.File("x" + std::to_string(k) + ".json"));
    ASSERT_EQ(r.exit_code, 0) << r.output;
    results[k] = ReadJson(tmp_.File("x" + std::to_string(k) + ".json"));
  }
  EXPECT_NEAR(results[1]["sigma0"].get<double>() * 3,
              results[0]["sigma0"].get<double>(),
              kMixing * results[0]["sigma0"].get<double>());
  const auto& a = results[0]["calibration"]["uncertainty"];
  const auto& b = results[1]["calibration"]["uncertainty"];
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    if (a[i]["quantity"] == "m_0") continue;  // sigma0 itself, in um: scales with the sigmas
    const double u = a[i]["components"][0]["u"], u3 = b[i]["components"][0]["u"];
    EXPECT_EQ(a[i]["components"][0]["source"], b[i]["components"][0]["source"]);
    EXPECT_NEAR(u3, u, kMixing * u) << a[i]["quantity"];
    EXPECT_NEAR(b[i]["U"].get<double>(), a[i]["U"].get<double>(), kMixing * a[i]["U"].get<double>())
        << a[i]["quantity"];
  }
}

TEST_F(OlympusCalibration, GroupColumnOfTheObservationsGivesTheSameGroups) {
  // The groups as a `group` column of observations.csv instead of --groups: the same three groups
  // of 7 images, the same per-group results; both at once is a bad input.
  const CsvTable obs = CsvTable::Read(tmp_.File("oly/observations.csv"));
  std::ofstream out(tmp_.File("oly/observations_grouped.csv"));
  for (size_t i = 0; i < obs.header().size(); ++i) out << (i ? "," : "") << obs.header()[i];
  out << ",group\n";
  for (const auto& row : obs.rows()) {
    for (size_t i = 0; i < obs.header().size(); ++i)
      out << (i ? "," : "") << obs.String(row, obs.header()[i]);
    const int number = std::stoi(obs.String(row, "image").substr(6));
    out << ",G" << number % 3 + 1 << "\n";
  }
  out.close();
  const std::string grouped = "calibrate --camera " + tmp_.File("oly/camera_cam1.yaml") +
                              " --observations " + tmp_.File("oly/observations_grouped.csv") +
                              " --points " + tmp_.File("oly/points.csv") +
                              " --self-calibration c,x0,y0,K1,K2,K3,P1,P2,B1 --no-snooping ";
  const auto r = RunAerocal(grouped + "--out " + tmp_.File("col.json"));
  ASSERT_EQ(r.exit_code, 3) << r.output;  // the groups disagree, as with --groups
  const auto a = ReadJson(tmp_.File("col.json"));
  ASSERT_EQ(a["calibration"]["groups"].size(), 3u);
  for (const auto& g : a["calibration"]["groups"]) EXPECT_EQ(g["images"].size(), 7u);
  const auto both = RunAerocal(grouped + "--groups " + tmp_.File("groups.csv") + " --out " +
                               tmp_.File("both.json"));
  EXPECT_EQ(both.exit_code, 2) << both.output;
  EXPECT_NE(both.output.find("has a group column already"), std::string::npos) << both.output;
  EXPECT_FALSE(std::filesystem::exists(tmp_.File("both.json")));
}

TEST(CalibrateCommand, BadInputExitsTwoAndWritesNothing) {
  TempDir tmp("aerocal_calibrate_bad");
  WriteText(tmp.File("camera.yaml"),
            "name: c\npixel_size_mm: 0.006\nformat_px: [640, 480]\ninterior: {c: 3.0}\n");
  WriteText(tmp.File("points.csv"),
            "point,X,Y,Z,sX,sY,sZ,role\nA,0,0,0,0.001,0.001,0.001,control\n");
  WriteText(tmp.File("obs.csv"), "image,point,col,row,sigma_px\ni1,A,10,10,0.5\ni1,B,abc,20,0.5\n");
  WriteText(tmp.File("few.csv"), "image,point,col,row,sigma_px\ni1,A,10,10,0.5\ni1,B,20,20,0.5\n");
  auto r =
      RunAerocal("calibrate --camera " + tmp.File("camera.yaml") + " --images '" +
                 tmp.File("*.jpg") + "' --board chessboard:9:25 --out " + tmp.File("out.json"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--board"), std::string::npos) << r.output;
  r = RunAerocal("calibrate --camera " + tmp.File("camera.yaml") + " --observations " +
                 tmp.File("obs.csv") + " --points " + tmp.File("points.csv") + " --out " +
                 tmp.File("out.json"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("obs.csv:3"), std::string::npos) << r.output;  // col is not a number
  r = RunAerocal("calibrate --camera " + tmp.File("camera.yaml") + " --observations " +
                 tmp.File("few.csv") + " --points " + tmp.File("points.csv") + " --out " +
                 tmp.File("out.json"));
  EXPECT_EQ(r.exit_code, 2) << r.output;  // one control point: no resection
  EXPECT_NE(r.output.find("no starting orientation by resection for i1"), std::string::npos)
      << r.output;
  r = RunAerocal("calibrate --camera " + tmp.File("camera.yaml") + " --observations " +
                 tmp.File("obs.csv") + " --images x --board chessboard:9x6:25 --out " +
                 tmp.File("out.json"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  for (const char* bad : {"0", "-1", "nan", "2e3"}) {  // issue 28: the effect limit, by name
    r = RunAerocal("calibrate --camera " + tmp.File("camera.yaml") + " --observations " +
                   tmp.File("few.csv") + " --points " + tmp.File("points.csv") +
                   " --suspect-effect-limit " + bad + " --out " + tmp.File("out.json"));
    EXPECT_EQ(r.exit_code, 2) << bad << ": " << r.output;
    EXPECT_NE(r.output.find("suspect"), std::string::npos) << r.output;
  }
  r = RunAerocal("certificate --result " + tmp.File("points.csv") + " --out " + tmp.File("cert"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_FALSE(std::filesystem::exists(tmp.File("out.json")));
  EXPECT_FALSE(std::filesystem::exists(tmp.File("cert/certificate.json")));
}

}  // namespace
}  // namespace aerocal
