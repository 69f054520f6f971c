// Sub-image -> virtual-image pixel mappings of a multi-CCD camera (CONVENTIONS.md "Sub-image to
// virtual image"):
//   translation (2): U = u + Tx,                      V = v + Ty
//   conformal   (4): U = a u - b v + Tx,              V = b u + a v + Ty
//   affine      (6): U = a1 u + a2 v + a0,            V = b1 u + b2 v + b0
//   projective  (8): U = (a1 u + a2 v + a3) / (c1 u + c2 v + 1),  V = (b1 u + b2 v + b3) / (...)
// Files store these plain parameters. Adjustments estimate the same model in a CONDITIONED form:
// the input (u, v) is centred on the sub-image centre and divided by half the larger side
// (translation: centred only), so that every parameter is of pixel magnitude and the normal
// equations are well conditioned. Conversion plain <-> conditioned goes through the 3x3 homography
// H with [U V 1]^T ~ H [u v 1]^T, since all four models are special projectivities.
//
// These models live in calib/ (not stitch/) because the camera file carries them and the shared
// problem builder's joint residual (sub-image mapping in front of the camera) evaluates them.
#pragma once

#include <Eigen/Core>

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace aerocal::calib {

enum class MappingModel : int { kTranslation = 0, kConformal = 1, kAffine = 2, kProjective = 3 };

struct TranslationMapping {
  static constexpr MappingModel kModel = MappingModel::kTranslation;
  static constexpr std::string_view kName = "translation";
  static constexpr int kNumParams = 2;  // Tx, Ty [px]
  template <typename T>
  static void Apply(const T* p, const T* uv, T* out) {
    out[0] = uv[0] + p[0];
    out[1] = uv[1] + p[1];
  }
};

struct ConformalMapping {
  static constexpr MappingModel kModel = MappingModel::kConformal;
  static constexpr std::string_view kName = "conformal";
  static constexpr int kNumParams = 4;  // a, b [1], Tx, Ty [px]
  template <typename T>
  static void Apply(const T* p, const T* uv, T* out) {
    out[0] = p[0] * uv[0] - p[1] * uv[1] + p[2];
    out[1] = p[1] * uv[0] + p[0] * uv[1] + p[3];
  }
};

struct AffineMapping {
  static constexpr MappingModel kModel = MappingModel::kAffine;
  static constexpr std::string_view kName = "affine";
  static constexpr int kNumParams = 6;  // a1, a2 [1], a0 [px], b1, b2 [1], b0 [px]
  template <typename T>
  static void Apply(const T* p, const T* uv, T* out) {
    out[0] = p[0] * uv[0] + p[1] * uv[1] + p[2];
    out[1] = p[3] * uv[0] + p[4] * uv[1] + p[5];
  }
};

struct ProjectiveMapping {
  static constexpr MappingModel kModel = MappingModel::kProjective;
  static constexpr std::string_view kName = "projective";
  static constexpr int kNumParams = 8;  // a1, a2, a3, b1, b2, b3, c1, c2
  template <typename T>
  static void Apply(const T* p, const T* uv, T* out) {
    const T w = p[6] * uv[0] + p[7] * uv[1] + T(1);
    out[0] = (p[0] * uv[0] + p[1] * uv[1] + p[2]) / w;
    out[1] = (p[3] * uv[0] + p[4] * uv[1] + p[5]) / w;
  }
};

/// The one dispatch over mapping models: calls visitor(ModelStruct{}) for `model`.
template <typename Visitor>
decltype(auto) VisitMappingModel(MappingModel model, Visitor&& visitor) {
  switch (model) {
    case MappingModel::kTranslation:
      return visitor(TranslationMapping{});
    case MappingModel::kConformal:
      return visitor(ConformalMapping{});
    case MappingModel::kAffine:
      return visitor(AffineMapping{});
    case MappingModel::kProjective:
      break;
  }
  return visitor(ProjectiveMapping{});
}

inline constexpr MappingModel kAllMappingModels[] = {MappingModel::kTranslation,
                                                     MappingModel::kConformal,
                                                     MappingModel::kAffine,
                                                     MappingModel::kProjective};

std::string_view MappingModelName(MappingModel model);
std::optional<MappingModel> ParseMappingModel(std::string_view name);
int MappingParamCount(MappingModel model);
/// Identity parameters of a model (plain form).
std::vector<double> IdentityMappingParams(MappingModel model);

/// Centre and scale of the conditioning: u' = (u - cu) / scale, v' = (v - cv) / scale.
struct MappingConditioning {
  double cu = 0.0, cv = 0.0, scale = 1.0;
  static MappingConditioning ForSubimage(MappingModel model, int width_px, int height_px);
};

/// One sub-image of a multi-CCD camera and its mapping onto the virtual image.
struct SubimageMapping {
  std::string id;
  int width_px = 0, height_px = 0;
  MappingModel model = MappingModel::kAffine;
  std::vector<double> params;  // plain form, MappingParamCount(model) values

  /// Virtual-image pixel (U, V) of sub-image pixel (u, v).
  Eigen::Vector2d VirtualFromSub(const Eigen::Vector2d& uv) const;
  /// Sub-image pixel of a virtual-image pixel (exact inverse of the projectivity).
  Eigen::Vector2d SubFromVirtual(const Eigen::Vector2d& virtual_uv) const;
  /// True when (u, v) lies on the sub-image (pixel centres 0 .. W-1, 0 .. H-1, plus `margin_px`).
  bool Contains(const Eigen::Vector2d& uv, double margin_px = 0.0) const;
  MappingConditioning Conditioning() const {
    return MappingConditioning::ForSubimage(model, width_px, height_px);
  }
};

/// H with [U V 1] ~ H [u v 1] for plain parameters.
Eigen::Matrix3d HomographyFromParams(MappingModel model, const double* params);
/// Plain parameters of `model` from H (H normalised so H(2,2) = 1; entries the model lacks
/// ignored).
std::vector<double> ParamsFromHomography(MappingModel model, const Eigen::Matrix3d& h);

std::vector<double> ConditionedFromPlain(MappingModel model,
                                         const MappingConditioning& cond,
                                         const std::vector<double>& plain);
std::vector<double> PlainFromConditioned(MappingModel model,
                                         const MappingConditioning& cond,
                                         const std::vector<double>& conditioned);
/// d(plain)/d(conditioned) at `conditioned` (central differences; exact for the linear models).
Eigen::MatrixXd PlainFromConditionedJacobian(MappingModel model,
                                             const MappingConditioning& cond,
                                             const std::vector<double>& conditioned);

}  // namespace aerocal::calib
