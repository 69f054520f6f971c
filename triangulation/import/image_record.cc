#include "triangulation/import/image_record.h"

#include "calib/core/csv.h"

#include <cmath>
#include <cstdio>

namespace aerocal::triangulation::internal {
namespace {

using calib::TiffIfd;
using calib::xmp_ns::kDji;

class Reader {
 public:
  Reader(const calib::ImageMetadata& meta, const std::string& path, ImageRecord* record)
      : m_(meta), path_(path), r_(record) {}

  // A DJI XMP number; nullopt when absent. "+12.5" is DJI's usual form.
  std::optional<double> Dji(const std::string& name, const std::string& quantity) {
    if (!m_.xmp) return std::nullopt;
    const calib::XmpProperty* p = m_.xmp->Find(kDji, name);
    if (!p) return std::nullopt;
    const std::optional<double> v = p->structured ? std::nullopt : ParseDouble(p->value);
    if (!v) ThrowInputError(p->where, p->qualified + " is not a number (got '" + p->value + "')");
    Use(quantity, "XMP " + p->qualified, p->value);
    return v;
  }

  const calib::TiffEntry* Exif(TiffIfd ifd, uint16_t tag) const {
    const auto it = m_.exif.find({ifd, tag});
    return it == m_.exif.end() ? nullptr : &it->second;
  }

  // One finite number of an EXIF tag; nullopt when absent.
  std::optional<double> ExifNumber(TiffIfd ifd, uint16_t tag, const std::string& quantity) {
    const calib::TiffEntry* e = Exif(ifd, tag);
    if (!e) return std::nullopt;
    if (e->numbers.empty() || !std::isfinite(e->numbers[0]))
      Fail(calib::TiffTagName(ifd, tag) + " is not a finite number");
    Use(quantity, calib::TiffTagName(ifd, tag), FormatNumber(e->numbers[0], 10));
    return e->numbers[0];
  }

  std::string ExifText(TiffIfd ifd, uint16_t tag, const std::string& quantity) {
    const calib::TiffEntry* e = Exif(ifd, tag);
    if (!e || e->type != 2) return "";
    std::string text;
    for (char c : e->text) text += (static_cast<unsigned char>(c) < 32 || c == ',') ? ' ' : c;
    const size_t b = text.find_first_not_of(' '), end = text.find_last_not_of(' ');
    text = b == std::string::npos ? "" : text.substr(b, end - b + 1);
    if (!text.empty()) Use(quantity, calib::TiffTagName(ifd, tag), text);
    return text;
  }

  // EXIF GPS degrees, minutes, seconds with its ref: -1 for `negative`, +1 for `positive`.
  std::optional<double> ExifDegrees(uint16_t tag,
                                    uint16_t ref_tag,
                                    char positive,
                                    char negative,
                                    double bound,
                                    const std::string& quantity) {
    const calib::TiffEntry* e = Exif(TiffIfd::kGps, tag);
    if (!e) return std::nullopt;
    const std::string name = calib::TiffTagName(TiffIfd::kGps, tag);
    if (e->numbers.size() != 3) Fail(name + " must hold 3 rationals (degrees, minutes, seconds)");
    for (double v : e->numbers)
      if (!(v >= 0 && v < 1e4))
        Fail(name + " holds " + FormatNumber(v) + " (degrees, minutes, seconds >= 0)");
    const double deg = e->numbers[0] + e->numbers[1] / 60.0 + e->numbers[2] / 3600.0;
    const calib::TiffEntry* ref = Exif(TiffIfd::kGps, ref_tag);
    const std::string ref_name = calib::TiffTagName(TiffIfd::kGps, ref_tag);
    if (!ref || ref->text.empty()) Fail(name + " without " + ref_name);
    const char c = ref->text[0];
    if (c != positive && c != negative)
      Fail(ref_name + " must be " + positive + " or " + negative + " (got '" + ref->text + "')");
    const double value = c == negative ? -deg : deg;
    if (!(std::abs(value) <= bound))
      Fail(name + " " + FormatNumber(value) + " is beyond " + FormatNumber(bound) + " deg");
    Use(quantity,
        name + " + " + ref_name,
        FormatNumber(e->numbers[0]) + " " + FormatNumber(e->numbers[1]) + " " +
            FormatNumber(e->numbers[2]) + " " + c);
    return value;
  }

