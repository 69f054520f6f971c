#include "calib/problem/levenberg_marquardt.h"

#include "calib/core/stopwatch.h"

#include <algorithm>
#include <cmath>

namespace aerocal::calib::internal {

namespace {

constexpr double kInitialRadius = 1e4, kMaxRadius = 1e16, kMinRadius = 1e-32;
constexpr double kMinRelativeDecrease = 1e-3;
constexpr int kMaxConsecutiveInvalidSteps = 5;

double Norm(const std::vector<double>& x) {
  double s = 0;
  for (double v : x) s += v * v;
  return std::sqrt(s);
}

// One run of the loop: the state between steps (x, cost, radius) and the summary it fills.
class LmLoop {
 public:
  LmLoop(const LmOptions& options, ResidualEvaluator* ev, ReducedSystem* system, LmSummary* summary)
      : options_(options), ev_(*ev), system_(*system), summary_(*summary) {}

  /// Cost and Jacobian at the blocks' values, linearised; false when they cannot be evaluated.
  bool Start();
  /// One step tried (taken or not); false when the solve ends (the summary says why).
  bool Iterate();
  /// The final cost and the last accepted state written back into the blocks.
  void Finish();

 private:
  bool Evaluate(const std::vector<double>& at, bool jacobians, double* cost);
  void Linearize();
  /// Ends the solve at a tolerance: before the step is tried, or on a rejected step at the
  /// minimum radius.
  bool StopsBeforeStep();
  /// The factorisation failed: a smaller radius, unless it failed too often in a row.
  bool Unsolvable();
  /// The step dx_ evaluated against the model: taken, rejected, or a tolerance met.
  bool TryStep();
  /// The trial state becomes the state, relinearised; the radius grows by the gain ratio.
  bool Accept(double new_cost, double rho);
  void Shrink() {
    radius_ /= decrease_;
    decrease_ *= 2.0;
  }
  /// A step that meets a tolerance ends the solve without being counted (as Ceres counts).
  void Converge(const char* why);

  const LmOptions& options_;
  ResidualEvaluator& ev_;
  ReducedSystem& system_;
  LmSummary& summary_;
  std::vector<double> x_, x_new_;
  double cost_ = 0, radius_ = kInitialRadius, decrease_ = 2.0;
  int invalid_ = 0;
  Eigen::VectorXd dx_;
};

bool LmLoop::Evaluate(const std::vector<double>& at, bool jacobians, double* cost) {
  const Stopwatch evaluation;
  const bool ok = ev_.Evaluate(at, jacobians, cost);
  summary_.evaluation_seconds += evaluation.Seconds();
  return ok;
}

void LmLoop::Linearize() {
  const Stopwatch solution;
  system_.Linearize(ev_);
  summary_.linear_solver_seconds += solution.Seconds();
}

bool LmLoop::Start() {
  x_ = ev_.Gather();
  if (!Evaluate(x_, true, &cost_)) {
    summary_.message = "the residuals cannot be evaluated at the starting values";
    return false;
  }
  summary_.initial_cost = cost_;
  summary_.usable = true;
  Linearize();
  return true;
}

void LmLoop::Converge(const char* why) {
  --summary_.iterations;
  summary_.converged = true;
  summary_.termination = "CONVERGENCE";
  summary_.message = why;
}

bool LmLoop::StopsBeforeStep() {
  if (system_.gradient().lpNorm<Eigen::Infinity>() <= options_.gradient_tolerance) {
    ++summary_.iterations;  // checked before a step is tried
    Converge("Gradient tolerance reached.");
    return true;
  }
  if (summary_.iterations >= options_.max_iterations) {
    summary_.termination = "NO_CONVERGENCE";
    summary_.message = "Maximum number of iterations reached.";
    return true;
  }
  return false;
}

bool LmLoop::Iterate() {
  if (StopsBeforeStep()) return false;
  ++summary_.iterations;
  const Stopwatch solution;
  const bool solved = system_.Solve(ev_, radius_, &dx_);
  summary_.linear_solver_seconds += solution.Seconds();
  if (!solved) return Unsolvable();
  invalid_ = 0;
  return TryStep();
}

bool LmLoop::Unsolvable() {
  if (++invalid_ > kMaxConsecutiveInvalidSteps) {
    summary_.termination = "FAILURE";
    summary_.message = "the damped normal equations could not be solved";
    return false;
  }
  Shrink();
  return true;
}

bool LmLoop::TryStep() {
  // Model reduction of the damped Gauss-Newton step: -(g^T dx + dx^T J^T J dx / 2) with
  // (J^T J + D^2) dx = -g, i.e. (-g^T dx + dx^T D^2 dx) / 2.
  const Eigen::VectorXd& g = system_.gradient();
  const double model = 0.5 * (-g.dot(dx_) + dx_.dot(system_.damping().cwiseProduct(dx_)));
  const bool moved = ev_.Plus(x_, dx_.data(), &x_new_);
  if (moved) {
    double step2 = 0;
    for (size_t k = 0; k < x_.size(); ++k) step2 += (x_new_[k] - x_[k]) * (x_new_[k] - x_[k]);
    const double tol = options_.parameter_tolerance;
    if (std::sqrt(step2) <= (Norm(x_) + tol) * tol) {
      Converge("Parameter tolerance reached.");
      return false;
    }
  }
  double new_cost = 0;
  const bool evaluated = moved && Evaluate(x_new_, false, &new_cost);
  if (evaluated && std::abs(cost_ - new_cost) <= options_.function_tolerance * cost_) {
    Converge("Function tolerance reached.");
    return false;
  }
  const double rho = evaluated && model > 0 ? (cost_ - new_cost) / model : -1.0;
  if (rho > kMinRelativeDecrease) return Accept(new_cost, rho);
  Shrink();
  if (radius_ < kMinRadius) {
    ++summary_.iterations;  // the rejected step counts
    Converge("Minimum trust region radius reached.");
    return false;
  }
  return true;
}

bool LmLoop::Accept(double new_cost, double rho) {
  x_.swap(x_new_);
  cost_ = new_cost;
  if (!Evaluate(x_, true, &cost_)) {  // cannot happen after a successful cost evaluation
    summary_.termination = "FAILURE";
    summary_.message = "the Jacobian cannot be evaluated";
    return false;
  }
  Linearize();
  radius_ = std::min(kMaxRadius, radius_ / std::max(1.0 / 3.0, 1.0 - std::pow(2.0 * rho - 1.0, 3)));
  decrease_ = 2.0;
  return true;
}

void LmLoop::Finish() {
  summary_.final_cost = cost_;
  summary_.usable = summary_.termination != "FAILURE";
  ev_.Scatter(x_);
}

}  // namespace

LmSummary MinimizeLevenbergMarquardt(const LmOptions& options,
                                     ResidualEvaluator* evaluator,
                                     ReducedSystem* system) {
  LmSummary summary;
  LmLoop loop(options, evaluator, system, &summary);
  if (!loop.Start()) return summary;
  while (loop.Iterate()) {
  }
  loop.Finish();
  return summary;
}

}  // namespace aerocal::calib::internal
