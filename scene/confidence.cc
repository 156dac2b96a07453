#include "evfs/scene/confidence.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "evfs/core/error.h"
#include "evfs/core/option_checker.h"
#include "evfs/scene/exposure_blur.h"

namespace evfs {
namespace {

// What the events leave out, as factors of the model's terms. They were chosen on the 17 windows
// of the shared data with a truth, the real DAVIS windows first, and on the realistic variants;
// they are not derived (docs/model.md, "A confidence for every output pixel"; BENCHMARKS.md,
// "Real recordings").
//  * A change the events drove is uncertain by a share of itself: the events' threshold and the
//    response's offset are not known exactly. Measured as the estimate's departure from the
//    observed frame (prediction) or from the frames' blend (between two sharp frames, where the
//    second frame bounds it), at the pixels that fired.
constexpr double kPredictionChangeFactor = 0.2;
constexpr double kBridgeChangeFactor = 0.25;
//  * Between two sharp frames, a pixel that fired errs by more than the pooled gap of the pair
//    (one sample of its walk, shared with quiet neighbours) says; a quiet pixel changed by less
//    than a threshold, smoothly, and the solve follows its own gap most of the way.
constexpr double kBridgeEventGapFactor = 2.0;
constexpr double kQuietGapFactor = 0.35;
//  * After an observation, at a pixel that fired since, the change since its last crossing,
//    under one threshold: half of what a change uniform over the threshold would leave (C² / 12
//    in g).
constexpr double kUnrecordedFactor = 0.5;
//  * After an observation, a pixel that fired no event may still have changed by up to a
//    threshold: by its own gradient times how far the scene around it moved (UnrecordedChange).
//    The variance is this share of that change squared.
constexpr double kQuietUnrecordedFactor = 0.35;
// Half-width in pixels of the square over which UnrecordedChange measures the motion.
constexpr int kMotionRadiusPx = 7;

// An observed frame where the latent video is pinned: a sharp frame at its latent frame, or a
// blurred one at the middle of its exposure.
struct Anchor {
  int latent = 0;
  const Image* image = nullptr;
  bool sharp = true;
};

// The observation nearest to latent frame t among the anchors at or before it (`before`) and
// after it (`after`), either -1 when there is none.
const Anchor& NearestAnchor(const std::vector<Anchor>& anchors, int before, int after, int t) {
  if (before < 0) return anchors[after];
  if (after < 0) return anchors[before];
  return t - anchors[before].latent <= anchors[after].latent - t ? anchors[before] : anchors[after];
}

// The mean of `values` (rows × cols) over the (2 radius + 1)² square around each pixel, the
// border reflected.
std::vector<float> BoxMean(const std::vector<float>& values, int rows, int cols, int radius) {
  std::vector<float> mean(values.size());
  const cv::Mat in(rows, cols, CV_32F, const_cast<float*>(values.data()));
  cv::Mat out(rows, cols, CV_32F, mean.data());
  const int size = 2 * radius + 1;
  cv::blur(in, out, cv::Size(size, size), cv::Point(-1, -1), cv::BORDER_REFLECT);
  return mean;
}

// The change, in thresholds and at most 1, that each pixel of `estimate` (rows × cols) may have
// undergone since the observation without firing: its gradient |∇g| (g = log(I + b), in
// thresholds per pixel) times how far the scene around it moved, read as the events there per
// unit of gradient (an edge of contrast k thresholds crossing a pixel fires k events):
// r = |∇g| · mean(n) / mean(|∇g|) over the (2 kMotionRadiusPx + 1)² square around the pixel, n
// the events of each pixel since the observation. 0 where nothing around it fired.
std::vector<float> UnrecordedChange(const double* estimate, const std::vector<float>& events,
                                    int rows, int cols, double b, double threshold) {
  cv::Mat g(rows, cols, CV_64F);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      g.at<double>(r, c) = std::log(std::max(estimate[static_cast<size_t>(r) * cols + c], 0.0) + b);
    }
  }
  cv::Mat dx, dy;
  cv::Sobel(g, dx, CV_64F, 1, 0, 3, 1.0 / 8.0);
  cv::Sobel(g, dy, CV_64F, 0, 1, 3, 1.0 / 8.0);
  std::vector<float> gradient(events.size());
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      gradient[static_cast<size_t>(r) * cols + c] =
          static_cast<float>(std::hypot(dx.at<double>(r, c), dy.at<double>(r, c)) / threshold);
    }
  }
  const std::vector<float> mean_events = BoxMean(events, rows, cols, kMotionRadiusPx);
  const std::vector<float> mean_gradient = BoxMean(gradient, rows, cols, kMotionRadiusPx);
  std::vector<float> change(events.size(), 0.0f);
  for (size_t p = 0; p < change.size(); ++p) {
    if (mean_events[p] <= 0.0f || mean_gradient[p] <= 0.0f) continue;
    change[p] = std::min(1.0f, gradient[p] * mean_events[p] / mean_gradient[p]);
  }
  return change;
}

