// The scalable linear algebra of the statistics: the selected inverse (Takahashi) of a sparse
// matrix against the dense inverse; observation cofactors (redundancy numbers, Q_vv per point)
// and covariance blocks of a ProblemBuilder problem, sparse path, against the dense
// J (J^T J)^+ J^T of the same Jacobian; the datum-defect cases; one manifold per block; and
// bit-identical results of two identical solves.
#include "calib/problem/normal_equations.h"

#include "calib/problem/problem_builder.h"
#include "calib/residuals/autodiff_residual.h"

#include <Eigen/Dense>
#include <ceres/ceres.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

namespace aerocal::calib {
namespace {

// Agreement of two exact computations of the same numbers in double precision (the problems here
// are Jacobi-scaled and well conditioned, so round-off stays far below this).
constexpr double kExact = 1e-9;

TEST(SelectedInverse, MatchesTheDenseInverseOnEveryEntry) {
  // A banded-plus-random sparse SPD matrix of 500 unknowns: the Takahashi entries (pattern of L)
  // and the solved ones (outside it) must both equal the dense inverse.
  const int n = 500;
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  std::uniform_int_distribution<int> pick(0, n - 1);
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < n; ++i)
    for (int k = std::max(0, i - 4); k <= i; ++k) a(i, k) = a(k, i) = uniform(rng);
  for (int e = 0; e < 300; ++e) {
    const int i = pick(rng), k = pick(rng);
    a(i, k) = a(k, i) = uniform(rng);
  }
  a.diagonal().array() += 12.0;  // diagonally dominant: positive definite
  const Eigen::SparseMatrix<double> lower =
      Eigen::MatrixXd(a.triangularView<Eigen::Lower>()).sparseView();
  internal::SelectedInverse inverse;
  ASSERT_TRUE(inverse.Compute(lower, 0, 0)) << inverse.message();
  EXPECT_FALSE(inverse.dense());
  EXPECT_GT(inverse.factor_nonzeros(), 0);
  std::vector<int> all(n);
  for (int i = 0; i < n; ++i) all[i] = i;
  const Eigen::MatrixXd z = inverse.Gather(all, all);
  const Eigen::MatrixXd dense = a.inverse();
  EXPECT_LT((z - dense).cwiseAbs().maxCoeff(), kExact * dense.cwiseAbs().maxCoeff());
}

TEST(SelectedInverse, ASingularMatrixIsNotInvertedAboveTheDenseLimit) {
  // Rank n - 1 (a zero row and column): not ok above max_dense, the pseudo-inverse below it.
  const int n = 40;
  Eigen::MatrixXd a = Eigen::MatrixXd::Identity(n, n) * 2.0;
  for (int i = 0; i + 1 < n; ++i) a(i + 1, i) = a(i, i + 1) = 0.5;
  a.row(7).setZero();
  a.col(7).setZero();
  const Eigen::SparseMatrix<double> lower =
      Eigen::MatrixXd(a.triangularView<Eigen::Lower>()).sparseView();
  internal::SelectedInverse refused;
  EXPECT_FALSE(refused.Compute(lower, 0, 10));
  EXPECT_NE(refused.message().find("singular"), std::string::npos);
  internal::SelectedInverse pseudo;
  ASSERT_TRUE(pseudo.Compute(lower, 0, 100));
  EXPECT_TRUE(pseudo.singular());
  EXPECT_TRUE(pseudo.dense());
  std::vector<int> all(n);
  for (int i = 0; i < n; ++i) all[i] = i;
  const Eigen::MatrixXd z = pseudo.Gather(all, all);
  EXPECT_LT((a * z * a - a).cwiseAbs().maxCoeff(), kExact);  // a generalised inverse
}

// r = U interior + V pose + W point - y: a linear model with the block structure of a bundle
// (every row one point, one pose, the shared interior), random coefficients per observation.
struct LinearRayResidual : AutoDiffResidual<LinearRayResidual, 2, 4, 6, 3> {
  LinearRayResidual(const Eigen::Matrix<double, 2, 13>& m, const Eigen::Vector2d& y)
      : m_(m), y_(y) {}
  template <typename T>
  bool operator()(const T* interior, const T* pose, const T* point, T* r) const {
    for (int i = 0; i < 2; ++i) {
      T sum = T(-y_(i));
      for (int k = 0; k < 4; ++k) sum += T(m_(i, k)) * interior[k];
      for (int k = 0; k < 6; ++k) sum += T(m_(i, 4 + k)) * pose[k];
      for (int k = 0; k < 3; ++k) sum += T(m_(i, 10 + k)) * point[k];
      r[i] = sum;
    }
    return true;
  }
  Eigen::Matrix<double, 2, 13> m_;
  Eigen::Vector2d y_;
};

// A prior on one pose: r = pose - y (6 rows, no point).
struct PosePriorResidual : AutoDiffResidual<PosePriorResidual, 6, 6> {
  explicit PosePriorResidual(const Eigen::Matrix<double, 6, 1>& y) : y_(y) {}
  template <typename T>
  bool operator()(const T* pose, T* r) const {
    for (int k = 0; k < 6; ++k) r[k] = pose[k] - T(y_(k));
    return true;
  }
  Eigen::Matrix<double, 6, 1> y_;
};

// 70 poses (420 reduced parameters + 4 interior: above the dense limit, so the sparse path runs),
// 300 points seen by 2-5 poses of a strip-like neighbourhood, a prior on every tenth pose.
// `defect`: the last pose's sixth parameter is observed by nothing (a rank defect of S).
struct LinearBlock {
  Eigen::Vector4d interior = Eigen::Vector4d::Zero();
  std::vector<Eigen::Matrix<double, 6, 1>> poses;
  std::vector<Eigen::Vector3d> points;
  ProblemBuilder builder;
  BlockId interior_block = -1;
  std::vector<BlockId> pose_blocks, point_blocks;
  std::vector<ResidualId> rays, priors;

