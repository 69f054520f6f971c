// Camera files in other tools' languages (issue 15): one reader and one writer per format, each in
// its own file calib/camera/formats/<format>_format.cc, converting that tool's conventions at this
// boundary and nowhere else. A format reads into the registry model that IS its model
// (camera_model.h: a COLMAP camera stays colmap_*, a Metashape one metashape_frame, a DJI or
// OpenSfM one opencv); nothing is refitted on reading. Writing takes a camera already in the
// format's model (FormatTarget says which; the `camera convert` command converts first and reports
// how exactly). The OpenCV FileStorage format lives in tools/ (OpenCV stays out of calib).
//
// Conventions per format (sources in the README of this folder, calib/README.md "Camera file
// formats"):
// - colmap: cameras.txt `CAMERA_ID MODEL WIDTH HEIGHT PARAMS[]`; pixel origin converted by the
//   colmap_* models (models/colmap.h). Shared with the COLMAP import (ColmapCameraFromFields).
// - metashape: <calibration> (projection frame, width, height, f, cx, cy, b1, b2, k1-k4, p1-p4,
//   optional <covariance><params>names</params><coeffs>row-major</coeffs>) or a project/cameras
//   XML (<sensor id=...> holding it); models/metashape.h converts.
// - pix4d: the .cam text file (F, Px, Py mm; K1-K3 (or R1-R3), T1, T2; sensor size in the comment
//   line); models/pix4d.h converts.
// - opensfm: cameras.json / reconstruction.json (perspective, simple_radial, radial, brown,
//   fisheye): focal and principal point normalised by max(W, H), principal point from the image
//   centre; OpenSfM's normalised coordinates put the top-left pixel centre at
//   (0.5 - W / 2) / max(W, H), so cx = (W - 1) / 2 + c_x max(W, H) in aerocal/OpenCV pixels.
// - dji: XMP DewarpData `[date;]fx,fy,cx,cy,k1,k2,p1,p2,k3` (DewarpDataK6 adds k4, k5, k6) with
//   cx, cy offsets from the image centre: cx_opencv = W / 2 + cx, cy_opencv = H / 2 + cy (the DJI
//   manuals: "origin point: photo center"; which centre, W / 2 or (W - 1) / 2, they do not say:
//   the other reading moves the principal point by 0.5 px).
// - dbat: DBAT camera XML (c, pp mm from the top-left corner, y down, K1-K3, P1, P2): our
//   correction model (brown_fraser_10 without B1, B2).
// - photomodeler: a PhotoModeler "Bundle Soln" export's camera (f, pp mm from the upper-left
// corner,
//   format size, K1-K3, P1, P2; photomodeler_format.cc): brown_fraser_10 without B1, B2.
// - australis: an Australis "Camera Parameters" report (C, XP, YP, K1-K3, P1, P2, B1, B2 with their
//   standard errors; australis_format.cc): brown_fraser_10, all ten terms, diagonal covariance.
// - kalibr: camchain YAML (camera_model pinhole, distortion_model radtan / equidistant,
//   intrinsics fu fv pu pv, distortion_coeffs, resolution); pixels as OpenCV.
#pragma once

#include "calib/camera/camera.h"
#include "calib/camera/camera_model.h"
#include "calib/camera/convert_camera.h"
#include "calib/core/error.h"

#include <Eigen/Core>
#include <yaml-cpp/yaml.h>

#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace aerocal::calib {

/// A camera as a file holds it.
struct CameraFile {
  std::string name;
  ModelCamera camera;
  /// False when neither the file nor the caller gave a pixel size (frame.pixel_size_mm is then a
  /// placeholder of 0.001 mm: geometry in pixels is unaffected, mm values are meaningless).
  bool pixel_size_known = true;
  /// Covariance of camera.params (table order and units) where the file gives it.
  std::optional<Eigen::MatrixXd> covariance;
  std::vector<std::string> notes;  // what the reader assumed or left out
  /// True when the reader picked this camera among the file's by CameraReadOptions::camera_id.
  /// A --camera the reader did not use names no camera of the file: ReadCameraFileAs refuses it.
  bool chosen_by_camera_id = false;
};

/// What the command line adds to a file.
struct CameraReadOptions {
  std::string camera_id;  // picks one camera of a file holding several ("" = the only one)
  int width_px = 0;       // 0 = from the file; given and contradicting the file: InputError
  int height_px = 0;
  double pixel_size_mm = 0;  // 0 = from the file (or unknown)
};

inline constexpr double kPlaceholderPixelSizeMm = 0.001;