// The noise sigma, in units of the quantisation step, of two frames whose quantised difference is
// zero (after the shift common to all pixels) at a share `zeros` of the still pixels. With each
// frame's noise N(0, σ²) and the scene's level uniform within a step, a continuous difference u
// rounds to zero with probability max(0, 1 − |u|), so with u ~ N(0, τ²), τ = √2 σ,
//   P(0) = erf(1 / (√2 τ)) − 2 τ (φ(0) − φ(1 / τ)),
// which falls from 1 at τ = 0; solved for τ by bisection. Unlike the median absolute difference
// it resolves noise below one step, where most differences are 0 or ±1.
double NoiseFromZeroShare(double zeros) {
  const auto phi = [](double v) { return std::exp(-0.5 * v * v) / std::sqrt(2.0 * M_PI); };
  const auto zero_share = [&phi](double tau) {
    return std::erf(1.0 / (std::sqrt(2.0) * tau)) - 2.0 * tau * (phi(0.0) - phi(1.0 / tau));
  };
  double low = 0.0, high = 1e3;
  for (int i = 0; i < 100; ++i) {
    const double tau = 0.5 * (low + high);
    (tau > 0.0 && zero_share(tau) > zeros ? low : high) = tau;
  }
  return 0.5 * (low + high) / std::sqrt(2.0);
}

// The frames' temporal noise, measured where the scene holds still: between two sharp frames,
// a pixel none of whose 3×3 neighbours fired an event saw no change above a threshold, so the
// difference of its two frames is mostly their noise (variance 2σ²). Robust estimates over every
// such pixel d = F_b − F_a of every pair, about the median difference (a change of exposure or
// gain between the frames shifts every difference alike and is not noise): for 8-bit frames,
// from the share of differences that round to zero (NoiseFromZeroShare) while that share is
// large enough to count; otherwise 1.4826 · median |d − median d| / √2, which for 8-bit frames
// reads one step wherever most differences are 0 or ±1 however small the noise is. Unlike a single
// frame's estimate neither reads texture or fixed-pattern noise, which the reconstruction carries
// from the frames and the truth shares. A pixel clipped in either frame (IsClippedLevel) shows no
// noise and is left out, as from the single-frame estimate: under a saturated region the still
// pixels would otherwise measure none, and every quiet pixel's band would shrink to nothing. −1
// when the scene has no pair of sharp frames or fewer than kMinStillPixels still pixels.
double TemporalNoise(const std::vector<Anchor>& anchors, const std::vector<float>& counts,
                     size_t pixels, int rows, int cols) {
  constexpr size_t kMinStillPixels = 500;
  std::vector<float> differences;
  double quantisation_step = -1.0;  // 1/255 when every frame compared is 8-bit, else 0
  for (size_t i = 0; i + 1 < anchors.size(); ++i) {
    const Anchor& first = anchors[i];
    const Anchor& second = anchors[i + 1];
    if (!first.sharp || !second.sharp || second.latent <= first.latent) continue;
    for (const Anchor* frame : {&first, &second}) {
      const double step = QuantisationStep(*frame->image);
      quantisation_step = quantisation_step < 0.0 || quantisation_step == step ? step : 0.0;
    }
    std::vector<uint8_t> fired(pixels, 0);
    for (size_t p = 0; p < pixels; ++p) {
      fired[p] = counts[static_cast<size_t>(second.latent) * pixels + p] !=
                 counts[static_cast<size_t>(first.latent) * pixels + p];
    }
    for (int r = 0; r < rows; ++r) {
      for (int c = 0; c < cols; ++c) {
        bool still = true;
        for (int dr = -1; dr <= 1 && still; ++dr) {
          for (int dc = -1; dc <= 1 && still; ++dc) {
            const int rr = r + dr, cc = c + dc;
            if (rr < 0 || rr >= rows || cc < 0 || cc >= cols) continue;
            still = !fired[static_cast<size_t>(rr) * cols + cc];
          }
        }
        if (!still) continue;
        const size_t p = static_cast<size_t>(r) * cols + c;
        const double a = first.image->data()[p], b = second.image->data()[p];
        if (IsClippedLevel(a) || IsClippedLevel(b)) continue;
        differences.push_back(b - a);
      }
    }
  }
  if (differences.size() < kMinStillPixels) return -1.0;
  const auto median = [](std::vector<float>* values) {
    auto middle = values->begin() + values->size() / 2;
    std::nth_element(values->begin(), middle, values->end());
    return static_cast<double>(*middle);
  };
  const double shift = median(&differences);
  for (float& difference : differences) difference = std::abs(difference - shift);
  // Below this share of zeros (noise above about four steps) the steps no longer bias the median
  // and too few zeros remain to count.
  constexpr double kMinZeroShare = 0.1;
  if (quantisation_step > 0.0) {
    const double zeros =
        static_cast<double>(std::count_if(differences.begin(), differences.end(),
                                          [&](float d) { return d < 0.5 * quantisation_step; })) /
        static_cast<double>(differences.size());
    if (zeros >= kMinZeroShare) return quantisation_step * NoiseFromZeroShare(zeros);
  }
  return 1.4826 * median(&differences) / std::sqrt(2.0);
}

}  // namespace

