// Issue 37: bad input never passes quietly, part 2 (the classes that are not camera-file formats).
// One row per case, as tests/tools/bad_input_test.cc: a small input, the command, the exit code
// and the FILE:LINE (or option, or key path) the message must name; the output must not exist
// afterwards. Classes: 1 numbers from files read through a schema (certificate --result /
// --previous), 2 units of a budget, 6 absurd geometry, 7 resources (sizes bounded before
// allocation, rig heads), 8 user text in a renderer and outputs written as a set. Plus the walk
// over every numeric option of every command (NaN, infinities, zero, negative, huge values).
#include "calib/camera/camera_io.h"
#include "calib/camera/distortion_folding.h"
#include "calib/camera/rig_io.h"
#include "calib/core/error.h"
#include "calib/core/json_schema.h"
#include "calib/core/yaml_util.h"
#include "tests/support/bad_input_case.h"
#include "tests/support/test_support.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <utility>

namespace aerocal {
namespace {

namespace fs = std::filesystem;
using testing::RunAerocal;
using testing::RunCommand;
using testing::TempDir;

std::string Read(const std::string& path) { return testing::ReadFileText(path); }
void Write(const std::string& path, const std::string& text) { testing::WriteFileText(path, text); }
void ReplaceFirst(const std::string& path, const std::string& from, const std::string& to) {
  testing::ReplaceFirstInFile(path, from, to);
}

// A simulated data set (`simulate --out NAME OPTIONS`), made once, copied into `d`/NAME.
std::string Simulated(const TempDir& d, const std::string& name, const std::string& options) {
  static TempDir base("aerocal_bad_input2_base");
  static std::map<std::string, bool> made;
  if (!made[name]) {
    const auto r = RunAerocal("simulate --out " + base.File(name) + " " + options);
    EXPECT_EQ(r.exit_code, 0) << r.output;
    made[name] = true;
  }
  fs::copy(base.File(name), d.File(name), fs::copy_options::recursive);
  return d.File(name);
}
std::string Flight(const TempDir& d) {
  return Simulated(
      d,
      "sim",
      "--exposures 6 --strips 1 --surveyed-points 12 --control 6 --tie-points 40 --stitch-ties 60");
}
std::string RigFlight(const TempDir& d) { return Simulated(d, "rig", "--rig dual-lens"); }
std::string PushbroomFlight(const TempDir& d) { return Simulated(d, "pb", "--pushbroom"); }
std::string TestField(const TempDir& d) {
  return Simulated(d, "tf", "--test-field --groups 2 --images-per-group 4");
}

std::string CalibrateArgs(const std::string& tf, const std::string& out) {
  return "calibrate --camera " + tf + "/camera_nominal.yaml --observations " + tf +
         "/observations.csv --points " + tf + "/points.csv --out " + out;
}

// A calibrate result of the test field (made once), copied to `path`.
void CalibrateResult(const std::string& path) {
  static TempDir base("aerocal_bad_input2_cal");
  static const bool made = [] {
    const std::string tf = TestField(base);
    const auto r = RunAerocal(CalibrateArgs(tf, base.File("cal.json")));
    EXPECT_EQ(r.exit_code, 0) << r.output;
    return true;
  }();
  (void)made;
  fs::copy_file(base.File("cal.json"), path, fs::copy_options::overwrite_existing);
}

// Edits the JSON document in `path`.
void EditJson(const std::string& path, const std::function<void(nlohmann::json&)>& edit) {
  nlohmann::json j = nlohmann::json::parse(Read(path));
  edit(j);
  Write(path, j.dump(1));
}

// A rig of `n` heads (ids H0, H1, ...), each a 1000 x 1000 px camera with c = 50 mm.
std::string RigYaml(int n,
                    const std::string& first_mount = "[0, 0, 0]",
                    const std::string& height = "1000") {
  std::string y =
      "name: test\nrig:\n  reference_head: H0\n  virtual:\n    c: 50\n    pixel_size_mm: 0.01\n"
      "    format_px: [2000, 2000]\n    height_m: " +
      height + "\n  heads:\n";
  for (int k = 0; k < n; ++k)
    y += "    - id: H" + std::to_string(k) +
         "\n      pixel_size_mm: 0.01\n      format_px: [1000, 1000]\n"
         "      interior: {c: 50}\n      mount_deg: " +
         (k == 0 ? first_mount : "[0, " + std::to_string(k % 20) + ", 0]") +
         "\n      lever_arm_m: [0, 0, 0]\n";
  return y;
}

using Case = testing::BadInputCase;

std::string CertificateArgs(const TempDir& d, const std::string& extra = "") {
  return "certificate --result " + d.File("r.json") + " " + extra + " --no-render --out " +
         d.File("cert");
}

std::string BudgetArgs(const TempDir& d, const std::string& budget) {
  const std::string tf = TestField(d);
  Write(d.File("budget.yaml"), budget);
  return CalibrateArgs(tf, d.File("cal.json")) + " --budget " + d.File("budget.yaml");
}

std::string ControlArgs(const TempDir& d, const std::string& extra = "") {
  const std::string pb = PushbroomFlight(d), sim = Flight(d);
  return "pushbroom control --camera " + pb + "/camera_nominal.yaml --pos " + pb +
         "/pos.csv --line-image " + d.File("line.png") + " --reference-camera " + sim +
         "/camera_nominal.yaml --reference-exposures " + d.File("exposures.csv") +
         " --reference-images " + d.path() + " --out " + d.File("control") + " " + extra;
}

const std::vector<Case>& Cases() {
  static const std::vector<Case> cases = {
      // ---- class 1: numbers from files through the schema, with the key path ----
      {"certificate_u_is_a_string",
       [](const TempDir& d) {
         CalibrateResult(d.File("r.json"));
         EditJson(d.File("r.json"),
                  [](nlohmann::json& j) { j["calibration"]["uncertainty"][0]["U"] = "0.001"; });
         return CertificateArgs(d);
       },
       2,
       "r.json: calibration.uncertainty[0].U: expected a finite number or a null (got \"0.001\")",
       "cert"},
      {"certificate_u_is_huge",
       [](const TempDir& d) {
         CalibrateResult(d.File("r.json"));
         EditJson(d.File("r.json"),
                  [](nlohmann::json& j) { j["calibration"]["uncertainty"][1]["U"] = 1e308; });
         return CertificateArgs(d);
       },
       2,
       "r.json: calibration.uncertainty[1].U: must be <= 1000000000",
       "cert"},
      {"certificate_u_beside_a_statement_quoting_another",
       [](const TempDir& d) {
         CalibrateResult(d.File("r.json"));
         EditJson(d.File("r.json"), [](nlohmann::json& j) {
           auto& q = j["calibration"]["uncertainty"][0];
           q["U"] = q["U"].get<double>() * 10;
           q["u_c"] = q["U"].get<double>() / q["k"].get<double>();
         });
         return CertificateArgs(d);
       },
       2,
       "r.json: calibration.uncertainty[0].statement: '",
       "cert"},
      {"certificate_value_is_null",
       [](const TempDir& d) {
         CalibrateResult(d.File("r.json"));
         EditJson(d.File("r.json"),
                  [](nlohmann::json& j) { j["calibration"]["uncertainty"][2]["value"] = nullptr; });
         return CertificateArgs(d);
       },
       2,
       "r.json: calibration.uncertainty[2].value: expected a finite number (got null)",
       "cert"},
      {"certificate_rms_negative",
       [](const TempDir& d) {
         CalibrateResult(d.File("r.json"));
         EditJson(d.File("r.json"), [](nlohmann::json& j) { j["calibration"]["rms_px"] = -1; });
         return CertificateArgs(d);
       },
       2,
       "r.json: calibration.rms_px: must be >= 0 (got -1)",
       "cert"},
      {"certificate_residual_not_a_number",
       [](const TempDir& d) {
         CalibrateResult(d.File("r.json"));
         EditJson(d.File("r.json"), [](nlohmann::json& j) { j["residuals"][3]["v_col_px"] = "x"; });
         return CertificateArgs(d);
       },
       2,
       "r.json: residuals[3].v_col_px: expected a finite number (got \"x\")",
       "cert"},
      {"certificate_previous_u_is_a_string",
       [](const TempDir& d) {
         CalibrateResult(d.File("r.json"));
         CalibrateResult(d.File("p.json"));
         EditJson(d.File("p.json"),
                  [](nlohmann::json& j) { j["calibration"]["uncertainty"][0]["U"] = "tiny"; });
         return CertificateArgs(d, "--previous " + d.File("p.json"));
       },
       2,
       "p.json: calibration.uncertainty[0].U: expected a finite number or a null (got \"tiny\")",
       "cert"},
      {"certificate_previous_in_another_unit",
       [](const TempDir& d) {
         CalibrateResult(d.File("r.json"));
         CalibrateResult(d.File("p.json"));
         EditJson(d.File("p.json"), [](nlohmann::json& j) {
           auto& q = j["calibration"]["uncertainty"][0];
           q["unit"] = "um";
           const std::string s = q["statement"];
           q["statement"] = std::regex_replace(s, std::regex(" mm"), " um");
         });
         return CertificateArgs(d, "--previous " + d.File("p.json"));
       },
       2,
       "p.json: quantity c is in um, the result's in mm (--previous)",
       "cert"},
      // ---- class 2: units of the budget, empty budgets, non-finite intermediates ----
      {"budget_unknown_unit",
       [](const TempDir& d) {
         return BudgetArgs(
             d,
             "components:\n  - {quantity: c, source: temperature, value: 0.002, unit: furlong}\n");
       },
       2,
       "budget.yaml:2: unknown unit 'furlong' (expected one of m, mm, um",
       "cal.json"},
      {"budget_empty",
       [](const TempDir& d) { return BudgetArgs(d, "# nothing\n"); },
       2,
       "budget.yaml:1: an empty budget file",
       "cal.json"},
      {"budget_empty_map",
       [](const TempDir& d) { return BudgetArgs(d, "{}\n"); },
       2,
       "budget.yaml:1: an empty budget file",
       "cal.json"},
      {"budget_unit_of_another_kind_without_sensitivity",
       [](const TempDir& d) {
         return BudgetArgs(
             d, "components:\n  - {quantity: c, source: temperature, value: 0.5, unit: K}\n");
       },
       2,
       "budget.yaml:2: budget component 'temperature' of c: unit K is no length; give its "
       "sensitivity (mm per K)",
       "cal.json"},
      {"budget_sensitivity_huge",
       [](const TempDir& d) {
         return BudgetArgs(d,
                           "components:\n  - {quantity: c, source: t, value: 0.5, unit: K, "
                           "sensitivity: 1e308}\n");
       },
       2,
       "budget.yaml:2: sensitivity out of range",
       "cal.json"},
      {"budget_radius_huge_option",
       [](const TempDir& d) {
         return CalibrateArgs(TestField(d), d.File("cal.json")) + " --radii-mm 1e308";
       },
       2,
       "--radii-mm",
       "cal.json"},
      // ---- class 6: absurd geometry ----
      {"principal_distance_tiny",
       [](const TempDir& d) {
         const std::string sim = Flight(d);
         ReplaceFirst(sim + "/camera_nominal.yaml", "c: 170", "c: 1e-9");
         return "adjust --project " + sim + "/project.yaml --out " + d.File("a.json");
       },
       2,
       "camera_nominal.yaml:6: interior.c must be at least 100 pixels (got 1e-09 mm",
       "a.json"},
      {"rig_head_looking_up",
       [](const TempDir& d) {
         Write(d.File("rig.yaml"), RigYaml(2, "[170, 0, 0]"));
         return "rig design --camera " + d.File("rig.yaml") + " --out " + d.File("design.json");
       },
       2,
       "rig.yaml:14: head H0: mount_deg turns the head's axis 170 deg off the rig's nadir",
       "design.json"},
      {"rig_height_tiny",
       [](const TempDir& d) {
         Write(d.File("rig.yaml"), RigYaml(2, "[0, 0, 0]", "1e-9"));
         return "rig design --camera " + d.File("rig.yaml") + " --out " + d.File("design.json");
       },
       2,
       "rig.yaml:8: virtual.height_m out of range",
       "design.json"},
      {"rig_height_huge",
       [](const TempDir& d) {
         Write(d.File("rig.yaml"), RigYaml(2, "[0, 0, 0]", "1e308"));
         return "rig design --camera " + d.File("rig.yaml") + " --out " + d.File("design.json");
       },
       2,
       "rig.yaml:8: virtual.height_m out of range",
       "design.json"},
      {"rig_design_height_option_tiny",
       [](const TempDir& d) {
         Write(d.File("rig.yaml"), RigYaml(2));
         return "rig design --camera " + d.File("rig.yaml") + " --height-m 1e-9 --out " +
                d.File("design.json");
       },
       2,
       "--height-m must be within 1 .. 100000 m (got 1e-09)",
       "design.json"},
      {"rig_relief_above_the_flight",
       [](const TempDir& d) {
         const std::string rig = RigFlight(d);
         return "rig error-analysis --camera " + rig + "/rig_nominal.yaml --limits " +
                std::string(AEROCAL_CONFIGS_DIR) +
                "/rig_dual_lens_limits.yaml --relief-m 5000 --no-plots --mkdir --out " + rig +
                "/ea/ea.json";
       },
       2,
       "--relief-m: 5000 m of relief reaches the flying height (1200 m)",
       "rig/ea"},
      {"flight_base_not_a_subimage",
       [](const TempDir& d) {
         const std::string sim = Flight(d);
         return "flight --data " + sim + " --camera " + sim +
                "/camera_nominal.yaml --base XIV --no-report --out " + d.File("flight");
       },
       2,
       "--base: sub-image 'XIV' is not in ",
       "flight"},
      {"pushbroom_reference_negative",
       [](const TempDir& d) {
         const std::string pb = PushbroomFlight(d);
         return "pushbroom calibrate --camera " + pb + "/camera_nominal.yaml --pos " + pb +
                "/pos.csv --observations " + pb + "/observations.csv --points " + pb +
                "/points.csv --reference -2 --out " + d.File("r.json");
       },
       2,
       "--reference",
       "r.json"},
      {"pushbroom_empty_subcamera_id",
       [](const TempDir& d) {
         const std::string pb = PushbroomFlight(d);
         ReplaceFirst(pb + "/camera_nominal.yaml", "{id: L,", "{id: '',");
         return "pushbroom calibrate --camera " + pb + "/camera_nominal.yaml --pos " + pb +
                "/pos.csv --observations " + pb + "/observations.csv --points " + pb +
                "/points.csv --out " + d.File("r.json");
       },
       2,
       "camera_nominal.yaml:9: sub-camera id must not be empty",
       "r.json"},
      {"pushbroom_sigma_negative",
       [](const TempDir& d) {
         const std::string pb = PushbroomFlight(d);
         return "pushbroom calibrate --camera " + pb + "/camera_nominal.yaml --pos " + pb +
                "/pos.csv --observations " + pb + "/observations.csv --points " + pb +
                "/points.csv --sigma-px -0.3 --out " + d.File("r.json");
       },
       2,
       "--sigma-px",
       "r.json"},
      // ---- class 7: resources ----
      {"rig_of_33_heads",
       [](const TempDir& d) {
         Write(d.File("rig.yaml"), RigYaml(33));
         return "rig design --camera " + d.File("rig.yaml") + " --out " + d.File("design.json");
       },
       2,
       "rig.yaml:10: rig.heads: 33 heads, at most 32",
       "design.json"},
      {"rig_of_1000_heads_refused_at_once",
       [](const TempDir& d) {
         Write(d.File("rig.yaml"), RigYaml(1000));
         return "rig design --camera " + d.File("rig.yaml") + " --out " + d.File("design.json");
       },
       2,
       "rig.yaml:10: rig.heads: 1000 heads, at most 32",
       "design.json"},
      {"rig_error_analysis_bins_1e9",
       [](const TempDir& d) {
         const std::string rig = RigFlight(d);
         return "rig error-analysis --camera " + rig + "/rig_nominal.yaml --limits " +
                std::string(AEROCAL_CONFIGS_DIR) +
                "/rig_dual_lens_limits.yaml --bins 1e9 --no-plots --out " + rig + "/ea/ea.json";
       },
       2,
       "--bins: must be in [1, 10000] (got 1e9)",
       "rig/ea"},
      {"rig_error_analysis_samples_huge",
       [](const TempDir& d) {
         const std::string rig = RigFlight(d);
         return "rig error-analysis --camera " + rig + "/rig_nominal.yaml --limits " +
                std::string(AEROCAL_CONFIGS_DIR) +
                "/rig_dual_lens_limits.yaml --samples 2e9 --no-plots --out " + rig + "/ea/ea.json";
       },
       2,
       "--samples: must be in [0, 10000000]",
       "rig/ea"},
      {"pushbroom_control_mean_height_1e6",
       [](const TempDir& d) { return ControlArgs(d, "--mean-height-m 1e6"); },
       2,
       "--mean-height-m: must be in [-500, 10000] (got 1e6)",
       "control"},
      {"pushbroom_control_header_only_reference_list",
       [](const TempDir& d) {
         Write(d.File("exposures.csv"), "image,camera,X,Y,Z,omega,phi,kappa\n");
         return ControlArgs(d);
       },
       2,
       "{DIR}/exposures.csv:1: no reference exposure (a header only)",
       "control"},
  };
  return cases;
}

class BadInput2 : public ::testing::TestWithParam<size_t> {};

TEST_P(BadInput2, ExitsWithItsCodeNamesWhereAndWritesNothing) {
  testing::RunBadInputCase(Cases()[GetParam()], 120);
}

INSTANTIATE_TEST_SUITE_P(Issue37,
                         BadInput2,
                         ::testing::Range<size_t>(0, Cases().size()),
                         [](const ::testing::TestParamInfo<size_t>& info) {
                           return std::string(Cases()[info.param].name);
                         });

// ---- class 2: a component in um counts as um, not as mm ----
TEST(BudgetUnits, AComponentInMicrometresIsConvertedToTheQuantitysUnit) {
  TempDir dir("aerocal_budget_units");
  const std::string tf = TestField(dir);
  auto u_c_of_c = [&](const std::string& component) {
    Write(dir.File("budget.yaml"),
          "components:\n  - {quantity: c, source: temperature, " + component + "}\n");
    const auto r = RunAerocal(CalibrateArgs(tf, dir.File("cal.json")) + " --budget " +
                              dir.File("budget.yaml"));
    EXPECT_EQ(r.exit_code, 0) << r.output;
    const nlohmann::json result =
        testing::ReadJson(dir.File("cal.json"));  // kept: the loop reads into it
    for (const auto& q : result["calibration"]["uncertainty"])
      if (q["quantity"] == "c") return q["u_c"].get<double>();
    return -1.0;
  };
  const double in_mm = u_c_of_c("value: 0.02, unit: mm");
  const double in_um = u_c_of_c("value: 20, unit: um");
  const double in_m = u_c_of_c("value: 2e-5, unit: m");
  EXPECT_NEAR(in_um, in_mm, 1e-12);
  EXPECT_NEAR(in_m, in_mm, 1e-12);
  EXPECT_GT(in_mm, 0.02);  // the component is there (u_c >= 0.02 mm)
  // A temperature needs its sensitivity: 0.5 K at 0.04 mm/K is 0.02 mm.
  EXPECT_NEAR(u_c_of_c("value: 0.5, unit: K, sensitivity: 0.04"), in_mm, 1e-12);
}

// ---- class 8: user text reaches the renderer; the outputs are one set ----
class CertificateRender : public ::testing::Test {
 protected:
  void SetUp() override {
    CalibrateResult(dir_.File("r.json"));
    Write(dir_.File("lab.yaml"),
          "lab: {name: 'Lab $\\frac{1}{0}$ and $x^$', address: '<script>alert(1)</script> & co'}\n"
          "certificate: {number: 'C-$1$', date: 2026-11-27}\n"
          "camera: {make: '$$', model: '\\$ {}'}\n"
          "signatures: {calibrated_by: '$_$'}\n");
  }
  testing::CommandResult Certificate(const std::string& env = "") {
    return RunCommand(env + " " + testing::AerocalBinary() + " certificate --result " +
                      dir_.File("r.json") + " --lab " + dir_.File("lab.yaml") + " --out " +
                      dir_.File("cert"));
  }
  std::vector<std::string> Files() const {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir_.File("cert")))
      names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
  }
  TempDir dir_{"aerocal_certificate_render"};
};

