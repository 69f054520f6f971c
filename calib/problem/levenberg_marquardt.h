// aerocal's own Levenberg-Marquardt solver for problems whose point blocks can be eliminated
// (every residual sees at most one point): residual_evaluator.h evaluates, reduced_system.h solves
// the damped normal equations, this loop decides the steps. Internal to calib/problem;
// ProblemBuilder::Solve chooses it (SolverOptions::engine) and keeps Ceres as the reference path.
//
// Why not ceres::Solve on several threads: Ceres 2.1 adds the points' terms into the reduced camera
// system in the order its threads finish (a mutex per cell), so reruns differ in the last digits
// (issue 31). Here every sum has a fixed order, so the result is the same bits for every thread
// count, and all cores are used.
//
// The trust-region strategy is Ceres' (trust_region_minimizer.cc, levenberg_marquardt_strategy.cc):
// initial radius 1e4; a step is taken when the gain ratio rho = actual / model cost reduction
// exceeds 1e-3, then radius /= max(1/3, 1 - (2 rho - 1)^3) (at most 1e16); otherwise
// radius /= decrease, decrease *= 2. Convergence as SolverOptions says: max |gradient| below
// gradient_tolerance, a step below parameter_tolerance (|x| + tol), a cost change below
// function_tolerance x cost. Without Ceres' Jacobi column scaling: the builder's manifolds scale
// the columns already, and the LM damping diag(J^T J) / radius is scale-invariant.
#pragma once

#include "calib/problem/reduced_system.h"
#include "calib/problem/residual_evaluator.h"

#include <string>

namespace aerocal::calib::internal {

struct LmOptions {
  int max_iterations = 100;
  double function_tolerance = 1e-12, gradient_tolerance = 1e-14, parameter_tolerance = 1e-12;
};

struct LmSummary {
  bool converged = false, usable = false;
  int iterations = 0;  // steps tried (taken or not), as Ceres counts them
  double initial_cost = 0, final_cost = 0;
  std::string termination = "FAILURE", message;
  double evaluation_seconds = 0, linear_solver_seconds = 0;
};

/// Minimises 0.5 sum rho(|r|^2) from the blocks' current values; writes the solution back into the
/// blocks (the last accepted state) when usable.
LmSummary MinimizeLevenbergMarquardt(const LmOptions& options,
                                     ResidualEvaluator* evaluator,
                                     ReducedSystem* system);

}  // namespace aerocal::calib::internal