bool ConfidenceOptions::IsValid(std::string* error) const {
  OptionChecker check;
  check
      .Check(std::isfinite(change_per_event) && change_per_event > 0.0,
             "change_per_event must be positive")
      .Check(std::isfinite(off_change_ratio) && off_change_ratio > 0.0,
             "off_change_ratio must be positive")
      .Check(std::isfinite(log_offset) && log_offset > 0.0, "log_offset must be positive")
      .Check(std::isfinite(prior_event_variance), "prior_event_variance must be finite")
      .Check(std::isfinite(threshold_spread) && threshold_spread > 0.0,
             "threshold_spread must be positive")
      .InRange("pool_radius_px", pool_radius_px, 0, 1000);
  return check.Passed(error);
}

Video PredictErrorSigma(const Scene& scene, const Video& latent, const ConfidenceOptions& options,
                        ConfidenceModel* model) {
  std::string error;
  if (!options.IsValid(&error)) throw InvalidArgumentError("confidence: " + error);
  const int frames = latent.num_frames();
  if (latent.height() != scene.height || latent.width() != scene.width ||
      frames != scene.num_latent_frames()) {
    throw InvalidArgumentError("confidence: the latent video does not match the scene's timeline");
  }
  const int rows = scene.height, cols = scene.width;
  const size_t pixels = static_cast<size_t>(rows) * cols;

  // G(t) and n(t) per pixel: the change of g the events record up to latent frame t, and how
  // many events that took. An event frame spread over several latent steps adds evenly to each.
  std::vector<float> g(static_cast<size_t>(frames) * pixels, 0.0f);
  std::vector<float> n(g.size(), 0.0f);
  const double on = options.change_per_event, off = on * options.off_change_ratio;
  for (int k = 0; k < scene.events.num_frames(); ++k) {
    const EventFrameSpan& span = scene.events.span(k);
    const int steps = span.latent_last - span.latent_first;
    if (steps <= 0) continue;
    const float* values = scene.events.frame_data(k);
    for (size_t p = 0; p < pixels; ++p) {
      const double value = values[p];
      if (value == 0.0) continue;
      const double change = value * (value > 0.0 ? on : off) / steps;
      const double count = std::abs(value) / steps;
      for (int s = span.latent_first + 1; s <= span.latent_last; ++s) {
        g[static_cast<size_t>(s) * pixels + p] += static_cast<float>(change);
        n[static_cast<size_t>(s) * pixels + p] += static_cast<float>(count);
      }
    }
  }
  for (int t = 1; t < frames; ++t) {
    for (size_t p = 0; p < pixels; ++p) {
      g[static_cast<size_t>(t) * pixels + p] += g[static_cast<size_t>(t - 1) * pixels + p];
      n[static_cast<size_t>(t) * pixels + p] += n[static_cast<size_t>(t - 1) * pixels + p];
    }
  }
  const auto at = [pixels](const std::vector<float>& v, int t, size_t p) {
    return static_cast<double>(v[static_cast<size_t>(t) * pixels + p]);
  };

  std::vector<Anchor> anchors;
  double noise = 0.0;
  for (const FrameObservation& frame : scene.frames) {
    anchors.push_back({(frame.latent_first + frame.latent_last) / 2, &frame.image,
                       frame.latent_first == frame.latent_last});
    noise += NoiseSigma(frame.image, /*leave_out_clipped=*/true);
  }
  if (!anchors.empty()) noise /= static_cast<double>(anchors.size());
  std::stable_sort(anchors.begin(), anchors.end(),
                   [](const Anchor& a, const Anchor& b) { return a.latent < b.latent; });
  bool noise_measured = false;
  // Both estimates bound the noise from above: a single frame's reads its texture too, the still
  // pixels' difference the change under one threshold that fired no event. The smaller is kept.
  const double temporal = TemporalNoise(anchors, n, pixels, rows, cols);
  if (temporal >= 0.0 && temporal < noise) {
    noise = temporal;
    noise_measured = true;
  }

  // The gap D between each pair of neighbouring sharp frames, pooled locally.
  const double b = options.log_offset;
  std::vector<std::vector<float>> own_gap(anchors.size());     // [i]: between anchors i, i + 1
  std::vector<std::vector<float>> pooled_gap(anchors.size());  // the same, pooled locally
  double sum_gap2 = 0.0, sum_events = 0.0;
  for (size_t i = 0; i + 1 < anchors.size(); ++i) {
    const Anchor& first = anchors[i];
    const Anchor& second = anchors[i + 1];
    if (!first.sharp || !second.sharp || second.latent <= first.latent) continue;
    std::vector<float> gap2(pixels);
    for (size_t p = 0; p < pixels; ++p) {
      const double change = at(g, second.latent, p) - at(g, first.latent, p);
      const double predicted = (first.image->data()[p] + b) * std::exp(change) - b;
      const double gap = second.image->data()[p] - predicted;
      gap2[p] = static_cast<float>(gap * gap);
      sum_gap2 += gap * gap;
      sum_events += at(n, second.latent, p) - at(n, first.latent, p) + 1.0;
    }
    pooled_gap[i] = BoxMean(gap2, rows, cols, options.pool_radius_px);
    own_gap[i] = std::move(gap2);
  }
  const double measured = sum_events > 0.0 ? sum_gap2 / sum_events : -1.0;
  const double per_event = measured >= 0.0 ? measured : options.prior_event_variance;

  Video sigma(rows, cols, frames);
  for (int t = 0; t < frames; ++t) {
    sigma.set_timestamp_ns(t, latent.timestamp_ns(t));
    // The anchors around t: the last at or before it and the first after it.
    int before = -1, after = -1;
    for (size_t i = 0; i < anchors.size(); ++i) {
      if (anchors[i].latent <= t) before = static_cast<int>(i);
      if (anchors[i].latent > t && after < 0) after = static_cast<int>(i);
    }
    const bool bridge = before >= 0 && after == before + 1 && !pooled_gap[before].empty();
    double* out = sigma.frame_data(t);
    const double* estimate = latent.frame_data(t);
    // Between two sharp frames: the time fraction of t, for the frames' blend.
    double time_fraction = 0.0;
    if (bridge) {
      const double start = static_cast<double>(latent.timestamp_ns(anchors[before].latent));
      const double span = static_cast<double>(latent.timestamp_ns(anchors[after].latent)) - start;
      time_fraction =
          span > 0.0 ? (static_cast<double>(latent.timestamp_ns(t)) - start) / span : 0.0;
    }
    // After an observation (prediction, blurred exposures): the change each quiet pixel may have
    // undergone unrecorded, from the events since the observation nearest to t.
    const Anchor* observed = nullptr;
    std::vector<float> unrecorded;
    if (!bridge) {
      observed = &NearestAnchor(anchors, before, after, t);
      std::vector<float> since(pixels);
      for (size_t p = 0; p < pixels; ++p) {
        since[p] = static_cast<float>(std::abs(at(n, t, p) - at(n, observed->latent, p)));
      }
      unrecorded = UnrecordedChange(estimate, since, rows, cols, b, on);
    }
    for (size_t p = 0; p < pixels; ++p) {
      double variance = 0.0;
      if (bridge) {
        const int a = anchors[before].latent, z = anchors[after].latent;
        const double events = at(n, z, p) - at(n, a, p);
        const double s = events > 0.0 ? (at(n, t, p) - at(n, a, p)) / events
                                      : static_cast<double>(t - a) / (z - a);
        // The truth's noise, and the two frames' noise that the blend at s carries.
        const double frames_noise = noise * noise * (1.0 + s * s + (1.0 - s) * (1.0 - s));
        if (events > 0.0) {
          const double blend = (1.0 - time_fraction) * anchors[before].image->data()[p] +
                               time_fraction * anchors[after].image->data()[p];
          const double change = estimate[p] - blend;
          variance = kBridgeEventGapFactor * pooled_gap[before][p] * s * (1.0 - s) +
                     kBridgeChangeFactor * change * change + frames_noise;
        } else {
          variance = kQuietGapFactor * own_gap[before][p] * s * (1.0 - s) + frames_noise;
        }
      } else {
        const int nearest = observed->latent;
        const double events = std::abs(at(n, t, p) - at(n, nearest, p));
        const double one_event = (std::max(estimate[p], 0.0) + b) * options.threshold_spread;
        const double v = per_event >= 0.0 ? per_event : one_event * one_event;
        // What the events have not recorded: at a pixel that fired since the observation, the
        // change since its last crossing, under one threshold and taken as uniform over it
        // (variance C² / 12 in g); at a pixel that did not, the change its gradient and the
        // motion around it suggest (UnrecordedChange).
        const double threshold = (std::max(estimate[p], 0.0) + b) * on;
        const double quiet_change = unrecorded[p] * threshold;
        const double residual = events > 0.0 ? kUnrecordedFactor * threshold * threshold / 12.0
                                             : kQuietUnrecordedFactor * quiet_change * quiet_change;
        const double change = events > 0.0 ? estimate[p] - observed->image->data()[p] : 0.0;
        variance =
            v * events + residual + kPredictionChangeFactor * change * change + 2.0 * noise * noise;
      }
      out[p] = std::sqrt(variance);
    }
  }
  if (model != nullptr) {
    model->frame_noise_sigma = noise;
    model->measured_event_variance = measured;
    const char* noise_source =
        noise_measured ? "measured where the scene holds still" : "single-frame estimate";
    char line[240];
    if (measured >= 0.0) {
      std::snprintf(line, sizeof(line),
                    "frame noise %.4f (%s); one event's error %.4f (measured between the sharp "
                    "frames)",
                    noise, noise_source, std::sqrt(measured));
    } else if (options.prior_event_variance >= 0.0) {
      std::snprintf(line, sizeof(line), "frame noise %.4f (%s); one event's error %.4f (prior)",
                    noise, noise_source, std::sqrt(options.prior_event_variance));
    } else {
      std::snprintf(line, sizeof(line),
                    "frame noise %.4f (%s); one event's error (I + b) x %.3f (the threshold's "
                    "spread: nothing measured it)",
                    noise, noise_source, options.threshold_spread);
    }
    model->description = line;
  }
  return sigma;
}