  explicit LinearBlock(bool defect, unsigned seed = 3) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> uniform(-1.0, 1.0);
    std::uniform_int_distribution<int> rays_per_point(2, 5);
    const int n_poses = 70, n_points = 300;
    poses.assign(n_poses, Eigen::Matrix<double, 6, 1>::Zero());
    points.assign(n_points, Eigen::Vector3d::Zero());
    interior_block = builder.AddBlock("interior", interior.data(), 4, BlockKind::kInterior);
    for (int i = 0; i < n_poses; ++i)
      pose_blocks.push_back(
          builder.AddBlock("pose" + std::to_string(i), poses[i].data(), 6, BlockKind::kOther));
    for (int p = 0; p < n_points; ++p)
      point_blocks.push_back(builder.AddBlock(
          "point" + std::to_string(p), points[p].data(), 3, BlockKind::kGroundPoint));
    for (int p = 0; p < n_points; ++p) {
      const int first = (p * n_poses) / n_points;
      const int count = rays_per_point(rng);
      for (int k = 0; k < count; ++k) {
        const int pose = (first + k) % n_poses;
        Eigen::Matrix<double, 2, 13> m;
        for (int r = 0; r < 2; ++r)
          for (int c = 0; c < 13; ++c) m(r, c) = uniform(rng);
        if (defect && pose == n_poses - 1) m.col(4 + 5).setZero();
        rays.push_back(builder.AddResidual(
            kGroupImage,
            LinearRayResidual::Create(m, Eigen::Vector2d(uniform(rng), uniform(rng))),
            {interior_block, pose_blocks[pose], point_blocks[p]},
            "ray " + std::to_string(p) + "/" + std::to_string(k)));
      }
    }
    for (int i = 0; i < n_poses; i += 10) {
      Eigen::Matrix<double, 6, 1> y;
      for (int k = 0; k < 6; ++k) y(k) = uniform(rng);
      priors.push_back(
          builder.AddResidual(kGroupEoPrior, PosePriorResidual::Create(y), {pose_blocks[i]}));
    }
  }