/// The registry model a format writes and which of its parameters the format cannot hold (they
/// must be 0; a conversion fits with them held at 0).
struct FormatTarget {
  CameraModelId model;
  std::vector<std::string> zero_params;
  bool needs_pixel_size = false;  // the format writes millimetres
  /// The target is OpenCV's distortion (opencv, colmap_opencv / full_opencv) reached by a fit:
  /// ConvertCameraFileSimplest may try 4 (k1 k2 p1 p2), 5 (+ k3) or 8 (+ k4-k6) coefficients.
  /// The registry's default is 5 (zero_params k4-k6).
  bool coefficient_choice = false;
};

/// A camera file expressed in a format's model, with how exactly (result) and, where the source
/// gives a covariance, the covariance propagated linearly through the conversion's Jacobian.
struct FileConversion {
  CameraFile file;
  ConversionResult result;
  std::vector<std::string> notes;
};
/// ConfigError("--pixel-size-mm ...") when the target needs a pixel size the source does not give.
FileConversion ConvertCameraFile(const CameraFile& from,
                                 const FormatTarget& target,
                                 const ConvertOptions& options = {});

/// ConvertCameraFile in the simplest form of the format (issue 29): where
/// target.coefficient_choice, the conversions with 4, 5 and 8 distortion coefficients up to
/// `max_coefficients` (>= 4), one line each in `tried` ("5 coefficients (k1 k2 p1 p2 k3): residual
/// max ... px, rms ... px"); the first whose max residual meets options.max_residual_px, or without
/// that gate the first within 0.01 px of the best tried. Otherwise ConvertCameraFile.
FileConversion ConvertCameraFileSimplest(const CameraFile& from,
                                         const FormatTarget& target,
                                         const ConvertOptions& options,
                                         int max_coefficients,
                                         std::vector<std::string>* tried);

/// Our camera (in its own model) as a camera file: interior_sigma as a diagonal covariance (the
/// terms without a sigma: 0), said in the notes. Sub-images and reference points are not carried.
CameraFile CameraFileFromCamera(const Camera& camera);

// ---- the registry (issue 30 item 7): the CLI, the tests and the fuzzers iterate it ----

/// What a format keeps of a camera's covariance.
enum class CovarianceForm {
  kNone,    // nothing (a conversion drops it and says so)
  kSigmas,  // the standard deviations (the diagonal): correlations dropped
  kFull,    // the whole matrix
};

/// A registry model a format's writer takes, with what the format holds of it: the parameters the
/// format has no field for (a camera written must have them at 0; a conversion holds them there)
/// and its covariance. The capabilities of a format are its rows of these and nothing else: the
/// registry's write refuses every other camera, `camera convert --model` offers these models.
struct WritableModel {
  CameraModelId model;
  std::vector<std::string> zero_params;
  CovarianceForm covariance = CovarianceForm::kNone;
  /// A camera of another model is fitted into this one choosing 4, 5 or 8 OpenCV distortion
  /// coefficients (FormatTarget::coefficient_choice; opencv-form models only).
  bool fit_coefficient_choice = false;
  /// Where the format derives parameters rather than storing them (OpenSfM's fisheye: fy = fx,
  /// the principal point at the image centre): sets them so. CheckWritable refuses a camera this
  /// would change; empty when the format stores every parameter it does not hold at 0.
  std::function<void(ModelCamera*)> conform = nullptr;
};

/// One camera-file format: a new format is its file plus one row in registry.cc (or, for the
/// OpenCV FileStorage entry that needs OpenCV, a RegisterCameraFormat call in the tool layer).
struct CameraFormat {
  std::string name;         // the command-line name (--from, --to, --camera-format)
  std::string description;  // one line for --help
  std::function<CameraFile(const std::string& path, const CameraReadOptions&)> read;
  /// The format's writer; in a registered row it first checks the camera against `models`
  /// (CheckWritable: InputError naming the format and the model).
  std::function<void(const std::string& path, const CameraFile&)> write;
  /// The models the writer takes (see WritableModel); a camera of another model is converted
  /// into one of them first (`target`).
  std::vector<WritableModel> models;
  /// True when a file whose first bytes (up to kDetectBytes) are `head` and whose path is `path`
  /// is of this format (`--from auto`, and what a wrong --from names). Content first: the path
  /// only where the content cannot tell (cameras.bin).
  std::function<bool(const std::string& head, const std::string& path)> looks_like;
  std::string extension;           // a file name ending the writer uses (tests, fuzzers)
  bool writes_size = true;         // a written file holds the image size (else --width/--height)
  bool writes_pixel_size = false;  // ... and the pixel size (else --pixel-size-mm)
  /// The model (and zero parameters) a source camera is written in. Left empty in a row, the
  /// registry sets DefaultFormatTarget: the source's own model when the format writes it, else a
  /// fit into models.front().
  std::function<FormatTarget(const ModelCamera& source)> target = nullptr;
};

