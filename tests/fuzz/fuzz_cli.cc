// libFuzzer target of the readers that live in the command line (issue 12): the `aerocal`
// commands run in process (tools/main.cc compiled with main renamed AerocalMain, tests/fuzz/
// CMakeLists.txt), so the fuzzed files go through the same reading and checking as for a user.
// The first byte picks the command (a seed's first character '0'..'5' names kind 0..5); the rest
// is split at "\n%%\n" into the files it reads:
//   0: certificate --result R --lab L --previous P --tolerances T (the typed reading of a
//      calibrate result.json and of a previous certificate, the lab YAML, the tolerances YAML);
//   1: calibrate --groups G on a simulated test field (2 groups of 4 images);
//   2: calibrate --budget B on the same test field;
//   3: rig stitch --project with the fuzzed project.yaml, exposures, observations and points of a
//      simulated four-head rig line (its rig file as given);
//   4: pushbroom control with the fuzzed line camera, pos.csv and reference exposures.csv (the
//      reference camera, line image and reference images fixed, small);
//   5: batch status --manifest M with the fuzzed manifest.json and unit u1's done and failed
//      records (docs/formats.md "Batch manifest"); run from the scratch folder, which holds a
//      simulated flight in sim_flight/ (a seed's "directory" and relative flight arguments).
// Exit 2 (bad input) and 3 (did not converge) are answers; exit 1 ("internal error": an exception
// the command did not turn into FILE:LINE) is a finding, as is any crash, leak or UB report.
#include "tests/fuzz/fuzz_support.h"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

int AerocalMain(int argc, char** argv);  // tools/main.cc

namespace {

namespace fs = std::filesystem;
using aerocal::fuzz::Parts;
using aerocal::fuzz::ScratchDir;
using aerocal::fuzz::WriteScratch;

int Run(std::vector<std::string> args) {
  args.insert(args.begin(), {"aerocal", "--quiet"});
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  return AerocalMain(int(args.size()), argv.data());
}

// Simulated inputs, made once per process by the real `simulate` command.
const std::string& Simulated(const std::string& name, const std::vector<std::string>& options) {
  static std::map<std::string, std::string> made;
  auto it = made.find(name);
  if (it != made.end()) return it->second;
  const std::string dir = ScratchDir() + "/sim_" + name;
  std::vector<std::string> args = {"simulate", "--out", dir};
  args.insert(args.end(), options.begin(), options.end());
  if (Run(args) != 0) {
    std::fprintf(stderr, "fuzz_cli: simulate %s failed\n", name.c_str());
    std::abort();
  }
  return made.emplace(name, dir).first->second;
}

constexpr int kKinds = 6;

const std::string& TestField() {
  return Simulated("tf", {"--test-field", "--groups", "2", "--images-per-group", "4"});
}

// The fixed inputs of `pushbroom control`: the test field's frame camera, a 64 x 64 line image
// and a reference image per exposure id 0001..0004 (a smooth pattern: matching finds little).
const std::string& PushbroomFixed() {
  static const std::string dir = [] {
    const std::string d = ScratchDir() + "/pb_fixed";
    fs::create_directories(d + "/images");
    fs::copy_file(TestField() + "/camera_nominal.yaml",
                  d + "/camera.yaml",
                  fs::copy_options::overwrite_existing);
    cv::Mat image(64, 64, CV_8U);
    for (int r = 0; r < image.rows; ++r)
      for (int c = 0; c < image.cols; ++c)
        image.at<uint8_t>(r, c) = uint8_t((r * 7 + c * 13) % 256);
    cv::imwrite(d + "/line.png", image);
    for (const char* id : {"0001", "0002", "0003", "0004"})
      cv::imwrite(d + "/images/" + id + ".png", image);
    return d;
  }();
  return dir;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  const int kind = (data[0] - '0' + 256 * kKinds) % kKinds;  // '0' -> 0, ..., '5' -> 5
  const auto parts = Parts(data + 1, size - 1, 4);
  const std::string out = ScratchDir() + "/out";
  fs::remove_all(out);
  int code = 0;
  if (kind == 0) {
    code = Run({"certificate",
                "--result",
                WriteScratch("result.json", parts[0]),
                "--lab",
                WriteScratch("lab.yaml", parts[1]),
                "--previous",
                WriteScratch("previous.json", parts[2]),
                "--tolerances",
                WriteScratch("tolerances.yaml", parts[3]),
                "--no-render",
                "--out",
                out});
  } else if (kind == 1 || kind == 2) {
    const std::string& tf = TestField();
    code = Run({"calibrate",
                "--camera",
                tf + "/camera_nominal.yaml",
                "--observations",
                tf + "/observations.csv",
                "--points",
                tf + "/points.csv",
                "--out",
                out,
                kind == 1 ? "--groups" : "--budget",
                WriteScratch(kind == 1 ? "groups.csv" : "budget.yaml", parts[0])});
  } else if (kind == 3) {
    const std::string& line = Simulated("uav4", {"--rig", "uav4", "--exposures", "2"});
    const std::string dir = ScratchDir() + "/rig";
    fs::create_directories(dir);
    for (const char* rig : {"rig_truth.yaml", "rig_nominal.yaml"})
      fs::copy_file(line + "/" + rig, dir + "/" + rig, fs::copy_options::overwrite_existing);
    WriteScratch("rig/project.yaml", parts[0]);
    WriteScratch("rig/exposures.csv", parts[1]);
    WriteScratch("rig/observations.csv", parts[2]);
    WriteScratch("rig/points.csv", parts[3]);
    code = Run({"rig",
                "stitch",
                "--camera",
                dir + "/rig_truth.yaml",
                "--project",
                dir + "/project.yaml",
                "--out",
                out});
  } else if (kind == 4) {
    const std::string& fixed = PushbroomFixed();
    code = Run({"pushbroom",
                "control",
                "--camera",
                WriteScratch("line.yaml", parts[0]),
                "--pos",
                WriteScratch("pos.csv", parts[1]),
                "--line-image",
                fixed + "/line.png",
                "--reference-camera",
                fixed + "/camera.yaml",
                "--reference-exposures",
                WriteScratch("reference.csv", parts[2]),
                "--reference-images",
                fixed + "/images",
                "--out",
                out});
  } else {
    Simulated("flight", {"--exposures", "2", "--strips", "1"});
    fs::remove_all(ScratchDir() + "/batch");
    fs::create_directories(ScratchDir() + "/batch/done");
    fs::create_directories(ScratchDir() + "/batch/failed");
    WriteScratch("batch/done/u1.json", parts[1]);
    WriteScratch("batch/failed/u1.json", parts[2]);
    const fs::path cwd = fs::current_path();  // the command enters the manifest's "directory"
    fs::current_path(ScratchDir());
    code = Run(
        {"batch", "status", "--list", "--manifest", WriteScratch("batch/manifest.json", parts[0])});
    fs::current_path(cwd);
  }
  if (code == 1) {
    std::fprintf(stderr, "fuzz_cli: exit 1 (internal error) on command kind %d\n", kind);
    std::abort();
  }
  return 0;
}
