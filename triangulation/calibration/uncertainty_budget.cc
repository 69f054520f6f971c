#include "triangulation/calibration/uncertainty_budget.h"

#include "calib/camera/rotation.h"
#include "calib/core/csv.h"
#include "calib/core/error.h"
#include "calib/core/string_printf.h"
#include "calib/core/yaml_util.h"
#include "stitch/adjustment/f_distribution.h"
#include "triangulation/calibration/distortion_figure.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <optional>
#include <string_view>

namespace aerocal::triangulation {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// Degrees of freedom from which k = 2 is kept (t_95.45(50) = 2.05).
constexpr double kLargeDof = 50.0;

double Divisor(const std::string& distribution, const std::string& where) {
  if (distribution == "normal") return 1.0;
  if (distribution == "rectangular") return std::sqrt(3.0);
  if (distribution == "triangular") return std::sqrt(6.0);
  throw ConfigError(where + ": distribution must be normal, rectangular or triangular (got " +
                    distribution + ")");
}

// A quantity as a function of the interior parameters: value and gradient (table order).
struct InteriorFunction {
  std::string name, unit, description;
  std::function<double(const calib::InteriorParams&)> f;
};

Eigen::VectorXd Gradient(const InteriorFunction& q, const calib::InteriorParams& p) {
  Eigen::VectorXd g(p.size());
  for (int k = 0; k < p.size(); ++k) {
    calib::InteriorParams hi = p, lo = p;
    const double h = 1e-6 * std::max(1e-6, std::abs(p[k]));
    hi[k] += h;
    lo[k] -= h;
    g(k) = (q.f(hi) - q.f(lo)) / (2 * h);
  }
  return g;
}

double Propagate(const InteriorFunction& q,
                 const calib::InteriorParams& p,
                 const Eigen::MatrixXd& covariance) {
  if (covariance.rows() != p.size()) return std::nan("");
  const Eigen::VectorXd g = Gradient(q, p);
  return std::sqrt(std::max(0.0, g.dot(covariance * g)));
}

void Finish(BudgetQuantity* q) {
  double sum2 = 0, sum4 = 0;
  for (const auto& c : q->components) {
    sum2 += c.u * c.u;
    if (std::isfinite(c.dof) && c.dof > 0) sum4 += std::pow(c.u, 4) / c.dof;
  }
  q->u_c = std::sqrt(sum2);
  q->dof_eff = sum4 > 0 ? std::pow(q->u_c, 4) / sum4 : kInf;
  q->k = CoverageFactor(q->dof_eff);
  q->expanded = q->k * q->u_c;
  q->statement = CertificateStatement(q->name, q->value, q->expanded, q->k, q->unit);
}

UncertaintyComponent Component(const std::string& source,
                               const std::string& type,
                               double u,
                               double dof,
                               const std::string& unit,
                               const std::string& distribution = "normal") {
  UncertaintyComponent c;
  c.source = source;
  c.type = type;
  c.distribution = distribution;
  c.value = u;
  c.value_unit = unit;
  c.u = u;
  c.dof = dof;
  return c;
}

// Largest image offset (px) of a circular target's centre over the run's observations.
double MaxEccentricityPx(const CalibrationRun& run, const Project& project, double radius_mm) {
  if (radius_mm <= 0) return 0.0;
  const calib::Camera& camera = project.cameras.at(run.camera);
  const AdjustmentResult& r = run.all.result;
  calib::Camera estimated = camera;
  estimated.interior = r.cameras[0].estimated;
  const double c = estimated.c_mm();
  const double radius_m = radius_mm * 1e-3;
  // Target normal: that of the best-fit plane of the control points (a 3-D field's targets face
  // the field's main direction).
  std::vector<Eigen::Vector3d> control;
  for (const auto& p : project.points)
    if (p.role == PointRole::kControl && p.xyz_m) control.push_back(*p.xyz_m);
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  if (control.size() >= 3) {
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const auto& p : control) mean += p;
    mean /= static_cast<double>(control.size());
    Eigen::MatrixXd centred(control.size(), 3);
    for (size_t i = 0; i < control.size(); ++i) centred.row(i) = (control[i] - mean).transpose();
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(centred, Eigen::ComputeFullV);
    normal = svd.matrixV().col(2);
  }
  std::map<std::string, const ExposureEstimate*> exposures;
  for (const auto& e : r.exposures) exposures[e.image] = &e;
  double max_mm = 0;
  for (const auto& o : project.observations) {
    const auto e = exposures.find(o.image);
    const auto p = r.points_m.find(o.point);
    if (e == exposures.end() || p == r.points_m.end() || normal.isZero()) continue;
    const Eigen::Vector3d ray = p->second - e->second->center_m;
    const double d = ray.norm();
    const double cos_a = std::abs(ray.dot(normal)) / d;
    const double sin_a = std::sqrt(std::max(0.0, 1 - cos_a * cos_a));
    const double e_mm =
        c * radius_m * radius_m * sin_a * cos_a / (d * d - radius_m * radius_m * sin_a * sin_a);
    max_mm = std::max(max_mm, e_mm);
  }
  return max_mm / camera.pixel_size_mm;
}

