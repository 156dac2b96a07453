#include "evfs/solver/event_model_calibration.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

#include "evfs/core/error.h"
#include "evfs/core/option_checker.h"
#include "evfs/cost_functions/event_count_residual.h"

namespace evfs {
namespace {

// Residuals beyond this many events are outliers (occlusion, noise, hot pixels) for the
// statistics taken after the fit: the band alone keeps a residual within ±1 event and a
// threshold spread of 20 % within ±2 at ten events.
constexpr double kInlierEvents = 3.0;
// A pixel's own threshold scale is fitted only over runs whose events move its level this many
// thresholds (root-mean-square about the mean, summed): below, the band decides the fit.
constexpr double kMinSpreadEvents = 4.0;
// Per-pixel scales further than this from 1 are occlusion or noise, not threshold mismatch.
constexpr double kMaxScaleDeviation = 0.5;
// Fewest pixels with their own scale for a spread.
constexpr int kMinSpreadPixels = 30;

// One pixel over a run of consecutive usable frames.
struct PixelRun {
  std::vector<double> intensities;
  std::vector<double> events_on;      // from the run's first frame to each of its frames
  std::vector<double> events_off;     // the same for OFF events
  std::vector<double> last_polarity;  // of the pixel's last event before each frame, 0: none
  int first_frame = 0;
};

// The events of one pair, counted per pixel.
struct PairCounts {
  std::vector<int> on;
  std::vector<int> off;
  int64_t events = 0;
};

PairCounts CountEvents(const EventStream& events, int64_t t_begin_ns, int64_t t_end_ns) {
  PairCounts counts;
  const size_t pixels = static_cast<size_t>(events.width()) * events.height();
  counts.on.assign(pixels, 0);
  counts.off.assign(pixels, 0);
  const std::vector<int64_t>& t = events.t_ns();
  const auto begin = std::lower_bound(t.begin(), t.end(), t_begin_ns);
  const auto end = std::lower_bound(begin, t.end(), t_end_ns);
  for (auto it = begin; it != end; ++it) {
    const size_t i = static_cast<size_t>(it - t.begin());
    const size_t p = static_cast<size_t>(events.y(i)) * events.width() + events.x(i);
    ++(events.polarity(i) > 0 ? counts.on : counts.off)[p];
  }
  counts.events = end - begin;
  return counts;
}

// The change of g = log(I + offset) between the frames.
double Change(double first, double second, double offset) {
  return std::log(second + offset) - std::log(first + offset);
}

// The residuals of EventCountResidual for `run`, in events, without their scale: d_k about its
// mean, with m_k = C_on · N_on,k - C_off · N_off,k about its mean in `level_changes`.
std::vector<double> LevelResiduals(const PixelRun& run, double offset, double on, double off,
                                   std::vector<double>* level_changes) {
  const size_t frames = run.intensities.size();
  std::vector<double> d(frames);
  level_changes->assign(frames, 0.0);
  double mean_d = 0.0, mean_m = 0.0;
  for (size_t k = 0; k < frames; ++k) {
    (*level_changes)[k] = on * run.events_on[k] - off * run.events_off[k];
    d[k] = std::log(run.intensities[k] + offset) - (*level_changes)[k] -
           (run.last_polarity[k] > 0.0 ? 0.5 * on : 0.0) +
           (run.last_polarity[k] < 0.0 ? 0.5 * off : 0.0);
    mean_d += d[k];
    mean_m += (*level_changes)[k];
  }
  for (size_t k = 0; k < frames; ++k) {
    d[k] -= mean_d / frames;
    (*level_changes)[k] -= mean_m / frames;
  }
  return d;
}

// The spread of the per-pixel thresholds from per-pixel fits: each run spanning several events
// gets its own scale s of the thresholds, log(I_k + b) = a + s · m_k + band, by least squares;
// a pixel's thresholds C_p = s · C scatter s by σ / C beyond what the band does (its variance
// over Σ m̃², with the band's variance the fit's inlier residual variance).
void FitThresholdSpread(const std::vector<PixelRun>& runs, double offset, double on, double off,
                        double band_variance, int pairs, CalibratedValue* sigma) {
  const double threshold = 0.5 * (on + off);
  std::vector<double> scales, scale_variances;
  std::vector<double> m;
  for (const PixelRun& run : runs) {
    const std::vector<double> d = LevelResiduals(run, offset, on, off, &m);
    double mm = 0.0, md = 0.0;
    for (size_t k = 0; k < d.size(); ++k) {
      mm += m[k] * m[k];
      md += m[k] * (d[k] + m[k]);  // log(I_k + b) about its mean is d̃_k + m̃_k
    }
    if (mm < kMinSpreadEvents * kMinSpreadEvents * threshold * threshold) continue;
    const double scale = md / mm;
    if (std::abs(scale - 1.0) > kMaxScaleDeviation) continue;  // occlusion, noise
    scales.push_back(scale);
    scale_variances.push_back(band_variance / mm);
  }
  if (static_cast<int>(scales.size()) < kMinSpreadPixels) return;
  const double n = static_cast<double>(scales.size());
  double mean = 0.0, band = 0.0;
  for (size_t i = 0; i < scales.size(); ++i) {
    mean += scales[i] / n;
    band += scale_variances[i] / n;
  }
  double excess = 0.0, excess_square = 0.0;
  for (size_t i = 0; i < scales.size(); ++i) {
    const double e = (scales[i] - mean) * (scales[i] - mean) - scale_variances[i];
    excess += e / n;
    excess_square += e * e / n;
  }
  const double relative_variance = std::max(0.0, excess);
  const double excess_error = std::sqrt(std::max(0.0, excess_square - excess * excess) / n);
  sigma->value = std::sqrt(relative_variance) * threshold;
  // Delta method on σ = sqrt(σ²); near σ² = 0 the error of σ² itself bounds σ.
  const double relative_error =
      relative_variance > 0.0
          ? std::min(excess_error / (2.0 * std::sqrt(relative_variance)), std::sqrt(excess_error))
          : std::sqrt(excess_error);
  sigma->standard_error = relative_error * threshold;
  sigma->pixels = static_cast<int>(scales.size());
  sigma->pairs = pairs;
  sigma->estimated = true;
}

// Events per pixel per second at the pixels that are quiet in a pair (EventModelCalibrationOptions
// ::quiet_fraction), over every pair.
void MeasureBackgroundRate(const std::vector<Image>& frames, const std::vector<int64_t>& times_ns,
                           const EventStream& events, const std::vector<PairCounts>& counts,
                           double offset, double quiet_change, double saturation_level,
                           CalibratedValue* rate) {
  const int height = events.height();
  const int width = events.width();
  double pixel_seconds = 0.0;
  int64_t quiet_events = 0;
  int quiet_pixels = 0;
  int pairs_used = 0;
  std::vector<double> change(static_cast<size_t>(height) * width);
  for (size_t k = 0; k < counts.size(); ++k) {
    const double* first = frames[k].data();
    const double* second = frames[k + 1].data();
    for (size_t p = 0; p < change.size(); ++p) {
      const bool saturated = first[p] >= saturation_level || second[p] >= saturation_level;
      change[p] = saturated ? HUGE_VAL : std::abs(Change(first[p], second[p], offset));
    }
    const double duration_s = (times_ns[k + 1] - times_ns[k]) * 1e-9;
    int quiet_here = 0;
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        bool quiet = true;
        for (int dy = -1; dy <= 1 && quiet; ++dy) {
          for (int dx = -1; dx <= 1 && quiet; ++dx) {
            const int yy = std::clamp(y + dy, 0, height - 1);
            const int xx = std::clamp(x + dx, 0, width - 1);
            quiet = change[static_cast<size_t>(yy) * width + xx] < quiet_change;
          }
        }
        if (!quiet) continue;
        const size_t p = static_cast<size_t>(y) * width + x;
        quiet_events += counts[k].on[p] + counts[k].off[p];
        ++quiet_here;
      }
    }
    if (quiet_here == 0) continue;
    quiet_pixels += quiet_here;
    pixel_seconds += quiet_here * duration_s;
    ++pairs_used;
  }
  if (!(pixel_seconds > 0.0)) return;
  rate->value = quiet_events / pixel_seconds;
  // Poisson counts; with none seen, one event is the scale of what could have been missed.
  rate->standard_error = std::sqrt(std::max<double>(quiet_events, 1.0)) / pixel_seconds;
  rate->pixels = quiet_pixels;
  rate->pairs = pairs_used;
  rate->estimated = true;
}