  // The dense oracle: J of every active residual over the free blocks, in the builder's order,
  // and H = J (J^T J)^+ J^T.
  Eigen::MatrixXd DenseHat() {
    ceres::Problem::EvaluateOptions eval;
    std::vector<BlockId> order = {interior_block};
    order.insert(order.end(), pose_blocks.begin(), pose_blocks.end());
    order.insert(order.end(), point_blocks.begin(), point_blocks.end());
    for (BlockId b : order) eval.parameter_blocks.push_back(builder.BlockValues(b));
    ceres::CRSMatrix crs;
    double cost = 0.0;
    EXPECT_TRUE(builder.problem().Evaluate(eval, &cost, nullptr, nullptr, &crs));
    Eigen::MatrixXd j = Eigen::MatrixXd::Zero(crs.num_rows, crs.num_cols);
    for (int r = 0; r < crs.num_rows; ++r)
      for (int k = crs.rows[r]; k < crs.rows[r + 1]; ++k) j(r, crs.cols[k]) = crs.values[k];
    const Eigen::MatrixXd n = j.transpose() * j;
    const Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod(n);
    return j * cod.pseudoInverse() * j.transpose();
  }
  // Row of each residual's first component in the dense oracle (residuals in insertion order:
  // rays, then priors).
  int Row(ResidualId id) const {
    return id < static_cast<int>(rays.size())
               ? 2 * id
               : 2 * static_cast<int>(rays.size()) + 6 * (id - static_cast<int>(rays.size()));
  }
};

std::vector<ResidualId> AllResiduals(const LinearBlock& block) {
  std::vector<ResidualId> ids = block.rays;
  ids.insert(ids.end(), block.priors.begin(), block.priors.end());
  return ids;
}

TEST(ObservationCofactors, SparsePathMatchesTheDenseHatMatrix) {
  LinearBlock block(false);
  const SolveReport report = block.builder.Solve({});
  ASSERT_TRUE(report.usable);
  const std::vector<ResidualId> ids = AllResiduals(block);
  const ObservationCofactors cof = block.builder.ComputeObservationCofactors(ids, true);
  ASSERT_TRUE(cof.ok) << cof.message;
  EXPECT_EQ(cof.method, "schur_selected_inverse");
  EXPECT_EQ(cof.reduced_parameters, 4 + 70 * 6);
  EXPECT_GT(cof.factor_nonzeros, 0);
  const Eigen::MatrixXd hat = block.DenseHat();
  double worst = 0.0, trace = 0.0;
  for (ResidualId id : ids) {
    const std::vector<double>& r = cof.redundancy.at(id);
    for (size_t k = 0; k < r.size(); ++k) {
      const int row = block.Row(id) + static_cast<int>(k);
      worst = std::max(worst, std::abs(r[k] - (1.0 - hat(row, row))));
      trace += r[k];
    }
  }
  EXPECT_LT(worst, kExact);
  // sum r_ii = n - u (the trace of the projector I - H).
  EXPECT_NEAR(trace, report.redundancy, 1e-6);
  // Q_vv among the rays of each point.
  ASSERT_EQ(cof.clusters.size(), block.point_blocks.size());
  double worst_cluster = 0.0;
  for (const ResidualCluster& c : cof.clusters) {
    for (size_t a = 0; a < c.residuals.size(); ++a)
      for (size_t b = 0; b < c.residuals.size(); ++b)
        for (int i = 0; i < 2; ++i)
          for (int k = 0; k < 2; ++k) {
            const int ra = block.Row(c.residuals[a]) + i, rb = block.Row(c.residuals[b]) + k;
            const double expected = (ra == rb ? 1.0 : 0.0) - hat(ra, rb);
            worst_cluster =
                std::max(worst_cluster, std::abs(c.qvv(2 * a + i, 2 * b + k) - expected));
          }
  }
  EXPECT_LT(worst_cluster, kExact);
  // The wrapper gives the same numbers.
  const auto wrapped = block.builder.RedundancyNumbers({ids[5], block.priors[2]}, 4000);
  for (ResidualId id : {ids[5], block.priors[2]})
    for (size_t k = 0; k < wrapped.at(id).size(); ++k)
      EXPECT_NEAR(wrapped.at(id)[k], cof.redundancy.at(id)[k], kExact);
}