// The parameters' covariance split by input: the GUM's law of propagation for the weighted
// estimator x = Q A^T P l (Q = N^-1) with uncorrelated image and control observations gives
// Cov(x) = Q A_i^T P_i S_i P_i A_i Q + Q A_c^T P_c S_c P_c A_c Q. The image sigmas are scaled by
// the estimated sigma0 (S_i = sigma0^2 P_i^-1, type A), the control survey sigmas are taken as
// stated (S_c = P_c^-1, type B): image part sigma0^2 Q N_i Q = sigma0^2 (Q - Q N_c Q), control
// part Q N_c Q (CalibrationAdjustment::control_cofactor: with control weights t N_c at one
// linearisation, dQ/dt = -Q N_c Q).
struct CovarianceSplit {
  Eigen::MatrixXd image;    // sigma0^2 Q N_i Q (all of sigma0^2 Q without the control part)
  Eigen::MatrixXd control;  // Q N_c Q; empty without control
};

CovarianceSplit SplitCovariance(const Eigen::MatrixXd& covariance,
                                const Eigen::MatrixXd& control,
                                double s0) {
  CovarianceSplit split;
  split.image = covariance;
  if (!(s0 > 0) || split.image.size() == 0 || control.rows() != split.image.rows()) return split;
  split.control = control;
  split.image -= s0 * s0 * control;
  return split;
}

// Length dimension of a parameter's unit: the photo coordinates (mm) scale with the pixel pitch,
// so mm -> 1, mm^-k -> -k; px and 1 do not change with it.
int LengthExponent(std::string_view unit) {
  if (unit == "mm") return 1;
  if (unit.substr(0, 3) == "mm^") return std::atoi(std::string(unit.substr(3)).c_str());
  return 0;
}

// d quantity / d pitch (quantity unit per mm): a pitch s times the stated one makes every photo
// coordinate s times larger, so the same camera has the parameters p_k s^e_k (e_k their length
// exponent: c' = s c, K1' = K1 / s^2) and the quantity f(p'); central difference in s.
double PitchSensitivity(const InteriorFunction& f,
                        const calib::InteriorParams& p,
                        const std::vector<calib::ParamInfo>& table,
                        double pixel_size_mm) {
  constexpr double kStep = 1e-6;
  const auto scaled = [&](double s) {
    calib::InteriorParams out = p;
    for (size_t k = 0; k < table.size(); ++k) out[k] *= std::pow(s, LengthExponent(table[k].unit));
    return f.f(out);
  };
  return (scaled(1 + kStep) - scaled(1 - kStep)) / (2 * kStep) / pixel_size_mm;
}

