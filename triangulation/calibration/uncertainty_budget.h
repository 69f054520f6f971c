// Uncertainty budget of a calibration per the ISO GUM (JCGM 100:2008; JJF 1059.1-2012 is its
// Chinese edition): for every certified quantity the components u_i (already multiplied by their
// sensitivity coefficient c_i, in the quantity's unit), their type (A: statistical, B: other),
// distribution and degrees of freedom; the combined standard uncertainty u_c = sqrt(sum u_i^2);
// the effective degrees of freedom (Welch-Satterthwaite) nu_eff = u_c^4 / sum(u_i^4 / nu_i); the
// coverage factor k = t_{95.45 %}(nu_eff), taken as 2 when nu_eff >= 50 (t differs by < 0.05);
// the expanded uncertainty U = k u_c.
//
// Components of every interior quantity (CalibrationRun, calibration.h), each with its `origin`
// (where it comes from, printed by the certificate):
// - A "image measurements": the part of the adjustment's covariance that comes from the image
//   observations, sigma0^2 Q N_image Q (their a-priori sigmas scaled by the estimated sigma0, nu =
//   redundancy); for a function f of the parameters (distortion at a radius) sqrt(g^T C g),
//   g = df/dp. Without a control run: all of sigma0^2 Q.
// - A "group reproducibility": with G >= 2 image groups, the scatter of the groups' values not
//   explained by the image measurements (the groups share the control):
//   sqrt(max(0, s_g^2 / G - u_image^2)) (nu = G - 1), s_g the groups' standard deviation.
// - B "control coordinates": the control/target survey sigmas, as stated, propagated through the
//   weighted adjustment: Q N_control Q (the GUM's law of propagation for x = Q A^T P l: the
//   sensitivity of x to a control coordinate times its sigma, summed in quadrature), computed as
//   the derivative of Q with respect to the control weights at the solution (calibration.h,
//   CalibrationAdjustment::control_cofactor).
//   Image part + control part = the adjustment's covariance when sigma0 = 1. The field's scale
//   comes from these coordinates (aerocal has no scale-bar observations; the interior parameters
//   do not change under a similarity of object space).
// - B "target eccentricity": the image offset of a circular target's centre e = c r^2 sin(a)
//   cos(a) / (D^2 - r^2 sin^2 a) (r target radius, D distance, a viewing angle to the target
//   normal, taken as the normal of the control points' best-fit plane; Ahn, Warnecke, Kotowski
//   1999), largest over all observations, rectangular
//   (u_px = e_max / sqrt 3), propagated as an image error: u = u_image u_px / sigma0_px.
// - B "pixel pitch": the maker's tolerance +-T of the pixel size (camera file or budget file
//   `pixel_size_tolerance_mm`), rectangular (T / sqrt 3), times df/dpitch: a pitch s times the
//   stated one scales every photo coordinate by s, so the parameter p_k with length exponent e_k
//   (mm: 1, mm^-2: -2, px and 1: 0) becomes p_k s^e_k; zero (and said so) without a tolerance.
// - No component for the a-priori image sigma, even where a file states its uncertainty: a
//   common factor s on the stated sigmas gives P_i / s^2, Q s^2, N_i / s^2 and sigma0^2 / s^2,
//   so sigma0^2 Q N_i Q is unchanged (exactly when the images are the only weighted
//   observations; with control or GNSS/IMU priors the estimator stays unbiased and the
//   propagation uses the weights actually used). What remains is sigma0's own
//   uncertainty from r degrees of freedom: the image component's nu. Counting the stated sigma's
//   uncertainty again would count it twice (tools/certificate/README.md).
// - B user components (temperature, ...) of the budget file: value with its distribution (normal:
//   divisor 1, rectangular sqrt 3, triangular sqrt 6), sensitivity coefficient and degrees of
//   freedom; one named like a default component of its quantity (case aside) replaces it.
// Check-point accuracy m_X, m_Y, m_Z (RMSE, CONVENTIONS.md): A sqrt(1 / (2 n)) m (nu = n - 1),
// B the check points' survey sigma (RMS of sX, sY, sZ). m_0 = sigma0 in um: A sigma0_um / sqrt(2
// r).
#pragma once

