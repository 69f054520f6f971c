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

}  // namespace

CameraFile ReadPix4dXmp(const std::string& path, const CameraReadOptions& options) {
  using M = Pix4dPerspectiveModel;
  const std::string bytes = ReadTextFile(path);
  int width = 0, height = 0;
  const bool image = IsJpegOrTiff(bytes);
  const std::optional<XmpPacket> xmp = XmpOfCameraFile(bytes, path, &width, &height);
  if (!xmp) ThrowInputError({path, 1}, "neither an image nor an XMP packet (x:xmpmeta / rdf:RDF)");
  // Properties by namespace URI (kPix4dCameraUri, with or without its trailing '/'): the prefix is
  // whatever the file binds ("Camera", "P4", ...); messages quote it as written.
  const auto find = [&](const char* uri, const std::string& name) -> std::optional<XmpText> {
    const XmpProperty* p = xmp->Find(uri, name);
    if (!p) return std::nullopt;
    if (p->structured) ThrowInputError(p->where, p->qualified + " must be a simple value");
    return XmpText{p->value, p->where, p->qualified};
  };
  const auto camera = [&](const std::string& name) { return find(kPix4dCameraUri, name); };
  const auto numbers = [&](const XmpText& t, size_t count) {
    const std::vector<std::string> fields = SplitCommaList(t.value, {true, true});
    if (fields.size() != count)
      ThrowInputError(t.where,
                      t.name + " must hold " + std::to_string(count) +
                          " comma-separated values (got '" + t.value + "')");
    std::vector<double> v;
    for (const std::string& f : fields) v.push_back(internal::ParseNumber(f, t.where, t.name, 1e4));
    return v;
  };
  const auto focal = camera("PerspectiveFocalLength");
  const auto pp = camera("PrincipalPoint");
  if (!focal || !pp) {
    const auto type = camera("ModelType");
    ThrowInputError(type ? type->where : SourceRef{path, image ? 0 : 1},
                    std::string("no PerspectiveFocalLength / PrincipalPoint of namespace ") +
                        kPix4dCameraUri + " (Pix4D camera XMP)");
  }
  if (const auto type = camera("ModelType"); type && type->value != "perspective")
    ThrowInputError(type->where,
                    type->name + " '" + type->value +
                        "': only the perspective model is read (Pix4D's fisheye "
                        "polynomial is not a registry model)");
  CameraFile file;
  file.name = "pix4d";
  file.camera.model = M::kId;
  file.camera.params.assign(M::kNumParams, 0.0);
  file.camera.params[M::kF] = numbers(*focal, 1)[0];
  if (!(file.camera.params[M::kF] > 0))
    ThrowInputError(focal->where, "the focal length must be > 0 mm");
  const std::vector<double> principal = numbers(*pp, 2);
  file.camera.params[M::kPx] = principal[0];
  file.camera.params[M::kPy] = principal[1];
  if (const auto d = camera("PerspectiveDistortion")) {
    const std::vector<double> v = numbers(*d, 5);  // R1, R2, R3, T1, T2
    for (int i = 0; i < 5; ++i) file.camera.params[M::kR1 + i] = v[i];
  }
  const SourceRef where{path, focal->where.line};
  if (!image) {
    const auto w = find(xmp_ns::kTiff, "ImageWidth"), h = find(xmp_ns::kTiff, "ImageLength");
    if (w && h) {
      width = static_cast<int>(internal::ParseNumber(w->value, w->where, w->name, 1e6));
      height = static_cast<int>(internal::ParseNumber(h->value, h->where, h->name, 1e6));
    }
  }
  double pixel_mm = 0.0;
  if (const auto res = find(xmp_ns::kExif, "FocalPlaneXResolution")) {
    const auto unit = find(xmp_ns::kExif, "FocalPlaneResolutionUnit");
    const int u =
        unit ? static_cast<int>(internal::ParseNumber(unit->value, unit->where, unit->name, 10))
             : 2;
    const double mm_per_unit = u == 2 ? 25.4 : u == 3 ? 10.0 : u == 4 ? 1.0 : 0.0;
    if (mm_per_unit == 0)
      ThrowInputError(unit->where,
                      "exif:FocalPlaneResolutionUnit must be 2 (inch), 3 (cm) or 4 (mm)");
    const double per_unit = ParseRational(*res, res->name);
    if (!(per_unit > 0)) ThrowInputError(res->where, "exif:FocalPlaneXResolution must be > 0");
    pixel_mm = mm_per_unit / per_unit;
  }
  internal::ResolveFormat(&file, options, where, width, height, pixel_mm);
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
