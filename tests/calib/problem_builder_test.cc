// The shared problem builder on a test-field calibration (known targets, convergent exposures,
// all 10 interior parameters free): exact recovery without noise, sigma0 and 3-sigma recovery
// with known Gaussian noise, reported sigmas against the spread of 200 Monte-Carlo repetitions,
// data snooping of a planted gross error, and the diagnostics of rank-deficient and badly
// determined problems.
#include "calib/problem/problem_builder.h"

#include "calib/camera/camera.h"
#include "calib/problem/data_snooping.h"
#include "calib/problem/smallest_eigenpairs.h"
#include "calib/residuals/autodiff_residual.h"
#include "calib/residuals/collinearity.h"

#include <Eigen/Geometry>
#include <ceres/sized_cost_function.h>
#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace aerocal::calib {
namespace {

using Model = BrownFraser10Model;

struct TestField {
  Camera camera;  // truth
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector3d> opk, centers;
  struct Obs {
    int image, point;
    Eigen::Vector2d pixel;
  };
  std::vector<Obs> observations;  // noise-free
};

// Exposure looking from `center` at `target`, rotated by `kappa` about the viewing axis.
Eigen::Vector3d LookAt(const Eigen::Vector3d& center, const Eigen::Vector3d& target, double kappa) {
  const Eigen::Vector3d w = (center - target).normalized();  // camera looks along -W
  Eigen::Vector3d u = Eigen::Vector3d::UnitY().cross(w);
  if (u.norm() < 1e-6) u = Eigen::Vector3d::UnitX();
  u.normalize();
  const Eigen::Vector3d v = w.cross(u);
  Eigen::Matrix3d r;  // columns: image axes in object space
  r.col(0) = u;
  r.col(1) = v;
  r.col(2) = w;
  r = r * Eigen::AngleAxisd(kappa, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return OpkFromRotation(r);
}

TestField MakeTestField() {
  TestField f;
  f.camera.pixel_size_mm = 0.009;
  f.camera.width_px = 6000;
  f.camera.height_px = 4000;
  f.camera.interior = {50.2, 0.031, -0.042, 4e-5, -3e-8, 5e-12, 3e-6, -2e-6, 1e-4, -5e-5};
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  for (int i = 0; i < 150; ++i)
    f.points.push_back({5.0 * uniform(rng), 5.0 * uniform(rng), 1.5 + 1.5 * uniform(rng)});
  const Eigen::Vector3d target(0, 0, 1.5);
  for (int k = 0; k < 8; ++k) {
    const double a = 2 * M_PI * k / 8;
    const Eigen::Vector3d c(8.0 * std::cos(a), 8.0 * std::sin(a), 14.0 + (k % 2));
    f.centers.push_back(c);
    f.opk.push_back(LookAt(c, target, (k % 4) * M_PI / 2));
  }
  f.centers.push_back({0.3, -0.2, 15.0});
  f.opk.push_back(LookAt(f.centers.back(), target, 0.4));
  for (size_t i = 0; i < f.centers.size(); ++i)
    for (size_t p = 0; p < f.points.size(); ++p) {
      Eigen::Vector2d px;
      if (!f.camera.ProjectToPixel(f.opk[i], f.centers[i], f.points[p], &px)) continue;
      if (px.x() < 0 || px.y() < 0 || px.x() > f.camera.width_px - 1 ||
          px.y() > f.camera.height_px - 1)
        continue;
      f.observations.push_back({static_cast<int>(i), static_cast<int>(p), px});
    }
  return f;
}

// The adjustment under test: interior (all 10 free), exposures free, targets fixed (known).
struct Adjustment {
  InteriorParams interior;
  std::vector<Eigen::Vector4d> rotations;  // quaternions of the exposures' opk
  std::vector<Eigen::Vector3d> centers, points;
  ProblemBuilder builder;
  BlockId interior_block;
  std::vector<ResidualId> residuals;

  Adjustment(const TestField& f,
             const std::vector<Eigen::Vector2d>& pixels,
             double sigma_px,
             const InteriorParams& start)
      : interior(start), centers(f.centers), points(f.points) {
    for (const auto& opk : f.opk) rotations.push_back(QuaternionFromOpk(opk));
    std::vector<std::string> names;
    for (const auto& info : Model::kParams) names.emplace_back(info.name);
    interior_block = builder.AddBlock("interior", interior.data(), 10, BlockKind::kInterior, names);
    std::vector<BlockId> o, c, p;
    for (size_t i = 0; i < rotations.size(); ++i) {
      o.push_back(builder.AddRotationBlock("opk" + std::to_string(i), rotations[i].data()));
      c.push_back(
          builder.AddBlock("center" + std::to_string(i), centers[i].data(), 3, BlockKind::kCenter));
    }
    for (size_t i = 0; i < points.size(); ++i) {
      p.push_back(builder.AddBlock(
          "point" + std::to_string(i), points[i].data(), 3, BlockKind::kGroundPoint));
      builder.FixBlock(p.back());
    }
    const PixelFrame frame{f.camera.pixel_size_mm, f.camera.width_px, f.camera.height_px};
    for (size_t k = 0; k < f.observations.size(); ++k) {
      const auto& obs = f.observations[k];
      residuals.push_back(builder.AddResidual(
          kGroupImage,
          CollinearityResidual::Create(frame, pixels[k], sigma_px),
          {interior_block, o[obs.image], c[obs.image], p[obs.point]},
          "image " + std::to_string(obs.image) + " point " + std::to_string(obs.point)));
    }
  }
};

InteriorParams PerturbedStart(const InteriorParams& truth) {
  InteriorParams start = truth;
  start[Model::kC] += 0.3;
  start[Model::kX0] -= 0.05;
  start[Model::kY0] += 0.05;
  for (int i = Model::kK1; i < Model::kNumParams; ++i) start[i] = 0.0;
  return start;
}

std::vector<Eigen::Vector2d> NoisyPixels(const TestField& f,
                                         double noise_px,
                                         std::mt19937_64& rng) {
  std::normal_distribution<double> normal(0.0, noise_px);
  std::vector<Eigen::Vector2d> out;
  for (const auto& obs : f.observations)
    out.push_back(obs.pixel + Eigen::Vector2d(normal(rng), normal(rng)));
  return out;
}

TEST(ProblemBuilder, NoiseFreeDataGiveExactRecovery) {
  const TestField f = MakeTestField();
  ASSERT_GT(f.observations.size(), 1000u);
  std::mt19937_64 rng(1);
  Adjustment a(f, NoisyPixels(f, 0.0, rng), 0.1, PerturbedStart(f.camera.interior));
  // Start the exterior orientation off as well.
  for (auto& c : a.centers) c += Eigen::Vector3d(0.05, -0.05, 0.1);
  const SolveReport report = a.builder.Solve({});
  ASSERT_TRUE(report.converged) << report.message;
  for (int i = 0; i < Model::kNumParams; ++i) {
    // 1e-9 relative to the parameter, or to its effect of one pixel for the tiny terms.
    const double truth = f.camera.interior[i];
    EXPECT_NEAR(a.interior[i], truth, 1e-9 * std::max(std::abs(truth), 1e-12))
        << Model::kParams[i].name;
  }
  EXPECT_LT(report.sigma0, 1e-6);
  // Snooping noise-free data rejects nothing (round-off is not a gross error).
  const SnoopingOutcome snooped = SolveWithDataSnooping(a.builder, {}, {});
  EXPECT_TRUE(snooped.rejected.empty()) << snooped.rejected.size() << " rejected";
}

TEST(ProblemBuilder, GaussianNoiseGivesSigma0AndThreeSigmaRecovery) {
  const TestField f = MakeTestField();
  std::mt19937_64 rng(2);
  const double noise_px = 0.25;
  Adjustment a(f, NoisyPixels(f, noise_px, rng), noise_px, PerturbedStart(f.camera.interior));
  const SolveReport report = a.builder.Solve({});
  ASSERT_TRUE(report.converged);
  EXPECT_GE(report.n_observations, 1000);
  EXPECT_NEAR(report.sigma0, 1.0, 0.10) << "sigma0 must match the injected noise within 10 %";
  EXPECT_EQ(report.redundancy, report.n_observations - (10 + 6 * 9));
  ASSERT_NE(report.Group(kGroupImage), nullptr);
  EXPECT_EQ(report.Group(kGroupImage)->n_observations, report.n_observations);
  const CovarianceReport cov = a.builder.EstimateCovariance({a.interior_block}, report.sigma0);
  ASSERT_TRUE(cov.ok) << cov.message;
  for (int i = 0; i < Model::kNumParams; ++i) {
    EXPECT_GT(cov.sigma(i), 0.0);
    EXPECT_LT(std::abs(a.interior[i] - f.camera.interior[i]), 3.0 * cov.sigma(i))
        << Model::kParams[i].name;
  }
  EXPECT_EQ(cov.names[0], "interior.c");
}

TEST(ProblemBuilder, ReportedSigmasMatchTheMonteCarloSpread) {
  const TestField f = MakeTestField();
  const double noise_px = 0.25;
  const int repetitions = 200;
  std::mt19937_64 rng(3);
  std::vector<InteriorParams> estimates;
  Eigen::VectorXd reported;
  for (int rep = 0; rep < repetitions; ++rep) {
    Adjustment a(f, NoisyPixels(f, noise_px, rng), noise_px, f.camera.interior);
    SolverOptions options;
    options.num_threads = 1;
    const SolveReport report = a.builder.Solve(options);
    ASSERT_TRUE(report.usable);
    estimates.push_back(a.interior);
    if (rep == 0) {
      // A-priori precision (sigma0 = 1: the injected noise is the a-priori sigma).
      const CovarianceReport cov = a.builder.EstimateCovariance({a.interior_block}, 1.0);
      ASSERT_TRUE(cov.ok);
      reported = cov.sigma;
    }
  }
  for (int i = 0; i < Model::kNumParams; ++i) {
    double mean = 0, sq = 0;
    for (const auto& e : estimates) mean += e[i];
    mean /= repetitions;
    for (const auto& e : estimates) sq += (e[i] - mean) * (e[i] - mean);
    const double spread = std::sqrt(sq / (repetitions - 1));
    // 200 repetitions: the empirical sigma itself scatters by ~5 %; 15 % is the stated tolerance.
    EXPECT_NEAR(spread / reported(i), 1.0, 0.15) << Model::kParams[i].name;
  }
}

TEST(ProblemBuilder, DataSnoopingFindsAndListsAPlantedGrossError) {
  const TestField f = MakeTestField();
  std::mt19937_64 rng(4);
  auto pixels = NoisyPixels(f, 0.2, rng);
  const size_t planted = pixels.size() / 3;
  pixels[planted].x() += 3.0;  // 15 sigma
  Adjustment a(f, pixels, 0.2, PerturbedStart(f.camera.interior));
  const SnoopingOutcome snooped = SolveWithDataSnooping(a.builder, {}, {});
  const SolveReport& report = snooped.report;
  const auto& rejected = snooped.rejected;
  ASSERT_TRUE(report.converged);
  ASSERT_GE(rejected.size(), 1u);
  EXPECT_EQ(rejected[0].id, a.residuals[planted]);
  EXPECT_LE(rejected.size(), 3u) << "no more than a few false alarms at 5 % family-wise";
  EXPECT_FALSE(a.builder.IsActive(a.residuals[planted]));
  EXPECT_NEAR(report.sigma0, 1.0, 0.1);
}

TEST(ProblemBuilder, DatumDefectIsReportedWithTheParametersInvolved) {
  // A free network: two exposures and free object points, nothing fixing position, attitude and
  // scale: the covariance cannot be computed and the diagnostics name the exterior orientation.
  const TestField f = MakeTestField();
  std::vector<Eigen::Vector4d> rotations = {QuaternionFromOpk(f.opk[0]),
                                            QuaternionFromOpk(f.opk[2])};
  std::vector<Eigen::Vector3d> centers = {f.centers[0], f.centers[2]};
  std::vector<Eigen::Vector3d> points = f.points;
  InteriorParams interior = f.camera.interior;
  ProblemBuilder builder;
  const BlockId ib = builder.AddBlock("interior", interior.data(), 10, BlockKind::kInterior);
  builder.FixBlock(ib);
  const PixelFrame frame{f.camera.pixel_size_mm, f.camera.width_px, f.camera.height_px};
  std::vector<BlockId> pb(points.size(), -1);
  BlockId ob[2], cb[2];
  for (int i = 0; i < 2; ++i) {
    ob[i] = builder.AddRotationBlock("opk" + std::to_string(i), rotations[i].data());
    cb[i] =
        builder.AddBlock("center" + std::to_string(i), centers[i].data(), 3, BlockKind::kCenter);
  }
  for (const auto& obs : f.observations) {
    const int i = obs.image == 0 ? 0 : obs.image == 2 ? 1 : -1;
    if (i < 0) continue;
    if (pb[obs.point] < 0)
      pb[obs.point] = builder.AddBlock("point" + std::to_string(obs.point),
                                       points[obs.point].data(),
                                       3,
                                       BlockKind::kGroundPoint);
    builder.AddResidual(kGroupImage,
                        CollinearityResidual::Create(frame, obs.pixel, 0.2),
                        {ib, ob[i], cb[i], pb[obs.point]});
  }
  const SolveReport report = builder.Solve({});
  EXPECT_TRUE(report.usable);
  const CovarianceReport cov = builder.EstimateCovariance({ob[0], cb[0], ob[1], cb[1]}, 1.0);
  EXPECT_FALSE(cov.ok);
  EXPECT_FALSE(cov.undetermined.empty());
  EXPECT_NE(cov.message.find("datum defect"), std::string::npos);
  // The null space of the reduced normal matrix (points eliminated): the 7 parameters of a
  // similarity transform of the network, exact (the cost is invariant under it), far below the
  // first determined direction; every exterior block takes part.
  const NullSpaceReport null_space = builder.NullSpace(1e-10);
  ASSERT_TRUE(null_space.ok) << null_space.message;
  EXPECT_EQ(null_space.rank_defect, 7);
  EXPECT_GT(null_space.smallest_relative_eigenvalues[7],
            1e4 * null_space.smallest_relative_eigenvalues[6]);
  for (const BlockId b : {ob[0], cb[0], ob[1], cb[1]}) {
    ASSERT_TRUE(null_space.vectors.count(b));
    EXPECT_EQ(null_space.vectors.at(b).cols(), 7);
  }
  EXPECT_EQ(null_space.scaled.count(ob[0]), 0u);  // a rotation block: ambient is a quaternion
  ASSERT_TRUE(null_space.scaled.count(cb[0]));
  EXPECT_EQ(null_space.scaled.at(cb[0]).rows(), 3);
  bool names_a_center = false;
  for (const auto& n : cov.undetermined) names_a_center |= n.rfind("center", 0) == 0;
  EXPECT_TRUE(names_a_center) << cov.message;
}

// The singular values of a matrix divided by the largest (invariant under an orthogonal change of
// the null-space basis: what a caller derives from a block's rows of the null vectors).
Eigen::VectorXd RelativeSingularValues(const Eigen::MatrixXd& m) {
  const Eigen::VectorXd sv = Eigen::JacobiSVD<Eigen::MatrixXd>(m).singularValues();
  return sv(0) > 0 ? Eigen::VectorXd(sv / sv(0)) : sv;
}

TEST(ProblemBuilder, NullSpaceIterativeEqualsTheDenseDecomposition) {
  // A free network of 30 exposures on a ring (180 reduced parameters, points eliminated): the
  // null space from the smallest eigenpairs (shift-invert subspace iteration) against the dense
  // eigen-decomposition of the same matrix: the same rank defect (the 7 of a similarity), the
  // same eigenvalues above it, the same span, and per block the same reach into it.
  const TestField f = MakeTestField();
  std::vector<Eigen::Vector4d> rotations;
  std::vector<Eigen::Vector3d> centers, opks;
  for (int k = 0; k < 30; ++k) {
    const double a = 2 * M_PI * k / 30;
    centers.emplace_back(8.0 * std::cos(a), 8.0 * std::sin(a), 14.0 + (k % 3));
    opks.push_back(LookAt(centers.back(), {0, 0, 1.5}, 0.3 * (k % 5)));
    rotations.push_back(QuaternionFromOpk(opks.back()));
  }
  std::vector<Eigen::Vector3d> points = f.points;
  InteriorParams interior = f.camera.interior;
  ProblemBuilder builder;
  const BlockId ib = builder.AddBlock("interior", interior.data(), 10, BlockKind::kInterior);
  builder.FixBlock(ib);
  std::vector<BlockId> pb(points.size(), -1), ob, cb;
  const PixelFrame frame{f.camera.pixel_size_mm, f.camera.width_px, f.camera.height_px};
  for (size_t i = 0; i < centers.size(); ++i) {
    ob.push_back(builder.AddRotationBlock("opk" + std::to_string(i), rotations[i].data()));
    cb.push_back(
        builder.AddBlock("center" + std::to_string(i), centers[i].data(), 3, BlockKind::kCenter));
  }
  for (size_t i = 0; i < centers.size(); ++i)
    for (size_t p = 0; p < points.size(); ++p) {
      Eigen::Vector2d px;
      if (!f.camera.ProjectToPixel(opks[i], centers[i], points[p], &px) || px.x() < 0 ||
          px.y() < 0 || px.x() > f.camera.width_px - 1 || px.y() > f.camera.height_px - 1)
        continue;
      if (pb[p] < 0)  // only observed points (a block without residuals is not in the problem)
        pb[p] = builder.AddBlock(
            "point" + std::to_string(p), points[p].data(), 3, BlockKind::kGroundPoint);
      builder.AddResidual(
          kGroupImage, CollinearityResidual::Create(frame, px, 0.2), {ib, ob[i], cb[i], pb[p]});
    }
  // Before the first Solve the rotations have no tangent space: a message, not a crash.
  const NullSpaceReport unsolved = builder.NullSpace(1e-10);
  EXPECT_FALSE(unsolved.ok);
  EXPECT_NE(unsolved.message.find("not been solved"), std::string::npos) << unsolved.message;
  ASSERT_TRUE(builder.Solve({}).usable);  // sets the manifolds up (noise-free: at the truth)
  builder.SetDenseNullSpaceLimit(100000);
  const NullSpaceReport dense = builder.NullSpace(1e-10);
  builder.SetDenseNullSpaceLimit(0);
  const NullSpaceReport iterative = builder.NullSpace(1e-10);
  ASSERT_TRUE(dense.ok) << dense.message;
  ASSERT_TRUE(iterative.ok) << iterative.message;
  EXPECT_EQ(dense.reduced_parameters, 180);
  EXPECT_EQ(dense.rank_defect, 7);
  EXPECT_EQ(iterative.rank_defect, 7);
  ASSERT_EQ(iterative.smallest_relative_eigenvalues.size(), 16u);
  for (int k = 0; k < 16; ++k) {
    const double a = iterative.smallest_relative_eigenvalues[k];
    const double b = dense.smallest_relative_eigenvalues[k];
    if (k < 7)
      EXPECT_LT(std::abs(a), 1e-13) << k;  // rounding noise of a null eigenvalue, both ways
    else
      EXPECT_NEAR(a, b, 1e-9 * b) << k;
  }
  // The span: the dense null vectors (ambient, every block stacked) reproduce the iterative ones.
  Eigen::MatrixXd v_dense(0, 7), v_iterative(0, 7);
  auto append = [](Eigen::MatrixXd* stack, const Eigen::MatrixXd& rows) {
    stack->conservativeResize(stack->rows() + rows.rows(), Eigen::NoChange);
    stack->bottomRows(rows.rows()) = rows;
  };
  for (const auto& [id, v] : dense.vectors) {
    ASSERT_TRUE(iterative.vectors.count(id));
    append(&v_dense, v);
    append(&v_iterative, iterative.vectors.at(id));
    EXPECT_TRUE(
        RelativeSingularValues(v).isApprox(RelativeSingularValues(iterative.vectors.at(id)), 1e-8))
        << builder.BlockName(id);
  }
  const Eigen::MatrixXd coefficients = v_dense.colPivHouseholderQr().solve(v_iterative);
  EXPECT_LT((v_dense * coefficients - v_iterative).norm(), 1e-9 * v_iterative.norm());
  for (const BlockId b : cb) {
    ASSERT_TRUE(iterative.scaled.count(b));
    EXPECT_TRUE(RelativeSingularValues(dense.scaled.at(b))
                    .isApprox(RelativeSingularValues(iterative.scaled.at(b)), 1e-8));
    EXPECT_TRUE(dense.scale.at(b).isApprox(iterative.scale.at(b), 1e-14));
  }
}

TEST(SmallestEigenpairs, PathLaplacianAgainstItsClosedForm) {
  // The Laplacian of a path of n nodes: eigenvalues 2 - 2 cos(k pi / n), k = 0 .. n - 1; the
  // null space is the constant vector. The 16 smallest by the iteration, to 1e-12 of the largest.
  const int n = 400;
  std::vector<Eigen::Triplet<double>> entries;
  for (int i = 0; i < n; ++i) {
    entries.emplace_back(i, i, (i == 0 || i == n - 1) ? 1.0 : 2.0);
    if (i > 0) entries.emplace_back(i, i - 1, -1.0);
  }
  Eigen::SparseMatrix<double> lower(n, n);
  lower.setFromTriplets(entries.begin(), entries.end());
  const internal::SymmetricEigenpairs eig = internal::SmallestEigenpairs(lower, 16, 0);
  ASSERT_TRUE(eig.ok);
  EXPECT_GT(eig.iterations, 0);
  // The path's largest eigenvalues are a tight cluster (spacing ~ 1e-4): Lanczos' largest Ritz
  // value lands on an eigenvalue of it, 1e-7 below the largest (a ratio the reports can bear).
  EXPECT_NEAR(eig.largest, 2.0 - 2.0 * std::cos((n - 1) * M_PI / n), 1e-6);
  for (int k = 0; k < 16; ++k)
    EXPECT_NEAR(eig.values(k), 2.0 - 2.0 * std::cos(k * M_PI / n), 1e-12 * eig.largest) << k;
  const Eigen::VectorXd constant = Eigen::VectorXd::Constant(n, 1.0 / std::sqrt(n));
  EXPECT_NEAR(std::abs(eig.vectors.col(0).dot(constant)), 1.0, 1e-12);
}

// y = a t + b (t + 1e-3 t^2): a and b are almost indistinguishable.
struct NearlyCollinearResidual : AutoDiffResidual<NearlyCollinearResidual, 1, 2> {
  NearlyCollinearResidual(double t, double y) : t_(t), y_(y) {}
  template <typename T>
  bool operator()(const T* ab, T* r) const {
    r[0] = ab[0] * T(t_) + ab[1] * T(t_ + 1e-3 * t_ * t_) - T(y_);
    return true;
  }
  double t_, y_;
};

TEST(ProblemBuilder, HighCorrelationsAreListed) {
  double ab[2] = {0.5, 0.5};
  ProblemBuilder builder;
  const BlockId b = builder.AddBlock("line", ab, 2, BlockKind::kOther, {"a", "b"});
  std::mt19937_64 rng(5);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (int i = 0; i < 100; ++i) {
    const double t = i * 0.1;
    builder.AddResidual(
        "samples", NearlyCollinearResidual::Create(t, 2 * t + 1e-3 * t * t + normal(rng)), {b});
  }
  const SolveReport report = builder.Solve({});
  ASSERT_TRUE(report.converged);
  const CovarianceReport cov = builder.EstimateCovariance({b}, report.sigma0);
  ASSERT_TRUE(cov.ok) << cov.message;
  ASSERT_EQ(cov.high_correlations.size(), 1u);
  EXPECT_EQ(cov.high_correlations[0].a, "line.a");
  EXPECT_EQ(cov.high_correlations[0].b, "line.b");
  EXPECT_LT(cov.high_correlations[0].correlation, -0.95);
}

TEST(ProblemBuilder, FixedEntriesStayAndAreNotCounted) {
  const TestField f = MakeTestField();
  std::mt19937_64 rng(6);
  InteriorParams start = PerturbedStart(f.camera.interior);
  Adjustment a(f, NoisyPixels(f, 0.2, rng), 0.2, start);
  a.builder.FixEntries(a.interior_block, {Model::kK3, Model::kB1, Model::kB2});
  const SolveReport report = a.builder.Solve({});
  EXPECT_EQ(report.n_unknowns, 7 + 6 * 9);
  EXPECT_EQ(a.interior[Model::kK3], 0.0);
  EXPECT_EQ(a.interior[Model::kB1], 0.0);
  EXPECT_NE(a.interior[Model::kK1], 0.0);
  const CovarianceReport cov = a.builder.EstimateCovariance({a.interior_block}, report.sigma0);
  ASSERT_TRUE(cov.ok) << cov.message;
  EXPECT_EQ(cov.sigma(Model::kK3), 0.0);
  EXPECT_FALSE(cov.free[Model::kK3]);
  // Entries fixed after a solve are fixed for the next covariance at once, before any Solve().
  a.builder.FixEntries(a.interior_block, {Model::kP1, Model::kP2});
  const CovarianceReport again = a.builder.EstimateCovariance({a.interior_block}, report.sigma0);
  ASSERT_TRUE(again.ok) << again.message;
  EXPECT_FALSE(again.free[Model::kP1]);
  EXPECT_EQ(again.sigma(Model::kP2), 0.0);
  EXPECT_GT(again.sigma(Model::kK1), 0.0);
  // Fewer free parameters: K1 is determined at least as well as before.
  EXPECT_LE(again.sigma(Model::kK1), cov.sigma(Model::kK1) * (1 + 1e-9));
}

// r = (x - m) / sigma over a point block [3], Jacobian I / sigma; counts its evaluations.
class CountingOffsetCost : public ceres::SizedCostFunction<3, 3> {
 public:
  CountingOffsetCost(const Eigen::Vector3d& m, double sigma, int* evaluations)
      : m_(m), sigma_(sigma), evaluations_(evaluations) {}
  bool Evaluate(double const* const* x, double* r, double** jacobians) const override {
    ++*evaluations_;
    for (int i = 0; i < 3; ++i) r[i] = (x[0][i] - m_[i]) / sigma_;
    if (jacobians && jacobians[0])
      for (int i = 0; i < 9; ++i) jacobians[0][i] = i % 4 == 0 ? 1.0 / sigma_ : 0.0;
    return true;
  }

 private:
  Eigen::Vector3d m_;
  double sigma_;
  int* evaluations_;
};

TEST(ProblemBuilder, FixedEntriesWaitForTheirNextUse) {
  // The rig stitching holds the height of every tie point (FixEntries(point, {2})): each call used
  // to evaluate the whole problem's Jacobian at once, quadratic in the points. The manifolds are
  // now set up at the next use, once. Each point: X, Y free, Z held 1 sigma off its measurement,
  // so v^T P v = n, redundancy 3n - 2n = n, sigma0 = 1 and sigma_X = sigma exactly.
  constexpr int kPoints = 200;
  constexpr double kSigma = 0.5;
  int evaluations = 0;
  ProblemBuilder builder;
  std::vector<Eigen::Vector3d> points(kPoints), measured(kPoints);
  std::vector<BlockId> blocks;
  for (int i = 0; i < kPoints; ++i) {
    measured[i] = Eigen::Vector3d(i, -2.0 * i, 100.0 + i);
    points[i] = measured[i] + Eigen::Vector3d(3.0, -1.0, kSigma);
    blocks.push_back(builder.AddBlock(
        "p" + std::to_string(i), points[i].data(), 3, BlockKind::kGroundPoint, {"X", "Y", "Z"}));
    builder.AddResidual(kGroupControl,
                        std::make_unique<CountingOffsetCost>(measured[i], kSigma, &evaluations),
                        {blocks.back()});
    builder.FixEntries(blocks.back(), {2});
  }
  EXPECT_EQ(evaluations, 0);  // before: 1 + 2 + ... + 200 residual evaluations
  const SolveReport report = builder.Solve({});
  ASSERT_TRUE(report.converged) << report.message;
  EXPECT_EQ(report.n_unknowns, 2 * kPoints);
  EXPECT_EQ(report.redundancy, kPoints);
  EXPECT_NEAR(report.sigma0, 1.0, 1e-12);
  // The solver stops on its function tolerance a few 1e-9 px short of the exact solution.
  constexpr double kSolvedPx = 1e-7;
  for (int i = 0; i < kPoints; ++i) {
    EXPECT_NEAR(points[i].x(), measured[i].x(), kSolvedPx);
    EXPECT_NEAR(points[i].y(), measured[i].y(), kSolvedPx);
    EXPECT_EQ(points[i].z(), measured[i].z() + kSigma);  // held: never moved
  }
  const CovarianceReport cov = builder.EstimateCovariance({blocks[7]}, report.sigma0);
  ASSERT_TRUE(cov.ok) << cov.message;
  EXPECT_NEAR(cov.sigma(0), kSigma, 1e-12);
  EXPECT_NEAR(cov.sigma(1), kSigma, 1e-12);
  EXPECT_FALSE(cov.free[2]);
  EXPECT_EQ(cov.sigma(2), 0.0);
}

TEST(NormalCriticalValue, KnownQuantiles) {
  EXPECT_NEAR(NormalCriticalValue(0.05), 1.959964, 1e-5);
  EXPECT_NEAR(NormalCriticalValue(0.001), 3.290527, 1e-5);
}

}  // namespace
}  // namespace aerocal::calib
