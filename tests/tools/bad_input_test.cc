// Issue 12: bad input never crashes, hangs or passes quietly. Each case of the mutation campaign
// is one row: a mutation of a small simulated flight (or a hand-written import file), the command,
// the exit code (2 bad input, 3 numerical failure) and the FILE:LINE (or option) the message must
// name; the output must not exist afterwards. Plus the reader rules that must ACCEPT input (BOM,
// CRLF, CR, '#' inside a row) and the stitching robust start against a 20000 px decimal slip.
#include "calib/camera/camera_io.h"
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"
#include "calib/core/error.h"
#include "calib/core/yaml_util.h"
#include "stitch/adjustment/stitch_adjustment.h"
#include "tests/support/bad_input_case.h"
#include "tests/support/test_support.h"
#include "triangulation/block/block_io.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <sys/stat.h>
#include <unistd.h>

namespace aerocal {
namespace {

namespace fs = std::filesystem;
using testing::RunAerocal;
using testing::RunCommand;
using testing::TempDir;

std::string Read(const std::string& path) { return testing::ReadFileText(path); }
void Write(const std::string& path, const std::string& text) { testing::WriteFileText(path, text); }

std::vector<std::string> Lines(const std::string& path) {
  std::vector<std::string> lines;
  std::istringstream in(Read(path));
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

void WriteLines(const std::string& path, const std::vector<std::string>& lines) {
  std::string text;
  for (const auto& l : lines) text += l + "\n";
  Write(path, text);
}

// Replaces the first occurrence of `from` in the file; fails the test when absent.
void Replace(const std::string& path, const std::string& from, const std::string& to) {
  std::string text = Read(path);
  const auto at = text.find(from);
  ASSERT_NE(at, std::string::npos) << from << " not in " << path;
  text.replace(at, from.size(), to);
  Write(path, text);
}

// Sets field `col` (0-based) of 1-based line `line` of a CSV file.
void SetField(const std::string& path, int line, int col, const std::string& value) {
  auto lines = Lines(path);
  std::vector<std::string> f;
  std::stringstream in(lines[line - 1]);
  for (std::string x; std::getline(in, x, ',');) f.push_back(x);
  f.resize(std::max<size_t>(f.size(), col + 1));
  f[col] = value;
  std::string joined;
  for (size_t i = 0; i < f.size(); ++i) joined += (i ? "," : "") + f[i];
  lines[line - 1] = joined;
  WriteLines(path, lines);
}

// The small simulated flight every CLI case starts from (made once).
const std::string& BaseFlight() {
  static TempDir dir("aerocal_bad_input_base");
  static const bool made = [] {
    const auto r =
        RunAerocal("simulate --out " + dir.File("sim") +
                   " --exposures 6 --strips 1 --surveyed-points 12 --control 6 --tie-points 40 "
                   "--stitch-ties 60");
    EXPECT_EQ(r.exit_code, 0) << r.output;
    return true;
  }();
  (void)made;
  static const std::string path = dir.File("sim");
  return path;
}

// A copy of the base flight in a fresh folder `d`/sim.
std::string Flight(const TempDir& d) {
  fs::copy(BaseFlight(), d.File("sim"), fs::copy_options::recursive);
  return d.File("sim");
}

// A copy of a simulated pushbroom flight (`simulate --pushbroom`) or dual-lens rig flight
// (`simulate --rig dual-lens`), each simulated once, in the fresh folder `d`/`name`.
std::string SimulatedCopy(const TempDir& d, const std::string& name, const std::string& options) {
  static TempDir base("aerocal_bad_input_kinds");
  static std::map<std::string, bool> made;
  if (!made[name]) {
    const auto r = RunAerocal("simulate --out " + base.File(name) + " " + options);
    EXPECT_EQ(r.exit_code, 0) << r.output;
    made[name] = true;
  }
  fs::copy(base.File(name), d.File(name), fs::copy_options::recursive);
  return d.File(name);
}
std::string PushbroomFlight(const TempDir& d) { return SimulatedCopy(d, "pb", "--pushbroom"); }
std::string RigFlight(const TempDir& d) { return SimulatedCopy(d, "rig", "--rig dual-lens"); }
// A frame flight whose exposures.csv carries the velocity columns vX, vY, vZ.
std::string VelocityFlight(const TempDir& d) {
  return SimulatedCopy(
      d,
      "vel",
      "--exposures 6 --strips 1 --surveyed-points 12 --control 6 --tie-points 40 --speed-mps 60");
}
// A small test field (`simulate --test-field`): 2 groups (A, B) of 4 images, groups.csv lines 2-9.
std::string TestField(const TempDir& d) {
  return SimulatedCopy(d, "tf", "--test-field --groups 2 --images-per-group 4");
}

// Replaces the first `from` in the file by `to` (the case's one defect); `from` must be there.
void ReplaceFirst(const std::string& path, const std::string& from, const std::string& to) {
  testing::ReplaceFirstInFile(path, from, to);
}

std::string PushbroomArgs(const std::string& pb) {
  return "pushbroom calibrate --camera " + pb + "/camera_nominal.yaml --pos " + pb +
         "/pos.csv --observations " + pb + "/observations.csv --points " + pb +
         "/points.csv --out " + pb + "/r.json --write-camera " + pb + "/cam_out.yaml";
}

// A line of the four-head rig (`simulate --rig uav4`, 2 exposures) and `rig stitch` on it.
std::string Uav4Line(const TempDir& d) {
  return SimulatedCopy(d, "uav4", "--rig uav4 --exposures 2");
}
std::string RigStitchArgs(const std::string& line, const std::string& extra = "") {
  return "rig stitch --camera " + line + "/rig_truth.yaml --project " + line + " " + extra +
         " --out " + line + "/stitch.json";
}

std::string RigAnalysisArgs(const std::string& rig) {
  return "rig error-analysis --camera " + rig + "/rig_nominal.yaml --limits " +
         std::string(AEROCAL_CONFIGS_DIR) + "/rig_dual_lens_limits.yaml --no-plots --out " + rig +
         "/ea";
}

// Minimal DBAT block: a camera XML, two images, eight marks each, initial EO.
void WriteDbat(const std::string& dir) {
  Write(dir + "/cam.xml",
        "<?xml version=\"1.0\"?>\n<document><cameras><camera>\n<name>test</name>\n"
        "<sensor>auto,24</sensor>\n<image>6000,4000</image>\n<focal>35</focal>\n<cc>35</cc>\n"
        "<pp>0,0</pp>\n<K>0,0,0</K>\n<P>0,0</P>\n</camera></cameras></document>\n");
  Write(dir + "/images.txt", "1, img1.jpg\n2, img2.jpg\n");
  Write(dir + "/eo.txt", "1, 0, 0, 100, 0, 0, 0\n2, 20, 0, 100, 0, 0, 0\n");
  std::string marks;
  for (int image = 1; image <= 2; ++image)
    for (int p = 1; p <= 8; ++p)
      marks += std::to_string(image) + ", " + std::to_string(p) + ", " +
               std::to_string(500 + 500 * p - 1500 * image) + ", " + std::to_string(800 + 300 * p) +
               "\n";
  Write(dir + "/marks.txt", marks);
}

std::string DbatArgs(const std::string& dir, const std::string& marks = "") {
  return "import dbat --camera-xml " + dir + "/cam.xml --marks " +
         (marks.empty() ? dir + "/marks.txt" : marks) + " --images " + dir +
         "/images.txt --initial-eo " + dir + "/eo.txt --out " + dir + "/out";
}

// Minimal COLMAP text model: one OPENCV camera, two images, four points.
void WriteColmap(const std::string& dir) {
  fs::create_directories(dir + "/model");
  Write(dir + "/model/cameras.txt",
        "# Camera list\n1 OPENCV 4000 3000 3000 3000 2000 1500 -0.05 0.01 0.001 -0.001\n");
  std::string images = "# Image list\n";
  for (int i = 1; i <= 2; ++i) {
    images += std::to_string(i) + " 1 0 0 0 " + std::to_string(-2 * i) + " 0 10 1 img" +
              std::to_string(i) + ".jpg\n";
    for (int p = 1; p <= 4; ++p)
      images += std::to_string(1000 + 400 * p) + " " + std::to_string(1000 + 200 * p) + " " +
                std::to_string(p) + " ";
    images += "\n";
  }
  Write(dir + "/model/images.txt", images);
  std::string points = "# 3D points\n";
  for (int p = 1; p <= 4; ++p)
    points += std::to_string(p) + " " + std::to_string(p) + " 1 0 128 128 128 0.5 1 0 2 0\n";
  Write(dir + "/model/points3D.txt", points);
}

std::string ColmapArgs(const std::string& dir) {
  return "import colmap --colmap-model " + dir + "/model --pixel-size-mm 0.005 --out " + dir +
         "/out";
}

// The ODM list of a 2x... near-nadir block: three targets seen by two images each.
void WriteOdm(const std::string& dir) {
  std::string gcp = "+proj=utm +zone=33 +datum=WGS84\n";
  const double xyz[3][3] = {{100, 100, 10}, {160, 100, 12}, {130, 150, 11}};
  for (int image = 1; image <= 2; ++image)
    for (int t = 0; t < 3; ++t)
      gcp += std::to_string(xyz[t][0]) + " " + std::to_string(xyz[t][1]) + " " +
             std::to_string(xyz[t][2]) + " " +
             std::to_string(3000 + 40 * (xyz[t][0] - 130) - 300 * image) + " " +
             std::to_string(2000 - 40 * (xyz[t][1] - 125)) + " img" + std::to_string(image) +
             ".jpg T" + std::to_string(t + 1) + "\n";
  Write(dir + "/gcp.txt", gcp);
  Write(dir + "/cam.yaml", "pixel_size_mm: 0.004\nformat_px: [6000, 4000]\ninterior: {c: 24}\n");
}

std::string OdmArgs(const std::string& dir) {
  return "import odm --gcp-list " + dir + "/gcp.txt --camera " + dir + "/cam.yaml --out " + dir +
         "/out";
}

// Sets the field of column `column` (by its header name) of 1-based line `line` of a CSV file.
void SetColumn(const std::string& path,
               int line,
               const std::string& column,
               const std::string& value) {
  const auto header = Lines(path).at(0);
  std::stringstream in(header);
  int index = 0;
  for (std::string name; std::getline(in, name, ','); ++index)
    if (name == column) return SetField(path, line, index, value);
  ADD_FAILURE() << column << " not in " << path;
}

// Appends `text` to the file.
void Append(const std::string& path, const std::string& text) { Write(path, Read(path) + text); }

// Adjusts the simulated rig project `rig` (RigFlight).
std::string RigAdjustArgs(const std::string& rig) {
  return "adjust --project " + rig + "/project.yaml --out " + rig + "/../a.json";
}

std::string CalibrateArgs(const std::string& tf) {
  return "calibrate --camera " + tf + "/camera_nominal.yaml --observations " + tf +
         "/observations.csv --points " + tf + "/points.csv --out " + tf + "/../cal.json";
}

// The test field's observations with a `group` column from its groups.csv; the image of
// observation row `odd_row` (1-based line) is put into group `odd_group` instead.
void AddGroupColumn(const std::string& tf,
                    const std::string& group_of_all = "",
                    int odd_row = 0,
                    const std::string& odd_group = "") {
  std::map<std::string, std::string> groups;
  for (const auto& line : Lines(tf + "/groups.csv"))
    groups[line.substr(0, line.find(','))] = line.substr(line.find(',') + 1);
  auto lines = Lines(tf + "/observations.csv");
  lines[0] += ",group";
  for (size_t i = 1; i < lines.size(); ++i) {
    const std::string image = lines[i].substr(0, lines[i].find(','));
    lines[i] += "," + (static_cast<int>(i) + 1 == odd_row ? odd_group
                       : group_of_all.empty()             ? groups.at(image)
                                                          : group_of_all);
  }
  WriteLines(tf + "/observations.csv", lines);
}

// A minimal calibrate result for `certificate`: one uncertainty row, with or without the
// calibration's stability table.
std::string CertificateResult(const std::string& uncertainty_row, bool stability = true) {
  return "{\"kind\": \"adjust\", \"schema_version\": 2, \"command\": \"calibrate\",\n"
         " \"valid\": true, \"cameras\": [{}],\n"
         " \"calibration\": {\"method\": {}, \"camera\": {}, \"data\": {}, \"rms_px\": 0.1,"
         " \"groups\": [],\n  \"uncertainty\": [" +
         uncertainty_row + "]" + (stability ? ", \"stability\": {}" : "") + "}}\n";
}

// A valid uncertainty row (its statement states its value, U, k and unit; issue 37).
const std::string kCertificateRow =
    "{\"quantity\": \"c\", \"unit\": \"mm\", \"value\": 1, \"U\": 0.1, \"k\": 2,"
    " \"statement\": \"c = 1.00 mm, U = 0.10 mm (k = 2)\"}";

using Case = testing::BadInputCase;

std::string StitchArgs(const std::string& sim, const std::string& out = "") {
  return "stitch --camera " + sim + "/camera_nominal.yaml --obs " + sim +
         "/stitch_obs.csv --base III,IV --out " + (out.empty() ? sim + "/../s.json" : out);
}

std::string AdjustArgs(const std::string& sim) {
  return "adjust --project " + sim + "/project.yaml --out " + sim + "/../a.json";
}

const std::vector<Case>& Cases() {
  static const std::vector<Case> cases = {
      // ---- input files: refused before reading ----
      {"fifo_as_camera",
       [](const TempDir& d) {
         const auto sim = Flight(d);
         ::mkfifo(d.File("fifo").c_str(), 0600);
         return "stitch --camera " + d.File("fifo") + " --obs " + sim + "/stitch_obs.csv --out " +
                d.File("s.json");
       },
       2, "{DIR}/fifo: is a FIFO", "s.json"},
      {"directory_as_obs",
       [](const TempDir& d) {
         const auto sim = Flight(d);
         return "stitch --camera " + sim + "/camera_nominal.yaml --obs " + sim + " --out " +
                d.File("s.json");
       },
       2, "{DIR}/sim: is a directory", "s.json"},
      {"symlink_loop_project",
       [](const TempDir& d) {
         fs::create_symlink(d.File("loop"), d.File("loop"));
         return "adjust --project " + d.File("loop") + " --out " + d.File("a.json");
       },
       2, "{DIR}/loop: symbolic-link loop", "a.json"},
      {"device_as_dbat_marks",
       [](const TempDir& d) {
         WriteDbat(d.path());
         return DbatArgs(d.path(), "/dev/zero");
       },
       2, "/dev/zero: is a device", "out"},
      {"directory_as_dbat_marks",
       [](const TempDir& d) {
         WriteDbat(d.path());
         return DbatArgs(d.path(), d.path());
       },
       2, "is a directory", "out"},
      {"empty_dbat_marks",
       [](const TempDir& d) {
         WriteDbat(d.path());
         Write(d.File("marks.txt"), "");
         return DbatArgs(d.path());
       },
       2, "{DIR}/marks.txt: no image observations", "out"},
      // ---- YAML strictly ----
      {"yaml_duplicate_key",
       [](const TempDir& d) {
         const auto sim = Flight(d);
         Replace(sim + "/camera_nominal.yaml", "format_px: [14000, 12000]",
                 "format_px: [14000, 12000]\npixel_size_mm: 0.5");
         return StitchArgs(sim);
       },
       2, "camera_nominal.yaml:5: duplicate key 'pixel_size_mm'", "s.json"},
      {"yaml_key_is_a_sequence",
       [](const TempDir& d) {
         const auto sim = Flight(d);
         Replace(sim + "/project.yaml", "exposures: exposures.csv", "[a, b]: 1\nexposures: exposures.csv");
         return AdjustArgs(sim);
       },
       2, "project.yaml:3: a map key must be a plain name", "a.json"},
      {"yaml_key_is_a_map",
       [](const TempDir& d) {
         const auto sim = Flight(d);
         Replace(sim + "/camera_nominal.yaml", "interior:", "? {a: 1}\n: 2\ninterior:");
         return StitchArgs(sim);
       },
       2, "camera_nominal.yaml:5: a map key must be a plain name", "s.json"},
      {"yaml_value_is_a_map",
       [](const TempDir& d) {
         const auto sim = Flight(d);
         Replace(sim + "/camera_nominal.yaml", "pixel_size_mm: 0.0089999999999999993",
                 "pixel_size_mm: {a: 1}");
         return StitchArgs(sim);
       },
       2, "camera_nominal.yaml:3: pixel_size_mm must be a number", "s.json"},
      // ---- frames ----
      {"frame_local_without_lat",
       [](const TempDir& d) {
         const auto sim = Flight(d);
         Replace(sim + "/project.yaml", "frame: {projected: \"simulated local frame\"}",
                 "frame: {local: {lon: 7}}");
         return AdjustArgs(sim);
       },
       2, "project.yaml:6: frame: local needs 'lat'", "a.json"},
      {"frame_utm_with_metre_coordinates",
       [](const TempDir& d) {
         const auto sim = Flight(d);
         Replace(sim + "/project.yaml", "frame: {projected: \"simulated local frame\"}",
                 "frame: {utm: \"33N\"}");
         return AdjustArgs(sim);
       },
       2, "points.csv:2: not a longitude/latitude/height", "a.json"},
      {"frame_local_with_metre_coordinates",
       [](const TempDir& d) {
         const auto sim = Flight(d);
         Replace(sim + "/project.yaml", "frame: {projected: \"simulated local frame\"}",
                 "frame: {local: {lat: 47, lon: 8}}");
         return AdjustArgs(sim);
       },
       2, "project.yaml:6) takes geodetic", "a.json"},
      {"frame_not_a_map",
       [](const TempDir& d) {
         const auto sim = Flight(d);
         Replace(sim + "/project.yaml", "frame: {projected: \"simulated local frame\"}",
                 "frame: [1, 2]");
         return AdjustArgs(sim);
       },
       2, "project.yaml:6: frame must be one of", "a.json"},
      // ---- CSV values ----
      {"control_point_without_sigma",
       [](const TempDir& d) {
         const auto sim = Flight(d);
         SetField(sim + "/points.csv", 2, 4, "");
         SetField(sim + "/points.csv", 2, 5, "");
         SetField(sim + "/points.csv", 2, 6, "");
         return AdjustArgs(sim);
       },
       2, "points.csv:2: control point 'C1' needs sX, sY, sZ", "a.json"},
      {"exposure_angle_out_of_range",
       [](const TempDir& d) {
         const auto sim = Flight(d);
         SetField(sim + "/exposures.csv", 3, 7, "1e300");
         return AdjustArgs(sim);
       },
       2, "exposures.csv:3: column 'kappa' out of range", "a.json"},
      {"observation_pixel_out_of_range",
       [](const TempDir& d) {
         const auto sim = Flight(d);
         SetField(sim + "/observations.csv", 4, 2, "1e200");
         return AdjustArgs(sim);
       },
       2, "observations.csv:4: column 'col' out of range", "a.json"},
      // ---- outputs ----
      {"out_device",
       [](const TempDir& d) { return StitchArgs(Flight(d), "/dev/null"); }, 2,
       "--out '/dev/null': exists and is a device", ""},
      {"out_empty",
       [](const TempDir& d) { return StitchArgs(Flight(d), "''"); }, 2, "--out: empty path",
       ""},
      {"out_directory",
       [](const TempDir& d) { return StitchArgs(Flight(d), d.path()); }, 2,
       "exists and is a directory", ""},
      {"out_below_a_file",
       [](const TempDir& d) {
         const auto sim = Flight(d);
         return StitchArgs(sim, sim + "/points.csv/s.json");
       },
       2, "a part of the path is a file", ""},
      {"out_name_too_long",
       [](const TempDir& d) { return StitchArgs(Flight(d), d.File(std::string(300, 'a'))); },
       2, "name too long", ""},
      {"simulate_out_device",
       [](const TempDir&) { return std::string("simulate --out /dev/null"); }, 2,
       "--out '/dev/null': exists and is not a folder", ""},
      {"resample_out_below_a_file",
       [](const TempDir& d) {
         const auto sim = Flight(d);
         return "resample --camera " + sim + "/camera_nominal.yaml --mapping x.json --images I=a.tif --out " +
                sim + "/points.csv/v.tif";
       },
       2, "--out", ""},
      {"resample_out_name_too_long",
       [](const TempDir& d) {
         const auto sim = Flight(d);
         return "resample --camera " + sim + "/camera_nominal.yaml --mapping x.json --images I=a.tif --out " +
                d.File(std::string(300, 'v') + ".tif");
       },
       2, "name too long", ""},
      // ---- options ----
      {"simulate_height_nan", [](const TempDir& d) { return "simulate --out " + d.File("o") + " --height-m nan"; },
       2, "--height-m: must be a finite number", "o"},
      {"simulate_height_inf", [](const TempDir& d) { return "simulate --out " + d.File("o") + " --height-m inf"; },
       2, "--height-m", "o"},
      {"simulate_height_huge", [](const TempDir& d) { return "simulate --out " + d.File("o") + " --height-m 1e308"; },
       2, "--height-m", "o"},
      {"simulate_layout_unbounded",
       [](const TempDir& d) { return "simulate --out " + d.File("o") + " --layout 200x200"; }, 2,
       "--layout must be ROWSxCOLS, 1..10 each", "o"},
      {"stitch_sigma_nan",
       [](const TempDir& d) { return StitchArgs(Flight(d)) + " --sigma-px nan"; }, 2,
       "--sigma-px: must be a finite number", "s.json"},
      // ---- stitching ----
      {"stitch_u_overflow",
       [](const TempDir& d) {
         const auto sim = Flight(d);
         SetField(sim + "/stitch_obs.csv", 5, 3, "1e300");
         return StitchArgs(sim);
       },
       2, "stitch_obs.csv:5: column 'u' out of range", "s.json"},
      {"stitch_subimage_params_overflow",
       [](const TempDir& d) {
         const auto sim = Flight(d);
         Replace(sim + "/camera_nominal.yaml", "params: [1, 0, 6900, 0, 1, 0]",
                 "params: [1, 0, 1e308, 0, 1, 0]");
         return StitchArgs(sim);
       },
       2, "camera_nominal.yaml:24: params out of range", "s.json"},
      {"stitch_reference_point_overflow",
       [](const TempDir& d) {
         const auto sim = Flight(d);
         Replace(sim + "/camera_nominal.yaml", "U: 30, V: 3963", "U: 1e308, V: 3963");
         return StitchArgs(sim);
       },
       2, "camera_nominal.yaml:42: U out of range", "s.json"},
      {"stitch_measured_twice",
       [](const TempDir& d) {
         const auto sim = Flight(d);
         auto lines = Lines(sim + "/stitch_obs.csv");
         lines.insert(lines.begin() + 9, lines[8]);  // line 9 again as line 10
         WriteLines(sim + "/stitch_obs.csv", lines);
         return StitchArgs(sim);
       },
       2, "stitch_obs.csv:10: frame 0001", "s.json"},
      {"resample_singular_mapping",
       [](const TempDir& d) {
         const auto sim = Flight(d);
         Write(d.File("m.json"),
               R"({"kind": "stitch", "schema_version": 2,
                   "subimages": [{"id": "I", "model": "affine", "params": [0,0,0,0,0,0]}]})");
         return "resample --camera " + sim + "/camera_nominal.yaml --mapping " + d.File("m.json") +
                " --images I=a.tif --out " + d.File("v.tif");
       },
       2, "m.json: sub-image I: the affine mapping is singular", "v.tif"},
      // Found by fuzz_stitch_result (2026-11-28): `frames` not an array ended in an uncaught
      // nlohmann type_error (exit 1 in the command, abort in the fuzzer).
      {"resample_frames_not_an_array",
       [](const TempDir& d) {
         const auto sim = Flight(d);
         Write(d.File("m.json"),
               R"({"kind": "stitch", "schema_version": 2, "frames": "conformal",
                   "subimages": [{"id": "I", "model": "affine", "params": [1,0,0,0,1,0]}]})");
         return "resample --camera " + sim + "/camera_nominal.yaml --mapping " + d.File("m.json") +
                " --frame 0001 --images I=a.tif --out " + d.File("v.tif");
       },
       2, "m.json: frames: not an array", "v.tif"},
      {"resample_frame_id_not_a_string",
       [](const TempDir& d) {
         const auto sim = Flight(d);
         Write(d.File("m.json"),
               R"({"kind": "stitch", "schema_version": 2, "frames": [{"frame": 1}, "x"],
                   "subimages": [{"id": "I", "model": "affine", "params": [1,0,0,0,1,0]}]})");
         return "resample --camera " + sim + "/camera_nominal.yaml --mapping " + d.File("m.json") +
                " --frame 0001 --images I=a.tif --out " + d.File("v.tif");
       },
       2, "m.json: no result for frame 0001", "v.tif"},
      // ---- COLMAP ----
      {"colmap_k1_minus_one",
       [](const TempDir& d) {
         WriteColmap(d.path());
         Replace(d.File("model/cameras.txt"), "-0.05 0.01", "-1 0.01");
         return ColmapArgs(d.path());
       },
       2, "model/cameras.txt:2: OPENCV distortion cannot be represented", "out"},
      {"colmap_k1_ten",
       [](const TempDir& d) {
         WriteColmap(d.path());
         Replace(d.File("model/cameras.txt"), "-0.05 0.01", "10 0.01");
         return ColmapArgs(d.path());
       },
       2, "model/cameras.txt:2: OPENCV distortion cannot be represented", "out"},
      {"colmap_fx_zero",
       [](const TempDir& d) {
         WriteColmap(d.path());
         Replace(d.File("model/cameras.txt"), "3000 3000 2000", "0 3000 2000");
         return ColmapArgs(d.path());
       },
       2, "model/cameras.txt:2: focal length must be > 0", "out"},
      {"colmap_width_zero",
       [](const TempDir& d) {
         WriteColmap(d.path());
         Replace(d.File("model/cameras.txt"), "OPENCV 4000", "OPENCV 0");
         return ColmapArgs(d.path());
       },
       2, "model/cameras.txt:2: WIDTH out of range", "out"},
      {"colmap_height_negative",
       [](const TempDir& d) {
         WriteColmap(d.path());
         Replace(d.File("model/cameras.txt"), "4000 3000", "4000 -100");
         return ColmapArgs(d.path());
       },
       2, "model/cameras.txt:2: HEIGHT out of range", "out"},
      {"colmap_width_2_31",
       [](const TempDir& d) {
         WriteColmap(d.path());
         Replace(d.File("model/cameras.txt"), "OPENCV 4000", "OPENCV 2147483648");
         return ColmapArgs(d.path());
       },
       2, "model/cameras.txt:2: WIDTH out of range", "out"},
      {"colmap_width_not_integer",
       [](const TempDir& d) {
         WriteColmap(d.path());
         Replace(d.File("model/cameras.txt"), "OPENCV 4000", "OPENCV 14000.5");
         return ColmapArgs(d.path());
       },
       2, "model/cameras.txt:2: WIDTH must be an integer", "out"},
      {"colmap_zero_quaternion",
       [](const TempDir& d) {
         WriteColmap(d.path());
         Replace(d.File("model/images.txt"), "1 1 0 0 0", "1 0 0 0 0");
         return ColmapArgs(d.path());
       },
       2, "model/images.txt:2: QW QX QY QZ is not a unit quaternion", "out"},
      {"colmap_empty_images",
       [](const TempDir& d) {
         WriteColmap(d.path());
         Write(d.File("model/images.txt"), "");
         return ColmapArgs(d.path());
       },
       2, "images.txt: no image observations", "out"},
      // ---- DBAT ----
      {"dbat_empty_field",
       [](const TempDir& d) {
         WriteDbat(d.path());
         Replace(d.File("marks.txt"), "1, 2, ", "1, 2, , ");
         return DbatArgs(d.path());
       },
       2, "marks.txt:2: empty field 3", "out"},
      {"dbat_two_ids_one_stem",
       [](const TempDir& d) {
         WriteDbat(d.path());
         Write(d.File("images.txt"), "1, img1.jpg\n2, other/img1.tif\n");
         return DbatArgs(d.path());
       },
       2, "images.txt:2: image 2 has the file name 'img1' of line 1", "out"},
      {"dbat_image_zero",
       [](const TempDir& d) {
         WriteDbat(d.path());
         Replace(d.File("cam.xml"), "<image>6000,4000</image>", "<image>0,0</image>");
         return DbatArgs(d.path());
       },
       2, "cam.xml:5: <image> must be two positive integers", "out"},
      {"dbat_xml_malformed",
       [](const TempDir& d) {
         WriteDbat(d.path());
         Replace(d.File("cam.xml"), "<focal>35</focal>", "<focal>35</focl>");
         return DbatArgs(d.path());
       },
       2, "cam.xml:6: invalid XML", "out"},
      // ---- ODM ----
      {"odm_projection_line_only",
       [](const TempDir& d) {
         WriteOdm(d.path());
         Write(d.File("gcp.txt"), "+proj=utm +zone=33 +datum=WGS84\n");
         return OdmArgs(d.path());
       },
       2, "gcp.txt: no targets listed", "out"},
      {"odm_control_matches_no_target",
       [](const TempDir& d) {
         WriteOdm(d.path());
         return OdmArgs(d.path()) + " --control X1,X2";
       },
       2, "--control: 'X1' is no target", "out"},
      {"odm_image_with_one_target_only",
       [](const TempDir& d) {
         WriteOdm(d.path());
         auto lines = Lines(d.File("gcp.txt"));
         lines.erase(lines.begin() + 5, lines.begin() + 7);  // img2 keeps one target
         WriteLines(d.File("gcp.txt"), lines);
         return OdmArgs(d.path());
       },
       2, "gcp.txt: 1 observed exposure(s)", "out"},
      // ---- match --list ----
      {"match_list_unknown_subimage",
       [](const TempDir& d) {
         const auto sim = Flight(d);
         Write(d.File("list.csv"), "frame,subimage,image\n0001,I,a.tif\n0001,XX,b.tif\n");
         Write(d.File("a.tif"), "x");
         Write(d.File("b.tif"), "x");
         return "match --camera " + sim + "/camera_nominal.yaml --list " + d.File("list.csv") +
                " --out " + d.File("m.csv");
       },
       2, "list.csv:3: sub-image XX", "m.csv"},
      {"match_detector_with_the_predicted_search",
       [](const TempDir& d) {
         const auto sim = Flight(d);
         Write(d.File("a.tif"), "x");
         return "match --camera " + sim + "/camera_nominal.yaml --frame 1 --images I=" +
                d.File("a.tif") + " --detector sift --out " + d.File("m.csv");
       },
       2, "--detector applies to --search descriptors", "m.csv"},
      {"match_unknown_search",
       [](const TempDir& d) {
         const auto sim = Flight(d);
         return "match --camera " + sim + "/camera_nominal.yaml --frame 1 --images I=x.tif"
                " --search nearest --out " + d.File("m.csv");
       },
       2, "search must be descriptors or predicted (got nearest)", "m.csv"},
      // ---- camera convert / show (issue 15): each format's reader ----
      {"metashape_calibration_without_f",
       [](const TempDir& d) {
         Write(d.File("cal.xml"), "<?xml version=\"1.0\"?>\n<calibration>\n  <projection>frame</projection>\n"
                                  "  <width>5472</width>\n  <height>3648</height>\n  <cx>2</cx>\n</calibration>\n");
         return "camera convert --from metashape --to opencv " + d.File("cal.xml") + " " + d.File("o.yml");
       },
       2, "cal.xml:2: missing <f>", "o.yml"},
      {"metashape_covariance_of_the_wrong_size",
       [](const TempDir& d) {
         Write(d.File("cal.xml"), "<calibration>\n<width>100</width><height>80</height><f>90</f>\n"
                                  "<covariance>\n<params>f cx</params>\n<coeffs>1 0 0</coeffs>\n</covariance>\n</calibration>\n");
         return "camera convert --from metashape --to aerocal " + d.File("cal.xml") + " " + d.File("o.yaml") + " --pixel-size-mm 0.005";
       },
       2, "cal.xml:5: <coeffs> must hold 2^2 = 4 values", "o.yaml"},
      {"colmap_camera_of_an_unknown_model",
       [](const TempDir& d) {
         Write(d.File("cameras.txt"), "# cameras\n1 THIN_PRISM_FISHEYE 4000 3000 1 2 3\n");
         return "camera convert --from colmap --to opencv " + d.File("cameras.txt") + " " + d.File("o.yml");
       },
       2, "cameras.txt:2: camera model THIN_PRISM_FISHEYE", "o.yml"},
      {"colmap_file_with_two_cameras_and_no_choice",
       [](const TempDir& d) {
         Write(d.File("cameras.txt"), "1 PINHOLE 400 300 300 300 200 150\n2 PINHOLE 400 300 300 300 200 150\n");
         return "camera convert --from colmap --to opencv " + d.File("cameras.txt") + " " + d.File("o.yml");
       },
       2, "name one with --camera (1, 2)", "o.yml"},
      {"dji_dewarpdata_with_eight_values",
       [](const TempDir& d) {
         Write(d.File("dji.txt"), "\n2018-09-06;3684.48,3677.57,2.24,22.05,-0.26,0.10,3.7e-5,-3.2e-4\n");
         return "camera convert --from dji --to opencv " + d.File("dji.txt") + " " + d.File("o.yml") + " --width 5472 --height 3648";
       },
       2, "dji.txt:2: DewarpData must hold 9 values", "o.yml"},
      {"dji_string_without_an_image_size",
       [](const TempDir& d) {
         Write(d.File("dji.txt"), "3684.48,3677.57,2.24,22.05,-0.26,0.10,3.7e-5,-3.2e-4,-0.03\n");
         return "camera convert --from dji --to opencv " + d.File("dji.txt") + " " + d.File("o.yml");
       },
       2, "dji.txt:1: the file gives no image size: pass --width", "o.yml"},
      {"opensfm_width_contradicted_by_the_option",
       [](const TempDir& d) {
         Write(d.File("cameras.json"), "{\n  \"c\": {\n    \"projection_type\": \"perspective\",\n"
                                       "    \"width\": 1368, \"height\": 912, \"focal\": 0.66, \"k1\": 0, \"k2\": 0\n  }\n}\n");
         return "camera convert --from opensfm --to opencv " + d.File("cameras.json") + " " + d.File("o.yml") + " --width 1000";
       },
       2, "cameras.json:2: the file says 1368 px, --width says 1000", "o.yml"},
      {"pix4d_cam_without_a_pixel_size",
       [](const TempDir& d) {
         Write(d.File("p.cam"), "Pix4D camera calibration file 0\nF 8.8\nPx 6.5\nPy 4.4\nK1 -0.1\n");
         return "camera convert --from pix4d --to opencv " + d.File("p.cam") + " " + d.File("o.yml");
       },
       2, "p.cam:1: the pixel size is needed", "o.yml"},
      {"pix4d_cam_with_an_unknown_parameter",
       [](const TempDir& d) {
         Write(d.File("p.cam"), "F 8.8\nPx 6.5\nPy 4.4\nK4 -0.1\n");
         return "camera convert --from pix4d --to opencv " + d.File("p.cam") + " " + d.File("o.yml") + " --width 100 --height 80 --pixel-size-mm 0.1";
       },
       2, "p.cam:4: unknown parameter 'K4'", "o.yml"},
      {"photomodeler_export_with_a_short_camera_line",
       [](const TempDir& d) {
         Write(d.File("pm.txt"), "Bundle Soln test\n 0.0005 20 2272 1704\n 1 0.1 10 100 100 100 20 20 20\n"
                                 " 7.4653 3.6173 2.6128 7.25319 5.43764 0.00498\n");
         return "camera convert --from photomodeler --to opencv " + d.File("pm.txt") + " " + d.File("o.yml");
       },
       2, "pm.txt:4: f ppx ppy fw fh K1 K2 K3 P1 P2 needs 10 numbers (got 6)", "o.yml"},
      {"australis_report_without_a_camera_constant",
       [](const TempDir& d) {
         Write(d.File("aus.txt"), "Australis Bundle Adjustment Results: Camera Parameters\nH 648 0.007\n"
                                  "V 494 0.007\nXP 0 -0.028 -0.028 1000 0.0069 (mm)\n");
         return "camera convert --from australis --to opencv " + d.File("aus.txt") + " " + d.File("o.yml");
       },
       2, "aus.txt:1: no camera constant", "o.yml"},
      {"adjust_camera_format_unknown",
       [](const TempDir& d) {
         return "adjust --project " + d.File("none.yaml") + " --out " + d.File("r.json") +
                " --self-calibration all --write-camera " + d.File("c.cam") + " --camera-format pix4dd";
       },
       2, "--camera-format: unknown camera format 'pix4dd'", "r.json"},
      {"kalibr_camchain_of_an_unknown_distortion",
       [](const TempDir& d) {
         Write(d.File("chain.yaml"), "cam0:\n  camera_model: pinhole\n  intrinsics: [400, 400, 320, 240]\n"
                                     "  distortion_model: fov\n  distortion_coeffs: [0.1]\n  resolution: [640, 480]\n");
         return "camera convert --from kalibr --to opencv " + d.File("chain.yaml") + " " + d.File("o.yml");
       },
       2, "chain.yaml:4: distortion_model 'fov'", "o.yml"},
      {"opencv_file_without_a_camera_matrix",
       [](const TempDir& d) {
         Write(d.File("cv.yml"), "%YAML:1.0\n---\nimage_width: 640\nimage_height: 480\n");
         return "camera show --from opencv " + d.File("cv.yml");
       },
       2, "cv.yml:1: no camera_matrix", ""},
      {"camera_convert_to_an_unknown_format",
       [](const TempDir& d) {
         Write(d.File("cam.yaml"), "pixel_size_mm: 0.005\nformat_px: [100, 80]\ninterior: {c: 10}\n");
         return "camera convert --from aerocal --to agisoft " + d.File("cam.yaml") + " " + d.File("o.xml");
       },
       2, "--to: unknown camera format 'agisoft'", "o.xml"},
      {"camera_convert_into_mm_without_a_pixel_size",
       [](const TempDir& d) {
         Write(d.File("cameras.txt"), "1 PINHOLE 400 300 300 300 200 150\n");
         return "camera convert --from colmap --to dbat " + d.File("cameras.txt") + " " + d.File("o.xml");
       },
       2, "--pixel-size-mm: the target holds millimetres", "o.xml"},
      {"camera_convert_out_is_a_directory",
       [](const TempDir& d) {
         Write(d.File("cameras.txt"), "1 PINHOLE 400 300 300 300 200 150\n");
         fs::create_directories(d.File("outdir"));
         return "camera convert --from colmap --to opencv " + d.File("cameras.txt") + " " + d.File("outdir");
       },
       2, "OUT", ""},
      // ---- line (pushbroom) camera, POS trajectory, rig camera, certificate (issues 13, 14, 17) ----
      {"line_camera_detectors_do_not_add_up",
       [](const TempDir& d) {
         const auto pb = PushbroomFlight(d);
         ReplaceFirst(pb + "/camera_nominal.yaml", "detectors: 900", "detectors: 901");
         return PushbroomArgs(pb);
       },
       2, "camera_nominal.yaml:9: line.subcameras hold 900 detectors, line.detectors is 901", "pb/r.json"},
      {"line_camera_mount_out_of_range",
       [](const TempDir& d) {
         const auto pb = PushbroomFlight(d);
         ReplaceFirst(pb + "/camera_nominal.yaml", "mount_deg: [0, 20, 0]", "mount_deg: [0, 2000, 0]");
         return PushbroomArgs(pb);
       },
       2, "camera_nominal.yaml:9: sub-camera mount_deg out of range (got 2000", "pb/r.json"},
      {"pos_line_not_increasing",
       [](const TempDir& d) {
         const auto pb = PushbroomFlight(d);
         ReplaceFirst(pb + "/pos.csv", "\n4,", "\n2,");
         return PushbroomArgs(pb);
       },
       2, "pos.csv:6: line must increase strictly", "pb/r.json"},
      {"pos_time_nan",
       [](const TempDir& d) {
         const auto pb = PushbroomFlight(d);
         ReplaceFirst(pb + "/pos.csv", "\n1,1000.0205932272146,", "\n1,nan,");
         return PushbroomArgs(pb);
       },
       2, "pos.csv:3: column 'time_s' must be a number (got 'nan')", "pb/r.json"},
      {"pushbroom_observation_outside_the_trajectory",
       [](const TempDir& d) {
         const auto pb = PushbroomFlight(d);
         ReplaceFirst(pb + "/observations.csv", "\nstrip,c1,804.94626214520156,393.78854414734786,",
                      "\nstrip,c1,804.94626214520156,1e6,");
         return PushbroomArgs(pb);
       },
       2, "observations.csv:2: row (scan line) 1000000 is outside the POS trajectory", "pb/cam_out.yaml"},
      {"pushbroom_boresight_mode_unknown",
       [](const TempDir& d) { return PushbroomArgs(PushbroomFlight(d)) + " --boresight loose"; },
       2, "--boresight must be fixed, free or weighted (got 'loose')", "pb/r.json"},
      {"pushbroom_lever_arm_weighted_without_sigma",
       [](const TempDir& d) { return PushbroomArgs(PushbroomFlight(d)) + " --lever-arm weighted"; },
       2, "--lever-arm-sigma-m must be > 0 when --lever-arm is weighted (got 0)", "pb/r.json"},
      {"pushbroom_boresight_sigma_negative",
       [](const TempDir& d) {
         return PushbroomArgs(PushbroomFlight(d)) + " --boresight weighted --boresight-sigma-deg -0.01";
       },
       2, "--boresight-sigma-deg: must be in (0, 180] (got -0.01)", "pb/r.json"},
      {"rig_reference_head_unknown",
       [](const TempDir& d) {
         const auto rig = RigFlight(d);
         ReplaceFirst(rig + "/rig_nominal.yaml", "reference_head: A", "reference_head: Q");
         return RigAnalysisArgs(rig);
       },
       2, "rig_nominal.yaml:3: reference_head 'Q' is not one of the heads", "rig/ea"},
      {"rig_head_id_twice",
       [](const TempDir& d) {
         const auto rig = RigFlight(d);
         ReplaceFirst(rig + "/rig_nominal.yaml", "- id: B", "- id: A");
         return RigAnalysisArgs(rig);
       },
       2, "rig_nominal.yaml:30: duplicate head id 'A'", "rig/ea"},
      {"rig_mount_out_of_range",
       [](const TempDir& d) {
         const auto rig = RigFlight(d);
         ReplaceFirst(rig + "/rig_nominal.yaml", "mount_deg: [0, 0, 0]", "mount_deg: [0, 0, 1e300]");
         return RigAnalysisArgs(rig);
       },
       2, "rig_nominal.yaml:28: mount_deg out of range (got 1e300", "rig/ea"},
      {"rig_lever_arm_sigma_zero",
       [](const TempDir& d) {
         const auto rig = RigFlight(d);
         ReplaceFirst(rig + "/rig_nominal.yaml", "lever_arm_m: [0, 0, 0]",
                      "lever_arm_m: [0, 0, 0]\n      lever_arm_sigma_m: [0.01, 0, 0.01]");
         return RigAnalysisArgs(rig);
       },
       2, "rig_nominal.yaml:30: lever_arm_sigma_m must be > 0", "rig/ea"},
      // ---- rig stitch (issue 16) ----
      {"rig_stitch_exposure_without_z_ref",
       [](const TempDir& d) {
         const auto line = Uav4Line(d);
         SetField(line + "/exposures.csv", 3, 17, "");
         return RigStitchArgs(line);
       },
       2, "exposures.csv:3: image 0002 has no z_ref", "uav4/stitch.json"},
      {"rig_stitch_z_ref_above_the_rig",
       [](const TempDir& d) {
         const auto line = Uav4Line(d);
         SetField(line + "/exposures.csv", 2, 17, "9000");
         return RigStitchArgs(line);
       },
       2, "exposures.csv:2: image 0001: z_ref (9000 m) must lie below the rig centre Z",
       "uav4/stitch.json"},
      {"rig_stitch_head_not_in_the_camera",
       [](const TempDir& d) {
         const auto line = Uav4Line(d);
         ReplaceFirst(line + "/rig_truth.yaml", "- id: D", "- id: E");
         return RigStitchArgs(line);
       },
       2, "observations.csv:27: head 'D' is not a head of", "uav4/stitch.json"},
      {"rig_stitch_unknown_mode",
       [](const TempDir& d) { return RigStitchArgs(Uav4Line(d), "--mode fast"); },
       2, "--mode must be line, per-exposure or angles (got 'fast')", "uav4/stitch.json"},
      {"rig_stitch_relief_above_the_height",
       [](const TempDir& d) { return RigStitchArgs(Uav4Line(d), "--relief-m 400"); },
       2, "--relief-m must be within [0, ", "uav4/stitch.json"},
      {"rig_stitch_increment_sigma_zero",
       [](const TempDir& d) { return RigStitchArgs(Uav4Line(d), "--increment-sigma-arcsec 0"); },
       2, "--increment-sigma-arcsec: must be in (0, 36000] (got 0)", "uav4/stitch.json"},
      {"rig_stitch_dt_sigma_negative",
       [](const TempDir& d) { return RigStitchArgs(Uav4Line(d), "--dt-sigma-ms -1"); },
       2, "--dt-sigma-ms: must be in (0, 10000] (got -1)", "uav4/stitch.json"},
      {"rig_stitch_alpha_one",
       [](const TempDir& d) { return RigStitchArgs(Uav4Line(d), "--alpha 1"); },
       2, "--alpha must be within (0, 1)", "uav4/stitch.json"},
      {"rig_stitch_rig_orientation_not_level",
       [](const TempDir& d) {
         const auto line = Uav4Line(d);
         ReplaceFirst(line + "/rig_truth.yaml", "orientation: level", "orientation: rig");
         return RigStitchArgs(line);
       },
       2, "rig_truth.yaml: virtual.orientation must be level for rig stitch", "uav4/stitch.json"},
      // ---- rig stitch --render-images / --stitched-out, simulate --rig --render-images (issue 16) ----
      {"rig_stitch_images_without_stitched_out",
       [](const TempDir& d) { return RigStitchArgs(Uav4Line(d), "--images " + d.File("uav4")); },
       2, "--images needs --stitched-out or --match-ties", "uav4/stitch.json"},
      {"rig_stitch_match_ties_without_images",
       [](const TempDir& d) { return RigStitchArgs(Uav4Line(d), "--match-ties"); },
       2, "--match-ties needs --images", "uav4/stitch.json"},
      {"rig_stitch_match_ties_with_observations",
       [](const TempDir& d) {
         const auto line = Uav4Line(d);
         return RigStitchArgs(line, "--images " + line + " --match-ties");
       },
       2, "observations.csv:2: --match-ties measures the ties on the head images: observations.csv "
          "must have no rows", "uav4/stitch.json"},
      {"rig_stitch_images_not_a_folder",
       [](const TempDir& d) {
         const auto line = Uav4Line(d);
         return RigStitchArgs(line, "--images " + line + "/nothing --stitched-out " + line + "/st");
       },
       2, "--images must be a folder of head images", "uav4/stitch.json"},
      {"rig_stitch_head_image_missing",
       [](const TempDir& d) {
         const auto line = Uav4Line(d);
         return RigStitchArgs(line, "--images " + line + "/truth --stitched-out " + line + "/st");
       },
       2, "/truth/0001_A.tif not found", "uav4/st"},
      {"rig_stitch_tile_not_a_multiple_of_16",
       [](const TempDir& d) {
         const auto line = Uav4Line(d);
         return RigStitchArgs(line, "--images " + line + " --stitched-out " + line + "/st --tile-px 100");
       },
       2, "--tile-px must be 0 (strips) or a multiple of 16 in 16..4096 (got 100)", "uav4/st"},
      {"rig_stitch_feather_zero",
       [](const TempDir& d) {
         const auto line = Uav4Line(d);
         return RigStitchArgs(line, "--images " + line + " --stitched-out " + line + "/st --feather-px 0");
       },
       2, "--feather-px: must be in [1, 255] (got 0)", "uav4/st"},
      {"simulate_rig_format_scale_zero",
       [](const TempDir& d) { return "simulate --rig uav4 --format-scale 0 --out " + d.File("o"); },
       2, "--format-scale: must be in (0, 1]", "o"},
      {"simulate_rig_format_scale_above_one",
       [](const TempDir& d) { return "simulate --rig uav4 --format-scale 1.5 --out " + d.File("o"); },
       2, "--format-scale: must be in (0, 1]", "o"},
      {"simulate_format_scale_without_rig",
       [](const TempDir& d) { return "simulate --format-scale 0.5 --out " + d.File("o"); },
       2, "--format-scale applies to a rig flight (--rig) only", "o"},
      {"simulate_edge_targets_with_rig",
       [](const TempDir& d) { return "simulate --rig uav4 --edge-targets --out " + d.File("o"); },
       2, "--edge-targets applies to a frame-camera flight only", "o"},
      {"simulate_psf_sigma_out_of_range",
       [](const TempDir& d) { return "simulate --edge-targets --psf-sigma-px 5 --out " + d.File("o"); },
       2, "--psf-sigma-px", "o"},
      {"simulate_edge_noise_without_edge_targets",
       [](const TempDir& d) { return "simulate --edge-noise-dn 10 --out " + d.File("o"); },
       2, "--edge-targets", "o"},
      {"simulate_rig_images_without_texture",
       [](const TempDir& d) { return "simulate --rig uav4 --render-images --out " + d.File("o"); },
       2, "--texture: the photograph of the scene is required with --render-images", "o"},
      {"simulate_rig_images_texture_missing",
       [](const TempDir& d) {
         return "simulate --rig uav4 --render-images --texture " + d.File("none.jpg") + " --out " + d.File("o");
       },
       2, "none.jpg", "o"},
      {"simulate_rig_images_reference_size",
       [](const TempDir& d) {
         return "simulate --rig uav4 --render-images --texture x.jpg --reference-size 200x200 --out " + d.File("o");
       },
       2, "--reference-size applies to --pushbroom --render-images only", "o"},
      {"simulate_rig_grey_noise_negative",
       [](const TempDir& d) {
         return "simulate --rig uav4 --render-images --texture x.jpg --grey-noise-dn -1 --out " + d.File("o");
       },
       2, "--grey-noise-dn", "o"},
      // ---- the rig in a project (issue 13): rig camera under `cameras:`, head column ----
      {"rig_project_head_unknown",
       [](const TempDir& d) {
         const auto rig = RigFlight(d);
         SetColumn(rig + "/observations.csv", 2, "head", "Q");
         return RigAdjustArgs(rig);
       },
       2, "observations.csv:2: rig 'rig1' has no head 'Q'", "a.json"},
      {"rig_project_head_empty",
       [](const TempDir& d) {
         const auto rig = RigFlight(d);
         SetColumn(rig + "/observations.csv", 2, "head", "");
         return RigAdjustArgs(rig);
       },
       2, "observations.csv:2: head must not be empty", "a.json"},
      {"rig_project_without_head_column",
       [](const TempDir& d) {
         const auto rig = RigFlight(d);
         std::vector<std::string> lines;
         for (auto l : Lines(rig + "/observations.csv")) {  // head A's rows, without the head field
           const size_t a = l.find(','), b = l.find(',', a + 1);
           if (l.substr(a, b - a) == ",B") continue;
           l.erase(a, b - a);
           lines.push_back(l);
         }
         WriteLines(rig + "/observations.csv", lines);
         return RigAdjustArgs(rig);
       },
       2, "observations.csv:2: image 0001 is taken by rig 'rig1': its observations need a head", "a.json"},
      {"rig_project_head_on_a_frame_camera",
       [](const TempDir& d) {
         const auto rig = RigFlight(d);
         Write(rig + "/frame.yaml", "pixel_size_mm: 0.006\nformat_px: [10000, 10000]\ninterior: {c: 150}\n");
         Replace(rig + "/project.yaml", "{rig1: rig_nominal.yaml}", "{rig1: frame.yaml}");
         return RigAdjustArgs(rig);
       },
       2, "observations.csv:2: head 'A' of image 0001: camera 'rig1' is not a rig", "a.json"},
      {"rig_project_duplicate_head_id",
       [](const TempDir& d) {
         const auto rig = RigFlight(d);
         ReplaceFirst(rig + "/rig_nominal.yaml", "- id: B", "- id: A");
         return RigAdjustArgs(rig);
       },
       2, "rig_nominal.yaml:30: duplicate head id 'A'", "a.json"},
      {"rig_project_mount_nan",
       [](const TempDir& d) {
         const auto rig = RigFlight(d);
         ReplaceFirst(rig + "/rig_nominal.yaml", "mount_deg: [0, 1, 0]", "mount_deg: [0, .nan, 0]");
         return RigAdjustArgs(rig);
       },
       2, "rig_nominal.yaml:45: mount_deg must be a number (got '.nan')", "a.json"},
      {"rig_project_lever_arm_inf",
       [](const TempDir& d) {
         const auto rig = RigFlight(d);
         ReplaceFirst(rig + "/rig_nominal.yaml", "lever_arm_m: [0.14999999999999999", "lever_arm_m: [.inf");
         return RigAdjustArgs(rig);
       },
       2, "rig_nominal.yaml:46: lever_arm_m must be a number (got '.inf')", "a.json"},
      {"rig_project_platform_nan",
       [](const TempDir& d) {
         const auto rig = RigFlight(d);
         Append(rig + "/project.yaml", "platform:\n  time_offset_ms: .nan\n");
         return RigAdjustArgs(rig);
       },
       2, "project.yaml:8: platform: time_offset_ms must be a number (got '.nan')", "a.json"},
      {"rig_project_with_two_rigs",
       [](const TempDir& d) {
         const auto rig = RigFlight(d);
         Replace(rig + "/project.yaml", "{rig1: rig_nominal.yaml}", "{rig1: rig_nominal.yaml, rig2: rig_truth.yaml}");
         SetColumn(rig + "/exposures.csv", 2, "camera", "rig2");
         return RigAdjustArgs(rig);
       },
       2, "rig cameras rig1, rig2: the rig bundle takes one rig per project", "a.json"},
      {"rig_adjust_compare",
       [](const TempDir& d) { return RigAdjustArgs(RigFlight(d)) + " --compare"; },
       2, "--compare: not available for a rig project (camera 'rig1')", "a.json"},
      {"rig_adjust_robust_start",
       [](const TempDir& d) { return RigAdjustArgs(RigFlight(d)) + " --robust-start"; },
       2, "--robust-start: not available for a rig project (camera 'rig1')", "a.json"},
      {"rig_adjust_joint_stitching",
       [](const TempDir& d) { return RigAdjustArgs(RigFlight(d)) + " --joint-stitching per-flight"; },
       2, "camera 'rig1' is a rig: the joint adjustment", "a.json"},
  // ---- the project's `platform:` section (lever arm, boresight, GNSS time offset) ----
#define AEROCAL_PLATFORM_CASE(name, yaml, expect)                        \
  {name,                                                                 \
   [](const TempDir& d) {                                                \
     const auto sim = Flight(d);                                         \
     Append(sim + "/project.yaml", std::string("platform:\n") + (yaml)); \
     return AdjustArgs(sim);                                             \
   },                                                                    \
   2,                                                                    \
   (expect),                                                             \
   "a.json"}
      AEROCAL_PLATFORM_CASE("platform_lever_arm_nan", "  lever_arm_m: [.nan, 0, 0]\n",
                            "project.yaml:9: platform: lever_arm_m must be a number (got '.nan')"),
      AEROCAL_PLATFORM_CASE("platform_lever_arm_inf", "  lever_arm_m: [0, -.inf, 0]\n",
                            "project.yaml:9: platform: lever_arm_m must be a number (got '-.inf')"),
      AEROCAL_PLATFORM_CASE("platform_lever_arm_out_of_bounds", "  lever_arm_m: [1e9, 0, 0]\n",
                            "project.yaml:9: platform: lever_arm_m out of range (got 1e9"),
      AEROCAL_PLATFORM_CASE("platform_lever_arm_not_a_list", "  lever_arm_m: 5\n",
                            "project.yaml:9: platform: lever_arm_m must be [x, y, z]"),
      AEROCAL_PLATFORM_CASE("platform_lever_arm_two_values", "  lever_arm_m: [1, 2]\n",
                            "project.yaml:9: platform: lever_arm_m must be [x, y, z]"),
      AEROCAL_PLATFORM_CASE("platform_lever_arm_text", "  lever_arm_m: [a, 0, 0]\n",
                            "project.yaml:9: platform: lever_arm_m must be a number (got 'a')"),
      AEROCAL_PLATFORM_CASE("platform_boresight_out_of_bounds", "  boresight_deg: [0, 0, 1e300]\n",
                            "project.yaml:9: platform: boresight_deg out of range (got 1e300"),
      AEROCAL_PLATFORM_CASE("platform_time_offset_nan", "  time_offset_ms: .nan\n",
                            "project.yaml:9: platform: time_offset_ms must be a number (got '.nan')"),
      AEROCAL_PLATFORM_CASE("platform_time_offset_out_of_bounds", "  time_offset_ms: 1e9\n",
                            "project.yaml:9: platform: time_offset_ms out of range (got 1e9"),
      AEROCAL_PLATFORM_CASE("platform_time_offset_a_list", "  time_offset_ms: [1]\n",
                            "project.yaml:9: platform: time_offset_ms must be a number"),
      AEROCAL_PLATFORM_CASE("platform_mode_a_list", "  lever_arm: [free]\n",
                            "project.yaml:9: platform: lever_arm must be a string"),
      AEROCAL_PLATFORM_CASE("platform_mode_unknown", "  boresight: sometimes\n",
                            "project.yaml:9: platform: boresight must be fixed, free or weighted (got 'sometimes')"),
      AEROCAL_PLATFORM_CASE("platform_duplicate_key", "  lever_arm_m: [0, 0, 0]\n  lever_arm_m: [1, 1, 1]\n",
                            "project.yaml:10: duplicate key 'lever_arm_m'"),
      AEROCAL_PLATFORM_CASE("platform_sigma_zero", "  lever_arm_sigma_m: 0\n",
                            "project.yaml:9: platform: lever_arm_sigma_m must be > 0"),
      AEROCAL_PLATFORM_CASE("platform_sigma_negative", "  boresight_sigma_deg: -1\n",
                            "project.yaml:9: platform: boresight_sigma_deg out of range (got -1"),
      AEROCAL_PLATFORM_CASE("platform_sigma_nan", "  boresight_sigma_deg: .nan\n",
                            "project.yaml:9: platform: boresight_sigma_deg must be a number (got '.nan')"),
      AEROCAL_PLATFORM_CASE("platform_sigma_inf", "  time_offset_sigma_ms: .inf\n",
                            "project.yaml:9: platform: time_offset_sigma_ms must be a number (got '.inf')"),
      AEROCAL_PLATFORM_CASE("platform_weighted_without_sigma", "  lever_arm: weighted\n",
                            "project.yaml:9: platform: weighted needs lever_arm_sigma_m > 0"),
      AEROCAL_PLATFORM_CASE("platform_unknown_key", "  lever_arm_mm: [0, 0, 0]\n",
                            "project.yaml:9: unknown key 'lever_arm_mm'"),
      AEROCAL_PLATFORM_CASE("platform_key_is_a_map", "  {a: 1}: 2\n",
                            "project.yaml:9: a map key must be a plain name"),
      AEROCAL_PLATFORM_CASE("platform_not_a_map", "  - 1\n",
                            "project.yaml:9: platform must be a map"),
#undef AEROCAL_PLATFORM_CASE
  // ---- velocity columns vX, vY, vZ of exposures.csv ----
#define AEROCAL_VELOCITY_CASE(name, value, expect)        \
  {name,                                                  \
   [](const TempDir& d) {                                 \
     const auto sim = VelocityFlight(d);                  \
     SetColumn(sim + "/exposures.csv", 3, "vX", (value)); \
     return AdjustArgs(sim);                              \
   },                                                     \
   2,                                                     \
   (expect),                                              \
   "a.json"}
      AEROCAL_VELOCITY_CASE("velocity_nan", "nan", "exposures.csv:3: column 'vX' must be a number (got 'nan')"),
      AEROCAL_VELOCITY_CASE("velocity_inf", "-inf", "exposures.csv:3: column 'vX' must be a number (got '-inf')"),
      AEROCAL_VELOCITY_CASE("velocity_text", "fast", "exposures.csv:3: column 'vX' must be a number (got 'fast')"),
      AEROCAL_VELOCITY_CASE("velocity_out_of_bounds", "1e9", "exposures.csv:3: vX, vY, vZ must be within +-10000 m/s"),
      AEROCAL_VELOCITY_CASE("velocity_partial", "", "exposures.csv:3: vX, vY, vZ must all be given or none (m/s)"),
#undef AEROCAL_VELOCITY_CASE
      {"velocity_one_column_only",
       [](const TempDir& d) {
         const auto sim = VelocityFlight(d);
         Replace(sim + "/exposures.csv", ",vX,vY,", ",vX,vY_,");
         return AdjustArgs(sim);
       },
       2, "exposures.csv:1: unknown column 'vY_'", "a.json"},
      // ---- a misspelt optional column is refused by name at the header's line (never read as
      // absent: issue 12), in every CSV table a user writes ----
      {"unknown_column_in_exposures",
       [](const TempDir& d) {
         const auto sim = Flight(d);
         Replace(sim + "/exposures.csv", "kappa\n", "kappa,sx\n");
         return AdjustArgs(sim);
       },
       2, "exposures.csv:1: unknown column 'sx' (known: image, camera,", "a.json"},
      {"unknown_column_after_comment_lines",
       [](const TempDir& d) {
         const auto sim = Flight(d);
         Replace(sim + "/points.csv", "role\n", "role,note\n");
         Write(sim + "/points.csv", "# surveyed 2026\n\n" + Read(sim + "/points.csv"));
         return AdjustArgs(sim);
       },
       2, "points.csv:3: unknown column 'note'", "a.json"},
      {"unknown_column_in_observations",
       [](const TempDir& d) {
         const auto sim = Flight(d);
         Replace(sim + "/observations.csv", ",sigma_px\n", ",sigma\n");
         return AdjustArgs(sim);
       },
       2, "observations.csv:1: unknown column 'sigma'", "a.json"},
      {"unknown_column_in_stitch_obs",
       [](const TempDir& d) {
         const auto sim = Flight(d);
         Replace(sim + "/stitch_obs.csv", ",sigma_px\n", ",sigma_pix\n");
         return StitchArgs(sim);
       },
       2, "stitch_obs.csv:1: unknown column 'sigma_pix'", "s.json"},
      {"unknown_column_in_pos",
       [](const TempDir& d) {
         const auto pb = PushbroomFlight(d);
         ReplaceFirst(pb + "/pos.csv", ",skappa\n", ",s_kappa\n");
         return PushbroomArgs(pb);
       },
       2, "pos.csv:1: unknown column 's_kappa'", "pb/r.json"},
      {"unknown_column_in_line_observations",
       [](const TempDir& d) {
         const auto pb = PushbroomFlight(d);
         ReplaceFirst(pb + "/observations.csv", ",sigma_px\n", ",sigmapx\n");
         return PushbroomArgs(pb);
       },
       2, "observations.csv:1: unknown column 'sigmapx'", "pb/r.json"},
      {"unknown_column_in_groups",
       [](const TempDir& d) {
         const auto tf = TestField(d);
         Replace(tf + "/groups.csv", "image,group", "image,group,groupe");
         return CalibrateArgs(tf) + " --groups " + tf + "/groups.csv";
       },
       2, "groups.csv:1: unknown column 'groupe'", "cal.json"},
      // ---- calibrate --budget: its lists are lists (a scalar read as no radii; a map threw
      // yaml-cpp's "invalid node" without FILE:LINE) ----
      {"budget_radii_not_a_list",
       [](const TempDir& d) {
         const auto tf = TestField(d);
         Write(d.File("budget.yaml"), "target_radius_mm: 0.5\nradii_mm: 5\n");
         return CalibrateArgs(tf) + " --budget " + d.File("budget.yaml");
       },
       2, "budget.yaml:2: radii_mm must be a list", "cal.json"},
      {"budget_components_a_map",
       [](const TempDir& d) {
         const auto tf = TestField(d);
         Write(d.File("budget.yaml"), "components: {quantity: c, source: temperature, value: 0.002}\n");
         return CalibrateArgs(tf) + " --budget " + d.File("budget.yaml");
       },
       2, "budget.yaml:1: components must be a list", "cal.json"},
      // ---- a random seed is an unsigned 64-bit integer (CLI11 wraps -1 into 2^64 - 1) ----
      {"simulate_seed_minus_one", [](const TempDir& d) { return "simulate --out " + d.File("o") + " --seed -1"; },
       2, "--seed: must be an integer within 0 .. 18446744073709551615 (got '-1')", "o"},
      {"simulate_seed_past_2_64",
       [](const TempDir& d) { return "simulate --out " + d.File("o") + " --seed 18446744073709551616"; },
       2, "--seed: must be an integer within 0 .. 18446744073709551615", "o"},
  // ---- simulate --test-field options ----
#define AEROCAL_TEST_FIELD_CASE(name, options, expect)                      \
  {name,                                                                    \
   [](const TempDir& d) {                                                   \
     return "simulate --test-field --out " + d.File("o") + " " + (options); \
   },                                                                       \
   2,                                                                       \
   (expect),                                                                \
   "o"}
      AEROCAL_TEST_FIELD_CASE("test_field_groups_zero", "--groups 0", "--groups: must be in [1, 26] (got 0)"),
      AEROCAL_TEST_FIELD_CASE("test_field_groups_27", "--groups 27", "--groups: must be in [1, 26] (got 27)"),
      AEROCAL_TEST_FIELD_CASE("test_field_groups_not_integer", "--groups 2.5", "--groups"),
      AEROCAL_TEST_FIELD_CASE("test_field_images_per_group_3", "--images-per-group 3", "--images-per-group: must be in [4, 1000] (got 3)"),
      AEROCAL_TEST_FIELD_CASE("test_field_distance_nan", "--distance-m nan", "--distance-m: must be a finite number"),
      AEROCAL_TEST_FIELD_CASE("test_field_distance_inf", "--distance-m inf", "--distance-m"),
      AEROCAL_TEST_FIELD_CASE("test_field_distance_zero", "--distance-m 0", "--distance-m: must be in [1, 1000] (got 0)"),
      AEROCAL_TEST_FIELD_CASE("test_field_survey_sigma_zero", "--survey-sigma-m 0", "--survey-sigma-m"),
      AEROCAL_TEST_FIELD_CASE("test_field_image_noise_negative", "--image-noise-px -1", "--image-noise-px"),
      AEROCAL_TEST_FIELD_CASE("test_field_image_sigma_nan", "--image-sigma-px nan", "--image-sigma-px: must be a finite number"),
      AEROCAL_TEST_FIELD_CASE("test_field_flight_option", "--control 3", "--control does not apply to --test-field"),
      AEROCAL_TEST_FIELD_CASE("test_field_relief", "--relief-m 5", "--relief-m does not apply to --test-field"),
      AEROCAL_TEST_FIELD_CASE("test_field_rig_option", "--rig dual-lens", "--rig does not apply to --test-field"),
      AEROCAL_TEST_FIELD_CASE("test_field_pushbroom_option", "--detectors 20", "--detectors does not apply to --test-field"),
#undef AEROCAL_TEST_FIELD_CASE
      {"test_field_option_without_test_field",
       [](const TempDir& d) { return "simulate --planar --out " + d.File("o"); }, 2,
       "--planar applies to --test-field only", "o"},
      // ---- calibrate --groups file and the `group` column of observations.csv ----
      {"groups_unknown_image",
       [](const TempDir& d) {
         const auto tf = TestField(d);
         Append(tf + "/groups.csv", "Z999,A\n");
         return CalibrateArgs(tf) + " --groups " + tf + "/groups.csv";
       },
       2, "groups.csv:10: image Z999 has no observations", "cal.json"},
      {"groups_image_twice",
       [](const TempDir& d) {
         const auto tf = TestField(d);
         Append(tf + "/groups.csv", "A001,B\n");
         return CalibrateArgs(tf) + " --groups " + tf + "/groups.csv";
       },
       2, "groups.csv:10: image A001 listed twice", "cal.json"},
      {"groups_empty_group",
       [](const TempDir& d) {
         const auto tf = TestField(d);
         SetField(tf + "/groups.csv", 2, 1, "");
         return CalibrateArgs(tf) + " --groups " + tf + "/groups.csv";
       },
       2, "groups.csv:2: image and group must not be empty", "cal.json"},
      {"groups_missing_column",
       [](const TempDir& d) {
         const auto tf = TestField(d);
         Replace(tf + "/groups.csv", "image,group", "image,grp");
         return CalibrateArgs(tf) + " --groups " + tf + "/groups.csv";
       },
       2, "groups.csv:1: missing column 'group'", "cal.json"},
      {"groups_group_of_one_image",
       [](const TempDir& d) {
         const auto tf = TestField(d);
         SetField(tf + "/groups.csv", 3, 1, "Z");
         return CalibrateArgs(tf) + " --groups " + tf + "/groups.csv";
       },
       2, "groups.csv:3: group Z has 1 image (a group needs two or more)", "cal.json"},
      {"groups_one_group_only",
       [](const TempDir& d) {
         const auto tf = TestField(d);
         for (int line = 6; line <= 9; ++line) SetField(tf + "/groups.csv", line, 1, "A");
         return CalibrateArgs(tf) + " --groups " + tf + "/groups.csv";
       },
       2, "groups.csv: 1 group(s): the stability test needs two groups or more", "cal.json"},
      {"groups_header_only",
       [](const TempDir& d) {
         const auto tf = TestField(d);
         Write(tf + "/groups.csv", "image,group\n");
         return CalibrateArgs(tf) + " --groups " + tf + "/groups.csv";
       },
       2, "groups.csv: 0 group(s)", "cal.json"},
      {"groups_a_directory",
       [](const TempDir& d) { return CalibrateArgs(TestField(d)) + " --groups " + d.path(); }, 2,
       "{DIR}: is a directory", "cal.json"},
      {"group_column_contradicts_itself",
       [](const TempDir& d) {
         const auto tf = TestField(d);
         AddGroupColumn(tf, "", 6, "Q");
         return CalibrateArgs(tf);
       },
       2, "observations.csv:6: image A001 is in group A above, here in Q", "cal.json"},
      {"group_column_one_group_only",
       [](const TempDir& d) {
         const auto tf = TestField(d);
         AddGroupColumn(tf, "G");
         return CalibrateArgs(tf);
       },
       2, "observations.csv: 1 group(s): the stability test needs two groups or more", "cal.json"},
      {"group_column_and_groups_option",
       [](const TempDir& d) {
         const auto tf = TestField(d);
         AddGroupColumn(tf);
         return CalibrateArgs(tf) + " --groups " + tf + "/groups.csv";
       },
       2, "has a group column already", "cal.json"},
      {"certificate_of_a_broken_json",
       [](const TempDir& d) {
         Write(d.File("r.json"), "{\"schema_version\": 2,\n \"values\": [1, 2\n");
         return "certificate --result " + d.File("r.json") + " --no-render --out " + d.File("cert");
       },
       2, "r.json:3: invalid JSON", "cert"},
      {"certificate_of_an_adjust_result",
       [](const TempDir& d) {
         Write(d.File("r.json"), "{\"schema_version\": 2, \"kind\": \"self_calibration\"}\n");
         return "certificate --result " + d.File("r.json") + " --no-render --out " + d.File("cert");
       },
       2, "r.json: not a result of `aerocal calibrate`", "cert"},
      // The typed reading of a result (fuzz target `cli`): a table missing or of the wrong JSON
      // type names the file and option, before anything is written (a missing key was read
      // through nlohmann's const operator[], undefined behaviour; a statement that is not text
      // threw after certificate.json was written).
      {"certificate_calibration_without_stability",
       [](const TempDir& d) {
         Write(d.File("r.json"), CertificateResult(kCertificateRow, false));
         return "certificate --result " + d.File("r.json") + " --no-render --out " + d.File("cert");
       },
       2, "r.json: calibration.stability: missing", "cert"},
      // The distortion samples read the certified camera's format (a list shorter than two was
      // undefined behaviour through const operator[]).
      {"certificate_format_px_too_short",
       [](const TempDir& d) {
         std::string r = CertificateResult(kCertificateRow);
         const std::string cameras = "\"cameras\": [{}]", camera = "\"camera\": {}";
         r.replace(r.find(cameras), cameras.size(),
                   "\"cameras\": [{\"estimated\": {\"c\": 24, \"x0\": 0, \"y0\": 0, \"K1\": 0, \"K2\": 0,"
                   " \"K3\": 0, \"P1\": 0, \"P2\": 0, \"B1\": 0, \"B2\": 0}}]");
         r.replace(r.find(camera), camera.size(), "\"camera\": {\"pixel_size_mm\": 0.006, \"format_px\": [640]}");
         Write(d.File("r.json"), r);
         return "certificate --result " + d.File("r.json") + " --no-render --out " + d.File("cert");
       },
       2, "r.json: calibration.camera.format_px: expected at least 2 items", "cert"},
      {"certificate_statement_not_text",
       [](const TempDir& d) {
         Write(d.File("r.json"), CertificateResult("{\"quantity\": \"c\", \"unit\": \"mm\", \"value\": 1, \"U\": 0.1, \"k\": 2, \"statement\": 5}"));
         return "certificate --result " + d.File("r.json") + " --no-render --out " + d.File("cert");
       },
       2, "r.json: calibration.uncertainty[0].statement: expected a string (got 5)", "cert"},
      {"certificate_previous_value_not_a_number",
       [](const TempDir& d) {
         Write(d.File("r.json"), CertificateResult(kCertificateRow));
         Write(d.File("p.json"), "{\"kind\": \"certificate\", \"schema_version\": 2,\n"
                                 " \"results\": [{\"quantity\": \"c\", \"unit\": \"mm\", \"value\": \"1.0\", \"U\": 0.1,"
                                 " \"k\": 2, \"statement\": \"c = 1.00 mm, U = 0.10 mm (k = 2)\"}]}\n");
         return "certificate --result " + d.File("r.json") + " --previous " + d.File("p.json") +
                " --no-render --out " + d.File("cert");
       },
       2, "p.json: results[0].value: expected a finite number (got \"1.0\")", "cert"},
  };
  return cases;
}