// What every interior quantity's default components need, computed once.
struct BudgetInputs {
  calib::InteriorParams params;                           // estimated, table units
  const std::vector<GroupCalibration>* groups = nullptr;  // image groups (test field), or none
  double sigma0_px = 0;
  CovarianceSplit split;
  std::vector<calib::ParamInfo> table;
  double dof_adjustment = 1;
  double eccentricity_px = 0;
  double target_radius_mm = 0;
  double pixel_size_mm = 0;
  std::optional<double> pitch_tolerance_mm;
  std::string pitch_source;  // where the tolerance was stated
  std::string image_origin, control_origin;
};

BudgetInputs MakeBudgetInputs(const CalibrationRun& run,
                              const Project& project,
                              const BudgetOptions& options) {
  BudgetInputs in;
  in.params = run.all.result.cameras[0].estimated;
  in.groups = &run.groups;
  in.sigma0_px = run.all.result.sigma0_px;
  in.split =
      SplitCovariance(run.all.interior_covariance, run.all.control_cofactor, run.all.result.sigma0);
  in.table = calib::CameraModelParams(run.all.result.cameras[0].model);
  in.dof_adjustment = std::max(1, run.all.result.solve.redundancy);
  in.eccentricity_px = MaxEccentricityPx(run, project, options.target_radius_mm);
  in.target_radius_mm = options.target_radius_mm;
  const calib::Camera& camera = project.cameras.at(run.camera);
  in.pixel_size_mm = camera.pixel_size_mm;
  in.pitch_tolerance_mm = options.pixel_size_tolerance_mm ? options.pixel_size_tolerance_mm
                                                          : camera.pixel_size_tolerance_mm;
  in.pitch_source = options.pixel_size_tolerance_mm ? "the budget file" : "the camera file";
  double sum2 = 0;
  for (const auto& o : project.observations) sum2 += o.sigma_px * o.sigma_px;
  const size_t n = project.observations.size();
  // The a-priori sigmas set the weights; their scale is estimated (sigma0, type A); their model
  // (each observation's own sigma, uncorrelated) is an assumption the document states.
  const std::string sigmas =
      n > 0 ? StringPrintf("%zu image observations, a-priori sigma RMS %.3g px",
                           n,
                           std::sqrt(sum2 / static_cast<double>(n)))
            : std::string("the observations' a-priori sigmas");
  in.image_origin = StringPrintf(
      "%s, scaled by sigma0 = %.3g (redundancy %d); their model (each observation's own sigma, "
      "uncorrelated) is assumed",
      sigmas.c_str(),
      run.all.result.sigma0,
      run.all.result.solve.redundancy);
  int n_control = 0;
  for (const auto& p : project.points) n_control += p.role == PointRole::kControl && p.xyz_m;
  in.control_origin = StringPrintf(
      "survey sigmas of %d control points propagated through the adjustment (Q N_control Q; "
      "the scale definition of the field is part of them)",
      n_control);
  return in;
}

UncertaintyComponent PixelPitchComponent(const InteriorFunction& f,
                                         const calib::InteriorParams& p,
                                         const BudgetInputs& in) {
  UncertaintyComponent c = Component("pixel pitch", "B", 0, kInf, "mm", "rectangular");
  c.divisor = std::sqrt(3.0);
  c.sensitivity = PitchSensitivity(f, p, in.table, in.pixel_size_mm);
  if (!in.pitch_tolerance_mm) {
    c.value = 0;
    c.origin = "no tolerance stated (camera file or budget file pixel_size_tolerance_mm)";
    return c;
  }
  c.value = *in.pitch_tolerance_mm;
  c.u = std::abs(c.sensitivity) * c.value / c.divisor;
  c.origin = StringPrintf("+-%g mm of the pixel size %g mm, stated in %s",
                          c.value,
                          in.pixel_size_mm,
                          in.pitch_source.c_str());
  return c;
}

