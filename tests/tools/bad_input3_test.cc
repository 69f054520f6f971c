// Issue 37, part 3: the OpenCV FileStorage reader's messages and bounds (class 9), `--camera` on
// files of one camera (class 9), outputs written as a set and refused when they name an input or
// another output (class 8), size products bounded before allocation (class 7).
#include "tests/support/bad_input_case.h"
#include "tests/support/test_support.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <regex>
#include <string>
#include <vector>

namespace aerocal {
namespace {

namespace fs = std::filesystem;
using testing::RunAerocal;
using testing::TempDir;

std::string Read(const std::string& path) { return testing::ReadFileText(path); }
void Write(const std::string& path, const std::string& text) { testing::WriteFileText(path, text); }
std::string Seed(const std::string& name) {
  return std::string(AEROCAL_TEST_DATA_DIR) + "/../fuzz/seeds/camera_formats/" + name;
}

// No staging folder or temporary file anywhere under `folder`.
void ExpectNoLeftovers(const std::string& folder) {
  for (const auto& e : fs::recursive_directory_iterator(folder)) {
    const std::string name = e.path().filename().string();
    EXPECT_EQ(name.find(".aerocal-staging"), std::string::npos) << e.path();
    EXPECT_EQ(name.find(".tmp"), std::string::npos) << e.path();
  }
}

// ---- class 9: cv::FileStorage input, bounded and located before OpenCV reads it ----

const char* const kGoodYaml =
    "%YAML:1.0\n"
    "---\n"
    "image_width: 640\n"
    "image_height: 480\n"
    "camera_matrix: !!opencv-matrix\n"
    "   rows: 3\n"
    "   cols: 3\n"
    "   dt: d\n"
    "   data: [ 500., 0., 320., 0., 500., 240., 0., 0., 1. ]\n"
    "distortion_coefficients: !!opencv-matrix\n"
    "   rows: 5\n"
    "   cols: 1\n"
    "   dt: d\n"
    "   data: [ -0.1, 0.01, 0., 0., 0. ]\n";

const char* const kGoodXml =
    "<?xml version=\"1.0\"?>\n"
    "<opencv_storage>\n"
    "<image_width>640</image_width>\n"
    "<image_height>480</image_height>\n"
    "<camera_matrix type_id=\"opencv-matrix\">\n"
    "  <rows>3</rows>\n"
    "  <cols>3</cols>\n"
    "  <dt>d</dt>\n"
    "  <data>\n"
    "    500. 0. 320. 0. 500. 240. 0. 0. 1.</data></camera_matrix>\n"
    "<distortion_coefficients type_id=\"opencv-matrix\">\n"
    "  <rows>5</rows>\n"
    "  <cols>1</cols>\n"
    "  <dt>d</dt>\n"
    "  <data>\n"
    "    -0.1 0.01 0. 0. 0.</data></distortion_coefficients>\n"
    "</opencv_storage>\n";

const char* const kGoodJson =
    "{\n"
    "    \"image_width\": 640,\n"
    "    \"image_height\": 480,\n"
    "    \"camera_matrix\": {\n"
    "        \"type_id\": \"opencv-matrix\",\n"
    "        \"rows\": 3,\n"
    "        \"cols\": 3,\n"
    "        \"dt\": \"d\",\n"
    "        \"data\": [ 500., 0., 320., 0., 500., 240., 0., 0., 1. ]\n"
    "    },\n"
    "    \"distortion_coefficients\": {\n"
    "        \"type_id\": \"opencv-matrix\",\n"
    "        \"rows\": 5,\n"
    "        \"cols\": 1,\n"
    "        \"dt\": \"d\",\n"
    "        \"data\": [ -0.1, 0.01, 0., 0., 0. ]\n"
    "    }\n"
    "}\n";

std::string Replaced(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

struct StorageCase {
  std::string name, extension, text;
  int line;           // the line the message must name
  std::string words;  // and a part of what it says
};

TEST(OpenCvStorage, TheUnmodifiedFilesRead) {
  TempDir d("aerocal_bad_input3_cv_good");
  for (const auto& [ext, text] : std::vector<std::pair<std::string, std::string>>{
           {".yml", kGoodYaml}, {".xml", kGoodXml}, {".json", kGoodJson}}) {
    Write(d.File("c" + ext), text);
    const auto r = RunAerocal("camera show --from opencv " + d.File("c" + ext));
    EXPECT_EQ(r.exit_code, 0) << ext << "\n" << r.output;
    EXPECT_NE(r.output.find("640 x 480 px"), std::string::npos) << r.output;
  }
}

TEST(OpenCvStorage, EveryErrorIsFileLineWithoutOpenCvInternals) {
  const std::vector<StorageCase> cases = {
      // Matrix headers out of bounds: refused before cv::FileStorage allocates anything.
      {"rows_nan",
       ".yml",
       Replaced(kGoodYaml, "rows: 3", "rows: nan"),
       6,
       "rows must be a whole number"},
      {"rows_huge",
       ".yml",
       Replaced(kGoodYaml, "rows: 5", "rows: 100000000"),
       11,
       "rows must be a whole number"},
      {"rows_x_cols",
       ".yml",
       Replaced(Replaced(kGoodYaml, "rows: 3", "rows: 20"), "cols: 3", "cols: 20"),
       7,
       "cannot be held by a file"},
      {"cols_negative",
       ".yml",
       Replaced(kGoodYaml, "cols: 1", "cols: -1"),
       12,
       "cols must be a whole number"},
      {"cols_fraction",
       ".yml",
       Replaced(kGoodYaml, "cols: 3", "cols: 2.5"),
       7,
       "cols must be a whole number"},
      {"dt_unknown",
       ".yml",
       Replaced(kGoodYaml, "dt: d", "dt: q"),
       8,
       "dt must be an OpenCV element type"},
      {"dt_channels",
       ".yml",
       Replaced(Replaced(kGoodYaml, "dt: d", "dt: \"3d\""), "cols: 3", "cols: 1"),
       5,
       "one channel"},
      {"flow_rows_nan",
       ".yml",
       Replaced(kGoodYaml,
                "camera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n",
                "camera_matrix: !!opencv-matrix { rows: nan, cols: 3, dt: d,\n   "),
       5,
       "rows must be"},
      {"xml_rows_huge",
       ".xml",
       Replaced(kGoodXml, "<rows>3</rows>", "<rows>1e12</rows>"),
       6,
       "rows must be"},
      {"xml_cols_nan",
       ".xml",
       Replaced(kGoodXml, "<cols>1</cols>", "<cols>nan</cols>"),
       13,
       "cols must be"},
      {"json_rows_huge",
       ".json",
       Replaced(kGoodJson, "\"rows\": 5", "\"rows\": 99999999999"),
       13,
       "rows must be"},
      {"nd_sizes",
       ".yml",
       Replaced(kGoodYaml,
                "distortion_coefficients: !!opencv-matrix\n   rows: 5\n   cols: 1\n",
                "distortion_coefficients: !!opencv-nd-matrix\n   sizes: [ 100000, 100000 ]\n"),
       11,
       "sizes must be"},
      // A key twice (cv::FileStorage would take one of them): class 4 of the issue.
      {"yaml_duplicate",
       ".yml",
       std::string(kGoodYaml) + "image_width: 1280\n",
       15,
       "occurs twice (first on line 3)"},
      {"xml_duplicate",
       ".xml",
       Replaced(kGoodXml, "<image_height>480</image_height>", "<image_width>480</image_width>"),
       4,
       "occurs twice (first on line 3)"},
      {"json_duplicate",
       ".json",
       Replaced(kGoodJson, "\"image_height\"", "\"image_width\""),
       3,
       "occurs twice"},
      // Values cv::FileStorage reads, refused with the line of their key.
      {"width_nan",
       ".yml",
       Replaced(kGoodYaml, "image_width: 640", "image_width: .nan"),
       3,
       "image_width must be"},
      {"width_huge",
       ".yml",
       Replaced(kGoodYaml, "image_width: 640", "image_width: 1e12"),
       3,
       "image_width must be"},
      {"width_text",
       ".xml",
       Replaced(kGoodXml, "<image_width>640</image_width>", "<image_width>wide</image_width>"),
       3,
       "image_width must be"},
      {"matrix_2x2",
       ".yml",
       Replaced(Replaced(Replaced(kGoodYaml, "rows: 3", "rows: 2"), "cols: 3", "cols: 2"),
                "500., 0., 320., 0., 500., 240., 0., 0., 1.",
                "1., 0., 0., 1."),
       5,
       "must be a 3 x 3 matrix"},
      {"matrix_short_data",
       ".yml",
       Replaced(kGoodYaml, "0., 0., 1. ]", "0. ]"),
       5,
       "not a matrix cv::FileStorage reads"},
      {"fx_nan",
       ".yml",
       Replaced(kGoodYaml, "[ 500., 0., 320.", "[ .nan, 0., 320."),
       5,
       "not finite"},
      {"k1_inf", ".xml", Replaced(kGoodXml, "-0.1 0.01", ".Inf 0.01"), 11, "not finite"},
      {"distortion_6",
       ".yml",
       Replaced(Replaced(kGoodYaml, "rows: 5", "rows: 6"), "0., 0., 0. ]", "0., 0., 0., 0. ]"),
       10,
       "must hold 4, 5, 8, 12 or 14 values"},
      // A top level that is no map (found by fuzz/camera_formats: cv::FileStorage asserted).
      {"yaml_root_sequence",
       ".yml",
       "%YAML:1.0\n- camera_matrix\n- 3\n",
       1,
       "the top level is not a map"},
      {"json_root_array", ".json", "[ 1, 2 ]\n", 1, "cv::FileStorage cannot parse"},
      // A NUL byte (found by fuzz/camera_formats: in the XML declaration it crashed OpenCV 4.6).
      {"xml_nul",
       ".xml",
       Replaced(kGoodXml, "version=\"1.0\"", std::string("version=\0\1.0\"", 13)),
       1,
       "a NUL byte"},
      {"yaml_nul",
       ".yml",
       Replaced(kGoodYaml, "cols: 1", std::string("cols: 1\0", 8)),
       12,
       "a NUL byte"},
      // An attribute's '=' at the end of the text (found by fuzz/camera_formats: OpenCV 4.6
      // crashed).
      {"xml_declaration_cut", ".xml", "<?xml version=\r\r\r", 1, "without a quoted value"},
      {"xml_attribute_cut", ".xml", std::string(kGoodXml) + "<a x=", 18, "without a quoted value"},
      {"xml_attribute_unquoted",
       ".xml",
       Replaced(kGoodXml, "type_id=\"opencv-matrix\"", "type_id=opencv-matrix"),
       5,
       "without a quoted value"},
      // An empty key (found by fuzz/camera_formats: std::length_error escaped OpenCV 4.6).
      {"yaml_empty_key",
       ".yml",
       Replaced(kGoodYaml, "   dt: d\n", "   : 460.4\n"),
       8,
       "a key is empty"},
      // Nesting cv::FileStorage would parse recursively until its stack overflows (exit 139
      // before).
      {"yaml_deep_flow",
       ".yml",
       std::string(kGoodYaml) + "deep: " + std::string(200000, '[') + "\n",
       15,
       "flow collections nested deeper than 64"},
      {"yaml_deep_block",
       ".yml",
       std::string(kGoodYaml) + "deep:\n" + std::string(300, ' ') + "- 1\n",
       16,
       "indented 302 columns"},
      {"yaml_deep_dashes",
       ".yml",
       std::string(kGoodYaml) + "deep:\n" +
           [] {
             std::string dashes;
             for (int i = 0; i < 100000; ++i) dashes += "- ";
             return dashes + "1\n";
           }(),
       16,
       "indented 200000 columns"},
      {"json_deep",
       ".json",
       Replaced(kGoodJson, "\"image_width\": 640,", "\"deep\": " + std::string(200000, '[') + ","),
       2,
       "objects and arrays nested deeper than 64"},
      {"xml_deep",
       ".xml",
       Replaced(kGoodXml,
                "<image_width>640</image_width>",
                [] {
                  std::string tags;
                  for (int i = 0; i < 200000; ++i) tags += "<a>";
                  return tags;
                }()),
       3,
       "elements nested deeper than 64"},
      // Syntax cv::FileStorage cannot parse: its line, not line 1.
      {"yaml_syntax",
       ".yml",
       Replaced(kGoodYaml, "image_height: 480\n", "image_height: 480\n  : : [\n"),
       5,
       "a key is empty"},
      {"xml_syntax", ".xml", Replaced(kGoodXml, "<cols>3</cols>", "<cols>3</rows>"), 7, "parse"},
  };
  TempDir d("aerocal_bad_input3_cv");
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    const std::string path = d.File(c.name + c.extension);
    Write(path, c.text);
    const auto r = RunAerocal("camera convert --from opencv --to aerocal " + path + " " +
                              d.File(c.name + ".out.yaml"));
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find(path + ":" + std::to_string(c.line) + ": "), std::string::npos)
        << r.output;
    EXPECT_NE(r.output.find(c.words), std::string::npos) << r.output;
    for (const char* internal : {"OpenCV(", "cv::Mat", ".cpp", "in function"})
      EXPECT_EQ(r.output.find(internal), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(d.File(c.name + ".out.yaml")));
  }
}

// ---- class 9: --camera names a camera of the file, or is refused ----

TEST(CameraOption, ACameraOnAFileOfOneCameraWithoutIdsIsRefused) {
  TempDir d("aerocal_bad_input3_camera_id");
  Write(d.File("cv.yml"), kGoodYaml);
  struct Case {
    std::string from, file, size;
  };
  for (const Case& c :
       std::vector<Case>{{"opencv", d.File("cv.yml"), ""},
                         {"aerocal", std::string(AEROCAL_CONFIGS_DIR) + "/camera_2x3.yaml", ""},
                         {"ros", Seed("ros.yaml"), ""},
                         {"pix4d", Seed("camera.cam"), " --width 14000 --height 12000"},
                         {"camodocal", Seed("camodocal.yaml"), ""}}) {
    SCOPED_TRACE(c.from);
    ASSERT_TRUE(fs::exists(c.file)) << c.file;
    const auto plain = RunAerocal("camera show --from " + c.from + " " + c.file + c.size);
    ASSERT_EQ(plain.exit_code, 0) << plain.output;
    const auto r =
        RunAerocal("camera show --from " + c.from + " " + c.file + c.size + " --camera 2");
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find(c.file + ":1: --camera 2: the file holds one " + c.from + " camera"),
              std::string::npos)
        << r.output;
  }
  // Files holding several cameras keep taking --camera (the COLMAP seed holds camera 1, the rig
  // file heads A and B).
  EXPECT_EQ(RunAerocal("camera show --from aerocal " + std::string(AEROCAL_CONFIGS_DIR) +
                       "/rig_dual_lens.yaml --camera B")
                .exit_code,
            0);
  EXPECT_EQ(
      RunAerocal("camera show --from colmap " + Seed("cameras.txt") + " --camera 1").exit_code, 0);
  const auto unknown =
      RunAerocal("camera show --from colmap " + Seed("cameras.txt") + " --camera 99");
  EXPECT_EQ(unknown.exit_code, 2) << unknown.output;
  EXPECT_NE(unknown.output.find("no camera 99"), std::string::npos) << unknown.output;
}