TEST(ObservationCofactors, DatumDefectIsInvertedDenselyOrReportedNotComputed) {
  LinearBlock block(true);
  ASSERT_TRUE(block.builder.Solve({}).usable);
  const std::vector<ResidualId> ids = AllResiduals(block);
  // Within the dense limit: exact (Q_vv does not depend on the generalised inverse).
  const ObservationCofactors cof = block.builder.ComputeObservationCofactors(ids, false, 4000);
  ASSERT_TRUE(cof.ok) << cof.message;
  EXPECT_EQ(cof.method, "schur_dense_pseudo_inverse");
  EXPECT_NE(cof.message.find("singular"), std::string::npos);
  const Eigen::MatrixXd hat = block.DenseHat();
  double worst = 0.0;
  for (ResidualId id : ids)
    for (size_t k = 0; k < cof.redundancy.at(id).size(); ++k) {
      const int row = block.Row(id) + static_cast<int>(k);
      worst = std::max(worst, std::abs(cof.redundancy.at(id)[k] - (1.0 - hat(row, row))));
    }
  EXPECT_LT(worst, 1e-7);  // a pseudo-inverse of a rank-deficient matrix: cut at 1e-12
  // Above it: not computed, NaN, never r/n.
  const ObservationCofactors refused = block.builder.ComputeObservationCofactors(ids, false, 100);
  EXPECT_FALSE(refused.ok);
  EXPECT_EQ(refused.method, "not_computed");
  EXPECT_NE(refused.message.find("singular"), std::string::npos);
  EXPECT_TRUE(std::isnan(refused.redundancy.at(ids[0])[0]));
}

TEST(Covariance, SelectedInverseMatchesTheDenseInverse) {
  LinearBlock block(false);
  const SolveReport report = block.builder.Solve({});
  ASSERT_TRUE(report.usable);
  const std::vector<BlockId> requested = {
      block.interior_block, block.pose_blocks[3], block.pose_blocks[60], block.point_blocks[17]};
  const CovarianceReport cov = block.builder.EstimateCovariance(requested, 2.0, 0.95);
  ASSERT_TRUE(cov.ok) << cov.message;
  EXPECT_EQ(cov.method, "schur_selected_inverse");
  // Oracle: (J^T J)^-1 in the tangent space, mapped to ambient by each block's Plus Jacobian.
  ceres::Problem::EvaluateOptions eval;
  std::vector<BlockId> order = {block.interior_block};
  order.insert(order.end(), block.pose_blocks.begin(), block.pose_blocks.end());
  order.insert(order.end(), block.point_blocks.begin(), block.point_blocks.end());
  std::map<BlockId, int> offset;
  int col = 0;
  for (BlockId b : order) {
    eval.parameter_blocks.push_back(block.builder.BlockValues(b));
    offset[b] = col;
    col += block.builder.BlockSize(b);
  }
  ceres::CRSMatrix crs;
  double cost = 0.0;
  ASSERT_TRUE(block.builder.problem().Evaluate(eval, &cost, nullptr, nullptr, &crs));
  Eigen::MatrixXd j = Eigen::MatrixXd::Zero(crs.num_rows, crs.num_cols);
  for (int r = 0; r < crs.num_rows; ++r)
    for (int k = crs.rows[r]; k < crs.rows[r + 1]; ++k) j(r, crs.cols[k]) = crs.values[k];
  const Eigen::MatrixXd q = (j.transpose() * j).inverse();
  auto plus = [&](BlockId b) {
    const int n = block.builder.BlockSize(b);
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> m(n, n);
    block.builder.problem()
        .GetManifold(block.builder.BlockValues(b))
        ->PlusJacobian(block.builder.BlockValues(b), m.data());
    return Eigen::MatrixXd(m);
  };
  double worst = 0.0;
  for (BlockId a : requested)
    for (BlockId b : requested) {
      Eigen::MatrixXd got;
      ASSERT_TRUE(cov.CrossCovariance(a, b, &got));
      const int na = block.builder.BlockSize(a), nb = block.builder.BlockSize(b);
      const Eigen::MatrixXd expected =
          4.0 * plus(a) * q.block(offset[a], offset[b], na, nb) * plus(b).transpose();
      worst =
          std::max(worst, (got - expected).cwiseAbs().maxCoeff() / expected.cwiseAbs().maxCoeff());
    }
  EXPECT_LT(worst, kExact);
  EXPECT_EQ(cov.interior_names.size(), 4u);
  EXPECT_NEAR(cov.interior_correlation(1, 1), 1.0, 0.0);
  // Only interior x everything: the pose-pose pair is not held, its correlation reads 0.
  const CovarianceReport cross =
      block.builder.EstimateCovariance(requested, 1.0, 0.95, {block.interior_block});
  ASSERT_TRUE(cross.ok);
  Eigen::MatrixXd unused;
  EXPECT_FALSE(cross.CrossCovariance(block.pose_blocks[3], block.pose_blocks[60], &unused));
  EXPECT_TRUE(cross.CrossCovariance(block.interior_block, block.pose_blocks[60], &unused));
}