// The default components of one interior quantity (see the header comment).
std::vector<UncertaintyComponent> InteriorComponents(const InteriorFunction& f,
                                                     const BudgetInputs& in) {
  const calib::InteriorParams& p = in.params;
  std::vector<UncertaintyComponent> out;
  const double u_image = Propagate(f, p, in.split.image);
  out.push_back(Component("image measurements", "A", u_image, in.dof_adjustment, f.unit));
  out.back().origin = in.image_origin;
  if (in.groups && in.groups->size() >= 2) {
    // The groups share the control: their scatter is compared with the image part alone.
    std::vector<double> values;
    for (const auto& g : *in.groups)
      if (!g.adjustment.result.cameras.empty())
        values.push_back(f.f(g.adjustment.result.cameras[0].estimated));
    const double n = static_cast<double>(values.size());
    double mean = 0, ss = 0;
    for (double v : values) mean += v / n;
    for (double v : values) ss += (v - mean) * (v - mean);
    const double s2_mean = ss / (n - 1) / n;
    out.push_back(Component("group reproducibility",
                            "A",
                            std::sqrt(std::max(0.0, s2_mean - u_image * u_image)),
                            n - 1,
                            f.unit));
    out.back().origin = StringPrintf(
        "scatter of %zu image groups' values beyond the image measurements' part", values.size());
  }
  if (in.split.control.size() > 0) {
    out.push_back(
        Component("control coordinates", "B", Propagate(f, p, in.split.control), kInf, f.unit));
    out.back().origin = in.control_origin;
  }
  const double sigma0_px = in.sigma0_px;
  if (in.eccentricity_px > 0 && sigma0_px > 0) {
    UncertaintyComponent c = Component("target eccentricity", "B", 0, kInf, "px", "rectangular");
    c.value = in.eccentricity_px;
    c.divisor = std::sqrt(3.0);
    c.sensitivity = u_image / sigma0_px;  // propagated as an image error
    c.u = c.sensitivity * in.eccentricity_px / c.divisor;
    c.origin = StringPrintf("circular targets of radius %g mm: largest centre offset %.3g px",
                            in.target_radius_mm,
                            in.eccentricity_px);
    out.push_back(c);
  }
  out.push_back(PixelPitchComponent(f, p, in));
  return out;
}

// An interior quantity with its default components (not yet combined: Finish).
BudgetQuantity InteriorQuantity(const InteriorFunction& f, const BudgetInputs& in) {
  BudgetQuantity q;
  q.name = f.name;
  q.unit = f.unit;
  q.description = f.description;
  q.value = f.f(in.params);
  q.components = InteriorComponents(f, in);
  return q;
}

}  // namespace

double CoverageFactor(double dof_eff) {
  if (!(dof_eff < kLargeDof)) return 2.0;
  const double t = std::sqrt(stitch::FDistributionQuantile(0.9545, 1.0, std::max(1.0, dof_eff)));
  return std::round(t * 100.0) / 100.0;
}

std::string CertificateStatement(
    const std::string& name, double value, double expanded, double k, const std::string& unit) {
  // A dimensionless quantity (table unit "1", e.g. B1) is written without a unit.
  const std::string u = unit == "1" || unit.empty() ? "" : " " + unit;
  if (!(expanded > 0) || !std::isfinite(expanded))
    return StringPrintf("%s = %.6g%s, U unknown", name.c_str(), value, u.c_str());
  // Two significant digits of U (trailing zeros kept: 1.0e-06, 0.60); the value to the same
  // last decimal.
  const int exponent = static_cast<int>(std::floor(std::log10(expanded)));
  const int decimals = std::max(0, 1 - exponent);
  if (decimals > 8 || std::abs(value) < 1e-3 || std::abs(value) >= 1e6)
    return StringPrintf("%s = %.4e%s, U = %#.2g%s (k = %g)",
                        name.c_str(),
                        value,
                        u.c_str(),
                        expanded,
                        u.c_str(),
                        k);
  return StringPrintf("%s = %.*f%s, U = %.*f%s (k = %g)",
                      name.c_str(),
                      decimals,
                      value,
                      u.c_str(),
                      decimals,
                      expanded,
                      u.c_str(),
                      k);
}

