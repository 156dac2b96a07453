// Minimising a function of one positive parameter (a contrast threshold) over an interval: a
// log-spaced grid to find the best basin, then golden-section search (J. Kiefer, "Sequential
// minimax search for a maximum", Proc. AMS 1953) inside the grid cells around the best point.
#ifndef EVFS_BASELINES_SCALAR_SEARCH_H_
#define EVFS_BASELINES_SCALAR_SEARCH_H_

#include <functional>

namespace evfs {

struct ScalarMinimum {
  double argument = 0.0;
  double value = 0.0;
  int evaluations = 0;
};

/// Minimises `f` over [low, high] (0 < low < high): `grid_points` (>= 3) log-spaced samples,
/// then golden-section search between the neighbours of the best sample until the bracket is
/// narrower than `relative_tolerance` times its centre. A multimodal f is minimised within the
/// grid's resolution.
ScalarMinimum MinimizeOnLogInterval(const std::function<double(double)>& f, double low, double high,
                                    int grid_points = 16, double relative_tolerance = 1e-3);

}  // namespace evfs

#endif  // EVFS_BASELINES_SCALAR_SEARCH_H_