// ---- class 8: camera convert's OUT and --report ----

TEST(CameraConvertOutputs, AReportOrOutNamingAnInputOrTheOtherOutputIsRefused) {
  TempDir d("aerocal_bad_input3_convert");
  Write(d.File("cv.yml"), kGoodYaml);
  const std::string in = d.File("cv.yml"), out = d.File("out.yaml");
  const std::string convert = "camera convert --from opencv --to aerocal ";
  struct Case {
    std::string args, option;
  };
  for (const Case& c : std::vector<Case>{
           {in + " " + out + " --report " + out, "--report: '" + out + "' is OUT"},
           {in + " " + out + " --report " + d.File("./sub/../out.yaml"), "--report"},
           {in + " " + out + " --report " + in, "--report: '" + in + "' is IN"},
           {in + " " + d.File("./cv.yml"), "OUT: '" + d.File("./cv.yml") + "' is IN"}}) {
    SCOPED_TRACE(c.args);
    const std::string before = Read(in);
    const auto r = RunAerocal(convert + c.args);
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find(c.option), std::string::npos) << r.output;
    EXPECT_EQ(Read(in), before);
    EXPECT_FALSE(fs::exists(out));
  }
  // A hard link to the input is the input.
  fs::create_hard_link(in, d.File("link.yml"));
  const auto linked = RunAerocal(convert + in + " " + out + " --report " + d.File("link.yml"));
  EXPECT_EQ(linked.exit_code, 2) << linked.output;
  EXPECT_NE(linked.output.find("--report"), std::string::npos) << linked.output;
}

