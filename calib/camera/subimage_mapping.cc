#include "calib/camera/subimage_mapping.h"

#include "calib/core/numeric_jacobian.h"

#include <Eigen/Geometry>
#include <Eigen/LU>

#include <algorithm>
#include <cmath>

namespace aerocal::calib {

std::string_view MappingModelName(MappingModel model) {
  return VisitMappingModel(model, [](auto m) { return decltype(m)::kName; });
}

std::optional<MappingModel> ParseMappingModel(std::string_view name) {
  for (MappingModel model : kAllMappingModels)
    if (MappingModelName(model) == name) return model;
  return std::nullopt;
}

int MappingParamCount(MappingModel model) {
  return VisitMappingModel(model, [](auto m) { return decltype(m)::kNumParams; });
}

std::vector<double> IdentityMappingParams(MappingModel model) {
  return ParamsFromHomography(model, Eigen::Matrix3d::Identity());
}

MappingConditioning MappingConditioning::ForSubimage(MappingModel model,
                                                     int width_px,
                                                     int height_px) {
  MappingConditioning c;
  c.cu = 0.5 * (width_px - 1);
  c.cv = 0.5 * (height_px - 1);
  c.scale = model == MappingModel::kTranslation ? 1.0 : 0.5 * std::max(width_px, height_px);
  if (c.scale <= 0) c.scale = 1.0;
  return c;
}

Eigen::Matrix3d HomographyFromParams(MappingModel model, const double* p) {
  Eigen::Matrix3d h = Eigen::Matrix3d::Identity();
  switch (model) {  // parameter layouts of FORMATS.md; dispatch of evaluation is VisitMappingModel
    case MappingModel::kTranslation:
      h(0, 2) = p[0];
      h(1, 2) = p[1];
      break;
    case MappingModel::kConformal:
      h << p[0], -p[1], p[2], p[1], p[0], p[3], 0, 0, 1;
      break;
    case MappingModel::kAffine:
      h << p[0], p[1], p[2], p[3], p[4], p[5], 0, 0, 1;
      break;
    case MappingModel::kProjective:
      h << p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7], 1;
      break;
  }
  return h;
}

std::vector<double> ParamsFromHomography(MappingModel model, const Eigen::Matrix3d& h_in) {
  const Eigen::Matrix3d h = h_in / h_in(2, 2);
  switch (model) {
    case MappingModel::kTranslation:
      return {h(0, 2), h(1, 2)};
    case MappingModel::kConformal:
      return {h(0, 0), h(1, 0), h(0, 2), h(1, 2)};
    case MappingModel::kAffine:
      return {h(0, 0), h(0, 1), h(0, 2), h(1, 0), h(1, 1), h(1, 2)};
    case MappingModel::kProjective:
      break;
  }
  return {h(0, 0), h(0, 1), h(0, 2), h(1, 0), h(1, 1), h(1, 2), h(2, 0), h(2, 1)};
}

namespace {
Eigen::Matrix3d ConditioningMatrix(const MappingConditioning& c) {
  Eigen::Matrix3d m;
  m << c.scale, 0, c.cu, 0, c.scale, c.cv, 0, 0, 1;  // [u v 1] = m [u' v' 1]
  return m;
}
}  // namespace

std::vector<double> ConditionedFromPlain(MappingModel model,
                                         const MappingConditioning& cond,
                                         const std::vector<double>& plain) {
  return ParamsFromHomography(model,
                              HomographyFromParams(model, plain.data()) * ConditioningMatrix(cond));
}

std::vector<double> PlainFromConditioned(MappingModel model,
                                         const MappingConditioning& cond,
                                         const std::vector<double>& conditioned) {
  return ParamsFromHomography(
      model, HomographyFromParams(model, conditioned.data()) * ConditioningMatrix(cond).inverse());
}

Eigen::MatrixXd PlainFromConditionedJacobian(MappingModel model,
                                             const MappingConditioning& cond,
                                             const std::vector<double>& conditioned) {
  return NumericJacobian(
      [&](const std::vector<double>& x) {
        const std::vector<double> plain = PlainFromConditioned(model, cond, x);
        return Eigen::Map<const Eigen::VectorXd>(plain.data(), plain.size()).eval();
      },
      conditioned);
}

Eigen::Vector2d SubimageMapping::VirtualFromSub(const Eigen::Vector2d& uv) const {
  Eigen::Vector2d out;
  VisitMappingModel(model,
                    [&](auto m) { decltype(m)::Apply(params.data(), uv.data(), out.data()); });
  return out;
}

Eigen::Vector2d SubimageMapping::SubFromVirtual(const Eigen::Vector2d& virtual_uv) const {
  const Eigen::Vector3d uvw =
      HomographyFromParams(model, params.data()).inverse() * virtual_uv.homogeneous();
  return uvw.hnormalized();
}

bool SubimageMapping::Contains(const Eigen::Vector2d& uv, double margin_px) const {
  return uv.x() >= -margin_px && uv.y() >= -margin_px && uv.x() <= width_px - 1 + margin_px &&
         uv.y() <= height_px - 1 + margin_px;
}

}  // namespace aerocal::calib
