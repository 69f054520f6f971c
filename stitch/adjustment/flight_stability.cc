#include "stitch/adjustment/flight_stability.h"

#include "calib/core/error.h"
#include "calib/core/progress.h"
#include "stitch/adjustment/f_distribution.h"
#include "stitch/adjustment/mapping_param_names.h"

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

namespace aerocal::stitch {
namespace {

struct Spread {
  double mean = 0, std = 0, median = 0;
};

Spread SpreadOf(const std::vector<double>& x) {
  Spread s;
  const size_t n = x.size();
  if (n == 0) return s;
  for (double v : x) s.mean += v;
  s.mean /= n;
  for (double v : x) s.std += (v - s.mean) * (v - s.mean);
  s.std = n > 1 ? std::sqrt(s.std / (n - 1)) : 0.0;
  auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    const size_t m = v.size() / 2;
    return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
  };
  s.median = median(x);
  return s;
}

/// One parameter of one free sub-image over the frames.
struct Series {
  std::string subimage, name;
  size_t k, i;  // sub-image and parameter index
  std::vector<double> values, sigmas;
};

/// Parameter series of the free sub-images (sub-image order of the first frame).
std::vector<Series> ParameterSeries(const std::vector<const FrameAdjustment*>& frames) {
  std::vector<Series> series;
  const FrameAdjustment& first = *frames.front();
  for (size_t k = 0; k < first.subimages.size(); ++k) {
    const SubimageEstimate& e = first.subimages[k];
    if (e.base) continue;
    const auto names = MappingParamNames(e.model);
    for (size_t i = 0; i < e.params.size(); ++i) series.push_back({e.id, names[i], k, i, {}, {}});
  }
  for (const FrameAdjustment* f : frames)
    for (Series& s : series) {
      s.values.push_back(f->subimages.at(s.k).params.at(s.i));
      s.sigmas.push_back(f->subimages.at(s.k).sigma.at(s.i));
    }
  return series;
}

/// sigma0 against the pooled sigma0 of the flight: F = sigma0^2 / (sum vtpv / sum redundancy)
/// above the F quantile at alpha / n_frames (Bonferroni over the frames).
void FlagSigma0(const std::vector<const FrameAdjustment*>& frames,
                const std::vector<double>& s0px,
                double alpha,
                std::vector<FlaggedFrame>& flags) {
  const size_t n_frames = frames.size();
  double vtpv = 0, redundancy = 0;
  for (const FrameAdjustment* f : frames) {
    vtpv += f->vtpv;
    redundancy += f->redundancy;
  }
  if (!(redundancy > 0 && vtpv > 0)) return;
  const double pooled = vtpv / redundancy;
  char text[240];
  for (size_t f = 0; f < n_frames; ++f) {
    if (frames[f]->redundancy <= 0) continue;
    const double ratio = frames[f]->sigma0 * frames[f]->sigma0 / pooled;
    const double critical =
        FDistributionQuantile(1.0 - alpha / n_frames, frames[f]->redundancy, redundancy);
    if (ratio <= critical) continue;
    std::snprintf(text,
                  sizeof(text),
                  "sigma0_px = %.4g: F = sigma0^2 / pooled sigma0^2 = %.3g > %.3g",
                  s0px[f],
                  ratio,
                  critical);
    flags[f].reasons.push_back(text);
  }
}

/// The parameter table: mean and spread of each series and its mean a-posteriori sigma.
std::vector<ParameterStability> ParameterTable(const std::vector<Series>& series) {
  std::vector<ParameterStability> table;
  for (const Series& s : series) {
    const Spread spread = SpreadOf(s.values);
    ParameterStability p;
    p.subimage = s.subimage;
    p.name = s.name;
    p.mean = spread.mean;
    p.std = spread.std;
    for (double v : s.sigmas) p.mean_sigma += v / s.sigmas.size();
    table.push_back(p);
  }
  return table;
}

/// d^2 of every frame's mapping of sub-image k (n parameters) against the mean of the other
/// frames in `use`: d^2 = dp^T ((1 + 1/others) C)^-1 dp, C the frame's covariance (the mean of
/// the others adds its share); 0 where it cannot be formed.
std::vector<double> MappingDistances(const std::vector<const FrameAdjustment*>& frames,
                                     size_t k,
                                     int n,
                                     const std::vector<bool>& use) {
  const size_t n_frames = frames.size();
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(n);
  int count = 0;
  for (size_t f = 0; f < n_frames; ++f)
    if (use[f]) {
      sum += Eigen::Map<const Eigen::VectorXd>(frames[f]->subimages[k].params.data(), n);
      ++count;
    }
  std::vector<double> d2(n_frames, 0.0);
  for (size_t f = 0; f < n_frames; ++f) {
    const SubimageEstimate& e = frames[f]->subimages[k];
    const Eigen::Map<const Eigen::VectorXd> p(e.params.data(), n);
    const int others = count - (use[f] ? 1 : 0);
    if (others < 2 || e.covariance.rows() != n || e.covariance.isZero(0.0)) continue;
    Eigen::VectorXd centre = sum;
    if (use[f]) centre -= p;
    centre /= others;
    // Equilibrated (unit diagonal): plain parameters span 1e-9 (c1, c2) to 1e3 px (a0, b0).
    const Eigen::VectorXd scale = e.covariance.diagonal().cwiseMax(1e-300).cwiseSqrt();
    const Eigen::VectorXd dp = (p - centre).cwiseQuotient(scale);
    const Eigen::MatrixXd correlation =
        scale.cwiseInverse().asDiagonal() * e.covariance * scale.cwiseInverse().asDiagonal();
    const Eigen::LDLT<Eigen::MatrixXd> ldlt((1.0 + 1.0 / others) * correlation);
    if (ldlt.info() == Eigen::Success) d2[f] = dp.dot(ldlt.solve(dp));
  }
  return d2;
}

/// The joint test per free sub-image: d^2 against n F(n, inf) at alpha / (n_frames n_free),
/// tested twice, the second time without the frames out of line in the reference.
void FlagMappings(const std::vector<const FrameAdjustment*>& frames,
                  double alpha,
                  std::vector<FlaggedFrame>& flags) {
  const size_t n_frames = frames.size();
  const FrameAdjustment& first = *frames.front();
  int n_free = 0;
  for (const SubimageEstimate& e : first.subimages) n_free += !e.base;
  char text[240];
  for (size_t k = 0; k < first.subimages.size(); ++k) {
    const SubimageEstimate& e0 = first.subimages[k];
    if (e0.base) continue;
    const int n = static_cast<int>(e0.params.size());
    const double critical =
        n * FDistributionQuantile(1.0 - alpha / (n_frames * std::max(1, n_free)), n, 1e7);
    std::vector<bool> use(n_frames, true);
    std::vector<double> d2 = MappingDistances(frames, k, n, use);
    for (size_t f = 0; f < n_frames; ++f) use[f] = d2[f] <= critical;
    d2 = MappingDistances(frames, k, n, use);
    for (size_t f = 0; f < n_frames; ++f) {
      if (d2[f] <= critical) continue;
      std::snprintf(text,
                    sizeof(text),
                    "sub-image %s: mapping differs from the other frames' mean by chi2 = %.3g > "
                    "%.3g (%d parameters)",
                    e0.id.c_str(),
                    d2[f],
                    critical,
                    n);
      flags[f].reasons.push_back(text);
    }
  }
}

}  // namespace