#include "triangulation/calibration/calibration.h"

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include <limits>
#include <optional>
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
  std::string origin;  // where the component comes from (input, file, formula), for the document
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
  std::vector<double> radii_mm;  // radii of the distortion values, mm, > 0
  double target_radius_mm = 0;   // circular targets' radius in object space; 0: corners
  /// The pixel pitch's tolerance (+-, mm, [0, 1]); overrides the camera file's.
  std::optional<double> pixel_size_tolerance_mm;
  std::vector<UserComponent> user;  // extra type-B components
};

/// Reads a budget YAML {radii_mm: [...], target_radius_mm: r, pixel_size_tolerance_mm: t,
/// components: [{quantity, source, value, unit, distribution, sensitivity, dof}]}; ConfigError
/// with FILE:LINE on bad content.
BudgetOptions ReadBudgetOptions(const std::string& path);

/// The budget of every free interior parameter, the radial and decentring distortion at
/// options.radii_mm, the check-point accuracies and m_0 (`project`: the calibrated block, for
/// the target geometry and the check points' survey sigmas).
std::vector<BudgetQuantity> UncertaintyBudget(const CalibrationRun& run,
                                              const Project& project,
                                              const BudgetOptions& options);

/// An adjusted camera's interior as the default components of its parameters need it: a test
/// field's CalibrationRun gives it (UncertaintyBudget), and so does a flight's certified
/// adjustment (the flight certificate, tools/certificate_writer.cc).
struct AdjustedInterior {
  calib::InteriorParams params;         // estimated, table units
  std::vector<calib::ParamInfo> table;  // the model's parameter table
  Eigen::MatrixXd covariance;           // sigma0^2 Q of the interior (table order)
  Eigen::MatrixXd control_cofactor;     // Q N_control Q (control_cofactor.h); empty: no control
  double sigma0 = 1;                    // of the adjustment, > 0
  double redundancy = 1;                // degrees of freedom of the type-A part
  double pixel_size_mm = 0;             // the pitch the photo coordinates were made with
  std::optional<double> pitch_tolerance_mm;  // +- (rectangular); none: the component is zero
  std::string pitch_source;                  // where the tolerance is stated
  std::string image_origin, control_origin;  // the components' origins, for the document
};

/// The budget of the interior parameter `index` (table order) of `interior` with the default
/// components that need no test field: A "image measurements" (sigma0^2 Q - sigma0^2 Q N_c Q),
/// B "control coordinates" (Q N_c Q, when known) and B "pixel pitch", combined (u_c, nu_eff, k,
/// U, statement) as UncertaintyBudget does.
BudgetQuantity InteriorParameterBudget(const AdjustedInterior& interior,
                                       int index,
                                       const std::string& description);

/// The budget of an adjusted quantity that is not an interior parameter (a sub-image's mapping
/// entry, a rig head's mount angle): one type-A component "image measurements", its a-posteriori
/// sigma (sigma0^2 Q, the adjustment's covariance: the directions' angular sigmas are part of the
/// observations' weights) with nu = `redundancy`; combined (k, U, statement) as every quantity.
BudgetQuantity AdjustedQuantityBudget(const std::string& name,
                                      const std::string& unit,
                                      const std::string& description,
                                      double value,
                                      double sigma,
                                      double redundancy,
                                      const std::string& origin);

/// k for the effective degrees of freedom (see the header comment).
double CoverageFactor(double dof_eff);
/// "c = 7.4570 mm, U = 0.0021 mm (k = 2)": U to two significant digits, the value to its decimals.
std::string CertificateStatement(
    const std::string& name, double value, double expanded, double k, const std::string& unit);

nlohmann::json BudgetToJson(const std::vector<BudgetQuantity>& budget);

}  // namespace aerocal::triangulation