TEST_F(CertificateRender, MathtextAndMarkupInLabFieldsAreTextNotACrash) {
  const auto r = Certificate();
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(Files(),
            (std::vector<std::string>{"certificate.html", "certificate.json", "certificate.pdf"}));
  const std::string html = Read(dir_.File("cert/certificate.html"));
  EXPECT_NE(html.find("Lab $\\frac{1}{0}$ and $x^$"), std::string::npos);
  EXPECT_EQ(html.find("<script>"), std::string::npos);
  EXPECT_NE(html.find("&lt;script&gt;alert(1)&lt;/script&gt; &amp; co"), std::string::npos);
}

TEST_F(CertificateRender, AFailingRendererReplacesNothingOfThePreviousSet) {
  ASSERT_EQ(Certificate().exit_code, 0);
  const std::string json = Read(dir_.File("cert/certificate.json")),
                    pdf = Read(dir_.File("cert/certificate.pdf"));
  // A renderer that writes one part, then fails.
  Write(
      dir_.File("fail.py"),
      "import sys, os\nopen(os.path.join(sys.argv[2], 'certificate.html'), 'w').write('partial')\n"
      "open(os.path.join(sys.argv[2], 'certificate.pdf.tmp'), "
      "'w').write('partial')\nsys.exit(1)\n");
  EditJson(dir_.File("r.json"), [](nlohmann::json& j) { j["calibration"]["rms_px"] = 0.5; });
  const auto r = Certificate("AEROCAL_CERTIFICATE_SCRIPT=" + dir_.File("fail.py"));
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("nothing written"), std::string::npos) << r.output;
  EXPECT_EQ(Files(),
            (std::vector<std::string>{"certificate.html", "certificate.json", "certificate.pdf"}));
  EXPECT_EQ(Read(dir_.File("cert/certificate.json")), json);
  EXPECT_EQ(Read(dir_.File("cert/certificate.pdf")), pdf);
  EXPECT_NE(Read(dir_.File("cert/certificate.html")), "partial");
}

