#include "triangulation/adjustment/mounted_json.h"

namespace aerocal::triangulation {
namespace {

nlohmann::json Scaled(calib::BlockMode mode,
                      const Eigen::VectorXd& value,
                      const std::optional<Eigen::VectorXd>& sigma,
                      double scale) {
  std::optional<Eigen::VectorXd> sigma_scaled;  // a held block: no sigma
  if (sigma && mode != calib::BlockMode::kFixed) sigma_scaled = Eigen::VectorXd(*sigma * scale);
  return calib::MountedBlockToJson(mode, value * scale, sigma_scaled);
}

}  // namespace

nlohmann::json MountedToJson(calib::BlockMode mode,
                             const Eigen::Vector3d& value,
                             const std::optional<Eigen::Vector3d>& sigma,
                             double scale) {
  return Scaled(mode, value, sigma ? std::optional<Eigen::VectorXd>(*sigma) : std::nullopt, scale);
}

nlohmann::json MountedToJson(calib::BlockMode mode,
                             double value,
                             const std::optional<double>& sigma,
                             double scale) {
  return Scaled(
      mode,
      Eigen::VectorXd::Constant(1, value),
      sigma ? std::optional<Eigen::VectorXd>(Eigen::VectorXd::Constant(1, *sigma)) : std::nullopt,
      scale);
}

}  // namespace aerocal::triangulation