ModelStability ComputeStability(calib::MappingModel model,
                                const std::vector<const FrameAdjustment*>& frames,
                                double alpha) {
  ModelStability out;
  out.model = model;
  out.n_frames = static_cast<int>(frames.size());
  if (frames.empty()) return out;
  std::vector<double> s0, s0px;
  for (const FrameAdjustment* f : frames) {
    s0.push_back(f->sigma0);
    s0px.push_back(f->sigma0_px);
  }
  const Spread sigma0 = SpreadOf(s0), sigma0_px = SpreadOf(s0px);
  out.mean_sigma0 = sigma0.mean;
  out.std_sigma0 = sigma0.std;
  out.mean_sigma0_px = sigma0_px.mean;
  out.std_sigma0_px = sigma0_px.std;

  const std::vector<Series> series = ParameterSeries(frames);
  std::vector<FlaggedFrame> flags(frames.size());
  FlagSigma0(frames, s0px, alpha, flags);
  out.parameters = ParameterTable(series);
  FlagMappings(frames, alpha, flags);
  for (size_t f = 0; f < frames.size(); ++f)
    if (!flags[f].reasons.empty()) {
      flags[f].frame = frames[f]->frame;
      out.flagged.push_back(std::move(flags[f]));
    }
  return out;
}

FrameRun StitchFrame(const calib::Camera& camera,
                     const FrameMeasurements& frame,
                     const BatchOptions& options) {
  FrameRun run;
  if (options.model) {
    run.adjustment = AdjustFrame(camera, frame, *options.model, options.stitch);
  } else {
    run.choice = ChooseModel(camera, frame, options.stitch, options.alpha);
    run.adjustment = run.choice->Chosen();
  }
  return run;
}