TEST_F(CertificateRender, AFailingRendererOfAFirstCertificateLeavesNoFolder) {
  Write(dir_.File("fail.py"), "import sys\nsys.exit(1)\n");
  const auto r = Certificate("AEROCAL_CERTIFICATE_SCRIPT=" + dir_.File("fail.py"));
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_FALSE(fs::exists(dir_.File("cert")));
}

// ---- class 7: the rig reader refuses more than 32 heads at read time, and reads linearly ----
TEST(RigReader, MoreThan32HeadsAreRefusedWithTheLineOfTheList) {
  try {
    calib::ParseRig(LoadYamlText(RigYaml(33), "rig.yaml"), "rig.yaml");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("rig.yaml:10: rig.heads: 33 heads, at most 32"),
              std::string::npos)
        << e.what();
  }
  EXPECT_EQ(calib::ParseRig(LoadYamlText(RigYaml(32), "rig.yaml"), "rig.yaml").heads.size(), 32u);
}

TEST(RigReader, ReadingIsLinearInTheNumberOfHeads) {
  // The time per head of a 32-head rig is within a generous factor of that of a 4-head rig (the
  // reader copied every head's camera keys into a new node, which merged the whole document's
  // memory per head: quadratic; 1000 heads took about 20 s).
  auto seconds_per_head = [](int n) {
    const std::string text = RigYaml(n);
    const auto t0 = std::chrono::steady_clock::now();
    for (int i = 0; i < 20; ++i) calib::ParseRig(LoadYamlText(text, "rig.yaml"), "rig.yaml");
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() /
           (20.0 * n);
  };
  seconds_per_head(4);  // warm up
  const double small = seconds_per_head(4), large = seconds_per_head(32);
  EXPECT_LT(large, 3.0 * small + 1e-5)
      << "per head: " << small << " s (4 heads), " << large << " s (32 heads)";
  // The heads' cameras of a 1000-head document read the way the reader reads them (in place):
  // linear, well below a second (the copying reader took 3.4 s here, 20 s on the campaign's
  // machine).
  const YAML::Node root = LoadYamlText(RigYaml(1000), "rig.yaml");
  const auto t0 = std::chrono::steady_clock::now();
  for (const auto& head : root["rig"]["heads"])
    calib::ParseCamera(head,
                       "rig.yaml",
                       calib::CameraModels::kBrownFraser10Only,
                       {"id", "mount_deg", "lever_arm_m"});
  const double in_place =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf(
      "rig reading per head: %.3g s (4 heads), %.3g s (32 heads); 1000 heads' cameras in place: "
      "%.3g s\n",
      small,
      large,
      in_place);
  EXPECT_LT(in_place, 1.0);
}