/// The row of `models` for `model`; nullptr when the format does not write it.
const WritableModel* FindWritableModel(const CameraFormat& format, CameraModelId model);
/// The names of the models a format writes, comma separated (messages, --help).
std::string WritableModelNames(const CameraFormat& format);
/// The target of a camera written in `model` by `format` (its zero parameters; a pixel size
/// needed when the format writes millimetres); InputError naming the format and the model when
/// the format does not write it.
FormatTarget TargetInModel(const CameraFormat& format, CameraModelId model);
/// The source's own model when `format` writes it, else a fit into the format's first model.
FormatTarget DefaultFormatTarget(const CameraFormat& format, const ModelCamera& source);
/// InputError ("<format> cannot hold a <model> camera (it writes ...)", or naming the parameter
/// the format has no field for and its value) unless `format` can write `camera` as it is.
void CheckWritable(const CameraFormat& format, const ModelCamera& camera);
/// What `format` keeps of a covariance of a camera in `model` (kNone when it does not write it).
CovarianceForm CovarianceHeld(const CameraFormat& format, CameraModelId model);

inline constexpr size_t kDetectBytes = 1 << 16;

/// Every registered format, in registration order (calib's, then the tool layer's).
const std::vector<CameraFormat>& CameraFormats();
/// Adds a format (the tool layer's OpenCV entry); LogicError on a duplicate name.
void RegisterCameraFormat(CameraFormat format);
/// ConfigError naming `option` and the format names when unknown.
const CameraFormat& FindCameraFormat(const std::string& name, const std::string& option);
std::string CameraFormatNames();
/// The names of the formats whose looks_like accepts the file (empty: none).
std::vector<std::string> DetectCameraFormats(const std::string& path);
/// Where aerocal's own camera file is expected: " (the file looks like a F camera file ...: convert
/// it with `aerocal camera convert --from F ...`)" when `path` looks like another tool's file and
/// not like ours, else "". Appended to the reader's error by ReadCamera and ReadProject.
std::string ForeignCameraHint(const std::string& path);
/// Writes `file` with `format` to `path` only after the format's own reader has read it back as
/// the same camera (model, size, every pixel within 1e-6 px over a 21 x 21 grid): the writer runs
/// on a scratch file beside `path`, which is renamed onto `path` when it reads back; else the
/// scratch is removed and Error names what differs (nothing is written).
void WriteCameraFileVerified(const CameraFormat& format,
                             const std::string& path,
                             const CameraFile& file);
/// Reads `path` as format `name`, or, with name "auto", as the one format it looks like
/// (InputError naming the candidates when none or several). A reader's InputError on a file that
/// looks like another format says so ("... (the file looks like kalibr: --from kalibr)").
/// `*used` (optional) receives the format read.
CameraFile ReadCameraFileAs(const std::string& name,
                            const std::string& path,
                            const CameraReadOptions& options,
                            std::string* used = nullptr);

// ---- per format (name: reader, writer) ----
CameraFile ReadAerocalCamera(const std::string& path, const CameraReadOptions& options);
void WriteAerocalCamera(const std::string& path, const CameraFile& camera);

/// cameras.txt, or cameras.bin by the .bin extension (written so too).
CameraFile ReadColmapCameras(const std::string& path, const CameraReadOptions& options);
/// True when `path` ends in .bin and `head` starts as a cameras.bin does.
bool LooksLikeColmapBinary(const std::string& head, const std::string& path);
void WriteColmapCameras(const std::string& path, const CameraFile& camera);
/// One cameras.txt row split into fields (CAMERA_ID MODEL WIDTH HEIGHT PARAMS...) -> the
/// registry's COLMAP model; InputError("FILE:LINE: ...") on a bad row. The COLMAP import uses it.
ModelCamera ColmapCameraFromFields(const std::vector<std::string>& fields,
                                   const SourceRef& where,
                                   double pixel_size_mm);

CameraFile ReadMetashapeCalibration(const std::string& path, const CameraReadOptions& options);
void WriteMetashapeCalibration(const std::string& path, const CameraFile& camera);

/// The .cam, or a project's calibrated_camera_parameters.txt (--camera IMAGE, else the first).
CameraFile ReadPix4dCam(const std::string& path, const CameraReadOptions& options);
/// True when `head` starts as Pix4D's calibrated_camera_parameters.txt does.
bool IsPix4dCalibratedParameters(const std::string& head);
void WritePix4dCam(const std::string& path, const CameraFile& camera);
/// Pix4D's camera XMP tags (Camera:PerspectiveFocalLength, PrincipalPoint, PerspectiveDistortion)
/// from a JPEG or an XMP sidecar; the pixel size from exif:FocalPlaneXResolution or
/// --pixel-size-mm.
CameraFile ReadPix4dXmp(const std::string& path, const CameraReadOptions& options);
void WritePix4dXmp(const std::string& path, const CameraFile& camera);

