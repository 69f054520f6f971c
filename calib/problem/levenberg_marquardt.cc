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

}  // namespace

LmSummary MinimizeLevenbergMarquardt(const LmOptions& options,
                                     ResidualEvaluator* evaluator,
                                     ReducedSystem* system) {
  LmSummary summary;
  ResidualEvaluator& ev = *evaluator;
  std::vector<double> x = ev.Gather(), x_new;
  double cost = 0;
  auto evaluate = [&](const std::vector<double>& at, bool jacobians, double* c) {
    const Stopwatch evaluation;
    const bool ok = ev.Evaluate(at, jacobians, c);
    summary.evaluation_seconds += evaluation.Seconds();
    return ok;
  };
  if (!evaluate(x, true, &cost)) {
    summary.message = "the residuals cannot be evaluated at the starting values";
    return summary;
  }
  summary.initial_cost = cost;
  summary.usable = true;
  auto linear = [&](auto&& f) {
    const Stopwatch solution;
    const auto result = f();
    summary.linear_solver_seconds += solution.Seconds();
    return result;
  };
  linear([&] {
    system->Linearize(ev);
    return true;
  });
  double radius = kInitialRadius, decrease = 2.0;
  int invalid = 0;
  Eigen::VectorXd dx;
  // A step that meets a tolerance ends the solve without being counted (as Ceres counts).
  auto converge = [&](const std::string& why) {
    --summary.iterations;
    summary.converged = true;
    summary.termination = "CONVERGENCE";
    summary.message = why;
  };
  while (true) {
    if (system->gradient().lpNorm<Eigen::Infinity>() <= options.gradient_tolerance) {
      ++summary.iterations;  // checked before a step is tried
      converge("Gradient tolerance reached.");
      break;
    }
    if (summary.iterations >= options.max_iterations) {
      summary.termination = "NO_CONVERGENCE";
      summary.message = "Maximum number of iterations reached.";
      break;
    }
    ++summary.iterations;
    if (!linear([&] { return system->Solve(ev, radius, &dx); })) {
      if (++invalid > kMaxConsecutiveInvalidSteps) {
        summary.termination = "FAILURE";
        summary.message = "the damped normal equations could not be solved";
        break;
      }
      radius /= decrease;
      decrease *= 2.0;
      continue;
    }
    invalid = 0;
    // Model reduction of the damped Gauss-Newton step: -(g^T dx + dx^T J^T J dx / 2) with
    // (J^T J + D^2) dx = -g, i.e. (-g^T dx + dx^T D^2 dx) / 2.
    const Eigen::VectorXd& g = system->gradient();
    const double model = 0.5 * (-g.dot(dx) + dx.dot(system->damping().cwiseProduct(dx)));
    const bool moved = ev.Plus(x, dx.data(), &x_new);
    if (moved) {
      double step2 = 0;
      for (size_t k = 0; k < x.size(); ++k) step2 += (x_new[k] - x[k]) * (x_new[k] - x[k]);
      const double tol = options.parameter_tolerance;
      if (std::sqrt(step2) <= (Norm(x) + tol) * tol) {
        converge("Parameter tolerance reached.");
        break;
      }
    }
    double new_cost = 0;
    const bool evaluated = moved && evaluate(x_new, false, &new_cost);
    if (evaluated && std::abs(cost - new_cost) <= options.function_tolerance * cost) {
      converge("Function tolerance reached.");
      break;
    }
    const double rho = evaluated && model > 0 ? (cost - new_cost) / model : -1.0;
    if (rho <= kMinRelativeDecrease) {
      radius /= decrease;
      decrease *= 2.0;
      if (radius < kMinRadius) {
        ++summary.iterations;  // the rejected step counts
        converge("Minimum trust region radius reached.");
        break;
      }
      continue;
    }
    x.swap(x_new);
    cost = new_cost;
    if (!evaluate(x, true, &cost)) {  // cannot happen after a successful cost evaluation
      summary.termination = "FAILURE";
      summary.message = "the Jacobian cannot be evaluated";
      break;
    }
    linear([&] {
      system->Linearize(ev);
      return true;
    });
    radius = std::min(kMaxRadius, radius / std::max(1.0 / 3.0, 1.0 - std::pow(2.0 * rho - 1.0, 3)));
    decrease = 2.0;
  }
  summary.final_cost = cost;
  summary.usable = summary.termination != "FAILURE";
  ev.Scatter(x);
  return summary;
}

}  // namespace aerocal::calib::internal