namespace {

bool SameName(const std::string& a, const std::string& b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) ==
                  std::tolower(static_cast<unsigned char>(y));
         });
}

// A unit of a budget component: its kind and its size in the kind's base unit.
struct BudgetUnit {
  const char* name;
  const char* kind;
  double scale;
};
constexpr BudgetUnit kBudgetUnits[] = {{"m", "length", 1.0},
                                       {"mm", "length", 1e-3},
                                       {"um", "length", 1e-6},
                                       {"nm", "length", 1e-9},
                                       {"px", "image", 1.0},
                                       {"rad", "angle", 1.0},
                                       {"mrad", "angle", 1e-3},
                                       {"deg", "angle", M_PI / 180},
                                       {"arcmin", "angle", M_PI / 10800},
                                       {"arcsec", "angle", M_PI / 648000},
                                       {"K", "temperature", 1.0},
                                       {"degC", "temperature", 1.0},
                                       {"1", "ratio", 1.0},
                                       {"%", "ratio", 1e-2},
                                       {"ppm", "ratio", 1e-6}};

const BudgetUnit* FindBudgetUnit(const std::string& name) {
  for (const auto& u : kBudgetUnits)
    if (name == u.name) return &u;
  return nullptr;
}

}  // namespace

std::string BudgetUnits() {
  std::string names;
  for (const auto& u : kBudgetUnits) names += (names.empty() ? "" : ", ") + std::string(u.name);
  return names;
}

BudgetOptions ReadBudgetOptions(const std::string& path) {
  const YAML::Node root = LoadYamlFile(path);
  BudgetOptions options;
  // An empty budget file is a mistake (a wrong file, a failed export), not "no options".
  if (!root || root.IsNull() || (root.IsMap() && root.size() == 0))
    throw InputError(
        path +
        ":1: an empty budget file (expected radii_mm, target_radius_mm, pixel_size_tolerance_mm "
        "or components)");
  if (!root.IsMap()) throw InputError(WhereIs(root, path).ToString() + ": expected a map");
  RejectUnknownKeys(
      root, {"radii_mm", "target_radius_mm", "pixel_size_tolerance_mm", "components"}, path);
  for (const char* list : {"radii_mm", "components"})  // a map or a scalar there is no list
    if (root[list] && !root[list].IsSequence())
      throw InputError(WhereIs(root[list], path).ToString() + ": " + list + " must be a list");
  if (root["radii_mm"]) {
    for (const auto& r : root["radii_mm"])
      options.radii_mm.push_back(YamlBounded(r, path, "radii_mm", 1e-9, 1e6));
  }
  if (root["target_radius_mm"])
    options.target_radius_mm =
        YamlBounded(root["target_radius_mm"], path, "target_radius_mm", 0, 1e6);
  if (root["pixel_size_tolerance_mm"])
    options.pixel_size_tolerance_mm =
        YamlBounded(root["pixel_size_tolerance_mm"], path, "pixel_size_tolerance_mm", 0, 1);
  if (root["components"]) {
    for (const auto& node : root["components"]) {
      RejectUnknownKeys(
          node,
          {"quantity", "source", "value", "unit", "distribution", "sensitivity", "dof"},
          path);
      UserComponent u;
      const std::string where = WhereIs(node, path).ToString();
      if (!node["quantity"] || !node["source"] || !node["value"])
        throw InputError(where + ": a component needs quantity, source and value");
      u.quantity = YamlString(node["quantity"], path, "quantity");
      u.source = YamlString(node["source"], path, "source");
      u.value = YamlBounded(node["value"], path, "value", 0, 1e12);
      u.where = where;
      if (node["unit"]) {
        u.unit = YamlString(node["unit"], path, "unit");
        if (!FindBudgetUnit(u.unit))
          throw InputError(WhereIs(node["unit"], path).ToString() + ": unknown unit '" + u.unit +
                           "' (expected one of " + BudgetUnits() + ")");
      }
      if (node["distribution"])
        u.distribution = YamlString(node["distribution"], path, "distribution");
      Divisor(u.distribution,
              WhereIs(node["distribution"] ? node["distribution"] : node, path).ToString());
      if (node["sensitivity"]) {
        u.sensitivity = YamlBounded(node["sensitivity"], path, "sensitivity", -1e6, 1e6);
        u.sensitivity_given = true;
      }
      if (node["dof"]) u.dof = YamlBounded(node["dof"], path, "dof", 1, 1e12);
      options.user.push_back(u);
    }
  }
  return options;
}

