// Every registered camera model (camera_model.h), one typed test instantiated for each: zero
// distortion is the pinhole (the equidistant projection for the fisheye), MeasuredFromIdeal
// inverts IdealFromMeasured to 1e-6 px over the format, autodiff derivatives (including those of
// the Newton inversions) agree with central differences, and the parameter table is well formed.
#include "calib/camera/camera_model.h"

#include "calib/camera/convert_camera.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <string>

namespace aerocal::calib {
namespace {

const PixelFrame kFrame{0.004, 4000, 3000};  // 16 x 12 mm, f ~ 3000 px (12 mm)

// A typical camera as OpenCV parameters (x right, y down, pixels).
OpenCvParams TypicalOpenCv(bool with_distortion) {
  OpenCvParams cv{};
  cv[OpenCvModel::kFx] = 3005.0;
  cv[OpenCvModel::kFy] = 3000.0;
  cv[OpenCvModel::kCx] = 2011.5;
  cv[OpenCvModel::kCy] = 1490.25;
  if (with_distortion) {
    cv[OpenCvModel::kK1] = -0.11;
    cv[OpenCvModel::kK2] = 0.06;
    cv[OpenCvModel::kP1] = 2e-4;
    cv[OpenCvModel::kP2] = -3e-4;
    cv[OpenCvModel::kK3] = -0.01;
    cv[OpenCvModel::kK4] = 0.02;
    cv[OpenCvModel::kK5] = 0.01;
  }
  return cv;
}

// Parameters of `Model` for the typical camera; terms the OpenCV mapping does not reach (our
// correction form, the fisheye, Metashape's b2/k4/p3/p4) set by name.
template <typename Model>
std::vector<double> Sample(bool with_distortion) {
  std::vector<double> p(Model::kNumParams, 0.0);
  const OpenCvParams cv = TypicalOpenCv(with_distortion);
  Model::FromOpenCv(cv, kFrame, p.data());
  if (!with_distortion) return p;
  const auto set = [&](std::string_view name, double value) {
    const int i = IndexOfParam(Model::kParams, name);
    ASSERT_GE(i, 0) << name;
    p[i] = value;
  };
  if constexpr (Model::kId == CameraModelId::kBrownFraser10) {
    set("K1", 4e-4);  // ~ 3 px at the corner (r = 10 mm)
    set("K2", -2e-6);
    set("K3", 1e-9);
    set("P1", 3e-5);
    set("P2", -2e-5);
    set("B2", -8e-5);
  } else if constexpr (Model::kId == CameraModelId::kOpenCvFisheye) {
    set("k1", -0.02);
    set("k2", 0.004);
    set("k3", -0.001);
    set("k4", 2e-4);
  } else if constexpr (Model::kId == CameraModelId::kMetashapeFrame) {
    set("b2", 0.7);
    set("k4", 0.003);
    set("p3", 0.05);
    set("p4", -0.02);
  }
  return p;
}

std::vector<Eigen::Vector2d> Grid(int n) { return FormatGrid(kFrame, n); }

template <typename List>
struct ToGtest;
template <typename... Models>
struct ToGtest<CameraModelList<Models...>> {
  using Types = ::testing::Types<Models...>;
};

template <typename Model>
class CameraModelTest : public ::testing::Test {};
struct ModelNames {
  template <typename Model>
  static std::string GetName(int) {
    return std::string(Model::kName);
  }
};
TYPED_TEST_SUITE(CameraModelTest, ToGtest<RegisteredCameraModels>::Types, ModelNames);

TYPED_TEST(CameraModelTest, ZeroDistortionIsThePinhole) {
  using Model = TypeParam;
  const std::vector<double> p = Sample<Model>(false);
  const double c = Model::PrincipalDistanceMm(p.data(), kFrame);
  const double zero[2] = {0.0, 0.0};
  double pp[2];  // the principal point, photo mm
  ASSERT_TRUE(Model::MeasuredFromIdeal(p.data(), kFrame, zero, pp));
  const OpenCvParams cv = TypicalOpenCv(false);
  const double affinity = cv[OpenCvModel::kFy] / cv[OpenCvModel::kFx];  // fx != fy: x scaled
  for (const Eigen::Vector2d& pixel : Grid(9)) {
    const Eigen::Vector2d xy = kFrame.PhotoFromPixel(pixel);
    Eigen::Vector2d ideal;
    ASSERT_TRUE(Model::IdealFromMeasured(p.data(), kFrame, xy.data(), ideal.data()));
    Eigen::Vector2d expected(xy.x() - pp[0], xy.y() - pp[1]);
    if constexpr (Model::kId == CameraModelId::kOpenCvFisheye) {
      // Equidistant: |measured - pp| / f = atan(|ideal| / c) (f per axis).
      const Eigen::Vector2d n(expected.x() * affinity / c, expected.y() / c);
      const double theta = n.norm();
      expected = theta > 0 ? Eigen::Vector2d(n * (c * std::tan(theta) / theta)) : n;
    } else if constexpr (Model::kId != CameraModelId::kColmapSimplePinhole &&
                         Model::kId != CameraModelId::kColmapSimpleRadial &&
                         Model::kId != CameraModelId::kColmapRadial &&
                         Model::kId != CameraModelId::kPix4dPerspective) {
      expected.x() *= affinity;  // models with two focal lengths (or B1) keep fx != fy
    }
    EXPECT_LT((ideal - expected).norm(), 1e-9) << Model::kName << " at " << pixel.transpose();
  }
}

TYPED_TEST(CameraModelTest, RoundTripOverTheFormatBelow1e6Px) {
  using Model = TypeParam;
  const std::vector<double> p = Sample<Model>(true);
  double worst = 0.0;
  for (const Eigen::Vector2d& pixel : Grid(41)) {
    const Eigen::Vector2d xy = kFrame.PhotoFromPixel(pixel);
    Eigen::Vector2d ideal, back;
    ASSERT_TRUE(Model::IdealFromMeasured(p.data(), kFrame, xy.data(), ideal.data()));
    ASSERT_TRUE(Model::MeasuredFromIdeal(p.data(), kFrame, ideal.data(), back.data()));
    worst = std::max(worst, (back - xy).norm() / kFrame.pixel_size_mm);
  }
  EXPECT_LT(worst, 1e-6) << Model::kName;
  // The distortion is real: the corner's ideal point is pixels away from the pinhole's.
  const Eigen::Vector2d corner = kFrame.PhotoFromPixel({0.0, 0.0});
  Eigen::Vector2d distorted, pinhole;
  const std::vector<double> p0 = Sample<Model>(false);
  ASSERT_TRUE(Model::IdealFromMeasured(p.data(), kFrame, corner.data(), distorted.data()));
  ASSERT_TRUE(Model::IdealFromMeasured(p0.data(), kFrame, corner.data(), pinhole.data()));
  if constexpr (Model::kId != CameraModelId::kColmapSimplePinhole &&
                Model::kId != CameraModelId::kColmapPinhole) {
    EXPECT_GT((distorted - pinhole).norm() / kFrame.pixel_size_mm, 1.0) << Model::kName;
  }
}

// d(out)/d(params) of a uniform function by Jets vs central differences.
template <typename Model, bool kForward>
void CheckDerivatives(const std::vector<double>& p, const Eigen::Vector2d& in) {
  using J = ceres::Jet<double, Model::kNumParams>;
  J pj[Model::kNumParams];
  for (int i = 0; i < Model::kNumParams; ++i) pj[i] = J(p[i], i);
  const J inj[2] = {J(in.x()), J(in.y())};
  J out[2];
  const auto eval = [&](const auto* params, const auto* x, auto* y) {
    if constexpr (kForward)
      return Model::MeasuredFromIdeal(params, kFrame, x, y);
    else
      return Model::IdealFromMeasured(params, kFrame, x, y);
  };
  ASSERT_TRUE(eval(pj, inj, out));
  for (int i = 0; i < Model::kNumParams; ++i) {
    const double step = 1e-6 * (p[i] != 0.0 ? std::abs(p[i]) : 1e-3);
    std::vector<double> plus = p, minus = p;
    plus[i] += step;
    minus[i] -= step;
    double a[2], b[2];
    ASSERT_TRUE(eval(plus.data(), in.data(), a));
    ASSERT_TRUE(eval(minus.data(), in.data(), b));
    for (int k = 0; k < 2; ++k) {
      const double numeric = (a[k] - b[k]) / (2 * step), autodiff = out[k].v[i];
      // Scaled to mm of image motion per relative parameter change.
      const double scale = std::max(1e-3, std::abs(p[i]));
      EXPECT_NEAR(autodiff * scale, numeric * scale, 1e-6 + 1e-5 * std::abs(numeric * scale))
          << Model::kName << (kForward ? " MeasuredFromIdeal d/d" : " IdealFromMeasured d/d")
          << Model::kParams[i].name << " component " << k;
    }
  }
}

TYPED_TEST(CameraModelTest, AutodiffMatchesNumericDerivatives) {
  using Model = TypeParam;
  const std::vector<double> p = Sample<Model>(true);
  for (const Eigen::Vector2d& pixel :
       {Eigen::Vector2d(100.0, 2900.0), Eigen::Vector2d(3100, 700)}) {
    const Eigen::Vector2d xy = kFrame.PhotoFromPixel(pixel);
    CheckDerivatives<Model, false>(p, xy);
    Eigen::Vector2d ideal;
    ASSERT_TRUE(Model::IdealFromMeasured(p.data(), kFrame, xy.data(), ideal.data()));
    CheckDerivatives<Model, true>(p, ideal);
  }
}

TYPED_TEST(CameraModelTest, ParameterTableAndRegistry) {
  using Model = TypeParam;
  static_assert(Model::kParams.size() == static_cast<size_t>(Model::kNumParams));
  const std::set<std::string_view> units = {"mm", "px", "1", "mm^-1", "mm^-2", "mm^-4", "mm^-6"};
  std::set<std::string_view> names;
  for (const ParamInfo& info : Model::kParams) {
    EXPECT_TRUE(names.insert(info.name).second) << "duplicate " << info.name;
    EXPECT_TRUE(units.count(info.unit)) << info.name << " unit " << info.unit;
  }
  EXPECT_EQ(CameraModelFromName(Model::kName), Model::kId);
  EXPECT_EQ(CameraModelName(Model::kId), Model::kName);
  EXPECT_EQ(CameraModelParamCount(Model::kId), Model::kNumParams);
  EXPECT_EQ(CameraModelParams(Model::kId)[0].name, Model::kParams[0].name);
  int registered = 0;
  ForEachCameraModel([&](auto other) {
    if (decltype(other)::kId == Model::kId) ++registered;
    if (decltype(other)::kName == Model::kName) ++registered;
  });
  EXPECT_EQ(registered, 2) << "id and name are unique in the registry";
}

TEST(CameraModelRegistry, FrozenIdsAndUnknownNames) {
  EXPECT_EQ(static_cast<int>(CameraModelId::kBrownFraser10), 1);
  EXPECT_EQ(static_cast<int>(CameraModelId::kOpenCv), 2);
  EXPECT_EQ(static_cast<int>(CameraModelId::kPix4dPerspective), 11);
  EXPECT_FALSE(CameraModelFromName("FISHEYE_X").has_value());
  EXPECT_NE(CameraModelNames().find("metashape_frame"), std::string::npos);
  EXPECT_THROW(CameraModelName(static_cast<CameraModelId>(99)), LogicError);
}

}  // namespace
}  // namespace aerocal::calib
