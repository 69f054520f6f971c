#include "stitch/adjustment/flight_stability.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "calib/core/progress.h"
#include "stitch/adjustment/mapping_param_names.h"

namespace aerocal::stitch {
namespace {

struct Spread {
  double mean = 0, std = 0, median = 0, robust_std = 0;
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
  std::vector<double> dev;
  for (double v : x) dev.push_back(std::abs(v - s.median));
  s.robust_std = 1.4826 * median(dev);
  return s;
}

}  // namespace

ModelStability ComputeStability(calib::MappingModel model,
                                const std::vector<const FrameAdjustment*>& frames, double alpha) {
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

  // Parameter series of the free sub-images (sub-image order of the first frame).
  struct Series {
    std::string subimage, name;
    size_t k, i;
    std::vector<double> values, sigmas;
  };
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
  const int n_tests = static_cast<int>(series.size()) + 1;
  const double k = std::max(3.0, calib::NormalCriticalValue(alpha / (n_tests * frames.size())));
  std::vector<FlaggedFrame> flags(frames.size());
  char text[200];
  auto check = [&](const Spread& spread, double value, size_t frame, const std::string& what) {
    if (spread.robust_std <= 0) return;
    const double z = (value - spread.median) / spread.robust_std;
    if (std::abs(z) <= k) return;
    std::snprintf(text, sizeof(text), "%s = %.6g is %.1f robust sigma from the flight median %.6g",
                  what.c_str(), value, z, spread.median);
    flags[frame].reasons.push_back(text);
  };
  for (size_t f = 0; f < frames.size(); ++f) check(sigma0_px, s0px[f], f, "sigma0_px");
  for (Series& s : series) {
    const Spread spread = SpreadOf(s.values);
    ParameterStability p;
    p.subimage = s.subimage;
    p.name = s.name;
    p.mean = spread.mean;
    p.std = spread.std;
    for (double v : s.sigmas) p.mean_sigma += v / s.sigmas.size();
    out.parameters.push_back(p);
    for (size_t f = 0; f < frames.size(); ++f)
      check(spread, s.values[f], f, "sub-image " + s.subimage + " " + s.name);
  }
  for (size_t f = 0; f < frames.size(); ++f)
    if (!flags[f].reasons.empty()) {
      flags[f].frame = frames[f]->frame;
      out.flagged.push_back(std::move(flags[f]));
    }
  return out;
}

BatchResult RunStitchBatch(const calib::Camera& camera, const std::vector<FrameMeasurements>& frames,
                           const BatchOptions& options, Progress* progress) {
  BatchResult result;
  for (const FrameMeasurements& frame : frames) {
    FrameRun run;
    if (options.model) {
      run.adjustment = AdjustFrame(camera, frame, *options.model, options.stitch);
    } else {
      run.choice = ChooseModel(camera, frame, options.stitch, options.alpha);
      run.adjustment = run.choice->Chosen();
    }
    result.frames.push_back(std::move(run));
    if (progress) progress->Advance();
  }
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

}  // namespace aerocal::stitch