BudgetQuantity InteriorParameterBudget(const AdjustedInterior& interior,
                                       int index,
                                       const std::string& description) {
  BudgetInputs in;
  in.params = interior.params;
  in.split = SplitCovariance(interior.covariance, interior.control_cofactor, interior.sigma0);
  in.table = interior.table;
  in.dof_adjustment = std::max(1.0, interior.redundancy);
  in.pixel_size_mm = interior.pixel_size_mm;
  in.pitch_tolerance_mm = interior.pitch_tolerance_mm;
  in.pitch_source = interior.pitch_source;
  in.image_origin = interior.image_origin;
  in.control_origin = interior.control_origin;
  const InteriorFunction f{std::string(in.table.at(index).name),
                           std::string(in.table.at(index).unit),
                           description,
                           [index](const calib::InteriorParams& p) { return p[index]; }};
  BudgetQuantity q = InteriorQuantity(f, in);
  Finish(&q);
  return q;
}

BudgetQuantity AdjustedQuantityBudget(const std::string& name,
                                      const std::string& unit,
                                      const std::string& description,
                                      double value,
                                      double sigma,
                                      double redundancy,
                                      const std::string& origin) {
  BudgetQuantity q;
  q.name = name;
  q.unit = unit;
  q.description = description;
  q.value = value;
  UncertaintyComponent c =
      Component("image measurements", "A", sigma, std::max(1.0, redundancy), unit);
  c.origin = origin;
  q.components.push_back(c);
  Finish(&q);
  return q;
}

