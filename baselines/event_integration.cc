#include "evfs/baselines/event_integration.h"

#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "evfs/core/error.h"

namespace evfs {
namespace {

// The sharp frames a latent frame is integrated from: `first` alone, or blended with `second`
// (the later one) with weight `weight_second`.
struct Anchors {
  int first = -1;   // index into the sharp frames
  int second = -1;  // -1 for none
  double weight_second = 0.0;
};

Anchors ChooseAnchors(const std::vector<int>& anchor_latent, const std::vector<int64_t>& latent_ns,
                      int t, IntegrationDirection direction) {
  const int count = static_cast<int>(anchor_latent.size());
  // The last sharp frame at or before t and the first at or after it.
  int before = -1, after = -1;
  for (int i = 0; i < count; ++i) {
    if (anchor_latent[i] <= t) before = i;
    if (anchor_latent[i] >= t && after < 0) after = i;
  }
  Anchors anchors;
  switch (direction) {
    case IntegrationDirection::kForward:
      anchors.first = before >= 0 ? before : after;
      break;
    case IntegrationDirection::kBackward:
      anchors.first = after >= 0 ? after : before;
      break;
    case IntegrationDirection::kBoth:
      anchors.first = before >= 0 ? before : after;
      if (before >= 0 && after >= 0 && before != after) {
        anchors.second = after;
        const int64_t begin_ns = latent_ns[anchor_latent[before]];
        anchors.weight_second = static_cast<double>(latent_ns[t] - begin_ns) /
                                static_cast<double>(latent_ns[anchor_latent[after]] - begin_ns);
      }
      break;
  }
  return anchors;
}

}  // namespace

Video CumulativeEventCount(const Scene& scene) {
  const std::vector<int64_t>& latent_ns = scene.latent_timestamps_ns();
  const int num_latent = static_cast<int>(latent_ns.size());
  Video count(scene.height, scene.width, num_latent);
  for (int t = 0; t < num_latent; ++t) count.set_timestamp_ns(t, latent_ns[t]);
  // First the events of each step (a frame's count shared evenly by the steps it spans) in
  // frame t + 1, then the running sum.
  const Eigen::Index pixels = count.pixels_per_frame();
  const auto frame = [&](int t) { return Eigen::Map<Eigen::ArrayXd>(count.frame_data(t), pixels); };
  for (int k = 0; k < scene.events.num_frames(); ++k) {
    const EventFrameSpan& span = scene.events.span(k);
    const Eigen::Map<const Eigen::ArrayXf> values(scene.events.frame_data(k), pixels);
    const double share = 1.0 / (span.latent_last - span.latent_first);
    for (int s = span.latent_first; s < span.latent_last; ++s) {
      frame(s + 1) += share * values.cast<double>();
    }
  }
  for (int t = 1; t < num_latent; ++t) frame(t) += frame(t - 1);
  return count;
}

std::vector<int> SharpFrameIndices(const Scene& scene) {
  std::vector<int> sharp;
  for (int j = 0; j < static_cast<int>(scene.frames.size()); ++j) {
    if (scene.frames[j].latent_first == scene.frames[j].latent_last) sharp.push_back(j);
  }
  std::stable_sort(sharp.begin(), sharp.end(), [&](int a, int b) {
    return scene.frames[a].latent_first < scene.frames[b].latent_first;
  });
  sharp.erase(std::unique(sharp.begin(), sharp.end(),
                          [&](int a, int b) {
                            return scene.frames[a].latent_first == scene.frames[b].latent_first;
                          }),
              sharp.end());
  return sharp;
}

void GaussianBlurImage(double sigma_px, Image* image) {
  if (sigma_px <= 0.0) return;
  cv::Mat wrapped(static_cast<int>(image->rows()), static_cast<int>(image->cols()), CV_64F,
                  image->data());
  const cv::Mat source = wrapped.clone();
  cv::GaussianBlur(source, wrapped, cv::Size(0, 0), sigma_px, sigma_px, cv::BORDER_REFLECT_101);
}

Image ImageToDomain(const Image& image, IntegrationDomain domain, double log_offset) {
  return image.unaryExpr(
      [&](double intensity) { return ToIntegrationDomain(intensity, domain, log_offset); });
}

Image ImageFromDomain(const Image& values, IntegrationDomain domain, double log_offset,
                      bool clamp) {
  return values.unaryExpr([&](double value) {
    const double intensity = FromIntegrationDomain(value, domain, log_offset);
    return clamp ? std::clamp(intensity, 0.0, 1.0) : intensity;
  });
}

Video IntegrateEvents(const Scene& scene, const BaselineOptions& options,
                      double contrast_threshold) {
  CheckContrastThreshold(contrast_threshold, "integrate");
  const std::vector<int> sharp = SharpFrameIndices(scene);
  if (sharp.empty()) {
    throw InvalidArgumentError(
        "event integration starts from a sharp frame, and this scene has none (a blurred frame "
        "is deblurred by edi)");
  }
  std::vector<int> anchor_latent;
  std::vector<Image> anchor_values;
  for (int j : sharp) {
    anchor_latent.push_back(scene.frames[j].latent_first);
    anchor_values.push_back(
        ImageToDomain(scene.frames[j].image, options.domain, options.log_offset));
  }
  const Video count = CumulativeEventCount(scene);
  const std::vector<int64_t>& latent_ns = scene.latent_timestamps_ns();
  Video latent(scene.height, scene.width, count.num_frames());
  for (int t = 0; t < latent.num_frames(); ++t) {
    latent.set_timestamp_ns(t, latent_ns[t]);
    const Anchors anchors = ChooseAnchors(anchor_latent, latent_ns, t, options.direction);
    // base: g of the sharp frame(s); reference: the event count at them, blended alike.
    Image base = anchor_values[anchors.first];
    Image reference = count.frame(anchor_latent[anchors.first]);
    if (anchors.second >= 0) {
      const double w = anchors.weight_second;
      base = (1.0 - w) * base + w * anchor_values[anchors.second];
      reference = (1.0 - w) * reference + w * count.frame(anchor_latent[anchors.second]);
    }
    Image frame = ImageFromDomain(base + contrast_threshold * (count.frame(t) - reference),
                                  options.domain, options.log_offset, /*clamp=*/false);
    GaussianBlurImage(options.blur_sigma_px, &frame);
    latent.frame(t) = options.clamp_to_unit_range ? frame.max(0.0).min(1.0) : frame;
  }
  return latent;
}

}  // namespace evfs
