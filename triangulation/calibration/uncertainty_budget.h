// Uncertainty budget of a calibration per the ISO GUM (JCGM 100:2008; JJF 1059.1-2012 is its
// Chinese edition): for every certified quantity the components u_i (already multiplied by their
// sensitivity coefficient c_i, in the quantity's unit), their type (A: statistical, B: other),
// distribution and degrees of freedom; the combined standard uncertainty u_c = sqrt(sum u_i^2);
// the effective degrees of freedom (Welch-Satterthwaite) nu_eff = u_c^4 / sum(u_i^4 / nu_i); the
// coverage factor k = t_{95.45 %}(nu_eff), taken as 2 when nu_eff >= 50 (t differs by < 0.05);
// the expanded uncertainty U = k u_c.
//
// Components (CalibrationRun, calibration.h):
// - A "adjustment": sigma0 sqrt(Qxx) of the run on all images (nu = its redundancy); for a
//   function f of parameters (distortion at a radius) sqrt(g^T C g), g = df/dp.
// - A "group reproducibility": with G >= 2 image groups, the scatter of the groups' values not
//   explained by the adjustment: sqrt(max(0, s_g^2 / G - u_adjustment^2)) (nu = G - 1), s_g the
//   groups' standard deviation.
// - B "control coordinates": the control/target survey sigmas propagated through the adjustment:
//   sqrt(max(0, u_weighted^2 - u_fixed^2)) from the run with the control weighted by its sigmas
//   and a run with them 1000 times smaller (nu = inf).
// - B "target eccentricity": the image offset of a circular target's centre e = c r^2 sin(a)
//   cos(a) / (D^2 - r^2 sin^2 a) (r target radius, D distance, a viewing angle to the target
//   normal, taken as the normal of the control points' best-fit plane; Ahn, Warnecke, Kotowski
//   1999), largest over all observations, rectangular
//   (u_px = e_max / sqrt 3), propagated as an image error: u = u_adjustment u_px / sigma0_px.
// - B user components (temperature, ...): value with its distribution (normal: divisor 1,
//   rectangular sqrt 3, triangular sqrt 6), sensitivity coefficient and degrees of freedom.
// Check-point accuracy m_X, m_Y, m_Z (RMSE, CONVENTIONS.md): A sqrt(1 / (2 n)) m (nu = n - 1),
// B the check points' survey sigma (RMS of sX, sY, sZ). m_0 = sigma0 in um: A sigma0_um / sqrt(2
// r).
#pragma once

#include "triangulation/calibration/calibration.h"

#include <nlohmann/json.hpp>

#include <limits>
#include <string>
#include <vector>

namespace aerocal::triangulation {

struct UncertaintyComponent {
  std::string source;
  std::string type;          // "A" | "B"
  std::string distribution;  // normal | rectangular | triangular
  double value = 0;          // as given, in `value_unit`
  std::string value_unit;
  double divisor = 1;      // value / divisor = standard uncertainty of the input
  double sensitivity = 1;  // c_i, quantity unit per value unit
  double u = 0;            // |c_i| value / divisor, quantity unit
  double dof = std::numeric_limits<double>::infinity();
};

struct BudgetQuantity {
  std::string name, unit, description;
  double value = 0;
  std::vector<UncertaintyComponent> components;
  double u_c = 0, dof_eff = std::numeric_limits<double>::infinity(), k = 2, expanded = 0;
  std::string statement;  // "c = 7.4570 mm, U = 0.0021 mm (k = 2)"
};

/// A user-given type-B component (YAML `components:` of the budget file).
struct UserComponent {
  std::string quantity;  // name of a certified quantity (c, x0, ..., dr@2.0, m_X, ...)
  std::string source;
  double value = 0;  // half-width (rectangular, triangular) or standard uncertainty (normal)
  std::string unit;  // one of BudgetUnits(); empty: the quantity's unit
  std::string distribution = "normal";
  double sensitivity = 1;  // quantity unit per `unit` (after converting `unit` when both are of
                           // one kind: a length in um for a quantity in mm is divided by 1000)
  bool sensitivity_given = false;
  double dof = std::numeric_limits<double>::infinity();
  std::string where;  // FILE:LINE of the component, for messages
};

/// The units a budget component's `unit` may name, by kind: length m, mm, um, nm; image px;
/// angle rad, mrad, deg, arcmin, arcsec; temperature K, degC; ratio 1, %, ppm. A value in a unit
/// of the quantity's kind is converted to the quantity's unit; another kind needs an explicit
/// sensitivity (quantity unit per component unit).
std::string BudgetUnits();

struct BudgetOptions {
  std::vector<double> radii_mm;     // radii of the distortion values, mm, > 0
  double target_radius_mm = 0;      // circular targets' radius in object space; 0: corners
  std::vector<UserComponent> user;  // extra type-B components
};

/// Reads a budget YAML {radii_mm: [...], target_radius_mm: r, components: [{quantity, source,
/// value, unit, distribution, sensitivity, dof}]}; ConfigError with FILE:LINE on bad content.
BudgetOptions ReadBudgetOptions(const std::string& path);

/// The budget of every free interior parameter, the radial and decentring distortion at
/// options.radii_mm, the check-point accuracies and m_0 (`project`: the calibrated block, for
/// the target geometry and the check points' survey sigmas).
std::vector<BudgetQuantity> UncertaintyBudget(const CalibrationRun& run,
                                              const Project& project,
                                              const BudgetOptions& options);

/// k for the effective degrees of freedom (see the header comment).
double CoverageFactor(double dof_eff);
/// "c = 7.4570 mm, U = 0.0021 mm (k = 2)": U to two significant digits, the value to its decimals.
std::string CertificateStatement(
    const std::string& name, double value, double expanded, double k, const std::string& unit);

nlohmann::json BudgetToJson(const std::vector<BudgetQuantity>& budget);

}  // namespace aerocal::triangulation