double QuantisationStep(const Image& image) {
  constexpr double kLevels = 255.0;
  for (int64_t p = 0; p < image.size(); ++p) {
    const double level = image.data()[p] * kLevels;
    if (std::abs(level - std::round(level)) > 1e-6) return 0.0;
  }
  return 1.0 / kLevels;
}

double ShareWithinSigma(const Image& estimate, const Image& truth, const Image& sigma) {
  if (estimate.size() == 0 || estimate.rows() != truth.rows() || estimate.cols() != truth.cols() ||
      sigma.rows() != truth.rows() || sigma.cols() != truth.cols()) {
    throw InvalidArgumentError("ShareWithinSigma: the images must be non-empty and of one size");
  }
  const double step = QuantisationStep(truth);
  double within = 0.0;
  for (int64_t p = 0; p < estimate.size(); ++p) {
    const double error = estimate.data()[p] - truth.data()[p];
    const double band = sigma.data()[p];
    if (step == 0.0) {
      within += std::abs(error) <= band;
    } else {
      // The share of the bin [truth - step/2, truth + step/2] within band of the estimate.
      const double low = std::max(error - band, -step / 2);
      const double high = std::min(error + band, step / 2);
      within += std::max(0.0, high - low) / step;
    }
  }
  return within / static_cast<double>(estimate.size());
}

}  // namespace evfs