class BadInput : public ::testing::TestWithParam<size_t> {};

TEST_P(BadInput, ExitsWithItsCodeNamesWhereAndWritesNothing) {
  testing::RunBadInputCase(Cases()[GetParam()]);
}

INSTANTIATE_TEST_SUITE_P(Issue12,
                         BadInput,
                         ::testing::Range<size_t>(0, Cases().size()),
                         [](const ::testing::TestParamInfo<size_t>& info) {
                           return std::string(Cases()[info.param].name);
                         });

// ---- what must be ACCEPTED ----

TEST(ReaderRules, ByteOrderMarkCrlfAndCrLineEndsAreAccepted) {
  for (const std::string eol : {"\n", "\r\n", "\r"}) {
    const auto t =
        CsvTable::Parse("\xEF\xBB\xBFimage,X" + eol + "a,1" + eol + "b,2" + eol, "f.csv");
    ASSERT_EQ(t.rows().size(), 2u);
    EXPECT_EQ(t.header()[0], "image");
    EXPECT_EQ(t.rows()[1].line, 3);
    EXPECT_EQ(t.Number(t.rows()[1], "X"), 2.0);
  }
}

TEST(ReaderRules, AnIdStartingWithHashIsAnIdAndACommentIsNamedByLine) {
  // Issue 28: '#101,p1' was read as a comment and the exposure vanished. After the header a '#'
  // line with the header's number of fields is a row; one that cannot be a row is a comment,
  // counted by line.
  const auto t = CsvTable::Parse(
      "# comment\n  # indented comment\nimage,point\n#101,p1\n a,#p2\n #b,p3\n# note\n", "f.csv");
  ASSERT_EQ(t.rows().size(), 3u);
  EXPECT_EQ(t.String(t.rows()[0], "image"), "#101");
  EXPECT_EQ(t.rows()[0].line, 4);
  EXPECT_EQ(t.String(t.rows()[1], "point"), "#p2");
  EXPECT_EQ(t.String(t.rows()[2], "image"), "#b");
  EXPECT_EQ(t.comment_lines(), std::vector<int>{7});
}

