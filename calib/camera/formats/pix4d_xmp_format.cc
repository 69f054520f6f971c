// Pix4D's camera XMP tags (namespace http://pix4d.com/camera/1.0, Pix4D support article
// 360016450032 "Specifications of XMP Camera Tags"): the "XML form" of Pix4D's internal camera
// parameters that a camera maker writes into its images for Pix4D to use:
//   Camera:ModelType              "perspective" (or "fisheye": not read, said)
//   Camera:PerspectiveFocalLength  F, mm
//   Camera:PrincipalPoint          "Px,Py", mm
//   Camera:PerspectiveDistortion   "R1,R2,R3,T1,T2"
// the same quantities as the .cam file (pix4d_format.cc), in the same conventions
// (models/pix4d.h: mm from the top-left corner, y down, T1 = p1, T2 = p2). The tags hold no image
// or pixel size: the image size from a JPEG's SOF marker or a sidecar's tiff:ImageWidth/Length,
// the pixel size from exif:FocalPlaneXResolution with exif:FocalPlaneResolutionUnit (2 inch,
// 3 cm, 4 mm), which the writer adds and Pix4D also reads, else --pixel-size-mm.
#include "calib/camera/formats/camera_formats.h"
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"
#include "calib/metadata/image_metadata.h"

#include <cmath>
#include <optional>
#include <sstream>

namespace aerocal::calib {
namespace {

constexpr const char* kPix4dCameraUri = xmp_ns::kPix4dCamera;

struct XmpText {
  std::string value;
  SourceRef where;
  std::string name;  // as written: "Camera:PrincipalPoint"
};

// A number or a rational "a/b" (EXIF rationals in XMP).
double ParseRational(const XmpText& t, const std::string& what) {
  const size_t slash = t.value.find('/');
  if (slash == std::string::npos) return internal::ParseNumber(t.value, t.where, what);
  const double a = internal::ParseNumber(t.value.substr(0, slash), t.where, what);
  const double b = internal::ParseNumber(t.value.substr(slash + 1), t.where, what);
  if (b == 0) ThrowInputError(t.where, what + ": zero denominator");
  return a / b;
}

// The packet's properties by namespace URI (with or without its trailing '/'): the prefix is
// whatever the file binds ("Camera", "P4", ...); messages quote it as written.
struct Tags {
  const XmpPacket& xmp;

