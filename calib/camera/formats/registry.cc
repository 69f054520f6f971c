// The camera-format registry (camera_formats.h CameraFormat): one row per format, with what its
// files look like for `--from auto`. The OpenCV FileStorage row is added by the tool layer
// (tools/camera_formats.cc, OpenCV staying out of calib).
#include "calib/camera/formats/camera_formats.h"
#include "calib/camera/formats/zip_archive.h"
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

namespace aerocal::calib {
namespace {

bool Has(const std::string& head, const char* marker) {
  return head.find(marker) != std::string::npos;
}

// Every registered model, with the covariance form a format keeps of each (our camera file).
std::vector<WritableModel> EveryModel(CovarianceForm covariance) {
  std::vector<WritableModel> models;
  ForEachCameraModel([&](auto m) { models.push_back({decltype(m)::kId, {}, covariance}); });
  return models;
}

// The models COLMAP has (their kColmapName, camera_model.h ColmapName).
std::vector<WritableModel> ColmapModels() {
  std::vector<WritableModel> models;
  ForEachCameraModel([&](auto m) {
    if (!ColmapName(decltype(m)::kId).empty()) models.push_back({decltype(m)::kId, {}});
  });
  return models;
}

// OpenCV's distortion, written as 4, 5 or 8 coefficients (opencv, dji, ros): a camera of another
// model is fitted choosing among them.
WritableModel OpenCvChoosingCoefficients() {
  WritableModel opencv{CameraModelId::kOpenCv, {}};
  opencv.fit_coefficient_choice = true;
  return opencv;
}

// A fit into OpenCV's distortion: 5 coefficients (k1 k2 p1 p2 k3) unless the caller chooses
// (ConvertCameraFileSimplest).
FormatTarget OpenCvFit(CameraModelId model) {
  FormatTarget t{model, {"k4", "k5", "k6"}};
  t.coefficient_choice = true;
  return t;
}

// COLMAP cameras.txt: its comment header or a first data line `ID MODEL W H PARAMS...`.
bool LooksLikeColmapText(const std::string& head) {
  if (Has(head, "# Camera list with one line of data per camera")) return true;
  std::istringstream in(head);
  static const std::regex kRow(
      R"(^\s*\S+\s+(SIMPLE_PINHOLE|PINHOLE|SIMPLE_RADIAL|RADIAL|OPENCV|FULL_OPENCV|OPENCV_FISHEYE|SIMPLE_RADIAL_FISHEYE|RADIAL_FISHEYE|THIN_PRISM_FISHEYE|FOV)\s+\d+\s+\d+(\s+\S+)+\s*$)");
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    return line.size() < 4000 && std::regex_match(line, kRow);
  }
  return false;
}

// One function per format: its row of the registry (name, description, reader, writer, the model
// it writes a camera in, what its files look like, extension and what a written file holds).
CameraFormat AerocalFormat() {
  return {"aerocal",
          "our camera YAML (any registry model; a rig file's head by --camera)",
          ReadAerocalCamera,
          WriteAerocalCamera,
          EveryModel(CovarianceForm::kSigmas),  // interior_sigma
          [](const std::string& h, const std::string&) {
            return Has(h, "format_px:") && Has(h, "pixel_size_mm:");
          },
          ".yaml",
          true,
          true};
}

CameraFormat ColmapFormat() {
  return {"colmap",
          "COLMAP cameras.txt or cameras.bin (SIMPLE_PINHOLE ... FULL_OPENCV; --camera ID)",
          ReadColmapCameras,
          WriteColmapCameras,
          ColmapModels(),
          [](const std::string& h, const std::string& path) {
            return LooksLikeColmapText(h) || LooksLikeColmapBinary(h, path);
          },
          ".txt",
          true,
          false,
          [](const ModelCamera& source) {
            if (!ColmapName(source.model).empty()) return FormatTarget{source.model, {}};
            if (source.model == CameraModelId::kOpenCv) {  // exact: OPENCV when k3-k6 are 0
              const bool full =
                  source.params[OpenCvModel::kK3] != 0 || source.params[OpenCvModel::kK4] != 0 ||
                  source.params[OpenCvModel::kK5] != 0 || source.params[OpenCvModel::kK6] != 0;
              return FormatTarget{
                  full ? CameraModelId::kColmapFullOpenCv : CameraModelId::kColmapOpenCv, {}};
            }
            return OpenCvFit(CameraModelId::kColmapFullOpenCv);
          }};
}

CameraFormat MetashapeFormat() {
  return {
      "metashape",
      "Agisoft Metashape / PhotoScan calibration XML, cameras XML, .psx / .psz project (--camera "
      "sensor id)",
      ReadMetashapeCalibration,
      WriteMetashapeCalibration,
      {{CameraModelId::kMetashapeFrame, {}, CovarianceForm::kFull}},
      [](const std::string& h, const std::string&) {
        // A calibration export, a cameras export, a .psx project, a .psz / .zip project archive.
        if (Has(h, "<opencv_storage>")) return false;  // OpenCV's <calibration_time>
        return Has(h, "<calibration>") || Has(h, "<calibration ") || Has(h, "<sensor ") ||
               Has(h, "<sensors") || (Has(h, "<document") && Has(h, "<chunks")) ||
               (internal::LooksLikeZip(h) && Has(h, "doc.xml"));
      },
      ".xml",
      true,
      false};
}

CameraFormat Pix4dFormat() {
  return {"pix4d",
          "Pix4D internal camera parameters (.cam), a project's calibrated_camera_parameters.txt "
          "(--camera IMAGE)",
          ReadPix4dCam,
          WritePix4dCam,
          {{CameraModelId::kPix4dPerspective, {}}},
          [](const std::string& h, const std::string&) {
            return Has(h, "Pix4D camera calibration file") || IsPix4dCalibratedParameters(h);
          },
          ".cam",
          false,
          true};
}

CameraFormat Pix4dXmpFormat() {
  return {"pix4d-xmp",
          "Pix4D camera XMP tags (Camera:PerspectiveFocalLength, PrincipalPoint, "
          "PerspectiveDistortion; a JPEG or an XMP sidecar)",
          ReadPix4dXmp,
          WritePix4dXmp,
          {{CameraModelId::kPix4dPerspective, {}}},
          [](const std::string& h, const std::string&) { return Has(h, "PerspectiveFocalLength"); },
          ".xmp",
          true,
          true};
}

CameraFormat OpenSfmFormat() {
  return {"opensfm",
          "OpenSfM / OpenDroneMap cameras.json",
          ReadOpenSfmCameras,
          WriteOpenSfmCameras,
          {{CameraModelId::kOpenCv, {"k4", "k5", "k6"}},
           {CameraModelId::kOpenCvFisheye,
            {"k3", "k4"},
            CovarianceForm::kNone,
            false,
            ConformOpenSfmFisheye}},
          [](const std::string& h, const std::string&) { return Has(h, "\"projection_type\""); },
          ".json"};
}

CameraFormat DjiFormat() {
  return {"dji",
          "DJI XMP DewarpData / DewarpDataK6 (a DJI JPEG, an XMP sidecar or the string)",
          ReadDjiDewarpData,
          WriteDjiDewarpData,
          {OpenCvChoosingCoefficients()},
          [](const std::string& h, const std::string&) {
            if (Has(h, "DewarpData") || Has(h, "Dewarp Data")) return true;
            // The bare string: "[date;]fx,fy,cx,cy,k1,k2,p1,p2,k3" on its first line.
            static const std::regex kRecord(
                R"(^\s*([0-9-]+;)?\s*[-+0-9.eE]+(\s*,\s*[-+0-9.eE]+){8}([-+0-9.eE,\s]*)$)");
            const std::string first = h.substr(0, h.find('\n'));
            return first.size() < 1000 && std::regex_match(first, kRecord);
          },
          ".xmp"};
}

CameraFormat DbatFormat() {
  return {
      "dbat",
      "DBAT camera XML, whole or a <cameras> / <camera> fragment, or DBAT's text report (c, pp, "
      "aspect, K1-K3, P1, P2 in mm)",
      ReadDbatCameraXml,
      WriteDbatCameraXml,
      {{CameraModelId::kBrownFraser10, {"B2"}}},  // B1 as DBAT's pixel aspect
      [](const std::string& h, const std::string&) {
        return ((Has(h, "<camera>") || Has(h, "<camera ")) && (Has(h, "<cc>") || Has(h, "<pp>"))) ||
               IsDbatReport(h);
      },
      ".xml",
      true,
      true};
}

CameraFormat PhotoModelerFormat() {
  return {"photomodeler",
          "PhotoModeler Bundle Soln export's camera or a calibration report's camera block (f, pp, "
          "format, K1-K3, P1, P2 mm)",
          ReadPhotoModelerCamera,
          WritePhotoModelerCamera,
          {{CameraModelId::kBrownFraser10, {"B1", "B2"}}},
          [](const std::string& h, const std::string&) {
            return h.rfind("Bundle Soln", 0) == 0 || IsPhotoModelerReport(h);
          },
          ".txt",
          true,
          true};
}

CameraFormat AustralisFormat() {
  return {"australis",
          "Australis camera-parameter report (C, XP, YP, K1-K3, P1, P2, B1, B2 mm)",
          ReadAustralisCamera,
          WriteAustralisCamera,
          {{CameraModelId::kBrownFraser10, {}, CovarianceForm::kSigmas}},
          [](const std::string& h, const std::string&) {
            return Has(h, "Australis") && Has(h, "Camera Parameters");
          },
          ".txt",
          true,
          true};
}

CameraFormat RosFormat() {
  return {"ros",
          "ROS camera_info YAML (camera_matrix/distortion_coefficients {rows, cols, data}; "
          "plumb_bob, rational_polynomial, equidistant)",
          ReadRosCameraInfo,
          WriteRosCameraInfo,
          {OpenCvChoosingCoefficients(), {CameraModelId::kOpenCvFisheye, {}}},
          [](const std::string& h, const std::string&) {
            return Has(h, "camera_matrix:") && Has(h, "rows:") && !Has(h, "opencv-matrix") &&
                   !Has(h, "model_type:");
          },
          ".yaml"};
}

CameraFormat CamodocalFormat() {
  return {"camodocal",
          "camodocal / VINS-Mono / VINS-Fusion PINHOLE camera YAML",
          ReadCamodocalCamera,
          WriteCamodocalCamera,
          {{CameraModelId::kOpenCv, {"k3", "k4", "k5", "k6"}}},
          [](const std::string& h, const std::string&) {
            return Has(h, "model_type:") && Has(h, "projection_parameters");
          },
          ".yaml"};
}

CameraFormat KalibrFormat() {
  return {"kalibr",
          "Kalibr camchain YAML (pinhole radtan / equidistant)",
          ReadKalibrCamchain,
          WriteKalibrCamchain,
          {{CameraModelId::kOpenCv, {"k3", "k4", "k5", "k6"}}, {CameraModelId::kOpenCvFisheye, {}}},
          [](const std::string& h, const std::string&) {
            return Has(h, "camera_model:") && Has(h, "intrinsics:");
          },
          ".yaml"};
}

// A row as the registry keeps it: the default target where the row gives none, and a writer that
// checks the camera against the row's models first (so no writer decides what it holds).
CameraFormat Registered(CameraFormat format) {
  if (!format.target)
    format.target = [rows = format](const ModelCamera& source) {
      return DefaultFormatTarget(rows, source);
    };
  format.write = [checked = format, write = format.write](const std::string& path,
                                                          const CameraFile& file) {
    try {
      CheckWritable(checked, file.camera);
    } catch (const InputError& e) {
      throw InputError(path + ": not written: " + e.what());
    }
    write(path, file);
  };
  return format;
}

std::vector<CameraFormat>& Registry() {
  static std::vector<CameraFormat> formats = {AerocalFormat(),
                                              ColmapFormat(),
                                              MetashapeFormat(),
                                              Pix4dFormat(),
                                              Pix4dXmpFormat(),
                                              OpenSfmFormat(),
                                              DjiFormat(),
                                              DbatFormat(),
                                              PhotoModelerFormat(),
                                              AustralisFormat(),
                                              RosFormat(),
                                              CamodocalFormat(),
                                              KalibrFormat()};
  static const bool registered = [] {
    for (CameraFormat& f : formats) f = Registered(std::move(f));
    return true;
  }();
  (void)registered;
  return formats;
}

std::string Head(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string head(kDetectBytes, '\0');
  if (!in) return {};
  in.read(&head[0], static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<size_t>(in.gcount()));
  return head;
}

std::string Joined(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

}  // namespace

const std::vector<CameraFormat>& CameraFormats() { return Registry(); }

const WritableModel* FindWritableModel(const CameraFormat& format, CameraModelId model) {
  for (const WritableModel& m : format.models)
    if (m.model == model) return &m;
  return nullptr;
}

std::string WritableModelNames(const CameraFormat& format) {
  std::vector<std::string> names;
  for (const WritableModel& m : format.models) names.emplace_back(CameraModelName(m.model));
  return Joined(names);
}

// The format's row for `model`, or InputError naming the format, the model and what it writes.
const WritableModel& RowFor(const CameraFormat& format, CameraModelId model) {
  const WritableModel* row = FindWritableModel(format, model);
  if (!row)
    throw InputError("the " + format.name + " format cannot hold a " +
                     std::string(CameraModelName(model)) + " camera (it writes " +
                     WritableModelNames(format) + ")");
  return *row;
}

FormatTarget TargetInModel(const CameraFormat& format, CameraModelId model) {
  return {model, RowFor(format, model).zero_params, format.writes_pixel_size};
}

FormatTarget DefaultFormatTarget(const CameraFormat& format, const ModelCamera& source) {
  AEROCAL_CHECK(!format.models.empty()) << "camera format " << format.name << " writes no model";
  if (FindWritableModel(format, source.model)) return TargetInModel(format, source.model);
  const WritableModel& fit = format.models.front();
  FormatTarget target =
      fit.fit_coefficient_choice ? OpenCvFit(fit.model) : FormatTarget{fit.model, fit.zero_params};
  target.needs_pixel_size = format.writes_pixel_size;
  return target;
}

void CheckWritable(const CameraFormat& format, const ModelCamera& camera) {
  const WritableModel& row = RowFor(format, camera.model);
  const std::string model(CameraModelName(camera.model));
  for (const std::string& name : row.zero_params)
    if (const double value = internal::Param(camera, name); value != 0.0)
      throw InputError("the " + format.name + " format holds no " + name + " of a " + model +
                       " camera (must be 0, got " + FormatNumber(value) +
                       "; convert with it held at 0)");
  if (!row.conform) return;
  ModelCamera conformed = camera;
  row.conform(&conformed);
  const std::vector<ParamInfo> table = CameraModelParams(camera.model);
  std::string derived;
  for (size_t i = 0; i < table.size(); ++i)
    if (conformed.params[i] != camera.params[i])
      derived += (derived.empty() ? "" : ", ") + std::string(table[i].name) + " = " +
                 FormatNumber(camera.params[i]) + " (it holds " +
                 FormatNumber(conformed.params[i]) + ")";
  if (!derived.empty())
    throw InputError("the " + format.name + " format cannot hold this " + model +
                     " camera: it derives " + derived);
}

CovarianceForm CovarianceHeld(const CameraFormat& format, CameraModelId model) {
  const WritableModel* row = FindWritableModel(format, model);
  return row ? row->covariance : CovarianceForm::kNone;
}

void RegisterCameraFormat(CameraFormat format) {
  for (const CameraFormat& f : Registry())
    AEROCAL_CHECK(f.name != format.name) << "camera format " << format.name << " registered twice";
  Registry().push_back(Registered(std::move(format)));
}

std::string CameraFormatNames() {
  std::vector<std::string> names;
  for (const CameraFormat& f : Registry()) names.push_back(f.name);
  return Joined(names);
}

const CameraFormat& FindCameraFormat(const std::string& name, const std::string& option) {
  for (const CameraFormat& f : Registry())
    if (f.name == name) return f;
  throw ConfigError(option + ": unknown camera format '" + name + "' (expected " +
                    CameraFormatNames() + (option == "--from" ? ", or auto" : "") + ")");
}

std::vector<std::string> DetectCameraFormats(const std::string& path) {
  const std::string head = Head(path);
  std::vector<std::string> names;
  for (const CameraFormat& f : Registry())
    if (f.looks_like && f.looks_like(head, path)) names.push_back(f.name);
  return names;
}

std::string ForeignCameraHint(const std::string& path) {
  // Only a regular file is looked into (a FIFO or a device would block or never end).
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return "";
  std::vector<std::string> names;
  try {
    names = DetectCameraFormats(path);
  } catch (const Error&) {
    return "";  // unreadable: the reader's own message says so
  }
  if (names.empty() || std::find(names.begin(), names.end(), "aerocal") != names.end()) return "";
  return " (the file looks like a " + names.front() +
         " camera file, not aerocal's: convert it with `aerocal camera convert --from " +
         names.front() + " --to aerocal " + path + " camera.yaml`)";
}

void WriteCameraFileVerified(const CameraFormat& format,
                             const std::string& path,
                             const CameraFile& file) {
  namespace fs = std::filesystem;
  const fs::path target(path);
  const fs::path scratch = target.parent_path() / (".aerocal_check_" + target.filename().string());
  try {
    CheckWritable(format, file.camera);  // before the scratch write, naming `path`
  } catch (const InputError& e) {
    throw InputError(path + ": not written: " + e.what());
  }
  format.write(scratch.string(), file);
  std::string problem;
  try {
    CameraReadOptions options;
    if (!format.writes_size) {
      options.width_px = file.camera.frame.width_px;
      options.height_px = file.camera.frame.height_px;
    }
    if (!format.writes_pixel_size && file.pixel_size_known)
      options.pixel_size_mm = file.camera.frame.pixel_size_mm;
    const CameraFile back = format.read(scratch.string(), options);
    const PixelFrame &a = file.camera.frame, &b = back.camera.frame;
    if (back.camera.model != file.camera.model)
      problem = "reads back as " + std::string(CameraModelName(back.camera.model));
    else if (a.width_px != b.width_px || a.height_px != b.height_px)
      problem = "reads back as " + std::to_string(b.width_px) + " x " +
                std::to_string(b.height_px) + " px";
    else if (const ConversionResidual r = CompareCameras(file.camera, back.camera, 21);
             r.failed_points > 0 || !(r.max_px <= 1e-6))
      problem = "reads back " + FormatNumber(r.max_px) + " px away";
  } catch (const Error& e) {
    problem = std::string("does not read back: ") + e.what();
  }
  std::error_code ignored;
  if (!problem.empty()) {
    fs::remove(scratch, ignored);
    throw Error(path + ": not written: the " + format.name + " file " + problem);
  }
  fs::rename(scratch, target);
}

CameraFile ReadCameraFileAs(const std::string& name,
                            const std::string& path,
                            const CameraReadOptions& options,
                            std::string* used) {
  std::string chosen = name;
  if (name == "auto") {
    CheckInputFile(path);
    const std::vector<std::string> candidates = DetectCameraFormats(path);
    if (candidates.empty())
      ThrowInputError({path, 1},
                      "--from auto: the file looks like none of the camera formats (" +
                          CameraFormatNames() + "): name one with --from");
    if (candidates.size() > 1)
      ThrowInputError({path, 1},
                      "--from auto: the file looks like several formats (" + Joined(candidates) +
                          "): name one with --from");
    chosen = candidates.front();
  }
  const CameraFormat& format = FindCameraFormat(chosen, "--from");
  if (used) *used = chosen;
  try {
    CameraFile file = format.read(path, options);
    // A --camera on a file of one camera without ids (a single-camera format, a camera YAML
    // that is no rig, an OpenCV file without M1/M2) names no camera in it (issue 37 class 9).
    if (!options.camera_id.empty() && !file.chosen_by_camera_id)
      ThrowInputError({path, 1},
                      "--camera " + options.camera_id + ": the file holds one " + chosen +
                          " camera and names no cameras (drop --camera)");
    return file;
  } catch (const InputError& e) {
    if (name == "auto") throw;
    const std::vector<std::string> candidates = DetectCameraFormats(path);
    if (candidates.empty() ||
        std::find(candidates.begin(), candidates.end(), chosen) != candidates.end())
      throw;
    throw InputError(std::string(e.what()) + " (the file looks like " + Joined(candidates) +
                     ": --from " + candidates.front() + ")");
  }
}

}  // namespace aerocal::calib
