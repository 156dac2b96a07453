// Shared checks for the cost function tests: evaluating a cost function whose parameter blocks
// are all scalars (the evfs layout), probing it with ceres::GradientChecker and comparing two
// implementations of the same residual.
#ifndef EVFS_TESTS_COST_FUNCTIONS_COST_FUNCTION_TESTING_H_
#define EVFS_TESTS_COST_FUNCTIONS_COST_FUNCTION_TESTING_H_

#include <ceres/cost_function.h>
#include <ceres/gradient_checker.h>
#include <ceres/manifold.h>
#include <ceres/numeric_diff_options.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

namespace evfs {
namespace test {

/// Gradient check precision for residuals linear in the intensities: finite differences are
/// exact up to rounding (~1e-12 relative), and a wrong coefficient is off by far more than 1e-8.
constexpr double kLinearGradientCheckPrecision = 1e-8;
/// Autodiff and the hand-written (analytic) Jacobians compute the same expressions in double.
constexpr double kAnalyticTolerance = 1e-12;
/// Random points each randomised test probes; the checks are cheap, a few dozen cover the range.
constexpr int kRandomPoints = 20;

/// Residuals and Jacobians of one evaluation; jacobians[i][k] = d residual_k / d block i.
struct Evaluation {
  bool return_value = false;
  std::vector<double> residuals;
  std::vector<std::vector<double>> jacobians;
};

/// Evaluates `cost_function` with one scalar parameter block per entry of `parameters`.
inline Evaluation Evaluate(const ceres::CostFunction& cost_function,
                           const std::vector<double>& parameters) {
  Evaluation evaluation;
  EXPECT_EQ(cost_function.parameter_block_sizes().size(), parameters.size());
  if (cost_function.parameter_block_sizes().size() != parameters.size()) return evaluation;
  const int num_residuals = cost_function.num_residuals();
  evaluation.residuals.assign(num_residuals, 0.0);
  evaluation.jacobians.assign(parameters.size(), std::vector<double>(num_residuals, 0.0));
  std::vector<const double*> parameter_blocks;
  std::vector<double*> jacobian_blocks;
  for (size_t i = 0; i < parameters.size(); ++i) {
    parameter_blocks.push_back(&parameters[i]);
    jacobian_blocks.push_back(evaluation.jacobians[i].data());
  }
  evaluation.return_value = cost_function.Evaluate(
      parameter_blocks.data(), evaluation.residuals.data(), jacobian_blocks.data());
  return evaluation;
}

/// Numeric differentiation for the gradient checks. The checker uses Ridders' method, whose
/// first step is 2^5 times max(relative step * |x|, relative step): with Ceres' default relative
/// step of 1e-2 that is 0.32 in absolute terms, a third of the intensity range and several times
/// the width 1/alpha of the tanh activation, and the extrapolation then settles on a derivative
/// that is off by ~10%. A relative step of 1e-4 starts at 3.2e-3, inside the activation's
/// curvature scale for alpha up to ~100.
inline ceres::NumericDiffOptions GradientCheckOptions() {
  ceres::NumericDiffOptions options;
  options.ridders_relative_initial_step_size = 1e-4;
  return options;
}

/// Probes `cost_function` at `parameters` (one scalar block each) against central differences.
inline void ExpectGradientCheckPasses(const ceres::CostFunction& cost_function,
                                      const std::vector<double>& parameters,
                                      double relative_precision) {
  std::vector<const double*> parameter_blocks;
  for (const double& parameter : parameters) parameter_blocks.push_back(&parameter);
  const std::vector<const ceres::Manifold*>* const all_euclidean = nullptr;
  const ceres::GradientChecker checker(&cost_function, all_euclidean, GradientCheckOptions());
  ceres::GradientChecker::ProbeResults results;
  EXPECT_TRUE(checker.Probe(parameter_blocks.data(), relative_precision, &results))
      << results.error_log;
}

/// Expects both implementations to give the same residuals and Jacobians at `parameters`, each
/// value within `relative_tolerance` of the larger magnitude of the two (or of 1 near zero).
inline void ExpectSameEvaluation(const ceres::CostFunction& expected,
                                 const ceres::CostFunction& actual,
                                 const std::vector<double>& parameters, double relative_tolerance) {
  const Evaluation expected_evaluation = Evaluate(expected, parameters);
  const Evaluation actual_evaluation = Evaluate(actual, parameters);
  ASSERT_TRUE(expected_evaluation.return_value);
  ASSERT_TRUE(actual_evaluation.return_value);
  const auto expect_close = [relative_tolerance](double expected_value, double actual_value) {
    const double scale = std::max({1.0, std::abs(expected_value), std::abs(actual_value)});
    EXPECT_NEAR(actual_value, expected_value, relative_tolerance * scale);
  };
  ASSERT_EQ(actual_evaluation.residuals.size(), expected_evaluation.residuals.size());
  for (size_t k = 0; k < expected_evaluation.residuals.size(); ++k) {
    expect_close(expected_evaluation.residuals[k], actual_evaluation.residuals[k]);
  }
  for (size_t i = 0; i < parameters.size(); ++i) {
    for (size_t k = 0; k < expected_evaluation.residuals.size(); ++k) {
      expect_close(expected_evaluation.jacobians[i][k], actual_evaluation.jacobians[i][k]);
    }
  }
}

/// Expects every residual and Jacobian entry of `evaluation` to be finite.
inline void ExpectFinite(const Evaluation& evaluation) {
  EXPECT_TRUE(evaluation.return_value);
  for (const double residual : evaluation.residuals) EXPECT_TRUE(std::isfinite(residual));
  for (const std::vector<double>& jacobian : evaluation.jacobians) {
    for (const double entry : jacobian) EXPECT_TRUE(std::isfinite(entry));
  }
}

/// `count` intensities drawn uniformly from [low, high).
inline std::vector<double> RandomIntensities(std::mt19937* rng, int count, double low,
                                             double high) {
  std::uniform_real_distribution<double> distribution(low, high);
  std::vector<double> intensities(count);
  for (double& intensity : intensities) intensity = distribution(*rng);
  return intensities;
}

}  // namespace test
}  // namespace evfs

#endif  // EVFS_TESTS_COST_FUNCTIONS_COST_FUNCTION_TESTING_H_