CameraFile ReadOpenSfmCameras(const std::string& path, const CameraReadOptions& options);
void WriteOpenSfmCameras(const std::string& path, const CameraFile& camera);
/// OpenSfM's fisheye holds one focal length and no principal point: fy = fx, (cx, cy) the image
/// centre ((W - 1) / 2, (H - 1) / 2 in aerocal/OpenCV pixels).
void ConformOpenSfmFisheye(ModelCamera* camera);

CameraFile ReadDjiDewarpData(const std::string& path, const CameraReadOptions& options);
/// The opencv camera of a DewarpData string ("[date;]fx,fy,cx,cy,k1,k2,p1,p2,k3" or the 12 values
/// of DewarpDataK6) for an image of width x height px.
ModelCamera DjiDewarpDataCamera(const std::string& text,
                                const SourceRef& where,
                                int width_px,
                                int height_px);
void WriteDjiDewarpData(const std::string& path, const CameraFile& camera);

/// DBAT camera XML (whole or a fragment) or DBAT's text report (--camera CameraN).
CameraFile ReadDbatCameraXml(const std::string& path, const CameraReadOptions& options);
/// True when `head` is (the start of) a DBAT text report with a camera block.
bool IsDbatReport(const std::string& head);
void WriteDbatCameraXml(const std::string& path, const CameraFile& camera);

/// A Bundle Soln export, or a calibration / status report's camera block (--camera CameraN).
CameraFile ReadPhotoModelerCamera(const std::string& path, const CameraReadOptions& options);
/// True when `head` holds a PhotoModeler-style report camera block (Focal Length, Xp - ...).
bool IsPhotoModelerReport(const std::string& head);
void WritePhotoModelerCamera(const std::string& path, const CameraFile& camera);

CameraFile ReadAustralisCamera(const std::string& path, const CameraReadOptions& options);
void WriteAustralisCamera(const std::string& path, const CameraFile& camera);

/// ROS camera_info YAML (plumb_bob, rational_polynomial, equidistant; ros_format.cc).
CameraFile ReadRosCameraInfo(const std::string& path, const CameraReadOptions& options);
void WriteRosCameraInfo(const std::string& path, const CameraFile& camera);

/// camodocal / VINS PINHOLE camera YAML (camodocal_format.cc).
CameraFile ReadCamodocalCamera(const std::string& path, const CameraReadOptions& options);
void WriteCamodocalCamera(const std::string& path, const CameraFile& camera);

CameraFile ReadKalibrCamchain(const std::string& path, const CameraReadOptions& options);
void WriteKalibrCamchain(const std::string& path, const CameraFile& camera);

// ---- shared by the readers ----
namespace internal {
/// Applies --width/--height/--pixel-size-mm to what a file gave (0 = not given): a given value that
/// contradicts the file is InputError at `where`; a size nobody gave is InputError naming the
/// options. Marks the pixel size as known or a placeholder.
void ResolveFormat(CameraFile* file,
                   const CameraReadOptions& options,
                   const SourceRef& where,
                   int file_width_px,
                   int file_height_px,
                   double file_pixel_size_mm);
/// A finite number of the whole text within [-bound, bound]; InputError naming `what` otherwise.
double ParseNumber(const std::string& text,
                   const SourceRef& where,
                   const std::string& what,
                   double bound = 1e12);
double Param(const ModelCamera& camera, std::string_view name);
/// A camera name as one line of text (control characters, a newline among them, become spaces):
/// line-oriented formats put the name on a line of its own.
std::string OneLine(std::string_view name);
/// The shortest decimal text that reads back to the same double (std::to_chars): 0.009, not
/// 0.0089999999999999993.
std::string ShortestNumber(double value);
/// `text` for a double-quoted YAML scalar (backslash and quote escaped).
std::string YamlQuoted(std::string_view text);
/// A YAML camera file, strict (calib/core/yaml_util.h LoadYamlText: duplicate keys are errors);
/// OpenCV's `%YAML:1.0` first line (cv::FileStorage's, not a YAML 1.x directive) is read as a
/// comment, so line numbers stay those of the file.
YAML::Node LoadCameraYaml(const std::string& path);
/// The camera of a DBAT or PhotoModeler text report (report_camera.cc): `tool` names it in
/// messages; --camera CameraN picks one of several.
CameraFile ReadReportCamera(const std::string& path,
                            const std::vector<std::string>& lines,
                            const CameraReadOptions& options,
                            const std::string& tool);
/// The largest difference (px) over the format between a correction acting on x scaled by the
/// pixel aspect s (DBAT's x = s xb) and ours with that scale as B1 = s - 1 (`ours` holds it).
double AspectAsB1ResidualPx(const ModelCamera& ours, double s);
/// `text` with & < > " ' as XML entities (a camera name in an XML element).
std::string XmlEscaped(std::string_view text);
}  // namespace internal

}  // namespace aerocal::calib