TEST(CameraConvertOutputs, OutAndReportInTwoFoldersAreOneSet) {
  TempDir d("aerocal_bad_input3_convert_set");
  Write(d.File("cv.yml"), kGoodYaml);
  const std::string convert = "camera convert --from opencv --to dji " + d.File("cv.yml") + " " +
                              d.File("a/out.txt") + " --report " + d.File("b/report.json") +
                              " --mkdir";
  const auto r = RunAerocal(convert);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(fs::exists(d.File("a/out.txt")));
  EXPECT_EQ(nlohmann::json::parse(Read(d.File("b/report.json")))["to"], "dji");
  ExpectNoLeftovers(d.path());
  // A conversion whose residual is too large: exit 3, OUT not replaced, the report says why.
  const std::string previous = Read(d.File("a/out.txt"));
  Write(d.File("cv.yml"),
        Replaced(kGoodYaml, "[ -0.1, 0.01, 0., 0., 0. ]", "[ -0.3, 0.2, 0., 0., 0. ]"));
  const auto fit = RunAerocal("camera convert --from opencv --to pix4d " + d.File("cv.yml") + " " +
                              d.File("a/out.txt") + " --report " + d.File("b/report.json") +
                              " --pixel-size-mm 0.005 --max-residual-px 1e-9");
  if (fit.exit_code == 3) {
    EXPECT_EQ(Read(d.File("a/out.txt")), previous);
    EXPECT_FALSE(nlohmann::json::parse(Read(d.File("b/report.json")))["acceptable"].get<bool>());
  } else {
    EXPECT_EQ(fit.exit_code, 0) << fit.output;  // exact: nothing to refuse
  }
  ExpectNoLeftovers(d.path());
}

