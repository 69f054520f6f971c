// Issue 37 class 4, across every reader of other tools' camera files: no silent substitution. Each
// number of each example file (tests/fuzz/seeds/camera_formats) is replaced in turn by `nan` and
// by nothing; the file's own reader must then either refuse it with an aerocal::Error or read the
// very camera it read before (the number was one the reader does not use: a date, a name, a
// comment). A reader that reads the `nan` or the empty field as 0, as the default or as another
// field's value gives another camera and fails here, naming format, file, line and number.
#include <algorithm>
#include <filesystem>
#include <regex>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "calib/camera/formats/camera_formats.h"
#include "calib/core/error.h"
#include "tests/support/bad_input_case.h"
#include "tests/support/test_support.h"

namespace aerocal::calib {
namespace {

namespace fs = std::filesystem;

// Same camera: model, size, pixel size and every parameter bit for bit (NaN never equals).
bool SameCamera(const CameraFile& a, const CameraFile& b) {
  const ModelCamera &x = a.camera, &y = b.camera;
  if (x.model != y.model || x.params.size() != y.params.size()) return false;
  if (x.frame.width_px != y.frame.width_px || x.frame.height_px != y.frame.height_px ||
      !(x.frame.pixel_size_mm == y.frame.pixel_size_mm) || a.pixel_size_known != b.pixel_size_known)
    return false;
  for (size_t i = 0; i < x.params.size(); ++i)
    if (!(x.params[i] == y.params[i])) return false;
  return true;
}

// The read options a seed needs: the Pix4D .cam holds millimetres, its sensor only in a comment.
CameraReadOptions OptionsFor(const std::string& seed) {
  CameraReadOptions options;
  if (fs::path(seed).extension() == ".cam") {
    options.width_px = 14000;
    options.height_px = 12000;
  }
  return options;
}

int LineOf(const std::string& text, size_t at) {
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(at), '\n'));
}

TEST(CameraFormatsNoSubstitution, ANanOrAnEmptyNumberIsRefusedOrUnused) {
  testing::TempDir dir("aerocal_formats_substitution");
  const fs::path seeds = fs::path(AEROCAL_TEST_DATA_DIR) / ".." / "fuzz" / "seeds" / "camera_formats";
  // A number not glued to a word (k1, cam0, 2023-01-01 are not touched as a whole).
  const std::regex number(R"((^|[^A-Za-z0-9_.+-])([-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?)(?![A-Za-z0-9_.]))");
  int seeds_read = 0, mutations = 0, refused = 0, unused = 0;
  std::vector<std::string> substituted;
  for (const auto& entry : fs::directory_iterator(seeds)) {
    const std::string seed = entry.path().string();
    const CameraReadOptions options = OptionsFor(seed);
    std::string format;
    CameraFile original;
    try {
      original = ReadCameraFileAs("auto", seed, options, &format);
    } catch (const Error&) {
      continue;  // the OpenCV FileStorage seeds: that reader lives in tools/ (bad_input3_test)
    }
    ++seeds_read;
    const CameraFormat& reader = FindCameraFormat(format, "--from");
    const std::string text = testing::ReadFileText(seed);
    for (auto it = std::sregex_iterator(text.begin(), text.end(), number); it != std::sregex_iterator(); ++it) {
      const size_t at = static_cast<size_t>(it->position(2));
      const size_t length = static_cast<size_t>(it->length(2));
      for (const std::string replacement : {"nan", ""}) {
        std::string mutated = text;
        mutated.replace(at, length, replacement);
        const std::string path = dir.File("mutated" + entry.path().extension().string());
        testing::WriteFileText(path, mutated);
        ++mutations;
        try {
          const CameraFile back = reader.read(path, options);
          if (SameCamera(original, back)) {
            ++unused;
          } else {
            substituted.push_back(format + " " + entry.path().filename().string() + ":" +
                                  std::to_string(LineOf(text, at)) + ": '" + it->str(2) + "' -> '" +
                                  replacement + "' read as another camera");
          }
        } catch (const Error&) {
          ++refused;
        }
      }
    }
  }
  std::printf("%d seeds, %d mutations: %d refused, %d unused numbers, %zu substituted\n", seeds_read,
              mutations, refused, unused, substituted.size());
  EXPECT_GE(seeds_read, 12);
  EXPECT_GT(refused, mutations / 2);
  for (const std::string& s : substituted) ADD_FAILURE() << s;
}

// What the mutations above found in the Australis reader: it took the first name followed by five
// numbers, so a damaged row was skipped and its parameter read as 0 (and a second row ignored).
TEST(CameraFormatsNoSubstitution, AustralisRowsAreOneLineEachWithFiveNumbers) {
  testing::TempDir dir("aerocal_formats_substitution");
  const std::string seed = std::string(AEROCAL_TEST_DATA_DIR) + "/../fuzz/seeds/camera_formats/australis.txt";
  const std::string text = testing::ReadFileText(seed);
  const std::string k1 = "K1 0.0420012803050355 0 0.0420012803050355 0 0\n";
  ASSERT_NE(text.find(k1), std::string::npos);
  const auto error = [&](const std::string& mutated) -> std::string {
    testing::WriteFileText(dir.File("a.txt"), mutated);
    try {
      ReadAustralisCamera(dir.File("a.txt"), {});
    } catch (const InputError& e) {
      return e.what();
    }
    return "(read)";
  };
  std::string nan = text;
  nan.replace(nan.find(k1), k1.size(), "K1 0.04 0 nan 0 0\n");
  EXPECT_NE(error(nan).find("a.txt:16: K1 final value must be a number"), std::string::npos) << error(nan);
  std::string twice = text;
  twice.insert(twice.find(k1) + k1.size(), "K1 0.05 0 0.05 0 0\n");
  EXPECT_NE(error(twice).find("a.txt:17: a second 'K1' line (the first is line 16)"), std::string::npos)
      << error(twice);
  std::string short_row = text;
  short_row.replace(short_row.find(k1), k1.size(), "K1 0.04 0 0.04 0\n");
  EXPECT_NE(error(short_row).find("a.txt:17: K1 final std. error must be a number"), std::string::npos)
      << error(short_row);
  std::string without = text;
  without.erase(without.find(k1), k1.size());
  testing::WriteFileText(dir.File("b.txt"), without);
  const CameraFile b = ReadAustralisCamera(dir.File("b.txt"), {});
  EXPECT_EQ(b.camera.params[BrownFraser10Model::kK1], 0.0);
  EXPECT_NE(std::find(b.notes.begin(), b.notes.end(), "K1: no line in the report, 0"), b.notes.end());
}

}  // namespace
}  // namespace aerocal::calib