  std::optional<XmpText> Find(const char* uri, const std::string& name) const {
    const XmpProperty* p = xmp.Find(uri, name);
    if (!p) return std::nullopt;
    if (p->structured) ThrowInputError(p->where, p->qualified + " must be a simple value");
    return XmpText{p->value, p->where, p->qualified};
  }
  std::optional<XmpText> CameraTag(const std::string& name) const {
    return Find(kPix4dCameraUri, name);
  }
};

// `count` comma-separated numbers of a tag.
std::vector<double> Numbers(const XmpText& t, size_t count) {
  const std::vector<std::string> fields = SplitCommaList(t.value, {true, true});
  if (fields.size() != count)
    ThrowInputError(t.where,
                    t.name + " must hold " + std::to_string(count) +
                        " comma-separated values (got '" + t.value + "')");
  std::vector<double> v;
  for (const std::string& f : fields) v.push_back(internal::ParseNumber(f, t.where, t.name, 1e4));
  return v;
}

// F, Px, Py and the distortion into Pix4D's perspective model; the line of the focal length's tag
// (the camera's place in the file). The fisheye model type is refused.
int ReadParameters(const Tags& tags, const std::string& path, bool image, ModelCamera* camera) {
  using M = Pix4dPerspectiveModel;
  const auto focal = tags.CameraTag("PerspectiveFocalLength");
  const auto pp = tags.CameraTag("PrincipalPoint");
  if (!focal || !pp) {
    const auto type = tags.CameraTag("ModelType");
    ThrowInputError(type ? type->where : SourceRef{path, image ? 0 : 1},
                    std::string("no PerspectiveFocalLength / PrincipalPoint of namespace ") +
                        kPix4dCameraUri + " (Pix4D camera XMP)");
  }
  if (const auto type = tags.CameraTag("ModelType"); type && type->value != "perspective")
    ThrowInputError(type->where,
                    type->name + " '" + type->value +
                        "': only the perspective model is read (Pix4D's fisheye "
                        "polynomial is not a registry model)");
  camera->model = M::kId;
  std::vector<double>& p = camera->params;
  p.assign(M::kNumParams, 0.0);
  p[M::kF] = Numbers(*focal, 1)[0];
  if (!(p[M::kF] > 0)) ThrowInputError(focal->where, "the focal length must be > 0 mm");
  const std::vector<double> principal = Numbers(*pp, 2);
  p[M::kPx] = principal[0];
  p[M::kPy] = principal[1];
  if (const auto d = tags.CameraTag("PerspectiveDistortion")) {
    const std::vector<double> v = Numbers(*d, 5);  // R1, R2, R3, T1, T2
    for (int i = 0; i < 5; ++i) p[M::kR1 + i] = v[i];
  }
  return focal->where.line;
}

// The pixel size (mm) from exif:FocalPlaneXResolution and its unit (2 inch, the default, 3 cm,
// 4 mm); 0 when the tag is absent.
double ReadPixelSize(const Tags& tags) {
  const auto res = tags.Find(xmp_ns::kExif, "FocalPlaneXResolution");
  if (!res) return 0.0;
  const auto unit = tags.Find(xmp_ns::kExif, "FocalPlaneResolutionUnit");
  const int u =
      unit ? static_cast<int>(internal::ParseNumber(unit->value, unit->where, unit->name, 10)) : 2;
  const double mm_per_unit = u == 2 ? 25.4 : u == 3 ? 10.0 : u == 4 ? 1.0 : 0.0;
  if (mm_per_unit == 0)
    ThrowInputError(unit->where,
                    "exif:FocalPlaneResolutionUnit must be 2 (inch), 3 (cm) or 4 (mm)");
  const double per_unit = ParseRational(*res, res->name);
  if (!(per_unit > 0)) ThrowInputError(res->where, "exif:FocalPlaneXResolution must be > 0");
  return mm_per_unit / per_unit;
}

}  // namespace

CameraFile ReadPix4dXmp(const std::string& path, const CameraReadOptions& options) {
  const std::string bytes = ReadTextFile(path);
  int width = 0, height = 0;
  const bool image = IsJpegOrTiff(bytes);
  const std::optional<XmpPacket> xmp = XmpOfCameraFile(bytes, path, &width, &height);
  if (!xmp) ThrowInputError({path, 1}, "neither an image nor an XMP packet (x:xmpmeta / rdf:RDF)");
  const Tags tags{*xmp};
  CameraFile file;
  file.name = "pix4d";
  const SourceRef where{path, ReadParameters(tags, path, image, &file.camera)};
  if (!image) {  // a sidecar: the image size from its tiff tags
    const auto w = tags.Find(xmp_ns::kTiff, "ImageWidth"),
               h = tags.Find(xmp_ns::kTiff, "ImageLength");
    if (w && h) {
      width = static_cast<int>(internal::ParseNumber(w->value, w->where, w->name, 1e6));
      height = static_cast<int>(internal::ParseNumber(h->value, h->where, h->name, 1e6));
    }
  }
  internal::ResolveFormat(&file, options, where, width, height, ReadPixelSize(tags));
  if (!file.pixel_size_known)
    ThrowInputError(where,
                    "the pixel size is needed (the tags are mm): the file has no "
                    "exif:FocalPlaneXResolution; pass --pixel-size-mm");
  return file;
}

void WritePix4dXmp(const std::string& path, const CameraFile& file) {
  using M = Pix4dPerspectiveModel;
  AEROCAL_CHECK(file.camera.model == M::kId) << "not pix4d_perspective";
  const PixelFrame& f = file.camera.frame;
  const std::vector<double>& p = file.camera.params;
  const auto n = [](double v) { return internal::ShortestNumber(v); };
  std::ostringstream out;
  out << "<x:xmpmeta xmlns:x=\"adobe:ns:meta/\">\n <rdf:RDF "
         "xmlns:rdf=\"http://www.w3.org/1999/02/22-rdf-syntax-ns#\">\n"
      << "  <rdf:Description xmlns:Camera=\"" << kPix4dCameraUri << "/\"\n"
      << "    xmlns:tiff=\"http://ns.adobe.com/tiff/1.0/\" "
         "xmlns:exif=\"http://ns.adobe.com/exif/1.0/\"\n"
      << "    tiff:ImageWidth=\"" << f.width_px << "\" tiff:ImageLength=\"" << f.height_px << "\"\n"
      << "    exif:FocalPlaneXResolution=\"" << n(1.0 / f.pixel_size_mm)
      << "\" exif:FocalPlaneYResolution=\"" << n(1.0 / f.pixel_size_mm)
      << "\" exif:FocalPlaneResolutionUnit=\"4\"\n"
      << "    Camera:ModelType=\"perspective\"\n"
      << "    Camera:PerspectiveFocalLength=\"" << n(p[M::kF]) << "\"\n"
      << "    Camera:PrincipalPoint=\"" << n(p[M::kPx]) << "," << n(p[M::kPy]) << "\"\n"
      << "    Camera:PerspectiveDistortion=\"" << n(p[M::kR1]) << "," << n(p[M::kR2]) << ","
      << n(p[M::kR3]) << "," << n(p[M::kT1]) << "," << n(p[M::kT2])
      << "\"/>\n </rdf:RDF>\n</x:xmpmeta>\n";
  WriteFileAtomically(path, out.str());
}

}  // namespace aerocal::calib
