// Issue 37 class 4, across every reader of other tools' camera files: no silent substitution. Each
// number of each example file (tests/fuzz/seeds/camera_formats) is replaced in turn by `nan` and
// by nothing; the file's own reader must then either refuse it with an aerocal::Error or read the
// very camera it read before (the number was one the reader does not use: a date, a name, a
// comment). A reader that reads the `nan` or the empty field as 0, as the default or as another
// field's value gives another camera and fails here, naming format, file, line and number.
#include "calib/camera/formats/camera_formats.h"
#include "calib/core/error.h"
#include "tests/support/bad_input_case.h"
#include "tests/support/test_support.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <regex>
#include <string>
#include <vector>

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
  const fs::path seeds =
      fs::path(AEROCAL_TEST_DATA_DIR) / ".." / "fuzz" / "seeds" / "camera_formats";
  // A number not glued to a word (k1, cam0, 2023-01-01 are not touched as a whole).
  const std::regex number(
      R"((^|[^A-Za-z0-9_.+-])([-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?)(?![A-Za-z0-9_.]))");
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
    for (auto it = std::sregex_iterator(text.begin(), text.end(), number);
         it != std::sregex_iterator();
         ++it) {
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
  std::printf("%d seeds, %d mutations: %d refused, %d unused numbers, %zu substituted\n",
              seeds_read,
              mutations,
              refused,
              unused,
              substituted.size());
  EXPECT_GE(seeds_read, 12);
  EXPECT_GT(refused, mutations / 2);
  for (const std::string& s : substituted) ADD_FAILURE() << s;
}

// A line holding a number given twice, the copy with another number (1, or 2 where it was 1),
// before and after the original: the reader refuses it or does not use that number. A reader that
// takes the first (or the last) of two values reads another camera. Not for two files whose lines
// mean nothing alone: a PhotoModeler export is positional (lines 1-5, the photos after them not
// read), and a copy of the XMP attribute line ending in "/>" leaves the original as character data
// outside the element (two attributes of one name are refused: not well-formed XML).
TEST(CameraFormatsNoSubstitution, ALineGivenTwiceIsRefusedOrUnused) {
  testing::TempDir dir("aerocal_formats_substitution");
  const fs::path seeds =
      fs::path(AEROCAL_TEST_DATA_DIR) / ".." / "fuzz" / "seeds" / "camera_formats";
  const std::regex number(
      R"((^|[^A-Za-z0-9_.+-])([-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?)(?![A-Za-z0-9_.]))");
  int mutations = 0, refused = 0;
  std::vector<std::string> taken;
  for (const auto& entry : fs::directory_iterator(seeds)) {
    const std::string seed = entry.path().string();
    const std::string name = entry.path().filename().string();
    if (name == "photomodeler.txt" || name == "dewarp.txt") continue;
    const CameraReadOptions options = OptionsFor(seed);
    std::string format;
    CameraFile original;
    try {
      original = ReadCameraFileAs("auto", seed, options, &format);
    } catch (const Error&) {
      continue;
    }
    const CameraFormat& reader = FindCameraFormat(format, "--from");
    const std::string text = testing::ReadFileText(seed);
    size_t begin = 0;
    for (int line = 1; begin < text.size(); ++line) {
      const size_t end = std::min(text.find('\n', begin), text.size());
      const std::string row = text.substr(begin, end - begin);
      std::smatch m;
      if (std::regex_search(row, m, number)) {
        std::string copy = row;
        copy.replace(static_cast<size_t>(m.position(2)),
                     static_cast<size_t>(m.length(2)),
                     m.str(2) == "1" ? "2" : "1");
        for (const bool before : {true, false}) {
          std::string mutated = text;
          mutated.insert(before ? begin : end, before ? copy + "\n" : "\n" + copy);
          const std::string path = dir.File("twice" + entry.path().extension().string());
          testing::WriteFileText(path, mutated);
          ++mutations;
          try {
            if (!SameCamera(original, reader.read(path, options)))
              taken.push_back(format + " " + entry.path().filename().string() + ":" +
                              std::to_string(line) + ": a copy " + (before ? "before" : "after") +
                              " it with '" + m.str(2) + "' changed is read");
          } catch (const Error&) {
            ++refused;
          }
        }
      }
      begin = end + 1;
    }
  }
  std::printf("%d duplicated lines: %d refused, %zu read as another camera\n",
              mutations,
              refused,
              taken.size());
  for (const std::string& t : taken) ADD_FAILURE() << t;
}

