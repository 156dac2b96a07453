#include "core/metrics.h"

#include <cmath>
#include <limits>
#include <string>

#include "core/error.h"

namespace evfs {
namespace {

constexpr int kSsimWindow = 11;
constexpr double kSsimSigma = 1.5;
constexpr double kSsimK1 = 0.01;
constexpr double kSsimK2 = 0.03;

void CheckSameSize(const Image& a, const Image& b, const char* metric) {
  if (a.rows() != b.rows() || a.cols() != b.cols() || a.size() == 0) {
    throw InvalidArgumentError(std::string(metric) +
                               ": images must be non-empty and of one size, got " +
                               std::to_string(a.cols()) + "x" + std::to_string(a.rows()) + " and " +
                               std::to_string(b.cols()) + "x" + std::to_string(b.rows()));
  }
}

Eigen::ArrayXd GaussianKernel() {
  Eigen::ArrayXd kernel(kSsimWindow);
  const int half = kSsimWindow / 2;
  for (int i = 0; i < kSsimWindow; ++i) {
    const double d = i - half;
    kernel[i] = std::exp(-d * d / (2.0 * kSsimSigma * kSsimSigma));
  }
  return kernel / kernel.sum();
}

// Separable 'valid' filtering: the output has (rows - n + 1) × (cols - n + 1) entries.
Image FilterValid(const Image& image, const Eigen::ArrayXd& kernel) {
  const int n = static_cast<int>(kernel.size());
  const Eigen::Index rows = image.rows(), cols = image.cols();
  Image horizontal(rows, cols - n + 1);
  for (Eigen::Index y = 0; y < rows; ++y) {
    for (Eigen::Index x = 0; x + n <= cols; ++x) {
      double sum = 0.0;
      for (int i = 0; i < n; ++i) sum += kernel[i] * image(y, x + i);
      horizontal(y, x) = sum;
    }
  }
  Image out(rows - n + 1, cols - n + 1);
  for (Eigen::Index y = 0; y + n <= rows; ++y) {
    for (Eigen::Index x = 0; x < out.cols(); ++x) {
      double sum = 0.0;
      for (int i = 0; i < n; ++i) sum += kernel[i] * horizontal(y + i, x);
      out(y, x) = sum;
    }
  }
  return out;
}

}  // namespace

double Psnr(const Image& estimate, const Image& reference) {
  CheckSameSize(estimate, reference, "PSNR");
  const double mse = (estimate - reference).square().mean();
  if (mse == 0.0) return std::numeric_limits<double>::infinity();
  return 10.0 * std::log10(1.0 / mse);
}

double Ssim(const Image& estimate, const Image& reference) {
  CheckSameSize(estimate, reference, "SSIM");
  if (estimate.rows() < kSsimWindow || estimate.cols() < kSsimWindow) {
    throw InvalidArgumentError("SSIM: images must be at least 11x11, got " +
                               std::to_string(estimate.cols()) + "x" +
                               std::to_string(estimate.rows()));
  }
  const Eigen::ArrayXd kernel = GaussianKernel();
  const double c1 = (kSsimK1 * 1.0) * (kSsimK1 * 1.0);
  const double c2 = (kSsimK2 * 1.0) * (kSsimK2 * 1.0);
  const Image mu_x = FilterValid(estimate, kernel);
  const Image mu_y = FilterValid(reference, kernel);
  const Image sigma_xx = FilterValid(estimate.square(), kernel) - mu_x.square();
  const Image sigma_yy = FilterValid(reference.square(), kernel) - mu_y.square();
  const Image sigma_xy = FilterValid(estimate * reference, kernel) - mu_x * mu_y;
  const Image ssim_map = ((2.0 * mu_x * mu_y + c1) * (2.0 * sigma_xy + c2)) /
                         ((mu_x.square() + mu_y.square() + c1) * (sigma_xx + sigma_yy + c2));
  return ssim_map.mean();
}

double LaplacianVariance(const Image& image) {
  if (image.rows() < 3 || image.cols() < 3) {
    throw InvalidArgumentError("Laplacian variance needs an image of at least 3x3");
  }
  const Eigen::Index rows = image.rows() - 2, cols = image.cols() - 2;
  const Image laplacian = image.block(0, 1, rows, cols) + image.block(2, 1, rows, cols) +
                          image.block(1, 0, rows, cols) + image.block(1, 2, rows, cols) -
                          4.0 * image.block(1, 1, rows, cols);
  return (laplacian - laplacian.mean()).square().mean();
}

}  // namespace evfs
