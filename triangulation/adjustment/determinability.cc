#include "triangulation/adjustment/determinability.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace aerocal::triangulation {

Determinability AssessDeterminability(const calib::CovarianceReport& cov,
                                      const std::string& prefix,
                                      double threshold) {
  Determinability det;
  det.covariance_ok = cov.ok;
  det.message = cov.message;
  det.covariance_method = cov.method;
  det.undetermined = cov.undetermined;
  if (!cov.ok) {
    det.warnings.push_back("the block cannot determine all parameters: " + cov.message);
    return det;
  }
  const int n = static_cast<int>(cov.names.size());
  for (int i = 0; i < n; ++i) {
    if (cov.names[i].rfind(prefix, 0) != 0 || !cov.free[i]) continue;
    int partner = -1;
    double best = 0.0;
    for (int k = 0; k < n; ++k)
      if (k != i && cov.free[k] && std::abs(cov.Correlation(i, k)) > std::abs(best)) {
        best = cov.Correlation(i, k);
        partner = k;
      }
    if (partner < 0 || !(std::abs(best) > threshold)) continue;
    const bool listed = std::any_of(det.high_correlations.begin(),
                                    det.high_correlations.end(),
                                    [&](const calib::HighCorrelation& h) {
                                      return h.a == cov.names[partner] && h.b == cov.names[i];
                                    });
    if (listed) continue;
    det.high_correlations.push_back({cov.names[i], cov.names[partner], best});
    char text[512];
    std::snprintf(text,
                  sizeof(text),
                  "%s is not separable from %s (correlation %.4f): the block cannot determine it "
                  "independently; add GNSS camera centres, control at different heights, cross "
                  "strips, or an a-priori sigma",
                  cov.names[i].c_str(),
                  cov.names[partner].c_str(),
                  best);
    det.warnings.push_back(text);
  }
  return det;
}

nlohmann::json DeterminabilityToJson(const Determinability& d, bool determinable) {
  nlohmann::json correlations = nlohmann::json::array();
  for (const auto& h : d.high_correlations)
    correlations.push_back({{"a", h.a}, {"b", h.b}, {"correlation", h.correlation}});
  return {{"determinable", determinable},
          {"message", d.message},
          {"covariance_method", d.covariance_method},
          {"undetermined", d.undetermined},
          {"high_correlations", correlations},
          {"warnings", d.warnings}};
}

}  // namespace aerocal::triangulation