TEST(ReaderRules, StrictYamlNamesTheLineOfADuplicateKey) {
  try {
    LoadYamlText("a: 1\nb: 2\na: 3\n", "x.yaml");
    FAIL() << "duplicate key accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("x.yaml:3: duplicate key 'a'"), std::string::npos)
        << e.what();
  }
  EXPECT_THROW(LoadYamlText(std::string(100, '[') + std::string(100, ']'), "deep.yaml"),
               InputError);
}

TEST(ReaderRules, ADirectoryIsNotAnEmptyFile) {
  TempDir dir;
  try {
    CsvTable::Read(dir.path());
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("is a directory"), std::string::npos) << e.what();
  }
}

TEST(ReaderRules, DbatCameraXmlIsParsedNotPatternMatched) {
  TempDir dir;
  WriteDbat(dir.path());
  // A commented-out <cc> and a <pp> inside <std> must not be taken.
  Replace(dir.File("cam.xml"), "<cc>35</cc>", "<!-- <cc>99</cc> -->\n<cc>35</cc>");
  Replace(dir.File("cam.xml"),
          "<pp>0,0</pp>",
          "<calibration_info><std><pp>1,2</pp></std></calibration_info>\n<pp>12.5,8.5</pp>");
  const auto r = RunAerocal(DbatArgs(dir.path()));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const calib::Camera camera = calib::ReadCamera(dir.File("out/camera_cam1.yaml"));
  EXPECT_NEAR(camera.c_mm(), 35.0, 1e-12);
  const double w_mm = 6000 * 24.0 / 4000;
  EXPECT_NEAR(camera.interior[1], 12.5 - w_mm / 2, 1e-9);  // x0 from the camera's own <pp>
  EXPECT_NEAR(camera.interior[2], 12.0 - 8.5, 1e-9);
}

