#include "evfs/baselines/scalar_search.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

namespace evfs {

ScalarMinimum MinimizeOnLogInterval(const std::function<double(double)>& f, double low, double high,
                                    int grid_points, double relative_tolerance) {
  CHECK(low > 0.0 && high > low && grid_points >= 3 && relative_tolerance > 0.0);
  ScalarMinimum best;
  std::vector<double> grid(grid_points);
  const double ratio = std::pow(high / low, 1.0 / (grid_points - 1));
  int best_index = 0;
  for (int i = 0; i < grid_points; ++i) {
    grid[i] = i + 1 == grid_points ? high : low * std::pow(ratio, i);
    const double value = f(grid[i]);
    ++best.evaluations;
    if (i == 0 || value < best.value) {
      best.value = value;
      best.argument = grid[i];
      best_index = i;
    }
  }

  // Golden section between the best sample's neighbours; the best point seen is kept, so the
  // result is never worse than the grid's.
  const double inverse_phi = (std::sqrt(5.0) - 1.0) / 2.0;
  double a = grid[std::max(best_index - 1, 0)];
  double b = grid[std::min(best_index + 1, grid_points - 1)];
  double x1 = b - inverse_phi * (b - a), x2 = a + inverse_phi * (b - a);
  double f1 = f(x1), f2 = f(x2);
  best.evaluations += 2;
  while (b - a > relative_tolerance * 0.5 * (a + b)) {
    if (f1 < f2) {
      b = x2;
      x2 = x1;
      f2 = f1;
      x1 = b - inverse_phi * (b - a);
      f1 = f(x1);
    } else {
      a = x1;
      x1 = x2;
      f1 = f2;
      x2 = a + inverse_phi * (b - a);
      f2 = f(x2);
    }
    ++best.evaluations;
  }
  for (const auto& [x, value] : {std::make_pair(x1, f1), std::make_pair(x2, f2)}) {
    if (value < best.value) {
      best.value = value;
      best.argument = x;
    }
  }
  return best;
}

}  // namespace evfs
