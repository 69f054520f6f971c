#include "tools/colmap_matching.h"

#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"
#include "calib/core/error.h"
#include "tools/run_program.h"

#include <filesystem>
#include <fstream>

namespace aerocal::tools {
namespace {

namespace fs = std::filesystem;

// Runs `colmap STEP ARGS...` with its output in work_dir/STEP.log; throws on failure.
void Step(const ColmapMatchingOptions& o, const std::string& step, std::vector<std::string> args) {
  args.insert(args.begin(), {o.program, step});
  const std::string log = o.work_dir + "/" + step + ".log";
  const int status = RunProgram(args, log);
  if (status == -1)
    throw ConfigError("--match colmap: cannot run '" + o.program +
                      "' (install COLMAP, e.g. apt-get install colmap, "
                      "or name it with --colmap)");
  if (status != 0)
    throw InputError("--match colmap: COLMAP " + step + " failed (exit " + std::to_string(status) +
                     "): see " + log + " (" + CommandLine(args) + ")");
}

// Registered images of a text model: images.txt holds two lines per image after its comments.
int RegisteredImages(const std::string& text_model) {
  std::ifstream in(text_model + "/images.txt");
  int lines = 0;
  for (std::string line; std::getline(in, line);)
    if (line.empty() || line[0] != '#') ++lines;
  return lines / 2;
}

// The text model (converted from sparse/N) of the model with the most registered images.
std::string LargestModel(const ColmapMatchingOptions& o) {
  std::string best;
  int best_images = 0;
  std::vector<fs::path> models;
  if (fs::is_directory(o.work_dir + "/sparse"))
    for (const auto& entry : fs::directory_iterator(o.work_dir + "/sparse"))
      models.push_back(entry.path());
  for (const fs::path& model : models) {
    const std::string text = o.work_dir + "/text_" + model.filename().string();
    fs::create_directories(text);
    Step(o,
         "model_converter",
         {"--input_path", model.string(), "--output_path", text, "--output_type", "TXT"});
    if (const int n = RegisteredImages(text); n > best_images)
      best = model.string(), best_images = n;
  }
  if (best_images < 3)
    throw InputError("--match colmap: COLMAP mapper registered " + std::to_string(best_images) +
                     " images (3 needed to align the model to the GNSS centres): see " +
                     o.work_dir + "/mapper.log");
  return best;
}

}  // namespace

std::string RunColmapMatching(
    const std::string& images_dir,
    const std::vector<std::pair<std::string, Eigen::Vector3d>>& ecef_centres,
    const ColmapMatchingOptions& o) {
  fs::create_directories(o.work_dir + "/sparse");
  const std::string db = o.work_dir + "/database.db";
  fs::remove(db);  // a rerun starts afresh (COLMAP would add the images a second time)
  Step(o,
       "feature_extractor",
       {"--database_path",
        db,
        "--image_path",
        images_dir,
        "--ImageReader.single_camera_per_folder",
        "1",
        "--SiftExtraction.use_gpu",
        "0",
        "--SiftExtraction.max_image_size",
        std::to_string(o.max_image_px)});
  Step(o,
       o.matcher + "_matcher",
       {"--database_path", db, "--SiftMatching.use_gpu", "0", "--random_seed", "1"});
  Step(o,
       "mapper",
       {"--database_path",
        db,
        "--image_path",
        images_dir,
        "--output_path",
        o.work_dir + "/sparse",
        "--random_seed",
        "1"});
  const std::string model = LargestModel(o);
  WriteFileAtomically(o.work_dir + "/ecef_centres.txt", [&](std::ostream& out) {
    for (const auto& [name, xyz] : ecef_centres)
      out << name << " " << FormatNumber(xyz.x(), 15) << " " << FormatNumber(xyz.y(), 15) << " "
          << FormatNumber(xyz.z(), 15) << "\n";
  });
  const std::string aligned = o.work_dir + "/aligned", text = o.work_dir + "/aligned_text";
  fs::create_directories(aligned);
  fs::create_directories(text);
  Step(o,
       "model_aligner",
       {"--input_path",
        model,
        "--output_path",
        aligned,
        "--ref_images_path",
        o.work_dir + "/ecef_centres.txt",
        "--ref_is_gps",
        "0",
        "--alignment_type",
        "custom",
        "--robust_alignment",
        "1",
        "--robust_alignment_max_error",
        FormatNumber(o.align_error_m, 6),
        "--random_seed",
        "1"});
  Step(o,
       "model_converter",
       {"--input_path", aligned, "--output_path", text, "--output_type", "TXT"});
  return text;
}

}  // namespace aerocal::tools
