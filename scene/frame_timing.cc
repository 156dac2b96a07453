#include "evfs/scene/frame_timing.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "evfs/core/error.h"
#include "evfs/core/option_checker.h"
#include "evfs/core/time.h"
#include "evfs/scene/event_model.h"

namespace evfs {
namespace {

// One pair, prepared: the centred change of log(F + b) and its sum of squares.
struct PreparedPair {
  std::vector<double> centred_change;
  double change_sum_squares = 0.0;
  int64_t first_t_ns = 0;
  int64_t second_t_ns = 0;
};

PreparedPair Prepare(const FramePair& pair, double log_offset) {
  EventModelParams log_model;
  log_model.model = EventModel::kLog;
  log_model.log_offset = log_offset;
  PreparedPair prepared;
  prepared.first_t_ns = pair.first_t_ns;
  prepared.second_t_ns = pair.second_t_ns;
  const Eigen::Index n = pair.first->size();
  prepared.centred_change.resize(static_cast<size_t>(n));
  double mean = 0.0;
  for (Eigen::Index p = 0; p < n; ++p) {
    const double change = IntensityTransform(pair.second->data()[p], log_model) -
                          IntensityTransform(pair.first->data()[p], log_model);
    prepared.centred_change[static_cast<size_t>(p)] = change;
    mean += change;
  }
  mean /= static_cast<double>(n);
  for (double& change : prepared.centred_change) {
    change -= mean;
    prepared.change_sum_squares += change * change;
  }
  return prepared;
}

// Pearson correlation over all pixels of the signed event sum over [t_first + lag, t_second +
// lag) with the pair's change; *active gets the pixels with a nonzero sum. `net` is scratch of
// the pair's pixel count, all zero on entry and on return.
double Correlation(const PreparedPair& pair, const EventStream& events, int64_t lag_ns,
                   std::vector<double>* net, std::vector<int32_t>* touched, int* active) {
  const size_t begin = events.LowerBound(pair.first_t_ns + lag_ns);
  const size_t end = events.LowerBound(pair.second_t_ns + lag_ns);
  const int width = events.width();
  touched->clear();
  for (size_t i = begin; i < end; ++i) {
    const int32_t p = static_cast<int32_t>(events.y(i)) * width + events.x(i);
    if ((*net)[p] == 0.0) touched->push_back(p);
    (*net)[p] += events.polarity(i);
  }
  double sum = 0.0, sum_squares = 0.0, product = 0.0;
  int nonzero = 0;
  for (const int32_t p : *touched) {
    const double value = (*net)[p];
    (*net)[p] = 0.0;
    if (value == 0.0) continue;  // fired and cancelled; may sit in `touched` twice
    ++nonzero;
    sum += value;
    sum_squares += value * value;
    product += value * pair.centred_change[p];
  }
  *active = nonzero;
  const double n = static_cast<double>(net->size());
  const double net_variance = sum_squares - sum * sum / n;
  if (!(net_variance > 0.0) || !(pair.change_sum_squares > 0.0)) return 0.0;
  return product / std::sqrt(net_variance * pair.change_sum_squares);
}

std::string Milliseconds(int64_t t_ns) {
  char text[32];
  std::snprintf(text, sizeof(text), "%+.1f ms", NanosecondsToSeconds(t_ns) * 1e3);
  return text;
}

}  // namespace

bool FrameLagOptions::IsValid(std::string* error) const {
  OptionChecker check;
  check
      .Check(std::isfinite(min_lag_s) && std::isfinite(max_lag_s) && min_lag_s <= 0.0 &&
                 max_lag_s >= 0.0 && max_lag_s - min_lag_s <= 1.0,
             "the frame lag range must contain 0 and span at most 1 s")
      .Positive("coarse_step_s", coarse_step_s)
      .Positive("fine_step_s", fine_step_s)
      .Check(fine_step_s <= coarse_step_s, "fine_step_s must not exceed coarse_step_s")
      .Check((max_lag_s - min_lag_s) / coarse_step_s <= 10000.0 &&
                 coarse_step_s / fine_step_s <= 10000.0,
             "the frame lag grid must have at most 10000 steps")
      .Positive("log_offset", log_offset)
      .InRange("min_pixels", min_pixels, 1, 1 << 30)
      .Check(min_misfit_reduction >= 0.0 && min_misfit_reduction <= 1.0,
             "min_misfit_reduction must be in [0, 1]");
  return check.Passed(error);
}

FrameLagEstimate EstimateFrameLag(const std::vector<FramePair>& pairs, const EventStream& events,
                                  const FrameLagOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw InvalidArgumentError("frame lag: " + error);
  std::vector<PreparedPair> prepared;
  for (const FramePair& pair : pairs) {
    if (pair.first == nullptr || pair.second == nullptr || pair.first->rows() != events.height() ||
        pair.first->cols() != events.width() || pair.second->rows() != events.height() ||
        pair.second->cols() != events.width()) {
      throw InvalidArgumentError("frame lag: the frames must have the events' sensor size");
    }
    if (pair.second_t_ns <= pair.first_t_ns) {
      throw InvalidArgumentError("frame lag: the second frame of a pair must come after the first");
    }
    prepared.push_back(Prepare(pair, options.log_offset));
  }

  FrameLagEstimate estimate;
  estimate.pairs = static_cast<int>(prepared.size());
  std::vector<double> net(static_cast<size_t>(events.width()) * events.height(), 0.0);
  std::vector<int32_t> touched;
  // Mean correlation over the pairs at one shift; the pixel count goes to *pixels.
  const auto score = [&](int64_t lag_ns, int* pixels) {
    double total = 0.0;
    *pixels = 0;
    for (const PreparedPair& pair : prepared) {
      int active = 0;
      total += Correlation(pair, events, lag_ns, &net, &touched, &active);
      *pixels += active;
    }
    return prepared.empty() ? 0.0 : total / static_cast<double>(prepared.size());
  };
  const auto evaluate = [&](int64_t lag_ns) {
    for (const LagScore& done : estimate.curve) {
      if (done.lag_ns == lag_ns) return done.correlation;
    }
    int pixels = 0;
    const double correlation = score(lag_ns, &pixels);
    estimate.curve.push_back({lag_ns, correlation});
    return correlation;
  };

  estimate.correlation_at_zero = score(0, &estimate.pixels);
  estimate.curve.push_back({0, estimate.correlation_at_zero});
  estimate.peak_correlation = estimate.correlation_at_zero;
  const int64_t coarse_ns = std::max<int64_t>(1, SecondsToNanoseconds(options.coarse_step_s));
  const int64_t fine_ns = std::max<int64_t>(1, SecondsToNanoseconds(options.fine_step_s));
  const int64_t min_ns = SecondsToNanoseconds(options.min_lag_s);
  const int64_t max_ns = SecondsToNanoseconds(options.max_lag_s);
  if (!prepared.empty() && estimate.pixels >= options.min_pixels) {
    // The coarse grid is anchored at 0 so that zero shift is one of its points.
    int64_t best_ns = 0;
    double best = estimate.correlation_at_zero;
    for (int64_t lag_ns = -(-min_ns / coarse_ns) * coarse_ns; lag_ns <= max_ns;
         lag_ns += coarse_ns) {
      const double correlation = evaluate(lag_ns);
      if (correlation > best) {
        best = correlation;
        best_ns = lag_ns;
      }
    }
    const int64_t coarse_best_ns = best_ns;
    for (int64_t lag_ns = std::max(min_ns, coarse_best_ns - coarse_ns);
         lag_ns <= std::min(max_ns, coarse_best_ns + coarse_ns); lag_ns += fine_ns) {
      const double correlation = evaluate(lag_ns);
      if (correlation > best) {
        best = correlation;
        best_ns = lag_ns;
      }
    }
    estimate.peak_lag_ns = best_ns;
    estimate.peak_correlation = best;
    if (best - estimate.correlation_at_zero >=
        options.min_misfit_reduction * (1.0 - estimate.correlation_at_zero)) {
      estimate.estimated = true;
      estimate.lag_ns = best_ns;
      estimate.correlation = best;
    }
  }
  if (!estimate.estimated) estimate.correlation = estimate.correlation_at_zero;
  std::sort(estimate.curve.begin(), estimate.curve.end(),
            [](const LagScore& a, const LagScore& b) { return a.lag_ns < b.lag_ns; });

  char line[256];
  if (estimate.estimated) {
    std::snprintf(line, sizeof(line),
                  "frame lag %s (correlation %.3f, %.3f at 0 ms; %d frame pair%s, %d pixels)",
                  Milliseconds(estimate.lag_ns).c_str(), estimate.correlation,
                  estimate.correlation_at_zero, estimate.pairs, estimate.pairs == 1 ? "" : "s",
                  estimate.pixels);
  } else if (estimate.pixels < options.min_pixels) {
    std::snprintf(line, sizeof(line),
                  "frame lag unknown, taken as 0 ms (%d frame pair%s, %d pixels with events: "
                  "fewer than %d)",
                  estimate.pairs, estimate.pairs == 1 ? "" : "s", estimate.pixels,
                  options.min_pixels);
  } else {
    const double misfit = 1.0 - estimate.correlation_at_zero;
    std::snprintf(line, sizeof(line),
                  "frame lag unknown, taken as 0 ms (best %s: correlation %.3f, %.3f at 0 ms, "
                  "removes %.1f %% of the misfit, less than %.1f %%; %d frame pair%s, %d pixels)",
                  Milliseconds(estimate.peak_lag_ns).c_str(), estimate.peak_correlation,
                  estimate.correlation_at_zero,
                  misfit > 0.0
                      ? 100.0 * (estimate.peak_correlation - estimate.correlation_at_zero) / misfit
                      : 0.0,
                  100.0 * options.min_misfit_reduction, estimate.pairs,
                  estimate.pairs == 1 ? "" : "s", estimate.pixels);
  }
  estimate.description = line;
  return estimate;
}

bool ParseFrameTime(const std::string& text, FrameTime* time, double* lag_s) {
  if (FindName(kFrameTimeNames, text, time)) return true;
  std::string number = text;
  if (number.size() > 2 && number.compare(number.size() - 2, 2, "ms") == 0) {
    number.resize(number.size() - 2);
  }
  char* end = nullptr;
  const double milliseconds = std::strtod(number.c_str(), &end);
  if (number.empty() || end != number.c_str() + number.size() || !std::isfinite(milliseconds) ||
      std::abs(milliseconds) > 1000.0) {
    return false;
  }
  *time = FrameTime::kLag;
  *lag_s = milliseconds * 1e-3;
  return true;
}

std::string FrameTimeName(FrameTime time, double lag_s) {
  if (time != FrameTime::kLag) return NameOf(kFrameTimeNames, time);
  char text[32];
  std::snprintf(text, sizeof(text), "%g", lag_s * 1e3);
  return text;
}

FrameSpan ModelledFrameSpan(int64_t t_ns, bool has_exposure, int64_t exposure_begin_ns,
                            int64_t exposure_end_ns, FrameTime time, int64_t lag_ns,
                            int64_t exposure_ns) {
  switch (time) {
    case FrameTime::kInstant:
      return {t_ns, t_ns};
    case FrameTime::kAuto:
    case FrameTime::kLag:
      return {t_ns + lag_ns, t_ns + lag_ns};
    case FrameTime::kStart:
    case FrameTime::kMiddle:
    case FrameTime::kEnd:
      break;
  }
  if (has_exposure) return {exposure_begin_ns, exposure_end_ns};
  if (exposure_ns <= 0) {
    throw InvalidArgumentError(std::string("--frame_time=") + NameOf(kFrameTimeNames, time) +
                               " needs the frames' exposure: the data has none; pass --exposure_s");
  }
  if (time == FrameTime::kStart) return {t_ns, t_ns + exposure_ns};
  if (time == FrameTime::kEnd) return {t_ns - exposure_ns, t_ns};
  return {t_ns - exposure_ns / 2, t_ns - exposure_ns / 2 + exposure_ns};
}

}  // namespace evfs