// What the mutations above found in the Australis reader: it took the first name followed by five
// numbers, so a damaged row was skipped and its parameter read as 0 (and a second row ignored).
TEST(CameraFormatsNoSubstitution, AustralisRowsAreOneLineEachWithFiveNumbers) {
  testing::TempDir dir("aerocal_formats_substitution");
  const std::string seed =
      std::string(AEROCAL_TEST_DATA_DIR) + "/../fuzz/seeds/camera_formats/australis.txt";
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
  EXPECT_NE(error(nan).find("a.txt:16: K1 final value must be a number"), std::string::npos)
      << error(nan);
  std::string twice = text;
  twice.insert(twice.find(k1) + k1.size(), "K1 0.05 0 0.05 0 0\n");
  EXPECT_NE(error(twice).find("a.txt:17: a second 'K1' line (the first is line 16)"),
            std::string::npos)
      << error(twice);
  std::string short_row = text;
  short_row.replace(short_row.find(k1), k1.size(), "K1 0.04 0 0.04 0\n");
  EXPECT_NE(error(short_row).find("a.txt:17: K1 final std. error must be a number"),
            std::string::npos)
      << error(short_row);
  std::string without = text;
  without.erase(without.find(k1), k1.size());
  testing::WriteFileText(dir.File("b.txt"), without);
  const CameraFile b = ReadAustralisCamera(dir.File("b.txt"), {});
  EXPECT_EQ(b.camera.params[BrownFraser10Model::kK1], 0.0);
  EXPECT_NE(std::find(b.notes.begin(), b.notes.end(), "K1: no line in the report, 0"),
            b.notes.end());
}

// What the duplicated lines found: each reader now names the second value (or the empty element).
TEST(CameraFormatsNoSubstitution, DbatDjiAndOpenSfmNameTheSecondValue) {
  testing::TempDir dir("aerocal_formats_substitution");
  const auto error =
      [&](const std::string& format, const std::string& name, const std::string& text) {
        testing::WriteFileText(dir.File(name), text);
        try {
          ReadCameraFileAs(format, dir.File(name), {});
        } catch (const InputError& e) {
          return std::string(e.what());
        }
        return std::string("(read)");
      };
  const std::string dbat =
      "<cameras><camera><sensor>auto,24</sensor><image>6000,4000</image>\n<cc>35</cc>\n";
  EXPECT_NE(error("dbat", "a.xml", dbat + "<cc>36</cc>\n</camera></cameras>\n")
                .find("a.xml:3: <cc> occurs twice in <camera> (first on line 2)"),
            std::string::npos);
  EXPECT_NE(
      error("dbat", "b.xml", dbat + "<K></K>\n</camera></cameras>\n").find("b.xml:3: <K> is empty"),
      std::string::npos);
  const std::string exif =
      "======== A.JPG\nImage Width : 5472\nExif Image Width : 5472\nImage Height : 3648\n"
      "Dewarp Data : 3684.48,3677.57,2.24,22.05,-0.26,0.1,3e-05,-3e-04,-0.03\n";
  EXPECT_EQ(error("dji", "c.txt", exif), "(read)");  // the same width twice, as exiftool prints it
  EXPECT_NE(error("dji", "d.txt", exif + "Exif Image Height : 3000\n")
                .find("d.txt:6: image height 3000 contradicts 3648 on line 4"),
            std::string::npos);
  EXPECT_NE(
      error("opensfm",
            "e.json",
            "{\"cam\": {\"projection_type\": \"perspective\", \"width\": 640, \"height\": 480,\n"
            "\"focal\": 0.9, \"focal\": 1.0, \"k1\": 0, \"k2\": 0}}\n")
          .find("e.json: cam: key \"focal\" occurs twice in one object"),
      std::string::npos);
}

}  // namespace
}  // namespace aerocal::calib