// Class 3: without --max-residual-px a fit that leaves part of the format unmapped (a drone lens
// whose strong k1 = -0.5, k2 = +0.3 folds inside the format; the ten-parameter model cannot follow
// it and is not invertible there) is exit 3 in every format it is fitted for, nothing written.
TEST(CameraConvertOutputs, AFitNotInvertibleOverTheFormatIsExit3WithoutAGate) {
  TempDir d("aerocal_bad_input3_convert_fit");
  Write(d.File("dji.txt"),
        "3684.48,3677.57,2.24,22.05,-0.5,0.3,3.71107e-3,-3.27247e-3,-0.0300783\n");
  for (const std::string to : {"aerocal --model brown10", "australis", "dbat"}) {
    SCOPED_TRACE(to);
    const auto r =
        RunAerocal("camera convert --from dji --to " + to + " " + d.File("dji.txt") + " " +
                   d.File("out.cam") + " --width 5472 --height 3648 --pixel-mm 0.0024");
    EXPECT_EQ(r.exit_code, 3) << r.output;
    EXPECT_NE(r.output.find("points not invertible"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(d.File("out.cam")));
  }
  ExpectNoLeftovers(d.path());
}

TEST(RigConvertOutputs, AnOutNamingTheDemIsRefusedBeforeAnythingIsRead) {
  TempDir d("aerocal_bad_input3_rig_convert");
  Write(d.File("dem.asc"), "ncols 2\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2\n3 4\n");
  const std::string before = Read(d.File("dem.asc"));
  const auto r =
      RunAerocal("rig convert --camera " + std::string(AEROCAL_CONFIGS_DIR) +
                 "/rig_dual_lens.yaml --images A=" + d.File("a.tif") + ",B=" + d.File("b.tif") +
                 " --out " + d.File("dem.asc") + " --dem " + d.File("./dem.asc"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--out: '" + d.File("dem.asc") + "' is --dem"), std::string::npos)
      << r.output;
  EXPECT_EQ(Read(d.File("dem.asc")), before);
}

// ---- class 7: size products of options, bounded before allocation ----

TEST(SizeProducts, AreRefusedByNameBeforeAnythingIsAllocated) {
  TempDir d("aerocal_bad_input3_sizes");
  Write(d.File("photo.pgm"), "P2\n2 2\n255\n0 255\n255 0\n");
  struct Case {
    std::string args, words;
  };
  for (const Case& c : std::vector<Case>{
           {"simulate --pushbroom --render-images --texture " + d.File("photo.pgm") +
                " --lines 1000000 --detectors 100000 --out " + d.File("pb"),
            "--lines x --detectors"},
           {"simulate --pushbroom --lines 2000000 --out " + d.File("pb"), "--lines"},
           {"simulate --exposures 20000 --stitch-ties 10000 --out " + d.File("pb"),
            "--exposures x --stitch-ties"},
           {"simulate --exposures 20000 --stitch-ties 0 --tie-points 1000000 --out " + d.File("pb"),
            "--exposures x (--surveyed-points + --tie-points)"},
           {"simulate --pushbroom --render-images --texture " + d.File("photo.pgm") +
                " --reference-size 20000x20000 --out " + d.File("pb"),
            "--reference-size"},
           {"rig error-analysis --camera " + std::string(AEROCAL_CONFIGS_DIR) +
                "/rig_dual_lens.yaml --limits " + std::string(AEROCAL_CONFIGS_DIR) +
                "/rig_dual_lens_limits.yaml --grid 200 --samples 1000000 --mkdir --out " +
                d.File("pb/ea.json"),
            "--grid x --grid x --samples"},
       }) {
    SCOPED_TRACE(c.args);
    const auto r = RunAerocal(c.args);
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find(c.words), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(d.File("pb")));
  }
}

}  // namespace
}  // namespace aerocal
