// r = F_j(p) - (1/n) sum_{t=a}^{b} H_t(p),  n = b - a + 1   (paper Eq. 3; a blurred frame is
// the mean over its exposure, paper §3.2 deblur)
//
// One residual per observed frame pixel. A sharp frame (a = b) takes one latent voxel; a
// motion-blurred frame takes the n voxels of pixel p over its exposure a..b. When runs of those
// voxels share one value (merged segments, solver/latent_layout.h), each run is one parameter
// block counted with its length: r = F - sum_i c_i x_i / sum_i c_i.
#ifndef EVFS_COST_FUNCTIONS_FRAME_RESIDUAL_H_
#define EVFS_COST_FUNCTIONS_FRAME_RESIDUAL_H_

#include <ceres/autodiff_cost_function.h>
#include <ceres/cost_function.h>
#include <ceres/sized_cost_function.h>
#include <glog/logging.h>

#include <utility>
#include <vector>

#include "evfs/cost_functions/scalar_parameter_blocks.h"

namespace evfs {

/// Residual of one frame pixel against the mean of the latent intensities over its exposure.
/// Parameter blocks: one per run of latent frames, each of size 1. Residual: 1.
struct FrameResidual {
  /// `observed_intensity` is F_j(p); `num_latent_frames` is n = b - a + 1 (at least 1), one
  /// parameter block per latent frame.
  FrameResidual(double observed_intensity, int num_latent_frames)
      : FrameResidual(observed_intensity, std::vector<int>(num_latent_frames, 1)) {}

  /// One parameter block per run; `run_lengths[i]` latent frames share block i's value.
  FrameResidual(double observed_intensity, std::vector<int> run_lengths)
      : observed_intensity(observed_intensity), run_lengths(std::move(run_lengths)) {
    CHECK(!this->run_lengths.empty());
    for (const int length : this->run_lengths) {
      CHECK_GE(length, 1);
      num_latent_frames += length;
    }
  }

  template <typename T>
  bool operator()(T const* const* intensities, T* residual) const {
    T intensity_sum(0.0);
    for (size_t i = 0; i < run_lengths.size(); ++i) {
      intensity_sum += static_cast<double>(run_lengths[i]) * intensities[i][0];
    }
    residual[0] = T(observed_intensity) - intensity_sum / static_cast<double>(num_latent_frames);
    return true;
  }

  /// A fixed-size AutoDiffCostFunction<SharpFrameResidual, 1, 1> when `num_latent_frames` is 1
  /// (a sharp frame, by far the most common), else a DynamicAutoDiffCostFunction with
  /// `num_latent_frames` parameter blocks of size 1.
  static ceres::CostFunction* Create(double observed_intensity, int num_latent_frames) {
    return Create(observed_intensity, std::vector<int>(num_latent_frames, 1));
  }
  /// The same over runs: fixed-size for a single run, else one block per run.
  static ceres::CostFunction* Create(double observed_intensity, std::vector<int> run_lengths);

  const double observed_intensity;
  const std::vector<int> run_lengths;
  int num_latent_frames = 0;  // n: the sum of the run lengths
};

/// FrameResidual for a sharp frame (n = 1) with a fixed parameter layout, so that Ceres can use
/// its fixed-size autodiff. It evaluates FrameResidual's formula.
struct SharpFrameResidual {
  explicit SharpFrameResidual(double observed_intensity) : frame_residual(observed_intensity, 1) {}

  template <typename T>
  bool operator()(const T* intensity, T* residual) const {
    const T* const intensities[] = {intensity};
    return frame_residual(intensities, residual);
  }

  const FrameResidual frame_residual;
};

inline ceres::CostFunction* FrameResidual::Create(double observed_intensity,
                                                  std::vector<int> run_lengths) {
  CHECK(!run_lengths.empty());
  if (run_lengths.size() == 1) {
    // The mean of one run is its value, whatever its length.
    return new ceres::AutoDiffCostFunction<SharpFrameResidual, 1, 1>(
        new SharpFrameResidual(observed_intensity));
  }
  const int num_blocks = static_cast<int>(run_lengths.size());
  return CreateDynamicAutoDiffOverScalarBlocks(
      new FrameResidual(observed_intensity, std::move(run_lengths)), num_blocks,
      /*num_residuals=*/1);
}

/// SharpFrameResidual with its Jacobian written by hand (dr/dH = -1), for the micro-benchmarks
/// that compare autodiff against analytic derivatives.
class FrameResidualAnalytic : public ceres::SizedCostFunction<1, 1> {
 public:
  explicit FrameResidualAnalytic(double observed_intensity)
      : observed_intensity_(observed_intensity) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    residuals[0] = observed_intensity_ - parameters[0][0];
    if (jacobians != nullptr && jacobians[0] != nullptr) jacobians[0][0] = -1.0;
    return true;
  }

 private:
  const double observed_intensity_;
};

}  // namespace evfs

#endif  // EVFS_COST_FUNCTIONS_FRAME_RESIDUAL_H_
