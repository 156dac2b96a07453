#include "evfs/baselines/event_double_integral.h"

#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <string>

#include "evfs/baselines/event_integration.h"
#include "evfs/baselines/scalar_search.h"
#include "evfs/core/error.h"

namespace evfs {
namespace {

// Mean over the pixels of `mask` of the anisotropic total variation |∂x I| + |∂y I| (forward
// differences, zero past the border).
double TotalVariation(const Image& image, const Image& mask) {
  const Eigen::Index rows = image.rows(), cols = image.cols();
  Image tv = Image::Zero(rows, cols);
  if (cols > 1) {
    tv.leftCols(cols - 1) += (image.rightCols(cols - 1) - image.leftCols(cols - 1)).abs();
  }
  if (rows > 1) {
    tv.topRows(rows - 1) += (image.bottomRows(rows - 1) - image.topRows(rows - 1)).abs();
  }
  return (tv * mask).sum() / std::max(mask.sum(), 1.0);
}

// Sobel gradient magnitude (3×3, reflected border).
Image GradientMagnitude(const Image& image) {
  Image copy = image;
  const cv::Mat source(static_cast<int>(copy.rows()), static_cast<int>(copy.cols()), CV_64F,
                       copy.data());
  cv::Mat dx, dy;
  cv::Sobel(source, dx, CV_64F, 1, 0, 3, 1.0, 0.0, cv::BORDER_REFLECT_101);
  cv::Sobel(source, dy, CV_64F, 0, 1, 3, 1.0, 0.0, cv::BORDER_REFLECT_101);
  Image magnitude(image.rows(), image.cols());
  for (Eigen::Index y = 0; y < image.rows(); ++y) {
    for (Eigen::Index x = 0; x < image.cols(); ++x) {
      const double gx = dx.at<double>(static_cast<int>(y), static_cast<int>(x));
      const double gy = dy.at<double>(static_cast<int>(y), static_cast<int>(x));
      magnitude(y, x) = std::sqrt(gx * gx + gy * gy);
    }
  }
  return magnitude;
}

// Pearson's correlation over the pixels of `mask`; 0 when either image is constant there.
double Correlation(const Image& a, const Image& b, const Image& mask) {
  const double count = std::max(mask.sum(), 1.0);
  const Image da = (a - (a * mask).sum() / count) * mask;
  const Image db = (b - (b * mask).sum() / count) * mask;
  const double norm = std::sqrt((da * da).sum() * (db * db).sum());
  return norm > 0.0 ? (da * db).sum() / norm : 0.0;
}

// Adds the number of events per pixel of event frame k (|value|) to `count`.
void AddEventCount(const EventFrames& events, int k, Image* count) {
  const Eigen::Map<const Eigen::ArrayXf> values(events.frame_data(k), count->size());
  Eigen::Map<Eigen::ArrayXd>(count->data(), count->size()) += values.abs().cast<double>();
}

// One blurred frame with the event counts of its scene: everything EDI needs for any threshold.
class EdiModel {
 public:
  EdiModel(const Scene& scene, const BaselineOptions& options)
      : options_(options), count_(CheckedCount(scene)) {
    const FrameObservation& blurred = scene.frames.front();
    blurred_ = blurred.image;
    exposure_first_ = blurred.latent_first;
    exposure_last_ = blurred.latent_last;
    const int64_t begin_ns = count_.timestamp_ns(exposure_first_);
    const int64_t end_ns = count_.timestamp_ns(exposure_last_);
    reference_ = count_.NearestFrame(begin_ns + (end_ns - begin_ns) / 2);
    // Where events happened, widened by a pixel: elsewhere L = B for every c, and static
    // texture there would only dilute both terms (measured: see edi_tv_weight).
    mask_ = Image::Zero(scene.height, scene.width);
    for (int k = 0; k < scene.events.num_frames(); ++k) AddEventCount(scene.events, k, &mask_);
    mask_ = (mask_ > 0.0).cast<double>();
    cv::Mat mask(static_cast<int>(mask_.rows()), static_cast<int>(mask_.cols()), CV_64F,
                 mask_.data());
    cv::dilate(mask.clone(), mask, cv::Mat::ones(3, 3, CV_8U));
    blurred_tv_ = TotalVariation(blurred_, mask_);

    // Events near f: every event frame whose time span meets the window around τ_f.
    const int64_t reference_ns = count_.timestamp_ns(reference_);
    const auto half_window_ns =
        static_cast<int64_t>(std::llround(options.edi_edge_window * (end_ns - begin_ns)));
    edge_events_ = Image::Zero(scene.height, scene.width);
    for (int k = 0; k < scene.events.num_frames(); ++k) {
      const EventFrameSpan& span = scene.events.span(k);
      const bool meets = count_.timestamp_ns(span.latent_first) <= reference_ns + half_window_ns &&
                         count_.timestamp_ns(span.latent_last) >= reference_ns - half_window_ns;
      if (meets) AddEventCount(scene.events, k, &edge_events_);
    }
  }