TEST(ReaderRules, OdmListWithCrOnlyLineEndsImports) {
  TempDir dir;
  WriteOdm(dir.path());
  std::string text = Read(dir.File("gcp.txt"));
  for (char& ch : text)
    if (ch == '\n') ch = '\r';
  Write(dir.File("gcp.txt"), text);
  const auto r = RunAerocal(OdmArgs(dir.path()));
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("imported 2 exposures, 6 observations, 3 points"), std::string::npos)
      << r.output;
}

// A decimal slip of 2e4..2e6 px in one stitching tie ray: found by the robust start before the
// F test, so the model is the clean data's and the slipped tie is the ONLY rejection (without the
// robust start, a 2e5 px slip masked itself and data snooping rejected four good ties instead).
TEST(StitchRobustStart, ADecimalSlipIsTheOnlyRejectionAndLeavesTheModelChoice) {
  TempDir dir;
  const std::string sim = Flight(dir);
  const auto clean = RunAerocal(StitchArgs(sim, dir.File("clean.json")));
  ASSERT_EQ(clean.exit_code, 0) << clean.output;
  std::ifstream a(dir.File("clean.json"));
  const nlohmann::json fa = nlohmann::json::parse(a).at("frames").at(0);
  ASSERT_TRUE(fa.at("rejected").empty()) << fa.at("rejected").dump();
  // The first tie row of frame 0001 (after the reference points).
  const auto lines = Lines(sim + "/stitch_obs.csv");
  int row = 0;
  for (size_t i = 1; i < lines.size() && !row; ++i)
    if (lines[i].rfind("0001,t", 0) == 0) row = static_cast<int>(i) + 1;
  ASSERT_GT(row, 0);
  std::vector<std::string> f;
  std::stringstream in(lines[row - 1]);
  for (std::string x; std::getline(in, x, ',');) f.push_back(x);
  for (const double slip : {2e4, 2e5, 2e6}) {
    SCOPED_TRACE(slip);
    WriteLines(sim + "/stitch_obs.csv", lines);
    SetField(sim + "/stitch_obs.csv", row, 3, std::to_string(std::stod(f[3]) + slip));
    const auto slipped = RunAerocal(StitchArgs(sim, dir.File("slip.json")));
    ASSERT_EQ(slipped.exit_code, 0) << slipped.output;
    std::ifstream b(dir.File("slip.json"));
    const nlohmann::json fb = nlohmann::json::parse(b).at("frames").at(0);
    EXPECT_EQ(fb.at("model"), fa.at("model"));
    ASSERT_FALSE(fb.at("rejected").empty());
    for (const auto& r : fb.at("rejected"))
      EXPECT_EQ(r.at("point").get<std::string>(), f[1]) << fb.at("rejected").dump();
  }
}