// ---- class 6: the distortion's folding radius ----
TEST(DistortionFolding, AStrongRadialTermFoldsInsideTheFormatAtTheAnalyticRadius) {
  // ideal r = r (1 +- K1 r^2) folds where 1 +- 3 K1 r^2 = 0: r = sqrt(1 / (3 |K1|)) = 10 mm for
  // |K1| = 1/300 mm^-2; one sign folds there, the other does not fold. 30 x 20 mm format.
  calib::ModelCamera camera;
  camera.frame.pixel_size_mm = 0.005;
  camera.frame.width_px = 6000;
  camera.frame.height_px = 4000;
  camera.params.assign(10, 0.0);
  camera.params[0] = 35.0;
  const auto none = calib::FindDistortionFolding(camera);
  EXPECT_FALSE(none.inside_format);
  EXPECT_EQ(calib::DistortionFoldingWarning(none), "");
  int folding = 0;
  for (const double sign : {-1.0, 1.0}) {
    camera.params[3] = sign / 300.0;
    const auto f = calib::FindDistortionFolding(camera);
    if (!f.inside_format) continue;
    ++folding;
    ASSERT_TRUE(f.radius_mm);
    EXPECT_NEAR(*f.radius_mm, 10.0, 0.1);
    EXPECT_NE(calib::DistortionFoldingWarning(f).find("the distortion folds at r = "),
              std::string::npos)
        << calib::DistortionFoldingWarning(f);
  }
  EXPECT_EQ(folding, 1);
}

