// A camera file expressed in a format's model (camera_formats.h ConvertCameraFile): ConvertCamera
// with the parameters the format cannot hold at 0, and the covariance carried through the
// conversion's Jacobian.
#include "calib/camera/formats/camera_formats.h"
#include "calib/core/numeric_jacobian.h"

namespace aerocal::calib {

FileConversion ConvertCameraFile(const CameraFile& from, const FormatTarget& target,
                                 const ConvertOptions& options) {
  if (target.needs_pixel_size && !from.pixel_size_known)
    throw ConfigError("--pixel-mm: the target holds millimetres and the source gives no pixel "
                      "size");
  FileConversion out;
  ConvertOptions o = options;
  o.zero.insert(o.zero.end(), target.zero_params.begin(), target.zero_params.end());
  out.result = ConvertCamera(from.camera, target.model, o);
  out.file.name = from.name;
  out.file.camera = out.result.camera;
  out.file.pixel_size_known = from.pixel_size_known;
  if (from.covariance) {
    // Linear propagation: C_to = J C_from J^T, J = d(target params)/d(source params) by central
    // differences of the whole conversion (closed form or fit; the fit converges far below the
    // step, see convert_file_test). The residual check of the perturbed conversions is skipped.
    ConvertOptions quick = o;
    quick.check_grid = 2;
    const Eigen::MatrixXd jacobian = NumericJacobian(
        [&](const std::vector<double>& params) {
          ModelCamera perturbed = from.camera;
          perturbed.params = params;
          const ConversionResult r = ConvertCamera(perturbed, target.model, quick);
          return Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(r.camera.params.data(),
                                                                   r.camera.params.size()));
        },
        from.camera.params);
    out.file.covariance = jacobian * *from.covariance * jacobian.transpose();
    out.notes.push_back("covariance propagated through the conversion's Jacobian (J C J^T)");
  }
  return out;
}

}  // namespace aerocal::calib