std::string Line(const char* name, const CalibratedValue& value, const char* unit) {
  char line[256];
  if (!value.estimated) {
    std::snprintf(line, sizeof(line), "%-22s not estimated (the frames cannot tell)\n", name);
  } else {
    std::snprintf(line, sizeof(line), "%-22s %.4g ± %.2g%s  (%d pixels, %d pairs)\n", name,
                  value.value, value.standard_error, unit, value.pixels, value.pairs);
  }
  return line;
}

}  // namespace

bool EventModelCalibrationOptions::IsValid(std::string* error) const {
  OptionChecker check;
  check.NonNegative("min_intensity", min_intensity)
      .NonNegative("min_frame_change", min_frame_change)
      .Positive("saturation_level", saturation_level)
      .Positive("huber_scale_events", huber_scale_events)
      .Positive("min_log_offset", min_log_offset)
      .Positive("min_threshold", min_threshold)
      .Positive("quiet_fraction", quiet_fraction)
      .Require(min_intensity < saturation_level, "min_intensity", "below saturation_level")
      .Require(max_log_offset > min_log_offset, "max_log_offset", "above min_log_offset")
      .Require(max_threshold > min_threshold, "max_threshold", "above min_threshold")
      .Require(!log_offset_starts.empty(), "log_offset_starts", "not empty")
      .InRange("min_pixels", min_pixels, 1, 1 << 30)
      .InRange("max_fit_pixels", max_fit_pixels, 0, 1 << 30);
  return check.Passed(error);
}