// Values that overflow (what the readers now refuse at 1e7 px) fed straight to the adjustment:
// a named numerical failure (not converged, no covariance), never a signal in the SVD.
TEST(StitchNumericalFailure, OverflowingMeasurementsAreNamedNotACrash) {
  const calib::Camera camera = calib::ParseCamera(
      LoadYamlText(
          "pixel_size_mm: 0.009\nformat_px: [14000, 8000]\ninterior: {c: 170}\n"
          "subimages:\n  - {id: I, format_px: [7100, 8000], model: affine}\n"
          "  - {id: II, format_px: [7100, 8000], model: affine, params: [1, 0, 6900, 0, 1, 0]}\n",
          "camera.yaml"),
      "camera.yaml");
  stitch::FrameMeasurements frame;
  frame.frame = "0001";
  for (int i = 0; i < 12; ++i) {
    stitch::TieMeasurement tie;
    tie.point = "t" + std::to_string(i);
    const double v = 300.0 + 600.0 * i;
    tie.rays.push_back({0, {7000.0 + (i % 3), v}, 0.1});
    tie.rays.push_back({1, {100.0 + (i % 3), i == 5 ? 1e200 : v}, 0.1});
    frame.ties.push_back(tie);
  }
  stitch::StitchOptions options;
  options.base_ids = {"I"};
  for (const bool snooping : {false, true}) {
    options.data_snooping = snooping;
    const auto a = stitch::AdjustFrame(camera, frame, calib::MappingModel::kAffine, options);
    if (snooping) {  // the robust start removes the overflowing ray: a clean solution
      EXPECT_TRUE(a.converged);
      ASSERT_FALSE(a.rejected.empty());
      EXPECT_EQ(a.rejected.front().point, "t5");
    } else {
      EXPECT_FALSE(a.converged);
      EXPECT_FALSE(a.covariance_ok);
      bool named = false;
      for (const auto& d : a.diagnostics) named |= d.find("numerical failure") != std::string::npos;
      EXPECT_TRUE(named);
    }
  }
}

}  // namespace
}  // namespace aerocal
