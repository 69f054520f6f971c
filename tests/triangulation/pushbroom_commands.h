// The `aerocal pushbroom` command lines of a simulated image-mode flight folder (`simulate
// --pushbroom --images`), shared by the image-mode tests.
#pragma once

#include <string>

namespace aerocal::triangulation {

/// `pushbroom control` on the flight in `dir` (line image, POS, reference camera and images),
/// without the reference orientation and the output folder.
inline std::string PushbroomControlInputs(const std::string& dir) {
  return "pushbroom control --camera " + dir + "/camera_nominal.yaml --pos " + dir +
         "/pos.csv --line-image " + dir + "/line_image.png --reference-camera " + dir +
         "/reference/camera.yaml --reference-images " + dir + "/reference";
}

/// `pushbroom control` on the flight in `dir`, oriented by its exposures.csv, into `out`.
inline std::string PushbroomControlCommand(const std::string& dir, const std::string& out) {
  return PushbroomControlInputs(dir) + " --reference-exposures " + dir +
         "/reference/exposures.csv --out " + out;
}

/// `pushbroom calibrate` of the flight's nominal camera and POS from control `obs` and `points`.
inline std::string PushbroomCalibrateCommand(const std::string& dir,
                                             const std::string& obs,
                                             const std::string& points,
                                             const std::string& out) {
  return "pushbroom calibrate --camera " + dir + "/camera_nominal.yaml --pos " + dir +
         "/pos.csv --observations " + obs + " --points " + points + " --out " + out;
}

}  // namespace aerocal::triangulation
