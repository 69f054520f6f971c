#include "calib/camera/subimage_mapping.h"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <gtest/gtest.h>

#include <random>

namespace aerocal::calib {
namespace {

std::vector<double> SomeParams(MappingModel model) {
  switch (model) {
    case MappingModel::kTranslation:
      return {6900.25, -3.5};
    case MappingModel::kConformal:
      return {1.0002, -1.5e-4, 6900.25, -3.5};
    case MappingModel::kAffine:
      return {1.0002, 2e-4, 6900.25, -1.5e-4, 0.9997, -3.5};
    case MappingModel::kProjective:
      break;
  }
  return {1.0002, 2e-4, 6900.25, -1.5e-4, 0.9997, -3.5, 2e-8, -1e-8};
}

class MappingModelTest : public ::testing::TestWithParam<MappingModel> {};

TEST_P(MappingModelTest, NameAndCountRoundTrip) {
  const MappingModel m = GetParam();
  EXPECT_EQ(ParseMappingModel(MappingModelName(m)), m);
  EXPECT_EQ(static_cast<int>(SomeParams(m).size()), MappingParamCount(m));
  EXPECT_EQ(static_cast<int>(IdentityMappingParams(m).size()), MappingParamCount(m));
}

TEST_P(MappingModelTest, ApplyAgreesWithTheHomography) {
  const MappingModel m = GetParam();
  SubimageMapping s{"I", 7100, 4134, m, SomeParams(m)};
  const Eigen::Matrix3d h = HomographyFromParams(m, s.params.data());
  for (const Eigen::Vector2d& uv :
       {Eigen::Vector2d(0, 0), Eigen::Vector2d(7099, 4133), Eigen::Vector2d(3000, 100)}) {
    const Eigen::Vector3d q = h * uv.homogeneous();
    EXPECT_NEAR((s.VirtualFromSub(uv) - q.hnormalized()).norm(), 0.0, 1e-8);
    EXPECT_NEAR((s.SubFromVirtual(s.VirtualFromSub(uv)) - uv).norm(), 0.0, 1e-7);
  }
}

TEST_P(MappingModelTest, ConditionedParametersMapTheSamePoints) {
  const MappingModel m = GetParam();
  SubimageMapping s{"I", 7100, 4134, m, SomeParams(m)};
  const MappingConditioning cond = s.Conditioning();
  const auto conditioned = ConditionedFromPlain(m, cond, s.params);
  const auto back = PlainFromConditioned(m, cond, conditioned);
  for (size_t i = 0; i < back.size(); ++i)
    EXPECT_NEAR(back[i], s.params[i], 1e-9 * std::max(1.0, std::abs(s.params[i])));
  const Eigen::Vector2d uv(1234.5, 3210.25);
  const Eigen::Vector2d uvc((uv.x() - cond.cu) / cond.scale, (uv.y() - cond.cv) / cond.scale);
  Eigen::Vector2d out;
  VisitMappingModel(
      m, [&](auto model) { decltype(model)::Apply(conditioned.data(), uvc.data(), out.data()); });
  EXPECT_NEAR((out - s.VirtualFromSub(uv)).norm(), 0.0, 1e-8);
  const Eigen::MatrixXd j = PlainFromConditionedJacobian(m, cond, conditioned);
  EXPECT_EQ(j.rows(), MappingParamCount(m));
  EXPECT_GT(std::abs(j.determinant()), 0.0);
}

INSTANTIATE_TEST_SUITE_P(AllModels,
                         MappingModelTest,
                         ::testing::Values(MappingModel::kTranslation,
                                           MappingModel::kConformal,
                                           MappingModel::kAffine,
                                           MappingModel::kProjective));

}  // namespace
}  // namespace aerocal::calib