namespace {

// The certified functions of the interior: every free parameter, and the distortion values at the
// radii. Those are the model's own terms (calib::ModelDistortionAtRadius: brown_fraser_10's,
// header), there when a term of their group is free; a camera in a model without such a profile
// certifies its parameters.
std::vector<InteriorFunction> InteriorFunctions(const CameraEstimate& camera,
                                                const std::vector<calib::ParamInfo>& table,
                                                const std::vector<double>& radii_mm) {
  std::vector<InteriorFunction> functions;
  for (int k = 0; k < static_cast<int>(table.size()); ++k) {
    if (!camera.free[k]) continue;
    functions.push_back({std::string(table[k].name),
                         std::string(table[k].unit),
                         "interior parameter",
                         [k](const calib::InteriorParams& p) { return p[k]; }});
  }
  const bool own = calib::HasDistortionAtRadius(camera.model);
  const auto any_free = [&](calib::ParamGroup group) {
    for (int k = 0; k < static_cast<int>(table.size()); ++k)
      if (table[k].group == group && camera.free[k]) return true;
    return false;
  };
  const bool radial = own && any_free(calib::ParamGroup::kRadial);
  const bool decentring = own && any_free(calib::ParamGroup::kDecentering);
  for (double r : radii_mm) {
    if (radial)
      functions.push_back({StringPrintf("dr@%g", r),
                           "um",
                           StringPrintf("radial distortion at r = %g mm", r),
                           [r, model = camera.model](const calib::InteriorParams& p) {
                             return calib::ModelDistortionAtRadius(model, p.data(), r)->radial_um;
                           }});
    if (decentring)
      functions.push_back(
          {StringPrintf("dt@%g", r),
           "um",
           StringPrintf("decentring distortion (magnitude) at r = %g mm", r),
           [r, model = camera.model](const calib::InteriorParams& p) {
             return calib::ModelDistortionAtRadius(model, p.data(), r)->decentring_um;
           }});
  }
  return functions;
}

// The check-point RMSE per axis: its sampling (m / sqrt(2 n), type A) and the RMS of the check
// points' survey sigmas (type B).
void AddCheckPointQuantities(const AdjustmentResult& all,
                             const Project& project,
                             std::vector<BudgetQuantity>* out) {
  if (all.check.n <= 0) return;
  const double n = all.check.n;
  const char* axes[] = {"m_X", "m_Y", "m_Z"};
  Eigen::Vector3d survey = Eigen::Vector3d::Zero();
  int n_survey = 0;
  for (const auto& d : all.check_points)
    if (const GroundPoint* p = project.FindPoint(d.point)) {
      survey += p->sigma_m.cwiseAbs2();
      ++n_survey;
    }
  if (n_survey > 0) survey = (survey / n_survey).cwiseSqrt();
  for (int a = 0; a < 3; ++a) {
    BudgetQuantity q;
    q.name = axes[a];
    q.unit = "mm";
    q.description = "check-point RMSE";
    q.value = 1e3 * all.check.rmse_m(a);
    q.components.push_back(Component(
        "check-point sampling", "A", q.value / std::sqrt(2 * n), std::max(1.0, n - 1), "mm"));
    q.components.back().origin =
        StringPrintf("%d check points: the RMSE's standard deviation m / sqrt(2 n)", all.check.n);
    q.components.push_back(Component("check-point survey", "B", 1e3 * survey(a), kInf, "mm"));
    q.components.back().origin = "RMS of the check points' survey sigmas (points file)";
    out->push_back(q);
  }
}

// m_0: sigma0 of the image measurements, its variance estimate sigma0 / sqrt(2 r).
BudgetQuantity SigmaZeroQuantity(const AdjustmentResult& all, double dof_adjustment) {
  BudgetQuantity q;
  q.name = "m_0";
  q.unit = "um";
  q.description = "sigma0 of the image measurements";
  q.value = all.sigma0_um;
  q.components.push_back(Component("variance estimate",
                                   "A",
                                   all.sigma0_um / std::sqrt(2.0 * dof_adjustment),
                                   dof_adjustment,
                                   "um"));
  q.components.back().origin =
      "sigma0 / sqrt(2 r), redundancy r = " + std::to_string(all.solve.redundancy);
  return q;
}

// A component of the budget file as a type B component of `q`, its value converted to the
// quantity's unit (0.002 um for a quantity in mm is 2e-6 mm; another kind needs the sensitivity
// that converts it). ConfigError naming the budget file's line.
UncertaintyComponent FromBudgetFile(const UserComponent& u, const BudgetQuantity& q) {
  UncertaintyComponent c;
  c.source = u.source;
  c.type = "B";
  c.distribution = u.distribution;
  c.value = u.value;
  c.value_unit = u.unit;
  c.divisor = Divisor(u.distribution, "budget component " + u.source);
  const std::string who = u.where + ": budget component '" + u.source + "' of " + u.quantity;
  const BudgetUnit* from = u.unit.empty() ? nullptr : FindBudgetUnit(u.unit);
  const BudgetUnit* to = FindBudgetUnit(q.unit);
  double factor = 1.0;
  if (from && u.unit != q.unit) {
    if (to && std::string(to->kind) == from->kind)
      factor = from->scale / to->scale;
    else if (!u.sensitivity_given)
      throw ConfigError(who + ": unit " + u.unit + " is no " + (to ? to->kind : q.unit) +
                        "; give its sensitivity (" + q.unit + " per " + u.unit + ")");
  }
  c.sensitivity = u.sensitivity * factor;
  c.u = std::abs(c.sensitivity) * u.value / c.divisor;
  if (!std::isfinite(c.u))
    throw ConfigError(who + ": the standard uncertainty is not finite (value " +
                      FormatNumber(u.value) + " " + u.unit + ", sensitivity " +
                      FormatNumber(u.sensitivity) + ")");
  c.dof = u.dof;
  c.origin = "budget file " + u.where;
  return c;
}

// The budget file's components added to their quantities; one of the same name (case aside)
// replaces the default one: the budget file overrides what aerocal derived (a pitch tolerance
// from a better datasheet, ...).
void AddUserComponents(const BudgetOptions& options, std::vector<BudgetQuantity>* out) {
  for (const auto& u : options.user) {
    auto q = std::find_if(
        out->begin(), out->end(), [&](const BudgetQuantity& b) { return b.name == u.quantity; });
    if (q == out->end())
      throw ConfigError(u.where + ": budget component '" + u.source + "': unknown quantity " +
                        u.quantity + " (not certified by this calibration)");
    UncertaintyComponent c = FromBudgetFile(u, *q);
    const auto same = std::find_if(
        q->components.begin(), q->components.end(), [&](const UncertaintyComponent& d) {
          return SameName(d.source, u.source);
        });
    if (same != q->components.end()) {
      c.origin += " (replaces aerocal's: " + same->origin + ")";
      *same = c;
    } else {
      q->components.push_back(c);
    }
  }
}

}  // namespace

