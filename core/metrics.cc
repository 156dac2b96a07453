#include "evfs/core/metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "evfs/core/error.h"

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

// EdgeWidth's settings (its comment in metrics.h).
constexpr double kEdgeSigmaPx = 2.0;
constexpr int kEdgeSmoothRadius = 6;  // 3 σ
constexpr double kEdgeTopFraction = 0.03;
constexpr double kEdgeHalfProfilePx = 6.0;
constexpr double kEdgeStepPx = 0.1;
constexpr double kEdgeMinContrast = 0.03;
constexpr int kEdgeMargin = 8;  // the smoothing radius, one pixel of gradient and one of maxima

// A normalised Gaussian of `size` taps (odd) and standard deviation `sigma`.
Eigen::ArrayXd GaussianKernel(int size, double sigma) {
  Eigen::ArrayXd kernel(size);
  const int half = size / 2;
  for (int i = 0; i < size; ++i) {
    const double d = i - half;
    kernel[i] = std::exp(-d * d / (2.0 * sigma * sigma));
  }
  return kernel / kernel.sum();
}

// `image` at (y, x), bilinear, coordinates clamped to the image.
double Bilinear(const Image& image, double y, double x) {
  y = std::clamp(y, 0.0, static_cast<double>(image.rows() - 1));
  x = std::clamp(x, 0.0, static_cast<double>(image.cols() - 1));
  const Eigen::Index y0 = std::min<Eigen::Index>(static_cast<Eigen::Index>(y), image.rows() - 2);
  const Eigen::Index x0 = std::min<Eigen::Index>(static_cast<Eigen::Index>(x), image.cols() - 2);
  const double fy = y - y0, fx = x - x0;
  return (1 - fy) * ((1 - fx) * image(y0, x0) + fx * image(y0, x0 + 1)) +
         fy * ((1 - fx) * image(y0 + 1, x0) + fx * image(y0 + 1, x0 + 1));
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
  const Eigen::ArrayXd kernel = GaussianKernel(kSsimWindow, kSsimSigma);
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

EdgeWidthScore EdgeWidth(const Image& image, const Image& edges_from) {
  CheckSameSize(image, edges_from, "edge width");
  constexpr int kMinSide = 2 * kEdgeMargin + 2;
  if (image.rows() < kMinSide || image.cols() < kMinSide) {
    throw InvalidArgumentError("edge width: images must be at least 18x18, got " +
                               std::to_string(image.cols()) + "x" + std::to_string(image.rows()));
  }
  // smooth(y, x) is edges_from smoothed at (y + r, x + r).
  constexpr int r = kEdgeSmoothRadius;
  const Image smooth = FilterValid(edges_from, GaussianKernel(2 * r + 1, kEdgeSigmaPx));
  const Eigen::Index rows = image.rows(), cols = image.cols();
  // Gradient (central differences of the smoothed image) over the pixels kEdgeMargin from the
  // border; one more pixel on each side for the local maxima.
  Image gy = Image::Zero(rows, cols), gx = Image::Zero(rows, cols);
  for (Eigen::Index y = kEdgeMargin - 1; y <= rows - kEdgeMargin; ++y) {
    for (Eigen::Index x = kEdgeMargin - 1; x <= cols - kEdgeMargin; ++x) {
      gy(y, x) = 0.5 * (smooth(y + 1 - r, x - r) - smooth(y - 1 - r, x - r));
      gx(y, x) = 0.5 * (smooth(y - r, x + 1 - r) - smooth(y - r, x - 1 - r));
    }
  }
  const Image magnitude = (gx.square() + gy.square()).sqrt();
  std::vector<double> values;
  for (Eigen::Index y = kEdgeMargin; y < rows - kEdgeMargin; ++y) {
    for (Eigen::Index x = kEdgeMargin; x < cols - kEdgeMargin; ++x) {
      values.push_back(magnitude(y, x));
    }
  }
  const size_t top = static_cast<size_t>((1.0 - kEdgeTopFraction) * (values.size() - 1));
  std::nth_element(values.begin(), values.begin() + top, values.end());
  const double threshold = values[top];

  const int samples = static_cast<int>(std::lround(2 * kEdgeHalfProfilePx / kEdgeStepPx)) + 1;
  const int end_samples = static_cast<int>(std::lround(1.0 / kEdgeStepPx));
  std::vector<double> profile(samples);
  EdgeWidthScore score;
  double sum = 0.0;
  for (Eigen::Index y = kEdgeMargin; y < rows - kEdgeMargin; ++y) {
    for (Eigen::Index x = kEdgeMargin; x < cols - kEdgeMargin; ++x) {
      const double g = magnitude(y, x);
      if (g <= 0.0 || g < threshold) continue;
      bool local_maximum = true;
      for (int dy = -1; dy <= 1 && local_maximum; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          if (magnitude(y + dy, x + dx) > g) local_maximum = false;
        }
      }
      if (!local_maximum) continue;
      const double ny = gy(y, x) / g, nx = gx(y, x) / g;
      for (int i = 0; i < samples; ++i) {
        const double t = -kEdgeHalfProfilePx + i * kEdgeStepPx;
        profile[i] = Bilinear(image, y + t * ny, x + t * nx);
      }
      double low = 0.0, high = 0.0;
      for (int i = 0; i < end_samples; ++i) {
        low += profile[i] / end_samples;
        high += profile[samples - 1 - i] / end_samples;
      }
      if (high - low < kEdgeMinContrast) continue;
      int at_10 = -1, at_90 = -1;
      double running = -std::numeric_limits<double>::infinity();
      for (int i = 0; i < samples && at_90 < 0; ++i) {
        running = std::max(running, (profile[i] - low) / (high - low));
        if (at_10 < 0 && running >= 0.1) at_10 = i;
        if (running >= 0.9) at_90 = i;
      }
      sum += (at_90 - at_10) * kEdgeStepPx;
      ++score.edges;
    }
  }
  score.mean_px = score.edges > 0 ? sum / score.edges : std::numeric_limits<double>::quiet_NaN();
  return score;
}

}  // namespace evfs