TEST(DistortionFolding, CameraShowWarnsWhereTheTableWouldJump) {
  // The same lens as above in a camera file: K1 = -1/300 mm^-2 folds at r = 10 mm inside the
  // 30 x 20 mm format; `camera show` says so (exit 0: showing a camera is not adjusting with it).
  TempDir dir("aerocal_folding");
  Write(dir.File("lens.yaml"),
        "name: folding\npixel_size_mm: 0.005\nformat_px: [6000, 4000]\n"
        "interior: {c: 35.0, K1: -0.0033333333333333335}\n");
  const auto r = RunAerocal("camera show --from auto " + dir.File("lens.yaml"));
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("warning: the distortion folds at r = "), std::string::npos) << r.output;
  Write(dir.File("fine.yaml"),
        "name: fine\npixel_size_mm: 0.005\nformat_px: [6000, 4000]\n"
        "interior: {c: 35.0, K1: -1.0e-5}\n");
  const auto fine = RunAerocal("camera show --from auto " + dir.File("fine.yaml"));
  EXPECT_EQ(fine.exit_code, 0) << fine.output;
  EXPECT_EQ(fine.output.find("folds"), std::string::npos) << fine.output;
}

// ---- class 1: the schema validator itself ----
TEST(JsonSchema, NamesTheKeyPathAndRefusesNonFiniteNumbers) {
  const nlohmann::json schema = nlohmann::json::parse(R"({
    "definitions": {"row": {"type": "object", "required": ["U"],
                            "properties": {"U": {"type": ["number", "null"], "minimum": 0}}}},
    "type": "object",
    "properties": {"calibration": {"type": "object",
                                   "properties": {"values": {"type": "array", "items": {"$ref": "#/definitions/row"}}}}}})");
  auto error = [&](const nlohmann::json& doc) -> std::string {
    try {
      ValidateJson(doc, schema, "result.json");
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  nlohmann::json doc = {
      {"calibration", {{"values", {{{"U", 1}}, {{"U", nullptr}}, {{"U", 2}}, {{"U", "x"}}}}}}};
  EXPECT_EQ(error(doc),
            "result.json: calibration.values[3].U: expected a finite number or a null (got \"x\")");
  doc["calibration"]["values"][3]["U"] = std::numeric_limits<double>::infinity();
  EXPECT_EQ(error(doc).rfind("result.json: calibration.values[3].U: expected a finite number", 0),
            0u)
      << error(doc);
  doc["calibration"]["values"][3]["U"] = -1;
  EXPECT_EQ(error(doc), "result.json: calibration.values[3].U: must be >= 0 (got -1)");
  doc["calibration"]["values"][3] = nlohmann::json::object();
  EXPECT_EQ(error(doc), "result.json: calibration.values[3].U: missing");
  doc["calibration"]["values"][3]["U"] = 3;
  EXPECT_EQ(error(doc), "");
}

// ---- every numeric option of every command: a documented range, enforced while parsing ----
struct OptionInfo {
  std::string command, name, type;
};

std::vector<OptionInfo> AllOptions() {
  const auto r = RunAerocal("options");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  std::vector<OptionInfo> out;
  std::istringstream in(r.output);
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> f;
    std::stringstream s(line);
    for (std::string x; std::getline(s, x, '\t');) f.push_back(x);
    if (f.size() >= 3) out.push_back({f[0], f[1], f[2]});
  }
  return out;
}