std::vector<BudgetQuantity> UncertaintyBudget(const CalibrationRun& run,
                                              const Project& project,
                                              const BudgetOptions& options) {
  const AdjustmentResult& all = run.all.result;
  if (all.cameras.empty()) return {};
  const BudgetInputs inputs = MakeBudgetInputs(run, project, options);
  std::vector<BudgetQuantity> out;
  for (const auto& f : InteriorFunctions(all.cameras[0], inputs.table, options.radii_mm))
    out.push_back(InteriorQuantity(f, inputs));
  AddCheckPointQuantities(all, project, &out);
  out.push_back(SigmaZeroQuantity(all, inputs.dof_adjustment));
  AddUserComponents(options, &out);
  for (auto& q : out) {
    Finish(&q);
    // A non-finite intermediate (a distortion at an absurd radius, an overflowing component) is
    // refused, never printed as a certified value.
    const bool at_radius = q.name.find('@') != std::string::npos;
    if (std::isinf(q.value) || std::isinf(q.u_c) || (at_radius && !std::isfinite(q.value)))
      throw ConfigError("budget: " + q.name + " (" + q.description + ") is not finite (value " +
                        FormatNumber(q.value) + " " + q.unit + ", u_c " + FormatNumber(q.u_c) +
                        "); check radii_mm / --radii-mm and the components");
  }
  return out;
}

nlohmann::json BudgetToJson(const std::vector<BudgetQuantity>& budget) {
  auto number = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); };
  nlohmann::json out = nlohmann::json::array();
  for (const auto& q : budget) {
    nlohmann::json j = {{"quantity", q.name},
                        {"unit", q.unit},
                        {"description", q.description},
                        {"value", q.value},
                        {"u_c", number(q.u_c)},
                        {"dof_eff", number(q.dof_eff)},
                        {"k", q.k},
                        {"U", number(q.expanded)},
                        {"statement", q.statement}};
    j["components"] = nlohmann::json::array();
    for (const auto& c : q.components)
      j["components"].push_back({{"source", c.source},
                                 {"type", c.type},
                                 {"distribution", c.distribution},
                                 {"value", number(c.value)},
                                 {"value_unit", c.value_unit},
                                 {"divisor", c.divisor},
                                 {"sensitivity", number(c.sensitivity)},
                                 {"u", number(c.u)},
                                 {"dof", number(c.dof)},
                                 {"origin", c.origin}});
    out.push_back(j);
  }
  return out;
}

}  // namespace aerocal::triangulation