  const Video& count() const { return count_; }

  // mean over the exposure of exp(c N_s), per pixel.
  Image Denominator(double c) const {
    Image sum = Image::Zero(blurred_.rows(), blurred_.cols());
    for (int s = exposure_first_; s <= exposure_last_; ++s) sum += (c * count_.frame(s)).exp();
    return sum / (exposure_last_ - exposure_first_ + 1);
  }

  // L_t = B exp(c N_t) / mean_s exp(c N_s), clipped to [0, 1] when the options say so.
  Image Latent(int t, double c, const Image& denominator) const {
    Image latent = blurred_ * (c * count_.frame(t)).exp() / denominator;
    if (options_.clamp_to_unit_range) latent = latent.max(0.0).min(1.0);
    return latent;
  }

  EdiSharpness Sharpness(double c) const {
    EdiSharpness sharpness;
    sharpness.reference_latent_frame = reference_;
    const Image latent = Latent(reference_, c, Denominator(c));
    sharpness.tv_ratio = blurred_tv_ > 0.0 ? TotalVariation(latent, mask_) / blurred_tv_ : 1.0;
    sharpness.edge_correlation = Correlation(GradientMagnitude(latent), edge_events_, mask_);
    sharpness.energy = options_.edi_tv_weight * sharpness.tv_ratio - sharpness.edge_correlation;
    return sharpness;
  }

 private:
  static Video CheckedCount(const Scene& scene) {
    if (scene.frames.size() != 1 ||
        scene.frames.front().latent_first == scene.frames.front().latent_last) {
      throw InvalidArgumentError(
          "edi deblurs one blurred frame: the scene must have exactly one frame observation, "
          "spanning an exposure (it has " +
          std::to_string(scene.frames.size()) + " frame observation(s)" +
          (scene.frames.size() == 1 ? ", sharp)" : ")"));
    }
    return CumulativeEventCount(scene);
  }

  const BaselineOptions& options_;
  Video count_;
  Image blurred_;
  int exposure_first_ = 0;
  int exposure_last_ = 0;
  int reference_ = 0;
  double blurred_tv_ = 0.0;
  Image edge_events_;
  Image mask_;
};

}  // namespace

Video EventDoubleIntegral(const Scene& scene, const BaselineOptions& options,
                          double contrast_threshold) {
  CheckContrastThreshold(contrast_threshold, "edi");
  const EdiModel model(scene, options);
  const Image denominator = model.Denominator(contrast_threshold);
  Video latent(scene.height, scene.width, model.count().num_frames());
  for (int t = 0; t < latent.num_frames(); ++t) {
    latent.set_timestamp_ns(t, model.count().timestamp_ns(t));
    latent.frame(t) = model.Latent(t, contrast_threshold, denominator);
  }
  return latent;
}

EdiSharpness EdiSharpnessEnergy(const Scene& scene, const BaselineOptions& options,
                                double contrast_threshold) {
  CheckContrastThreshold(contrast_threshold, "edi");
  return EdiModel(scene, options).Sharpness(contrast_threshold);
}

EdiThreshold ChooseEdiThreshold(const Scene& scene, const BaselineOptions& options) {
  const EdiModel model(scene, options);
  const ScalarMinimum minimum =
      MinimizeOnLogInterval([&](double c) { return model.Sharpness(c).energy; },
                            options.threshold_search_min, options.threshold_search_max);
  EdiThreshold threshold;
  threshold.contrast_threshold = minimum.argument;
  threshold.sharpness = model.Sharpness(minimum.argument);
  threshold.evaluations = minimum.evaluations;
  return threshold;
}

}  // namespace evfs
