// Camera files in other tools' formats (calib/camera/formats/, issue 15): every format's writer and
// reader round-trip a camera of its model exactly; ours -> format -> ours for the simulated aerial
// camera and a strong drone lens, with the residual each conversion states; the real files of
// ../shared/data against their published values; the covariance carried through a conversion.
// (The OpenCV FileStorage format and cv::projectPoints / undistortPoints: tests/tools/.)
#include "calib/camera/formats/camera_formats.h"

#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"
#include "tests/support/test_support.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <regex>
#include <sstream>

namespace aerocal::calib {
namespace {

using testing::TempDir;

// The simulated flight's aerial camera (as in convert_camera_test): 14000 x 12000 px of 9 um.
ModelCamera AerialCamera() {
  return {CameraModelId::kBrownFraser10,
          {170.038, -0.0024, 0.0015, 3.0e-8, -2.0e-12, 1.0e-16, 2.0e-7, -1.5e-7, 1.0e-5, -8.0e-6},
          {0.009, 14000, 12000}};
}

// DJI Phantom 4 RTK record A of ../shared/data/dji_dewarpdata_documented (its published values),
// 2.41 um pixels (8.8 mm / 3666.67 px design focal length ~ 2.4 um).
ModelCamera DjiRecordA() {
  return {CameraModelId::kOpenCv,
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
}

CameraFile File(const ModelCamera& camera, const std::string& name = "cam") {
  CameraFile file;
  file.name = name;
  file.camera = camera;
  return file;
}

double MaxDifferencePx(const ModelCamera& a, const ModelCamera& b) {
  const ConversionResidual r = CompareCameras(a, b, 41);
  EXPECT_EQ(r.failed_points, 0);
  return r.max_px;
}

void ExpectSameParams(const ModelCamera& a, const ModelCamera& b, const char* what) {
  ASSERT_EQ(a.model, b.model) << what;
  ASSERT_EQ(a.params.size(), b.params.size()) << what;
  for (size_t i = 0; i < a.params.size(); ++i)
    EXPECT_NEAR(a.params[i], b.params[i], 1e-13 * (1 + std::abs(a.params[i]))) << what << " " << i;
  EXPECT_EQ(a.frame.width_px, b.frame.width_px) << what;
  EXPECT_EQ(a.frame.height_px, b.frame.height_px) << what;
}

struct Format {
  std::string name;
  std::function<CameraFile(const std::string&, const CameraReadOptions&)> read;
  std::function<void(const std::string&, const CameraFile&)> write;
  FormatTarget target;       // for a non-fisheye source
  bool file_has_size;        // else --width/--height are given to the reader
  bool file_has_pixel_size;  // else --pixel-size-mm
  std::string extension;
};

// The registry's formats (calib's; the OpenCV row is the tool layer's: tests/tools/).
std::vector<Format> Formats() {
  std::vector<Format> formats;
  for (const CameraFormat& f : CameraFormats())
    formats.push_back({f.name,
                       f.read,
                       f.write,
                       f.target(AerialCamera()),
                       f.writes_size,
                       f.writes_pixel_size,
                       f.extension});
  return formats;
}

Format FormatNamed(const std::string& name) {
  for (const Format& f : Formats())
    if (f.name == name) return f;
  throw std::logic_error("no format " + name);
}

CameraFile WriteAndRead(const Format& f, const CameraFile& file, const TempDir& dir) {
  const std::string path = dir.File(f.name + f.extension);
  f.write(path, file);
  CameraReadOptions options;
  if (!f.file_has_size) {
    options.width_px = file.camera.frame.width_px;
    options.height_px = file.camera.frame.height_px;
  }
  if (!f.file_has_pixel_size) options.pixel_size_mm = file.camera.frame.pixel_size_mm;
  return f.read(path, options);
}

// ---- every format: its own model written and read back exactly ----

TEST(CameraFormats, EachFormatRoundTripsItsOwnModelExactly) {
  TempDir dir("aerocal_formats");
  const ModelCamera dji = DjiRecordA();
  for (const Format& f : Formats()) {
    SCOPED_TRACE(f.name);
    // A camera in the format's model with every term it can hold non-zero: the conversion of the
    // drone lens (a fit where the format's model differs), then written and read back.
    const FileConversion in_model = ConvertCameraFile(File(dji), f.target);
    const CameraFile back = WriteAndRead(f, in_model.file, dir);
    ExpectSameParams(in_model.file.camera, back.camera, f.name.c_str());
    EXPECT_LT(MaxDifferencePx(in_model.file.camera, back.camera), 1e-9);
  }
}

TEST(CameraFormats, AHostileNameNeverBreaksAFile) {
  // XML markup, quotes and a newline in the camera name: every format still reads back its
  // parameters exactly; the formats that keep a name keep it on one line, unescaped.
  TempDir dir("aerocal_formats_name");
  const std::string hostile = "A&B <lens> \"q\" 'p'\nsecond line";
  for (const Format& f : Formats()) {
    SCOPED_TRACE(f.name);
    FileConversion in_model = ConvertCameraFile(File(DjiRecordA()), f.target);
    in_model.file.name = hostile;
    const CameraFile back = WriteAndRead(f, in_model.file, dir);
    ExpectSameParams(in_model.file.camera, back.camera, f.name.c_str());
    if (std::string(f.name) == "dbat" || std::string(f.name) == "photomodeler") {
      EXPECT_EQ(back.name, "A&B <lens> \"q\" 'p' second line");
    }
  }
}

// Issue 37 class 3: a writer never leaves a file its own reader refuses. A camera whose principal
// distance is 1e9 times the DJI record's (3.7e12 px) is written by every format through
// WriteCameraFileVerified: an Error naming the file, and neither the file nor its scratch copy.
TEST(CameraFormats, AVerifiedWriteTheReaderRefusesLeavesNoFile) {
  namespace fs = std::filesystem;
  TempDir dir("aerocal_formats_verified");
  for (const CameraFormat& f : CameraFormats()) {
    SCOPED_TRACE(f.name);
    CameraFile file = ConvertCameraFile(File(DjiRecordA()), f.target(DjiRecordA())).file;
    const std::vector<ParamInfo> table = CameraModelParams(file.camera.model);
    for (size_t i = 0; i < table.size(); ++i)
      if (table[i].group == ParamGroup::kPrincipalDistance) file.camera.params[i] *= 1e9;
    const std::string path = dir.File("huge" + f.extension);
    EXPECT_THROW(WriteCameraFileVerified(f, path, file), Error);
    EXPECT_FALSE(fs::exists(path));
    for (const auto& entry : fs::directory_iterator(dir.path()))
      ADD_FAILURE() << "left " << entry.path();
  }
}

TEST(CameraFormats, Pix4dXmpTagsAreThePix4dCamValues) {
  // Pix4D's XMP camera tags in element form with the values of Pix4D's specification page
  // (article 360016450032) and a prefix other than "Camera": the same camera as a .cam with the
  // same numbers; the fisheye model type is refused by name; without a pixel size: --pixel-size-mm.
  TempDir dir("aerocal_pix4d_xmp");
  const std::string xmp = dir.File("p4d.xmp");
  const std::string body =
      "<x:xmpmeta xmlns:x=\"adobe:ns:meta/\"><rdf:RDF "
      "xmlns:rdf=\"http://www.w3.org/1999/02/22-rdf-syntax-ns#\">\n"
      "<rdf:Description xmlns:P4=\"http://pix4d.com/camera/1.0/\">\n"
      "<P4:ModelType>perspective</P4:ModelType>\n"
      "<P4:PrincipalPoint>2.42299,1.850154</P4:PrincipalPoint>\n"
      "<P4:PerspectiveFocalLength>4.569165</P4:PerspectiveFocalLength>\n"
      "<P4:PerspectiveDistortion>0.201690322, -0.358534038, 0.256185599, 0.004208643, "
      "0.000268361</P4:PerspectiveDistortion>\n"
      "</rdf:Description></rdf:RDF></x:xmpmeta>\n";
  WriteFileAtomically(xmp, body);
  CameraReadOptions options;
  options.width_px = 4000;
  options.height_px = 3000;
  options.pixel_size_mm = 0.00122;
  const CameraFile a = ReadPix4dXmp(xmp, options);
  const std::string cam = dir.File("p4d.cam");
  WriteFileAtomically(
      cam,
      "Pix4D camera calibration file 0\nF 4.569165\nPx 2.42299\nPy 1.850154\n"
      "K1 0.201690322\nK2 -0.358534038\nK3 0.256185599\nT1 0.004208643\nT2 0.000268361\n");
  const CameraFile b = ReadPix4dCam(cam, options);
  EXPECT_EQ(a.camera.params, b.camera.params);
  EXPECT_EQ(a.camera.frame.pixel_size_mm, b.camera.frame.pixel_size_mm);
  options.pixel_size_mm = 0;
  EXPECT_THROW(ReadPix4dXmp(xmp, options), InputError);
  WriteFileAtomically(xmp, std::regex_replace(body, std::regex(">perspective<"), ">fisheye<"));
  options.pixel_size_mm = 0.00122;
  try {
    ReadPix4dXmp(xmp, options);
    ADD_FAILURE() << "fisheye accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("p4d.xmp:3: P4:ModelType 'fisheye'"), std::string::npos)
        << e.what();
  }
}

TEST(CameraFormats, TermsOutsideOpenCvSurviveTheirFormat) {
  TempDir dir("aerocal_formats");
  // Metashape's b1, b2, k4, p3, p4; DewarpDataK6's k4-k6; a fisheye in OpenSfM and Kalibr.
  ModelCamera metashape{
      CameraModelId::kMetashapeFrame,
      {3680, 2.2, 22.0, 0.8, -0.3, -0.26, 0.1, -0.03, 0.002, 4e-5, -3e-4, 0.01, -0.002},
      {0.0024, 5472, 3648}};
  const CameraFile m = WriteAndRead(FormatNamed("metashape"), File(metashape), dir);
  ExpectSameParams(metashape, m.camera, "metashape");
  ModelCamera k6 = DjiRecordA();
  k6.params[OpenCvModel::kK4] = 0.01, k6.params[OpenCvModel::kK5] = -0.002,
  k6.params[OpenCvModel::kK6] = 1e-4;
  const CameraFile d = WriteAndRead(FormatNamed("dji"), File(k6), dir);
  ExpectSameParams(k6, d.camera, "DewarpDataK6");
  const ModelCamera fisheye{CameraModelId::kOpenCvFisheye,
                            {900, 900, 0.5 * 1279, 0.5 * 959, 0.05, -0.01, 0, 0},
                            {0.003, 1280, 960}};
  ExpectSameParams(
      fisheye, WriteAndRead(FormatNamed("opensfm"), File(fisheye), dir).camera, "opensfm fisheye");
  ModelCamera equi = fisheye;
  equi.params[6] = 0.002, equi.params[7] = -4e-4, equi.params[0] = 901;
  ExpectSameParams(
      equi, WriteAndRead(FormatNamed("kalibr"), File(equi), dir).camera, "kalibr equidistant");
  // Our file holds any registry model.
  ExpectSameParams(metashape,
                   WriteAndRead(FormatNamed("aerocal"), File(metashape), dir).camera,
                   "aerocal metashape_frame");
}

// ---- what a format holds: its registry row, every format x every model ----

// Runs `write`, which must throw an InputError whose message names each of `named`.
void ExpectRefused(const std::function<void()>& write, const std::vector<std::string>& named) {
  try {
    write();
    ADD_FAILURE() << "written";
  } catch (const InputError& e) {
    for (const std::string& name : named)
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
  }
}

// Issue 30 item 1: what a format can hold is its registry row (CameraFormat::models) and nothing
// else. Every registered format x every registered model: a pair the row lists round-trips
// through the format's own writer and reader (the camera: DJI record A fitted into the model with
// the row's zero parameters at 0, conformed where the format derives parameters), every parameter
// within 1e-9 relative; every other pair is refused by the registry's writer with an InputError
// naming the file, the format and the model, and nothing is written; so is a listed model with a
// term the format has no field for, or with a parameter the format derives set otherwise.
TEST(CameraFormats, EveryFormatWritesExactlyTheModelsItsRowLists) {
  namespace fs = std::filesystem;
  TempDir dir("aerocal_formats_models");
  std::vector<CameraModelId> models;
  ForEachCameraModel([&](auto m) { models.push_back(decltype(m)::kId); });
  int written = 0, refused = 0;
  // The DJI record in each model with each row's held terms: fitted once per pair (a fit is the
  // costly part, ~70x slower in the sanitized reader run), not once per format.
  std::map<std::pair<CameraModelId, std::vector<std::string>>, CameraFile> cameras;
  const auto camera_in = [&](CameraModelId id, const std::vector<std::string>& zero) {
    auto [it, added] = cameras.try_emplace({id, zero});
    if (added) {
      ConvertOptions options;
      options.zero = zero;
      it->second = File(ConvertCamera(DjiRecordA(), id, options).camera);
    }
    return it->second;
  };
  for (const CameraFormat& f : CameraFormats()) {
    for (const CameraModelId id : models) {
      const std::string model(CameraModelName(id));
      SCOPED_TRACE(f.name + " x " + model);
      const WritableModel* row = FindWritableModel(f, id);
      CameraFile file = camera_in(id, row ? row->zero_params : std::vector<std::string>{});
      const std::string path = dir.File(f.name + "_" + model + f.extension);
      if (!row) {
        ExpectRefused([&] { f.write(path, file); }, {path, f.name, model});
        EXPECT_FALSE(fs::exists(path));
        ++refused;
        continue;
      }
      if (row->conform) {
        ModelCamera derived = file.camera;
        row->conform(&derived);
        EXPECT_NE(derived.params, file.camera.params) << "DJI record A is not centred";
        ExpectRefused([&] { f.write(path, file); }, {f.name, model, "derives"});
        file.camera = derived;
      }
      if (!row->zero_params.empty()) {
        CameraFile held = file;
        const std::string& term = row->zero_params.front();
        const std::vector<ParamInfo> table = CameraModelParams(id);
        for (size_t i = 0; i < table.size(); ++i)
          if (table[i].name == term) held.camera.params[i] = 1e-3;
        ExpectRefused([&] { f.write(path, held); }, {f.name, model, term});
      }
      EXPECT_FALSE(fs::exists(path));
      const CameraFile back = WriteAndRead(FormatNamed(f.name), file, dir);
      ASSERT_EQ(back.camera.model, id);
      for (size_t i = 0; i < file.camera.params.size(); ++i) {
        const double a = file.camera.params[i], b = back.camera.params[i];
        EXPECT_LE(std::abs(a - b), 1e-9 * std::max(std::abs(a), std::abs(b))) << i;
      }
      ++written;
    }
  }
  std::printf("formats x models: %d pairs written and read back, %d refused\n", written, refused);
  EXPECT_GT(written, 20);
}

// ---- ours -> format -> ours ----

struct Trip {
  bool exact_out;
  double out_max_px, back_max_px;
};

Trip OursThroughFormat(const ModelCamera& ours, const Format& f, const TempDir& dir) {
  const FileConversion out = ConvertCameraFile(File(ours), f.target);
  const CameraFile read = WriteAndRead(f, out.file, dir);
  const FileConversion back = ConvertCameraFile(read, {CameraModelId::kBrownFraser10, {}, true});
  return {out.result.exact, out.result.residual.max_px, MaxDifferencePx(ours, back.file.camera)};
}

TEST(CameraFormats, OursThroughEveryFormatAndBackStatesItsResidual) {
  TempDir dir("aerocal_formats");
  const ModelCamera aerial = AerialCamera();
  // The drone lens as OUR camera: its refit (13-14 px at the corner, convert_camera_test) is now
  // the camera every format must carry.
  const ModelCamera drone = ConvertCamera(DjiRecordA(), CameraModelId::kBrownFraser10).camera;
  for (const Format& f : Formats()) {
    const Trip a = OursThroughFormat(aerial, f, dir);
    const Trip d = OursThroughFormat(drone, f, dir);
    std::printf(
        "ours -> %-9s -> ours: aerial %s out max %.3g px, back max %.3g px; drone %s out "
        "max %.3g px, back max %.3g px\n",
        f.name.c_str(),
        a.exact_out ? "exact" : "fit",
        a.out_max_px,
        a.back_max_px,
        d.exact_out ? "exact" : "fit",
        d.out_max_px,
        d.back_max_px);
    const bool ours_model = f.target.model == CameraModelId::kBrownFraser10;
    if (ours_model && f.target.zero_params.empty()) {  // our own file: exact both ways
      EXPECT_TRUE(a.exact_out) << f.name;
      EXPECT_LT(a.back_max_px, 1e-9) << f.name;
      EXPECT_LT(d.back_max_px, 1e-9) << f.name;
      continue;
    }
    EXPECT_FALSE(a.exact_out) << f.name;  // a correction model is no forward model (or B1/B2 lost)
    // The way back adds at most the way out's residual again (a fit in each direction); the
    // aerial camera's shear B2 (8e-6) is what the forward models cannot hold: 0.05-0.06 px.
    // (Triangle inequality: back <= out + the back fit's own residual, itself <= out.)
    EXPECT_LT(a.back_max_px, 2.0 * a.out_max_px + 1e-3) << f.name;
    EXPECT_LT(d.back_max_px, 2.0 * d.out_max_px + 1e-3) << f.name;
    // The residual each conversion states, measured (2026-11-24) with 20 % margin: the aerial
    // camera's shear B2 costs 0.05-0.09 px in the forward models (Metashape has b2: 6e-5 px); the
    // drone lens (our refit of DJI record A) 2-16 px where the target has fewer terms (Kalibr
    // radtan: k1, k2 only).
    const std::map<std::string, std::pair<double, double>> stated = {
        // colmap, dji, ros: the simplest form, 5 coefficients (k1 k2 p1 p2 k3; issue 29), 9.56 px
        // for the drone; the 8-coefficient rational form gave 1.95 px with k1 = +2.33 for a lens
        // whose k1 is about -0.28, which every 5-coefficient reader misreads.
        {"colmap", {0.048, 9.56}},
        {"metashape", {5.6e-5, 3.46}},
        {"pix4d", {0.090, 10.7}},
        {"pix4d-xmp", {0.090, 10.7}},
        {"opensfm", {0.048, 9.56}},
        {"dji", {0.048, 9.56}},
        {"dbat", {0.048, 0.013}} /* B1 as the aspect */,
        {"photomodeler", {0.090, 2.61}},
        {"kalibr", {0.064, 16.3}},
        {"ros", {0.048, 9.56}},
        {"camodocal", {0.064, 16.3}}};
    EXPECT_LT(a.out_max_px, 1.2 * stated.at(f.name).first) << f.name;
    EXPECT_LT(d.out_max_px, 1.2 * stated.at(f.name).second) << f.name;
  }
}

// ---- the real files ----

std::string Shared(const std::string& set) { return testing::SharedDataDir(set); }

struct DewarpRecord {
  std::string id;
  int width = 0, height = 0;
  std::string data;
  int line = 0;
};

std::vector<DewarpRecord> DewarpRecords(const std::string& path) {
  std::ifstream in(path);
  std::vector<DewarpRecord> records;
  int line_number = 0;
  for (std::string line; std::getline(in, line);) {
    ++line_number;
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> fields;
    std::stringstream s(line);
    for (std::string f; std::getline(s, f, '|');) fields.push_back(f);
    DewarpRecord r;
    r.id = SplitCommaList(fields.at(0))[0];
    std::sscanf(fields.at(2).c_str(), " %dx%d", &r.width, &r.height);
    r.data = fields.at(7);
    r.line = line_number;
    records.push_back(r);
  }
  return records;
}

TEST(CameraFormatsRealData, DjiDewarpDataRecordsGiveCentrePlusOffset) {
  const std::string dir = Shared("dji_dewarpdata_documented");
  if (dir.empty()) GTEST_SKIP() << "../shared/data absent";
  const auto records = DewarpRecords(dir + "/dewarpdata_examples.txt");
  ASSERT_EQ(records.size(), 2u);
  // PROVENANCE.md "Known values": A (5472 x 3648) centre + (2.24, 22.05) = (2738.24, 1846.05) px;
  // B (4864 x 3648) offset (-7.71, 45.90).
  const double expected[2][9] = {{3684.48,
                                  3677.57,
                                  2738.24,
                                  1846.05,
                                  -0.263482,
                                  0.106788,
                                  3.71107e-5,
                                  -3.27247e-4,
                                  -0.0300783},
                                 {3659.78,
                                  3653.17,
                                  2432 - 7.71,
                                  1824 + 45.90,
                                  -0.269478,
                                  0.115681,
                                  -8.75619e-5,
                                  -3.06177e-4,
                                  -0.0357628}};
  for (size_t k = 0; k < 2; ++k) {
    const DewarpRecord& r = records[k];
    const ModelCamera c = DjiDewarpDataCamera(r.data, {dir, r.line}, r.width, r.height);
    using O = OpenCvModel;
    const int order[9] = {O::kFx, O::kFy, O::kCx, O::kCy, O::kK1, O::kK2, O::kP1, O::kP2, O::kK3};
    for (int i = 0; i < 9; ++i)
      EXPECT_NEAR(c.params[order[i]], expected[k][i], 1e-9 * (1 + std::abs(expected[k][i])))
          << r.id << " " << i;
    // The refit into our 10 parameters: 13-14 px at the corner (the issue's 16-28 px for other
    // records), never exact; within 80 % of the half-diagonal 2-3 px.
    ModelCamera with_pixel = c;
    with_pixel.frame.pixel_size_mm = 0.0024;
    const ConversionResult ours = ConvertCamera(with_pixel, CameraModelId::kBrownFraser10);
    std::printf("DJI record %s -> brown_fraser_10: %s\n", r.id.c_str(), ours.Summary().c_str());
    EXPECT_FALSE(ours.exact);
    EXPECT_GT(ours.residual.max_px, 5.0);
    EXPECT_LT(ours.residual.max_px, 30.0);
    EXPECT_LT(ours.residual.max_inner80_px, 4.0);
  }
}

TEST(CameraFormatsRealData, OpenSfmBerlinReconstructionCamera) {
  const std::string dir = Shared("opensfm_berlin");
  if (dir.empty()) GTEST_SKIP() << "../shared/data absent";
  CameraReadOptions options;
  options.pixel_size_mm = 0.0014;  // iPhone 4S: 1.4 um
  const CameraFile f = ReadOpenSfmCameras(dir + "/reconstruction_example.json", options);
  using O = OpenCvModel;
  // PROVENANCE.md: perspective, focal 0.869666 (x 3264 = 2838.6 px), k1 0.0885146, k2 -0.232443.
  EXPECT_EQ(f.camera.model, CameraModelId::kOpenCv);
  EXPECT_NEAR(f.camera.params[O::kFx], 0.8696658484855359 * 3264, 1e-9);
  EXPECT_NEAR(f.camera.params[O::kFy], 2838.6, 0.05);
  EXPECT_DOUBLE_EQ(f.camera.params[O::kCx], 0.5 * 3263);
  EXPECT_DOUBLE_EQ(f.camera.params[O::kCy], 0.5 * 2447);
  EXPECT_DOUBLE_EQ(f.camera.params[O::kK1], 0.08851464962037196);
  EXPECT_DOUBLE_EQ(f.camera.params[O::kK2], -0.2324428377906099);
  // Exact in every forward format (written and read back), and back into OpenSfM.
  TempDir tmp("aerocal_formats");
  for (const Format& format : Formats()) {
    if (format.target.model == CameraModelId::kBrownFraser10) continue;
    const FileConversion out = ConvertCameraFile(f, format.target);
    EXPECT_TRUE(out.result.exact) << format.name;
    EXPECT_LT(out.result.residual.max_px, 1e-9) << format.name;
    const CameraFile read = WriteAndRead(format, out.file, tmp);
    const FileConversion back = ConvertCameraFile(read, FormatNamed("opensfm").target);
    EXPECT_TRUE(back.result.exact) << format.name;
    EXPECT_LT(MaxDifferencePx(f.camera, back.file.camera), 1e-9) << format.name;
  }
}

TEST(CameraFormatsRealData, OdmCamerasJsonOfTheOrthorityDocs) {
  // OpenDroneMap's cameras.json of a DJI FC6310R (Phantom 4 Pro), as quoted in the Orthority
  // documentation (orthority.readthedocs.io, file_formats/opensfm.html): ODM's brown model of the
  // images resized to 1368 x 912. No cameras.json is among ../shared/data's ODM sets.
  TempDir tmp("aerocal_formats");
  const std::string path = tmp.File("cameras.json");
  std::ofstream(path) << R"({
    "v2 dji fc6310r 5472 3648 brown 0.6666": {
        "projection_type": "brown",
        "width": 1368,
        "height": 912,
        "focal_x": 0.6664614123723713,
        "focal_y": 0.6664614123723713,
        "c_x": -0.0015460447606643697,
        "c_y": 0.004751874732641298,
        "k1": -0.2640629100413887,
        "k2": 0.10188934223670705,
        "p1": 0.0007345906274317972,
        "p2": 0.0002595206713083041,
        "k3": -0.02581956399353581
    }
})";
  const CameraFile f = ReadOpenSfmCameras(path, {});
  using O = OpenCvModel;
  EXPECT_NEAR(f.camera.params[O::kFx], 0.6664614123723713 * 1368, 1e-9);
  EXPECT_NEAR(f.camera.params[O::kCx], 683.5 - 0.0015460447606643697 * 1368, 1e-9);
  EXPECT_NEAR(f.camera.params[O::kCy], 455.5 + 0.004751874732641298 * 1368, 1e-9);
  EXPECT_DOUBLE_EQ(f.camera.params[O::kP1], 0.0007345906274317972);
  // The same lens class as the DJI DewarpData records: k1 -0.264 against -0.263 (record A).
  EXPECT_NEAR(f.camera.params[O::kK1], DjiRecordA().params[O::kK1], 0.01);
  const CameraFile back = WriteAndRead(FormatNamed("opensfm"), f, tmp);
  ExpectSameParams(f.camera, back.camera, "odm cameras.json");
  // The key, spaces and all, is the camera's name and survives (issue 29); --camera takes it.
  EXPECT_EQ(f.name, "v2 dji fc6310r 5472 3648 brown 0.6666");
  EXPECT_EQ(back.name, f.name);
  CameraReadOptions options;
  options.camera_id = "v2 dji fc6310r 5472 3648 brown 0.6666";
  EXPECT_EQ(ReadCameraFileAs("auto", path, options).camera.params, f.camera.params);
}

TEST(CameraFormatsRealData, DbatResultCameraAgainstItsReport) {
  const std::string dir = Shared("dbat_camcal_olympus_c4040z");
  if (dir.empty()) GTEST_SKIP() << "../shared/data absent";
  const CameraFile f = ReadDbatCameraXml(dir + "/result/c4040z.xml", {});
  using B = BrownFraser10Model;
  // PROVENANCE.md (DBAT 0.9.2.0 report): c 7.45700 mm, pp (3.61546, 2.61329) mm from the top-left
  // corner, K1 4.58861e-3, K2 -4.51351e-5, K3 -2.05253e-6, P1 -6.12803e-5, P2 -4.41171e-5.
  const double p = 5.43764 / 1704;
  EXPECT_NEAR(f.camera.params[B::kC], 7.45700, 5e-6);
  // DBAT's pixel aspect (report: as 3.89598e-4, the XML's aspect 1 - as; pixel width 0.00319235
  // mm, height 0.0031911 mm) scales DBAT's x: B1 = s - 1 = as, x0 = px / s - W p / 2 (0.44 px
  // from ignoring it).
  const double s = (7.25301132255482273 / 2272) / p;
  EXPECT_NEAR(s, 1.0 + 3.89598e-4, 1e-9);  // pixel width = pixel height (1 + as)
  EXPECT_NEAR(f.camera.params[B::kB1], s - 1.0, 1e-15);
  EXPECT_NEAR(f.camera.params[B::kX0], 3.61546 / s - 1136 * p, 5e-6);
  EXPECT_NEAR(f.camera.params[B::kY0], 852 * p - 2.61329, 5e-6);
  EXPECT_NEAR(f.camera.params[B::kK1], 4.58861e-3, 5e-9);
  EXPECT_NEAR(f.camera.params[B::kK2], -4.51351e-5, 5e-11);
  EXPECT_NEAR(f.camera.params[B::kK3], -2.05253e-6, 5e-12);
  EXPECT_NEAR(f.camera.params[B::kP1], -6.12803e-5, 5e-11);
  EXPECT_NEAR(f.camera.params[B::kP2], -4.41171e-5, 5e-11);
  ASSERT_EQ(f.notes.size(), 1u);  // the aspect as B1, not exact: said with its size
  std::printf("DBAT c4040z: %s\n", f.notes[0].c_str());
  EXPECT_NE(f.notes[0].find("not exact"), std::string::npos);
  TempDir tmp("aerocal_formats");
  const CameraFile back = WriteAndRead(FormatNamed("dbat"), f, tmp);
  ExpectSameParams(f.camera, back.camera, "dbat");
  // Into Metashape (a forward model: fitted) and back into DBAT.
  const FileConversion m = ConvertCameraFile(f, FormatNamed("metashape").target);
  const FileConversion again = ConvertCameraFile(
      WriteAndRead(FormatNamed("metashape"), m.file, tmp), FormatNamed("dbat").target);
  std::printf("DBAT c4040z -> metashape: %s; -> DBAT: %.3g px max against the original\n",
              m.result.Summary().c_str(),
              MaxDifferencePx(f.camera, again.file.camera));
  // Measured: 0.057 px at the corner (rms 0.005 px) out, 5e-4 px back.
  EXPECT_LT(m.result.residual.max_px, 0.07);
  EXPECT_LT(MaxDifferencePx(f.camera, again.file.camera), 1e-3);
}

TEST(CameraFormatsRealData, PhotoModelerExportOfTheDbatProjectAgreesWithDbat) {
  // PhotoModeler Scanner 2016's own calibration of the DBAT camcal images (line 4 of its Bundle
  // Soln export, PROVENANCE.md): f 7.4653, pp (3.6173, 2.6128) mm from the upper-left corner,
  // format 7.25319 x 5.43764 mm, K1 0.00498, K2 -0.0001, K3 0, P1 -0.00006, P2 -0.00004.
  const std::string dir = Shared("dbat_camcal_olympus_c4040z");
  if (dir.empty()) GTEST_SKIP() << "../shared/data absent";
  const CameraFile pm = ReadPhotoModelerCamera(dir + "/photomodeler/camcal-pmexport.txt", {});
  using B = BrownFraser10Model;
  const double p = 5.43764 / 1704;  // square pixels from the format height, as DBAT
  EXPECT_EQ(pm.camera.frame.width_px, 2272);
  EXPECT_NEAR(pm.camera.frame.pixel_size_mm, p, 1e-15);
  EXPECT_NEAR(pm.camera.params[B::kC], 7.4653, 1e-12);
  EXPECT_NEAR(pm.camera.params[B::kX0], (3.6173 / (7.25319 / 2272) - 1136) * p, 1e-12);
  EXPECT_NEAR(pm.camera.params[B::kY0], 852 * p - 2.6128, 1e-12);
  EXPECT_NEAR(pm.camera.params[B::kK1], 0.00498, 1e-15);
  EXPECT_NEAR(pm.camera.params[B::kP2], -0.00004, 1e-15);
  // PhotoModeler's format width is 4.1e-4 wider than square pixels give (DBAT estimates the same
  // aspect, 3.9e-4): said, not modelled.
  EXPECT_NE(pm.notes.front().find("not modelled"), std::string::npos);
  // Two programs' calibrations of the same 21 images: the same lens within what their
  // different c (7.4653 vs 7.4570 mm, 0.11 %) and PhotoModeler's 5-digit print explain. The
  // distortion curves agree: at r = 4 mm, dr = r^3 K1 + r^5 K2 + r^7 K3.
  const CameraFile dbat = ReadDbatCameraXml(dir + "/result/c4040z.xml", {});
  const auto dr = [](const std::vector<double>& q, double r) {
    return r * r * r * q[B::kK1] + std::pow(r, 5) * q[B::kK2] + std::pow(r, 7) * q[B::kK3];
  };
  const double dr_pm = dr(pm.camera.params, 4.0), dr_dbat = dr(dbat.camera.params, 4.0);
  std::printf("dr(4 mm): PhotoModeler %.5f mm, DBAT %.5f mm\n", dr_pm, dr_dbat);
  EXPECT_NEAR(dr_pm, dr_dbat, 0.1 * std::abs(dr_dbat));  // 10 %: PM prints K2 to 1e-5 (20 %)
  EXPECT_NEAR(pm.camera.params[B::kX0], dbat.camera.params[B::kX0], 0.01);  // 3 px
  EXPECT_NEAR(pm.camera.params[B::kY0], dbat.camera.params[B::kY0], 0.01);
  // Written and read back exactly.
  TempDir tmp("aerocal_formats");
  const Format f = FormatNamed("photomodeler");
  ExpectSameParams(pm.camera, WriteAndRead(f, pm, tmp).camera, "photomodeler");
}

TEST(CameraFormatsRealData, AustralisReportOfThePublicExample) {
  // The layout and values of a public Australis report (wiki.cis.rit.edu, WASP-LT camera 3, 2006),
  // lines as Australis prints them.
  TempDir tmp("aerocal_formats");
  const std::string path = tmp.File("camera3-report.txt");
  std::ofstream(path)
      << "Australis Bundle Adjustment Results: Camera Parameters\n02 August, 2006 14:11:14\n"
         "Project: camera3.aus\nAdjustment: Free-Network\nNumber of Points: 145\n"
         "Results for Camera 1\nWASP-LT Camera 3 Lens\n"
         "Sensor Size Pixel Size (mm)\nH 648 0.007\nV 494 0.007\n"
         "Camera Initial Total Final Initial Final\n"
         "Variable Value Adjustment Value Std. Error Std. Error\n"
         "C 8.0000 0.30937 8.3094 1.0e+003 6.782e-003 (mm)\n"
         "XP 0.0000 -0.02804 -0.0280 1.0e+003 6.879e-003 (mm)\n"
         "YP 0.0000 0.02142 0.0214 1.0e+003 7.204e-003 (mm)\n"
         "K1 0.00000e+000 1.674e-003 1.67381e-003 1.0e+003 1.238e-004\n"
         "K2 0.00000e+000 -7.808e-006 -7.80809e-006 1.0e+003 3.066e-005\n"
         "K3 0.00000e+000 -1.229e-006 -1.22907e-006 1.0e+003 2.327e-006\n"
         "P1 0.00000e+000 1.752e-005 1.75249e-005 1.0e+003 3.496e-005\n"
         "P2 0.00000e+000 -8.641e-006 -8.64105e-006 1.0e+003 3.400e-005\n"
         "B1 0.00000e+000 -4.343e-004 -4.34298e-004 1.0e+003 1.100e-004\n"
         "B2 0.00000e+000 1.797e-005 1.79692e-005 1.0e+003 1.101e-004\n"
         "Maximum Observational Radial Distance Encountered: 2.9 mm\n";
  const CameraFile a = ReadAustralisCamera(path, {});
  using B = BrownFraser10Model;
  EXPECT_EQ(a.camera.frame.width_px, 648);
  EXPECT_EQ(a.camera.frame.height_px, 494);
  EXPECT_DOUBLE_EQ(a.camera.frame.pixel_size_mm, 0.007);
  const double expected[B::kNumParams] = {8.3094,
                                          -0.0280,
                                          0.0214,
                                          1.67381e-3,
                                          -7.80809e-6,
                                          -1.22907e-6,
                                          1.75249e-5,
                                          -8.64105e-6,
                                          -4.34298e-4,
                                          1.79692e-5};
  for (int k = 0; k < B::kNumParams; ++k) EXPECT_DOUBLE_EQ(a.camera.params[k], expected[k]) << k;
  ASSERT_TRUE(a.covariance);
  EXPECT_NEAR(std::sqrt((*a.covariance)(B::kC, B::kC)), 6.782e-3, 1e-15);
  EXPECT_NEAR(std::sqrt((*a.covariance)(B::kB2, B::kB2)), 1.101e-4, 1e-18);
  EXPECT_EQ((*a.covariance)(B::kC, B::kX0), 0.0);
  // Written and read back: the same camera and sigmas.
  const Format f = FormatNamed("australis");
  const CameraFile back = WriteAndRead(f, a, tmp);
  ExpectSameParams(a.camera, back.camera, "australis");
  ASSERT_TRUE(back.covariance);
  EXPECT_NEAR((*back.covariance)(B::kK1, B::kK1), (*a.covariance)(B::kK1, B::kK1), 1e-22);
  // Into PhotoModeler (no B1, B2: a fit over the format, stated) and DBAT likewise.
  const FileConversion pm = ConvertCameraFile(a, FormatNamed("photomodeler").target);
  EXPECT_FALSE(pm.result.exact);
  std::printf("Australis WASP-LT -> photomodeler: %s\n", pm.result.Summary().c_str());
  EXPECT_GT(pm.result.residual.max_px, 0.01);  // B1 -4.3e-4 at 2.3 mm: 0.14 px, not nothing
  EXPECT_LT(pm.result.residual.max_px, 0.5);
}

// ---- the covariance carried through ----

TEST(CameraFormats, CovarianceThroughAnExactConversionIsTheLinearMap) {
  using M = MetashapeFrameModel;
  using P = Pix4dPerspectiveModel;
  CameraFile m = File({M::kId,
                       {3680, 2.2, 22.0, 0, 0, -0.26, 0.1, -0.03, 0, 4e-5, -3e-4, 0, 0},
                       {0.0024, 5472, 3648}});
  Eigen::MatrixXd c = Eigen::MatrixXd::Zero(M::kNumParams, M::kNumParams);
  c(M::kF, M::kF) = 0.5 * 0.5, c(M::kCx, M::kCx) = 0.3 * 0.3, c(M::kF, M::kCx) = 0.05;
  c(M::kP2, M::kP2) = 1e-5 * 1e-5, c(M::kK1, M::kK1) = 1e-4 * 1e-4;
  m.covariance = c;
  const FileConversion p = ConvertCameraFile(m, {P::kId, {}, true});
  ASSERT_TRUE(p.result.exact);
  ASSERT_TRUE(p.file.covariance);
  const Eigen::MatrixXd& q = *p.file.covariance;
  const double mm = 0.0024;  // F = f p, Px = (cx + W / 2) p, T1 = P2 (Metashape), R1 = k1
  EXPECT_NEAR(q(P::kF, P::kF), mm * mm * 0.25, 1e-6 * mm * mm * 0.25);
  EXPECT_NEAR(q(P::kPx, P::kPx), mm * mm * 0.09, 1e-6 * mm * mm * 0.09);
  EXPECT_NEAR(q(P::kF, P::kPx), mm * mm * 0.05, 1e-6 * mm * mm * 0.05);
  EXPECT_NEAR(q(P::kT1, P::kT1), 1e-10, 1e-16);
  EXPECT_NEAR(q(P::kR1, P::kR1), 1e-8, 1e-14);
  EXPECT_NEAR(q(P::kPy, P::kPy), 0.0, 1e-18);
}

TEST(CameraFormats, CovarianceThroughAFitFollowsTheExactScaleAndShift) {
  // Metashape's skew b2 has no OpenCV term, so Metashape -> ours is a FIT; without distortion ours
  // holds the camera exactly (B1, B2 are the inverse affinity), and then a change of f scales the
  // image (our c follows with dc/df = p) and a change of cx shifts it (x0 follows with p):
  // sigma_c = p sigma_f, sigma_x0 = p sigma_cx, no correlation. (With distortion the fit is not
  // exact and its c trades with K1 over the format: no such oracle, the propagation is the same
  // code.)
  using M = MetashapeFrameModel;
  using B = BrownFraser10Model;
  CameraFile m =
      File({M::kId, {3680, 2.2, 22.0, 0.8, -0.3, 0, 0, 0, 0, 0, 0, 0, 0}, {0.0024, 5472, 3648}});
  Eigen::MatrixXd c = Eigen::MatrixXd::Zero(M::kNumParams, M::kNumParams);
  c(M::kF, M::kF) = 0.8 * 0.8;
  c(M::kCx, M::kCx) = 0.4 * 0.4;
  m.covariance = c;
  const FileConversion ours = ConvertCameraFile(m, {B::kId, {}, true});
  ASSERT_FALSE(ours.result.exact);
  EXPECT_LT(ours.result.residual.max_px, 1e-6);
  ASSERT_TRUE(ours.file.covariance);
  const Eigen::MatrixXd& q = *ours.file.covariance;
  const double mm = 0.0024;
  EXPECT_NEAR(std::sqrt(q(B::kC, B::kC)), mm * 0.8, 1e-4 * mm * 0.8);
  EXPECT_NEAR(std::sqrt(q(B::kX0, B::kX0)), mm * 0.4, 1e-4 * mm * 0.4);
  EXPECT_NEAR(q(B::kC, B::kX0), 0.0, 1e-4 * mm * mm * 0.32);
}

}  // namespace
}  // namespace aerocal::calib