bool IsNumeric(const std::string& type) {
  for (const char* t : {"INT", "UINT", "FLOAT", "NUMBER"})
    if (type.rfind(t, 0) == 0) return true;
  return false;
}

TEST(OptionRanges, EveryNumericOptionRefusesNanInfinityAndValuesOutsideItsRange) {
  const std::vector<OptionInfo> options = AllOptions();
  ASSERT_GT(options.size(), 100u);
  const std::regex range(R"(:in ([\[(])([^,\]]+), ([^\]]+)\])");
  std::vector<std::string> unranged;
  int checked = 0;
  for (const auto& o : options) {
    if (!IsNumeric(o.type)) continue;
    // Per option NaN and one value outside its range: the validators themselves are tested on
    // every kind of value in process (tests/tools/option_ranges_test.cc); here each option shows
    // it carries one, with the range its help states (~70 ms per run of the program).
    if (o.type.find("UINT64") != std::string::npos) {  // a seed (SeedCheck): digits, 0 .. 2^64 - 1
      for (const std::string value : {"nan", "18446744073709551616"}) {
        SCOPED_TRACE(o.command + " " + o.name + " " + value);
        const auto r = RunAerocal(o.command + " " + o.name + "=" + value);
        ++checked;
        EXPECT_EQ(r.exit_code, 2) << r.output;
        EXPECT_NE(r.output.find(o.name), std::string::npos) << r.output;
      }
      continue;
    }
    std::smatch m;
    if (!std::regex_search(o.type, m, range)) {
      unranged.push_back(o.command + " " + o.name + " " + o.type);  // no exceptions: every option
      continue;
    }
    const bool open_lo = m[1] == "(";
    const double lo = std::stod(m[2]), hi = std::stod(m[3]);
    bool outside_checked = false;
    for (const std::string value : {"nan", "0", "-1", "1e308", "-1e308", "1e9"}) {
      const double v = std::stod(value);
      const bool inside = std::isfinite(v) && v <= hi && (open_lo ? v > lo : v >= lo);
      if (inside) continue;  // accepted by the range; the command's own checks follow
      if (std::isfinite(v) && std::exchange(outside_checked, true)) continue;
      SCOPED_TRACE(o.command + " " + o.name + " " + value);
      const auto r = RunAerocal(o.command + " " + o.name + "=" + value);  // "=": "-inf" is a value
      ++checked;
      EXPECT_EQ(r.exit_code, 2) << r.output;
      EXPECT_NE(r.output.find(o.name), std::string::npos) << r.output;
      EXPECT_NE(r.output.find("in " + std::string(open_lo ? "(" : "[")), std::string::npos)
          << r.output;
    }
  }
  EXPECT_GT(checked, 100);
  std::string list;
  for (const auto& u : unranged) list += "  " + u + "\n";
  EXPECT_TRUE(unranged.empty()) << "numeric options without a FiniteRange:\n" << list;
}

}  // namespace
}  // namespace aerocal