// After a solve by aerocal's engine the statistics take its reduced system at the solution
// (ProblemBuilder keeps it, issue 31) instead of evaluating the Jacobian and reducing again: the
// same redundancy numbers, Q_vv and covariance as a fresh reduction to 1e-12 (the fresh one is
// forced by a structure change that changes nothing), with the reduced system sparse (CHOLMOD in
// the solve) and dense.
TEST(ObservationCofactors, TheEnginesReducedSystemGivesTheFreshReductionsNumbers) {
  constexpr double kSame = 1e-12;
  for (const int max_dense : {0, 800}) {
    LinearBlock block(false);
    SolverOptions options;
    options.max_dense_schur_parameters = max_dense;
    ASSERT_TRUE(block.builder.Solve(options).usable);
    const std::vector<ResidualId> ids = AllResiduals(block);
    const std::vector<BlockId> requested = {
        block.interior_block, block.pose_blocks[3], block.point_blocks[17]};
    const ObservationCofactors shared = block.builder.ComputeObservationCofactors(ids, true);
    const CovarianceReport shared_cov = block.builder.EstimateCovariance(requested, 1.0, 0.95);
    block.builder.SetDenseInverseLimit(300);  // the same limit: only the kept state is dropped
    const ObservationCofactors fresh = block.builder.ComputeObservationCofactors(ids, true);
    const CovarianceReport fresh_cov = block.builder.EstimateCovariance(requested, 1.0, 0.95);
    ASSERT_TRUE(shared.ok && fresh.ok && shared_cov.ok && fresh_cov.ok);
    double worst = 0.0;
    for (ResidualId id : ids)
      for (size_t k = 0; k < fresh.redundancy.at(id).size(); ++k)
        worst = std::max(worst, std::abs(shared.redundancy.at(id)[k] - fresh.redundancy.at(id)[k]));
    ASSERT_EQ(shared.clusters.size(), fresh.clusters.size());
    for (size_t c = 0; c < fresh.clusters.size(); ++c)
      worst =
          std::max(worst, (shared.clusters[c].qvv - fresh.clusters[c].qvv).cwiseAbs().maxCoeff());
    EXPECT_LT(worst, kSame) << "max_dense_schur_parameters " << max_dense;
    for (BlockId a : requested)
      for (BlockId b : requested) {
        Eigen::MatrixXd x, y;
        ASSERT_TRUE(shared_cov.CrossCovariance(a, b, &x) && fresh_cov.CrossCovariance(a, b, &y));
        EXPECT_LT((x - y).cwiseAbs().maxCoeff(), kSame * y.cwiseAbs().maxCoeff());
      }
  }
}

