// Fixed-partition parallel loops for the deterministic solver (levenberg_marquardt.h): which thread
// computes what is decided before the threads start, and every result is written by exactly one
// thread in a fixed order, so sums never depend on the schedule.
#pragma once

#include <algorithm>
#include <thread>
#include <vector>

namespace aerocal::calib::internal {

/// `requested` threads when > 0, else every core.
inline int ResolveThreads(int requested) {
  if (requested > 0) return requested;
  return static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
}

/// Boundaries cutting items 0 .. n-1 (n = cost.size()) into `parts` contiguous ranges of about
/// equal total cost: part t is [bounds[t], bounds[t + 1]).
inline std::vector<int> BalancedBounds(const std::vector<double>& cost, int parts) {
  const int n = static_cast<int>(cost.size());
  parts = std::max(1, std::min(parts, std::max(n, 1)));
  double total = 0;
  for (double c : cost) total += c;
  std::vector<int> bounds = {0};
  double sum = 0;
  for (int i = 0; i < n && static_cast<int>(bounds.size()) < parts; ++i) {
    sum += cost[i];
    if (sum >= total * bounds.size() / parts) bounds.push_back(i + 1);
  }
  while (static_cast<int>(bounds.size()) <= parts) bounds.push_back(n);
  bounds.back() = n;
  return bounds;
}

/// f(begin, end, part) for every part of `bounds`, part 0 on the calling thread.
template <typename F>
void ParallelRanges(const std::vector<int>& bounds, F&& f) {
  const int parts = static_cast<int>(bounds.size()) - 1;
  std::vector<std::thread> pool;
  for (int t = 1; t < parts; ++t)
    if (bounds[t] < bounds[t + 1])
      pool.emplace_back([&f, &bounds, t] { f(bounds[t], bounds[t + 1], t); });
  if (parts > 0 && bounds[0] < bounds[1]) f(bounds[0], bounds[1], 0);
  for (std::thread& t : pool) t.join();
}

/// Even split of n items into `parts` ranges.
inline std::vector<int> EvenBounds(int n, int parts) {
  parts = std::max(1, std::min(parts, std::max(n, 1)));
  std::vector<int> bounds(parts + 1);
  for (int t = 0; t <= parts; ++t)
    bounds[t] = static_cast<int>(static_cast<long long>(n) * t / parts);
  return bounds;
}

}  // namespace aerocal::calib::internal
