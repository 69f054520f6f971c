// Camera calibration from a test field or a planar target (`aerocal calibrate`): starting values
// by resection (resection.h; Zhang's closed-form c for a planar target), then the existing
// self-calibrating bundle adjustment (block_adjustment.h, not a second solver) on all images and,
// with image groups, on each group; the stability of every free parameter over the groups.
//
// Stability (per free interior parameter p, groups g = 1..G with estimates v_g and sigmas s_g):
// mean and spread (sample standard deviation) of the v_g, the weighted mean
// m = sum(v_g / s_g^2) / sum(1 / s_g^2) and chi2 = sum((v_g - m)^2 / s_g^2) ~ chi^2(G - 1) when the
// groups measure the same camera with their stated precision. The groups agree when every
// parameter's chi2 stays below the (1 - alpha / n_free) quantile (Bonferroni: the family of tests
// keeps the level alpha); a parameter above it is flagged by name. The test's sensitivity is
// stated with it: per group the change of that group alone detected with probability
// `StabilityReport::power` (group_change_power.h), the analogue of the MDB of data snooping.
#pragma once

#include "triangulation/adjustment/adjust_options.h"
#include "triangulation/adjustment/adjustment_result.h"
#include "triangulation/block/block.h"
#include "triangulation/calibration/control_cofactor.h"
#include "triangulation/calibration/resection.h"

#include <Eigen/Core>

#include <map>
#include <optional>
#include <string>
#include <vector>

namespace aerocal::triangulation {

struct CalibrateOptions {
  AdjustOptions adjust;  // free_interior: the parameters calibrated
  /// Planar control: replace the camera file's c by Zhang's closed form before the resections
  /// when it is determined (within a factor of 2 of the file's value).
  bool closed_form_c = true;
  double stability_alpha = 0.05;  // level of the group agreement test, (0, 1)
  /// The part of the parameters' variance that comes from the control coordinates (the type-B
  /// component of uncertainty_budget.h): CalibrationAdjustment::control_cofactor of the run on
  /// all images.
  bool control_propagation = true;
};

/// One adjustment with the interior covariance (table order, table units; zero rows/columns for
/// fixed parameters; empty when not determinable).
struct CalibrationAdjustment {
  AdjustmentResult result;
  Eigen::MatrixXd interior_covariance;
  /// Q N_control Q of the interior (table order and units, not scaled by sigma0): the part of
  /// the cofactor matrix that the control coordinates' sigmas give (uncertainty_budget.h); empty
  /// without control or unless asked for (RunCalibrationAdjustment).
  Eigen::MatrixXd control_cofactor;
};

struct GroupCalibration {
  std::string group;
  std::vector<std::string> images;
  CalibrationAdjustment adjustment;
};

struct StabilityRow {
  std::string parameter, unit;
  std::vector<double> values, sigmas;  // per group, in the order of CalibrationRun::groups
  /// Per group: the change of that group's value alone which the test flags with probability
  /// StabilityReport::power (empty when a sigma is unknown).
  std::vector<double> detectable_change;
  double mean = 0, spread = 0, weighted_mean = 0, chi2 = 0, critical = 0;
  int dof = 0;
  bool agree = true;
};

struct StabilityReport {
  double alpha = 0.05;
  double power = 0.8;  // of the detectable changes
  bool agree = true;
  std::vector<StabilityRow> rows;
  std::vector<std::string> flagged;  // one sentence per parameter out of agreement
};

struct CalibrationRun {
  std::string camera;
  std::optional<double> closed_form_c_mm;  // Zhang's value, when determined
  double start_c_mm = 0;                   // the c the resections used
  std::vector<ResectionStart> starts;
  CalibrationAdjustment all;             // all images together: the certified result
  std::vector<GroupCalibration> groups;  // empty without groups
  StabilityReport stability;
  /// The calibrated block: the project with the resections as its exposures.
  Project project;
};

/// The project's single camera is calibrated; `group_of_image` (may be empty) maps image ids to
/// group names (images without a group are used only in the run on all images). The project's
/// exposures are ignored: they are replaced by the resections. Throws InputError when the images
/// cannot be started or a group has fewer than two images.
CalibrationRun Calibrate(const Project& project,
                         const CalibrateOptions& options,
                         const std::map<std::string, std::string>& group_of_image);

/// The adjustment of `project` as is (exposures given) with its interior covariance and, with
/// `control_cofactor`, the control part of its cofactor matrix (at the solution: the control
/// weights times 1 - kControlWeightStep, the covariance again, the weights restored).
CalibrationAdjustment RunCalibrationAdjustment(const Project& project,
                                               const AdjustOptions& options,
                                               bool control_cofactor = false);

/// The stability table of the groups' estimates (see the header comment).
StabilityReport GroupStability(const std::vector<GroupCalibration>& groups, double alpha);

/// Upper (1 - alpha) quantile of chi^2(dof), dof >= 1.
double ChiSquareQuantile(double p, int dof);

}  // namespace aerocal::triangulation
