#include "stitch/io/frame_run_json.h"

#include "calib/core/error.h"

#include <cmath>
#include <limits>

namespace aerocal::stitch {
namespace {

using nlohmann::json;

// JSON has no NaN or infinity: those travel as strings, every finite double as a number.
json Num(double x) {
  if (std::isfinite(x)) return x;
  return std::isnan(x) ? "nan" : (x > 0 ? "inf" : "-inf");
}

double ToNum(const json& j) {
  if (!j.is_string()) return j.get<double>();
  const std::string s = j.get<std::string>();
  if (s == "nan") return std::numeric_limits<double>::quiet_NaN();
  if (s == "inf") return std::numeric_limits<double>::infinity();
  if (s == "-inf") return -std::numeric_limits<double>::infinity();
  throw InputError("frame run: not a number: '" + s + "'");
}

json Vec(const Eigen::Vector2d& v) { return {Num(v.x()), Num(v.y())}; }
Eigen::Vector2d ToVec(const json& j) { return {ToNum(j.at(0)), ToNum(j.at(1))}; }

json Nums(const std::vector<double>& v) {
  json a = json::array();
  for (double x : v) a.push_back(Num(x));
  return a;
}
std::vector<double> ToNums(const json& j) {
  std::vector<double> v;
  for (const auto& x : j) v.push_back(ToNum(x));
  return v;
}

json Matrix(const Eigen::MatrixXd& m) {
  json rows = json::array();
  for (int r = 0; r < m.rows(); ++r) {
    std::vector<double> row(m.cols());
    for (int c = 0; c < m.cols(); ++c) row[c] = m(r, c);
    rows.push_back(Nums(row));
  }
  return {{"rows", m.rows()}, {"cols", m.cols()}, {"values", rows}};
}
Eigen::MatrixXd ToMatrix(const json& j) {
  Eigen::MatrixXd m(j.at("rows").get<int>(), j.at("cols").get<int>());
  for (int r = 0; r < m.rows(); ++r)
    for (int c = 0; c < m.cols(); ++c) m(r, c) = ToNum(j.at("values").at(r).at(c));
  return m;
}

json Model(calib::MappingModel m) { return std::string(calib::MappingModelName(m)); }
calib::MappingModel ToModel(const json& j) {
  const auto m = calib::ParseMappingModel(j.get<std::string>());
  if (!m) throw InputError("frame run: unknown mapping model '" + j.get<std::string>() + "'");
  return *m;
}

json SubimageToJson(const SubimageEstimate& s) {
  json corners = json::array();
  for (const CornerPrecision& c : s.corners)
    corners.push_back({{"uv", Vec(c.uv)},
                       {"virtual_px", Vec(c.virtual_px)},
                       {"sigma_U_px", Num(c.sigma_U_px)},
                       {"sigma_V_px", Num(c.sigma_V_px)}});
  return {{"id", s.id},
          {"model", Model(s.model)},
          {"base", s.base},
          {"params", Nums(s.params)},
          {"sigma", Nums(s.sigma)},
          {"covariance", Matrix(s.covariance)},
          {"corners", corners},
          {"max_corner_sigma_px", Num(s.max_corner_sigma_px)}};
}
SubimageEstimate SubimageFromJson(const json& j) {
  SubimageEstimate s;
  s.id = j.at("id").get<std::string>();
  s.model = ToModel(j.at("model"));
  s.base = j.at("base").get<bool>();
  s.params = ToNums(j.at("params"));
  s.sigma = ToNums(j.at("sigma"));
  s.covariance = ToMatrix(j.at("covariance"));
  for (size_t i = 0; i < s.corners.size(); ++i) {
    const json& c = j.at("corners").at(i);
    s.corners[i] = {ToVec(c.at("uv")),
                    ToVec(c.at("virtual_px")),
                    ToNum(c.at("sigma_U_px")),
                    ToNum(c.at("sigma_V_px"))};
  }
  s.max_corner_sigma_px = ToNum(j.at("max_corner_sigma_px"));
  return s;
}

json RejectedToJson(const std::vector<RejectedObservation>& rejected) {
  json a = json::array();
  for (const auto& r : rejected)
    a.push_back({{"point", r.point},
                 {"subimage", r.subimage},
                 {"reference", r.reference},
                 {"w", Num(r.w)},
                 {"v_px", Vec(r.v_px)}});
  return a;
}
std::vector<RejectedObservation> RejectedFromJson(const json& a) {
  std::vector<RejectedObservation> out;
  for (const auto& r : a)
    out.push_back({r.at("point").get<std::string>(),
                   r.at("subimage").get<std::string>(),
                   r.at("reference").get<bool>(),
                   ToNum(r.at("w")),
                   ToVec(r.at("v_px"))});
  return out;
}

json AdjustmentToJson(const FrameAdjustment& a) {
  json j = {{"frame", a.frame},
            {"model", Model(a.model)},
            {"converged", a.converged},
            {"iterations", a.iterations},
            {"sigma0", Num(a.sigma0)},
            {"sigma0_px", Num(a.sigma0_px)},
            {"vtpv", Num(a.vtpv)},
            {"redundancy", a.redundancy},
            {"n_observations", a.n_observations},
            {"n_unknowns", a.n_unknowns},
            {"n_ties", a.n_ties},
            {"n_references", a.n_references},
            {"n_single_ray_points", a.n_single_ray_points},
            {"covariance_ok", a.covariance_ok},
            {"diagnostics", a.diagnostics},
            {"max_corner_sigma_px", Num(a.max_corner_sigma_px)},
            {"rejected", RejectedToJson(a.rejected)}};
  j["subimages"] = json::array();
  for (const auto& s : a.subimages) j["subimages"].push_back(SubimageToJson(s));
  j["residuals"] = json::array();
  for (const auto& r : a.residuals)
    j["residuals"].push_back({{"point", r.point},
                              {"subimage", r.subimage},
                              {"reference", r.reference},
                              {"v_px", Vec(r.v_px)},
                              {"sigma_px", Num(r.sigma_px)}});
  return j;
}

FrameAdjustment AdjustmentFromJson(const json& j) {
  FrameAdjustment a;
  a.frame = j.at("frame").get<std::string>();
  a.model = ToModel(j.at("model"));
  a.converged = j.at("converged").get<bool>();
  a.iterations = j.at("iterations").get<int>();
  a.sigma0 = ToNum(j.at("sigma0"));
  a.sigma0_px = ToNum(j.at("sigma0_px"));
  a.vtpv = ToNum(j.at("vtpv"));
  a.redundancy = j.at("redundancy").get<int>();
  a.n_observations = j.at("n_observations").get<int>();
  a.n_unknowns = j.at("n_unknowns").get<int>();
  a.n_ties = j.at("n_ties").get<int>();
  a.n_references = j.at("n_references").get<int>();
  a.n_single_ray_points = j.at("n_single_ray_points").get<int>();
  a.covariance_ok = j.at("covariance_ok").get<bool>();
  a.diagnostics = j.at("diagnostics").get<std::vector<std::string>>();
  a.max_corner_sigma_px = ToNum(j.at("max_corner_sigma_px"));
  a.rejected = RejectedFromJson(j.at("rejected"));
  for (const auto& s : j.at("subimages")) a.subimages.push_back(SubimageFromJson(s));
  for (const auto& r : j.at("residuals"))
    a.residuals.push_back({r.at("point").get<std::string>(),
                           r.at("subimage").get<std::string>(),
                           r.at("reference").get<bool>(),
                           ToVec(r.at("v_px")),
                           ToNum(r.at("sigma_px"))});
  return a;
}

json CandidateToJson(const ModelCandidate& c) {
  json j = {{"model", Model(c.model)},
            {"determinable", c.determinable},
            {"refusal", c.refusal},
            {"tested", c.tested},
            {"against", c.against},
            {"f", Num(c.f)},
            {"f_critical", Num(c.f_critical)},
            {"p_value", Num(c.p_value)},
            {"df1", c.df1},
            {"df2", c.df2},
            {"significant", c.significant}};
  j["adjustment"] = AdjustmentToJson(c.adjustment);
  return j;
}

ModelCandidate CandidateFromJson(const json& j) {
  ModelCandidate c;
  c.model = ToModel(j.at("model"));
  c.determinable = j.at("determinable").get<bool>();
  c.refusal = j.at("refusal").get<std::string>();
  c.adjustment = AdjustmentFromJson(j.at("adjustment"));
  c.tested = j.at("tested").get<bool>();
  c.against = j.at("against").get<std::string>();
  c.f = ToNum(j.at("f"));
  c.f_critical = ToNum(j.at("f_critical"));
  c.p_value = ToNum(j.at("p_value"));
  c.df1 = j.at("df1").get<int>();
  c.df2 = j.at("df2").get<int>();
  c.significant = j.at("significant").get<bool>();
  return c;
}

}  // namespace

json FrameRunToJson(const FrameRun& run) {
  json j = {{"adjustment", AdjustmentToJson(run.adjustment)}, {"choice", nullptr}};
  if (run.choice) {
    const ModelChoice& c = *run.choice;
    json candidates = json::array();
    for (const auto& candidate : c.candidates) candidates.push_back(CandidateToJson(candidate));
    j["choice"] = {{"chosen", Model(c.chosen)},
                   {"test", c.test},
                   {"alpha", Num(c.alpha)},
                   {"reason", c.reason},
                   {"candidates", candidates},
                   {"rejected", RejectedToJson(c.rejected)}};
  }
  return j;
}

FrameRun FrameRunFromJson(const json& document, const std::string& path) {
  try {
    FrameRun run;
    run.adjustment = AdjustmentFromJson(document.at("adjustment"));
    const json& c = document.at("choice");
    if (!c.is_null()) {
      ModelChoice choice;
      choice.chosen = ToModel(c.at("chosen"));
      choice.test = c.at("test").get<std::string>();
      choice.alpha = ToNum(c.at("alpha"));
      choice.reason = c.at("reason").get<std::string>();
      for (const auto& candidate : c.at("candidates"))
        choice.candidates.push_back(CandidateFromJson(candidate));
      choice.rejected = RejectedFromJson(c.at("rejected"));
      run.choice = std::move(choice);
    }
    return run;
  } catch (const json::exception& e) {
    throw InputError(path + ": not a stitching frame run (" + e.what() + ")");
  } catch (const InputError& e) {
    throw InputError(path + ": " + e.what());
  }
}

}  // namespace aerocal::stitch