TEST(ProblemBuilder, ManifoldsAreCreatedOncePerBlock) {
  LinearBlock block(false);
  ASSERT_TRUE(block.builder.Solve({}).usable);
  const double* pose = block.builder.BlockValues(block.pose_blocks[2]);
  const ceres::Manifold* first = block.builder.problem().GetManifold(pose);
  ASSERT_NE(first, nullptr);
  ASSERT_TRUE(block.builder.Solve({}).usable);
  EXPECT_EQ(block.builder.problem().GetManifold(pose), first);
  block.builder.FixEntries(block.pose_blocks[2], {0});  // a new free subset: a new manifold
  EXPECT_NE(block.builder.problem().GetManifold(pose), first);
  EXPECT_EQ(block.builder.problem().GetManifold(pose)->TangentSize(), 5);
}

TEST(ProblemBuilder, IdenticalRunsGiveBitIdenticalResults) {
  // Deterministic solves (the default): two identical problems, identical bits.
  LinearBlock a(false, 9), b(false, 9);
  SolverOptions options;
  options.linear_solver = LinearSolverChoice::kSparseSchur;
  const SolveReport ra = a.builder.Solve(options), rb = b.builder.Solve(options);
  ASSERT_TRUE(ra.usable && rb.usable);
  EXPECT_EQ(std::memcmp(&ra.vtpv, &rb.vtpv, sizeof(double)), 0);
  for (size_t i = 0; i < a.poses.size(); ++i)
    EXPECT_EQ(std::memcmp(a.poses[i].data(), b.poses[i].data(), 6 * sizeof(double)), 0);
  for (size_t i = 0; i < a.points.size(); ++i)
    EXPECT_EQ(std::memcmp(a.points[i].data(), b.points[i].data(), 3 * sizeof(double)), 0);
  const auto ca = a.builder.ComputeObservationCofactors(a.rays, false);
  const auto cb = b.builder.ComputeObservationCofactors(b.rays, false);
  EXPECT_EQ(ca.redundancy, cb.redundancy);
}

TEST(ProblemBuilder, IterativeSchurAboveItsLimitReachesTheFactorisedSolution) {
  // kAuto with min_iterative_schur_parameters below the 424 reduced parameters: conjugate
  // gradients on the reduced system (SCHUR_JACOBI). The problem is linear, so both solvers must
  // reach the one least-squares solution. Ceres' CG stops at a relative residual and LM at a
  // relative cost change of 1e-12, so the parameters agree only to the precision the cost sees:
  // v^T P v to 1e-9, parameters of size ~1 to 1e-4 (measured 2.8e-5, in the weakest directions).
  LinearBlock iterative(false, 5), factorised(false, 5);
  SolverOptions options;
  options.min_iterative_schur_parameters = 100;
  const SolveReport ri = iterative.builder.Solve(options);
  options.min_iterative_schur_parameters = 0;
  options.linear_solver = LinearSolverChoice::kSparseSchur;
  const SolveReport rf = factorised.builder.Solve(options);
  ASSERT_TRUE(ri.usable && rf.usable);
  EXPECT_EQ(ri.linear_solver, "iterative_schur");
  EXPECT_EQ(rf.linear_solver, "sparse_schur");
  EXPECT_NEAR(ri.vtpv / rf.vtpv, 1.0, 1e-9);
  double worst = 0.0;
  for (size_t i = 0; i < iterative.poses.size(); ++i)
    worst = std::max(worst, (iterative.poses[i] - factorised.poses[i]).cwiseAbs().maxCoeff());
  for (size_t i = 0; i < iterative.points.size(); ++i)
    worst = std::max(worst, (iterative.points[i] - factorised.points[i]).cwiseAbs().maxCoeff());
  worst = std::max(worst, (iterative.interior - factorised.interior).cwiseAbs().maxCoeff());
  EXPECT_LT(worst, 1e-4);
}

}  // namespace
}  // namespace aerocal::calib