BatchResult CollectBatch(std::vector<FrameRun> frames, const BatchOptions& options) {
  BatchResult result;
  result.frames = std::move(frames);
  // Stability of every model adjusted in all frames.
  for (calib::MappingModel model : calib::kAllMappingModels) {
    std::vector<const FrameAdjustment*> series;
    for (const FrameRun& run : result.frames) {
      if (!run.choice) {
        if (run.adjustment.model == model) series.push_back(&run.adjustment);
        continue;
      }
      for (const ModelCandidate& c : run.choice->candidates)
        if (c.model == model && c.determinable) series.push_back(&c.adjustment);
    }
    if (!series.empty() && series.size() == result.frames.size())
      result.stability.push_back(ComputeStability(model, series, options.alpha));
  }
  return result;
}

BatchResult RunStitchBatch(const calib::Camera& camera,
                           const std::vector<FrameMeasurements>& frames,
                           const BatchOptions& options,
                           Progress* progress) {
  std::vector<FrameRun> runs;
  for (const FrameMeasurements& frame : frames) {
    runs.push_back(StitchFrame(camera, frame, options));
    if (progress) progress->Advance();
  }
  return CollectBatch(std::move(runs), options);
}

calib::MappingModel FlightModel(const BatchResult& result, const BatchOptions& options) {
  if (options.model) return *options.model;
  AEROCAL_CHECK(!result.frames.empty()) << "the flight's model of a batch without frames";
  std::map<calib::MappingModel, int> chosen;
  for (const FrameRun& run : result.frames) ++chosen[run.adjustment.model];
  calib::MappingModel model = chosen.begin()->first;
  for (const auto& [m, n] : chosen)
    if (n > chosen[model]) model = m;
  return model;
}

std::optional<calib::Camera> FlightMeanCamera(const calib::Camera& camera,
                                              const BatchResult& result,
                                              calib::MappingModel model) {
  const auto stability = std::find_if(result.stability.begin(),
                                      result.stability.end(),
                                      [&](const ModelStability& s) { return s.model == model; });
  if (stability == result.stability.end()) return std::nullopt;
  const std::vector<std::string> names = MappingParamNames(model);
  calib::Camera out = camera;
  for (calib::SubimageMapping& s : out.subimages) {
    std::vector<double> params(names.size());
    size_t found = 0;
    for (const ParameterStability& p : stability->parameters)
      if (p.subimage == s.id)
        for (size_t i = 0; i < names.size(); ++i)
          if (names[i] == p.name) {
            params[i] = p.mean;
            ++found;
          }
    if (found != names.size()) continue;  // a base sub-image
    s.model = model;
    s.params = params;
  }
  return out;
}

}  // namespace aerocal::stitch