  [[noreturn]] void Fail(const std::string& what) const { throw InputError(path_ + ": " + what); }

  void Use(const std::string& quantity, const std::string& tag, const std::string& value) {
    r_->tags.push_back({r_->image, quantity, tag, value});
  }

  const calib::ImageMetadata& m_;
  const std::string& path_;
  ImageRecord* r_;
};

void ReadPosition(Reader& rd, ImageRecord* r) {
  std::optional<double> lat = rd.Dji("GpsLatitude", "latitude_deg");
  std::optional<double> lon = rd.Dji("GpsLongitude", "longitude_deg");
  if (const std::optional<double> typo = rd.Dji("GpsLongtitude", "longitude_deg")) {
    if (lon && *lon != *typo) rd.Fail("drone-dji GpsLongitude and GpsLongtitude differ");
    lon = typo;
  }
  if (!lat || !lon) {
    lat = rd.ExifDegrees(0x0002, 0x0001, 'N', 'S', 90, "latitude_deg");
    lon = rd.ExifDegrees(0x0004, 0x0003, 'E', 'W', 180, "longitude_deg");
  }
  if (lat && !(std::abs(*lat) <= 90))
    rd.Fail("latitude " + FormatNumber(*lat) + " is beyond 90 deg");
  if (lon && !(std::abs(*lon) <= 180))
    rd.Fail("longitude " + FormatNumber(*lon) + " is beyond 180 deg");
  std::optional<double> alt = rd.Dji("AbsoluteAltitude", "altitude_m");
  if (!alt) {
    alt = rd.ExifNumber(TiffIfd::kGps, 0x0006, "altitude_m");
    if (alt) {
      const calib::TiffEntry* ref = rd.Exif(TiffIfd::kGps, 0x0005);
      if (ref && !ref->numbers.empty() && ref->numbers[0] != 0) {
        if (ref->numbers[0] != 1)
          rd.Fail("EXIF GPSAltitudeRef must be 0 (above) or 1 (below sea level)");
        *alt = -*alt;
        rd.Use("altitude_m", "EXIF GPSAltitudeRef", "1 (below sea level)");
      }
    }
  }
  if (alt && !(std::abs(*alt) <= 1e5))
    rd.Fail("altitude " + FormatNumber(*alt) + " m is beyond 1e5 m");
  rd.Dji("RelativeAltitude", "relative_altitude_m (listed; not used)");
  if (!lat || !lon) {
    r->no_position =
        "no GPS position (neither XMP drone-dji:GpsLatitude/GpsLongitude nor EXIF "
        "GPSLatitude/GPSLongitude)";
  } else if (!alt) {
    r->no_position =
        "no GPS altitude (neither XMP drone-dji:AbsoluteAltitude nor EXIF GPSAltitude)";
  } else if (*lat == 0 && *lon == 0) {
    r->no_position = "GPS position 0, 0 (the receiver had no fix)";
  } else {
    r->lon_lat_alt = Eigen::Vector3d(*lon, *lat, *alt);
  }
}

void ReadAttitudeAndSigmas(Reader& rd, ImageRecord* r) {
  const auto yaw = rd.Dji("GimbalYawDegree", "gimbal_yaw_deg");
  const auto pitch = rd.Dji("GimbalPitchDegree", "gimbal_pitch_deg");
  const auto roll = rd.Dji("GimbalRollDegree", "gimbal_roll_deg");
  if (yaw && pitch && roll) {
    for (double a : {*yaw, *pitch, *roll})
      if (!(std::abs(a) <= 360))
        rd.Fail("gimbal angle " + FormatNumber(a) + " deg is beyond 360 deg");
    r->gimbal_ypr_deg = Eigen::Vector3d(*yaw, *pitch, *roll);
  } else if (yaw || pitch || roll) {
    rd.Fail("drone-dji gimbal angles incomplete (yaw, pitch and roll are all needed)");
  }
  rd.Dji("FlightYawDegree", "aircraft_yaw_deg (listed; not used)");
  rd.Dji("FlightPitchDegree", "aircraft_pitch_deg (listed; not used)");
  rd.Dji("FlightRollDegree", "aircraft_roll_deg (listed; not used)");
  rd.Dji("RtkFlag", "rtk_flag");
  const auto lon = rd.Dji("RtkStdLon", "sigma_east_m");
  const auto lat = rd.Dji("RtkStdLat", "sigma_north_m");
  const auto hgt = rd.Dji("RtkStdHgt", "sigma_up_m");
  if (lon && lat && hgt) {
    for (double s : {*lon, *lat, *hgt})
      if (!(s > 0 && s <= 1e6))
        rd.Fail("RTK standard deviation " + FormatNumber(s) + " m must be in (0, 1e6]");
    r->sigma_enu_m = Eigen::Vector3d(*lon, *lat, *hgt);
  } else if (lon || lat || hgt) {
    rd.Fail("drone-dji RtkStdLon / RtkStdLat / RtkStdHgt incomplete");
  }
}

void ReadCameraEvidence(Reader& rd, const calib::ImageMetadata& m, ImageRecord* r) {
  const std::string make = rd.ExifText(TiffIfd::kImage, 0x010F, "make");
  const std::string model = rd.ExifText(TiffIfd::kImage, 0x0110, "model");
  r->make_model = (make + " " + model).find_first_not_of(' ') == std::string::npos
                      ? "unknown camera"
                      : make + " " + model;
  std::string serial = rd.ExifText(TiffIfd::kExif, 0xA431, "serial");
  if (serial.empty() && m.xmp)
    if (const calib::XmpProperty* p = m.xmp->Find(kDji, "CameraSerialNumber");
        p && !p->value.empty()) {
      serial = p->value;
      rd.Use("serial", "XMP " + p->qualified, serial);
    }
  r->camera_key = serial.empty() ? r->make_model : serial;
  r->width_px = m.width_px;
  r->height_px = m.height_px;
  rd.Use("format_px",
         m.format == "jpeg" ? "JPEG SOF" : "TIFF ImageWidth/ImageLength",
         std::to_string(m.width_px) + " x " + std::to_string(m.height_px));
  r->focal_mm = rd.ExifNumber(TiffIfd::kExif, 0x920A, "focal_length_mm");
  r->focal_35mm = rd.ExifNumber(TiffIfd::kExif, 0xA405, "focal_length_35mm_mm");
  if (const auto res = rd.ExifNumber(TiffIfd::kExif, 0xA20E, "focal_plane_x_resolution")) {
    const auto unit = rd.ExifNumber(TiffIfd::kExif, 0xA210, "focal_plane_resolution_unit");
    const double mm = !unit || *unit == 2 ? 25.4 : *unit == 3 ? 10.0 : *unit == 4 ? 1.0 : 0.0;
    if (mm > 0 && *res > 0) r->focal_plane_pixel_mm = mm / *res;
  }
  if (!m.xmp) return;
  const calib::XmpProperty* d = m.xmp->Find(kDji, "DewarpDataK6");
  if (!d) d = m.xmp->Find(kDji, "DewarpData");
  if (d) {
    r->dewarp_data = d->value;
    r->dewarp_where = d->where;
    rd.Use("camera", "XMP " + d->qualified, d->value);
  }
}

void ReadCaptureTime(Reader& rd) {
  const std::string time = rd.ExifText(TiffIfd::kExif, 0x9003, "capture_time");
  if (time.empty()) return;
  rd.ExifText(TiffIfd::kExif, 0x9291, "capture_time_subseconds");
  rd.ExifText(TiffIfd::kExif, 0x9011, "capture_time_utc_offset");
}

}  // namespace

ImageRecord ReadImageRecord(const calib::ImageMetadata& meta,
                            const std::string& path,
                            const std::string& image) {
  ImageRecord r;
  r.image = image;
  Reader rd(meta, path, &r);
  ReadPosition(rd, &r);
  ReadAttitudeAndSigmas(rd, &r);
  ReadCameraEvidence(rd, meta, &r);
  ReadCaptureTime(rd);
  return r;
}

}  // namespace aerocal::triangulation::internal