EventModelCalibration CalibrateEventModel(const std::vector<Image>& frames,
                                          const std::vector<int64_t>& times_ns,
                                          const EventStream& events,
                                          const EventModelCalibrationOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw InvalidArgumentError("calibration: " + error);
  if (frames.size() < 2 || times_ns.size() != frames.size()) {
    throw InvalidArgumentError(
        "cannot calibrate the event model: it needs two frames or more (one frame given)");
  }
  const int height = events.height();
  const int width = events.width();
  for (size_t k = 0; k < frames.size(); ++k) {
    if (frames[k].rows() != height || frames[k].cols() != width) {
      throw InvalidArgumentError("calibration: a frame differs in size from the event sensor");
    }
    if (k > 0 && !(times_ns[k] > times_ns[k - 1])) {
      throw InvalidArgumentError("calibration: frame times must increase");
    }
  }
  std::vector<PairCounts> counts;
  int64_t events_between = 0;
  for (size_t k = 0; k + 1 < frames.size(); ++k) {
    counts.push_back(CountEvents(events, times_ns[k], times_ns[k + 1]));
    events_between += counts.back().events;
  }
  // The polarity of each pixel's last event before each frame.
  const size_t num_pixels = static_cast<size_t>(height) * width;
  std::vector<std::vector<int8_t>> last_polarity(frames.size(), std::vector<int8_t>(num_pixels, 0));
  {
    std::vector<int8_t> last(num_pixels, 0);
    size_t i = 0;
    for (size_t k = 0; k < frames.size(); ++k) {
      for (; i < events.size() && events.t_ns()[i] < times_ns[k]; ++i) {
        last[static_cast<size_t>(events.y(i)) * width + events.x(i)] = events.polarity(i);
      }
      last_polarity[k] = last;
    }
  }
  if (events_between == 0) {
    throw InvalidArgumentError(
        "cannot calibrate the event model: there are no events between the frames");
  }

  // Each pixel's runs of usable frames (neither dark nor saturated) that change and fire.
  std::vector<PixelRun> runs;
  int with_events = 0, with_on = 0, with_off = 0;
  const int num_frames = static_cast<int>(frames.size());
  const auto usable = [&](int k, size_t p) {
    const double intensity = frames[k].data()[p];
    return intensity >= options.min_intensity && intensity < options.saturation_level;
  };
  for (size_t p = 0; p < num_pixels; ++p) {
    for (int k = 0; k < num_frames;) {
      if (!usable(k, p)) {
        ++k;
        continue;
      }
      PixelRun run;
      run.first_frame = k;
      double on = 0.0, off = 0.0;
      double lowest = HUGE_VAL, highest = -HUGE_VAL;
      for (; k < num_frames && usable(k, p); ++k) {
        if (k > run.first_frame) {
          on += counts[k - 1].on[p];
          off += counts[k - 1].off[p];
        }
        const double intensity = frames[k].data()[p];
        run.intensities.push_back(intensity);
        run.events_on.push_back(on);
        run.events_off.push_back(off);
        run.last_polarity.push_back(last_polarity[k][p]);
        lowest = std::min(lowest, intensity);
        highest = std::max(highest, intensity);
      }
      // A run without events says only that its level stayed inside the band, a bound that
      // the residual, divided by the threshold, would turn into a pull towards larger
      // thresholds; such runs are most of a real scene, so they enter the background rate only.
      if (run.intensities.size() < 2 || highest - lowest < options.min_frame_change ||
          on + off == 0.0) {
        continue;
      }
      with_events += on + off > 0.0 ? 1 : 0;
      with_on += on > 0.0 ? 1 : 0;
      with_off += off > 0.0 ? 1 : 0;
      runs.push_back(std::move(run));
    }
  }
  if (with_events < options.min_pixels) {
    throw InvalidArgumentError(
        "cannot calibrate the event model: " + std::to_string(with_events) +
        " pixels change between the frames where events fire, too few (" +
        std::to_string(options.min_pixels) +
        " needed; frames that do not change, or are dark or saturated there, cannot tell)");
  }

  EventModelCalibration result;
  result.thresholds_tied = with_on < options.min_pixels || with_off < options.min_pixels;
  if (options.max_fit_pixels > 0 && runs.size() > static_cast<size_t>(options.max_fit_pixels)) {
    const size_t stride = (runs.size() + options.max_fit_pixels - 1) / options.max_fit_pixels;
    size_t kept = 0;
    for (size_t i = 0; i < runs.size(); i += stride, ++kept) {
      if (kept != i) runs[kept] = std::move(runs[i]);
    }
    runs.resize(kept);
  }

  // One problem; each start of b solves it again from its own values.
  double log_offset = 0.0;
  double threshold_on = 0.2;
  double threshold_off = 0.2;
  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  ceres::HuberLoss loss(options.huber_scale_events);
  int64_t num_residuals = 0;
  for (const PixelRun& run : runs) {
    problem.AddResidualBlock(
        EventCountResidual::Create(run.intensities, run.events_on, run.events_off,
                                   run.last_polarity, result.thresholds_tied),
        &loss, {&log_offset, &threshold_on, &threshold_off});
    num_residuals += static_cast<int64_t>(run.intensities.size());
  }
  problem.SetParameterLowerBound(&log_offset, 0, std::log(options.min_log_offset));
  problem.SetParameterUpperBound(&log_offset, 0, std::log(options.max_log_offset));
  for (double* threshold : {&threshold_on, &threshold_off}) {
    problem.SetParameterLowerBound(threshold, 0, options.min_threshold);
    problem.SetParameterUpperBound(threshold, 0, options.max_threshold);
  }
  if (result.thresholds_tied) problem.SetParameterBlockConstant(&threshold_off);

  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::DENSE_QR;
  solver_options.max_num_iterations = 100;
  solver_options.num_threads = 2;
  solver_options.logging_type = ceres::SILENT;
  double best_cost = HUGE_VAL;
  double best[3] = {0.0, 0.0, 0.0};
  for (const double start : options.log_offset_starts) {
    log_offset = std::log(std::clamp(start, options.min_log_offset, options.max_log_offset));
    threshold_on = 0.2;
    threshold_off = 0.2;
    ceres::Solver::Summary summary;
    ceres::Solve(solver_options, &problem, &summary);
    if (summary.IsSolutionUsable() && summary.final_cost < best_cost) {
      best_cost = summary.final_cost;
      best[0] = log_offset;
      best[1] = threshold_on;
      best[2] = threshold_off;
    }
  }
  if (!std::isfinite(best_cost)) {
    throw SolverError("calibration: no start of the event model fit converged");
  }
  log_offset = best[0];
  threshold_on = best[1];
  threshold_off = result.thresholds_tied ? best[1] : best[2];
  const double b = std::exp(log_offset);

  // Standard errors: the inverse of JᵀJ at the answer, scaled by the residual variance (the
  // Huber cost is r²/2 for inliers, so 2 cost / (N - p) is their variance). A pixel's residuals
  // share its mean, so each run has one residual fewer than frames.
  const int free_parameters = result.thresholds_tied ? 2 : 3;
  const double degrees = static_cast<double>(num_residuals - runs.size() - free_parameters);
  const double residual_variance = 2.0 * best_cost / std::max(1.0, degrees);
  double error_log_offset = 0.0, error_on = 0.0, error_off = 0.0;
  {
    ceres::Covariance::Options covariance_options;
    ceres::Covariance covariance(covariance_options);
    std::vector<std::pair<const double*, const double*>> blocks = {{&log_offset, &log_offset},
                                                                   {&threshold_on, &threshold_on}};
    if (!result.thresholds_tied) blocks.push_back({&threshold_off, &threshold_off});
    if (covariance.Compute(blocks, &problem)) {
      double value = 0.0;
      covariance.GetCovarianceBlock(&log_offset, &log_offset, &value);
      error_log_offset = std::sqrt(std::max(0.0, value * residual_variance));
      covariance.GetCovarianceBlock(&threshold_on, &threshold_on, &value);
      error_on = std::sqrt(std::max(0.0, value * residual_variance));
      error_off = error_on;
      if (!result.thresholds_tied) {
        covariance.GetCovarianceBlock(&threshold_off, &threshold_off, &value);
        error_off = std::sqrt(std::max(0.0, value * residual_variance));
      }
    }
  }

  const int num_pairs = num_frames - 1;
  const double threshold = 0.5 * (threshold_on + threshold_off);
  double inlier_square = 0.0;
  int64_t inliers = 0;
  std::vector<double> level_changes;
  for (const PixelRun& run : runs) {
    for (const double d : LevelResiduals(run, b, threshold_on, threshold_off, &level_changes)) {
      if (std::abs(d) > kInlierEvents * threshold) continue;
      inlier_square += d * d;
      ++inliers;
    }
  }
  result.pixels_used = static_cast<int>(runs.size());
  result.pixels_with_events = with_events;
  result.pairs_used = num_pairs;
  const double band_variance = inliers > 0 ? inlier_square / inliers : 0.0;
  result.residual_rms_events = std::sqrt(band_variance) / threshold;
  // b, as the exponential of the fitted log b: its error by the delta method.
  result.log_offset = {b, b * error_log_offset, result.pixels_used, num_pairs, true};
  result.threshold_on = {threshold_on, error_on, result.thresholds_tied ? with_events : with_on,
                         num_pairs, true};
  result.threshold_off = {threshold_off, error_off, result.thresholds_tied ? with_events : with_off,
                          num_pairs, true};
  FitThresholdSpread(runs, b, threshold_on, threshold_off, band_variance, num_pairs,
                     &result.threshold_sigma);
  MeasureBackgroundRate(frames, times_ns, events, counts, b,
                        options.quiet_fraction * std::min(threshold_on, threshold_off),
                        options.saturation_level, &result.background_rate_hz);

  result.description =
      Line("b (log offset)", result.log_offset, "") +
      Line(result.thresholds_tied ? "C_on = C_off (tied)" : "C_on (ON threshold)",
           result.threshold_on, "") +
      (result.thresholds_tied ? std::string()
                              : Line("C_off (OFF threshold)", result.threshold_off, "")) +
      Line("threshold spread", result.threshold_sigma, "") +
      Line("background rate", result.background_rate_hz, " Hz/pixel");
  char summary[200];
  std::snprintf(summary, sizeof(summary),
                "fit over %d pixels (%d with events) across %d frame pairs, inlier residual rms "
                "%.3f events\n",
                result.pixels_used, result.pixels_with_events, num_pairs,
                result.residual_rms_events);
  result.description += summary;
  return result;
}

}  // namespace evfs
