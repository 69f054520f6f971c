#include "calib/problem/solve_statistics_json.h"

#include <cmath>

namespace aerocal::calib {

nlohmann::json ResidualGroupsToJson(const std::vector<ResidualGroupStats>& groups) {
  nlohmann::json out = nlohmann::json::array();
  for (const ResidualGroupStats& g : groups)
    out.push_back({{"name", g.name},
                   {"n", g.n_observations},
                   {"rms_sigma", std::isfinite(g.rms) ? nlohmann::json(g.rms) : nlohmann::json()}});
  return out;
}

nlohmann::json SolveStatisticsToJson(const SolveReport& report) {
  return {{"redundancy", report.redundancy},
          {"iterations", report.iterations},
          {"converged", report.converged},
          {"termination", report.termination},
          {"linear_solver", report.linear_solver},
          {"seconds", report.seconds},
          {"groups", ResidualGroupsToJson(report.groups)}};
}

}  // namespace aerocal::calib
