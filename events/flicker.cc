#include "evfs/events/flicker.h"

#include <algorithm>
#include <cmath>

#include "evfs/core/option_checker.h"
#include "evfs/core/time.h"

namespace evfs {
namespace {

/// Sub-steps per period of the fastest light source: enough to place both edges of a square
/// wave within 1/16 of a period and to follow a sinusoid within 2 % of its amplitude.
constexpr double kStepsPerPeriod = 16.0;

/// Highest LED frequency: beyond it the sub-steps (1/16 period) approach the nanosecond clock.
constexpr double kMaxLedHz = 100000.0;

/// Highest lamp frequency, for the same reason; real lamps flicker at 100 or 120 Hz.
constexpr double kMaxMainsHz = 100000.0;

constexpr double kTwoPi = 6.283185307179586476925;

/// The fraction of a period of frequency `hz` elapsed at `t_ns`, in [0, 1).
double Phase(double hz, int64_t t_ns) {
  const double cycles = NanosecondsToSeconds(t_ns) * hz;
  return cycles - std::floor(cycles);
}

}  // namespace

int64_t FlickerOptions::MaxStepNs() const {
  const double fastest_hz = std::max(led_hz, mains_hz);
  if (fastest_hz <= 0.0) return kNanosecondsPerSecond;
  return std::max<int64_t>(
      1, static_cast<int64_t>(std::floor(kNanosecondsPerSecond / (fastest_hz * kStepsPerPeriod))));
}

bool FlickerOptions::IsValid(std::string* error) const {
  OptionChecker check;
  check
      .Require(led_hz == 0.0 || (led_hz >= 1.0 && led_hz <= kMaxLedHz), "led_hz",
               "0 (no LED) or in [1, 100000]")
      .Require(std::isfinite(led_x_px) && std::isfinite(led_y_px), "led_x_px and led_y_px",
               "finite")
      .Positive("led_radius_px", led_radius_px)
      .Positive("led_intensity", led_intensity)
      .Require(led_duty > 0.0 && led_duty < 1.0, "led_duty", "in (0, 1)")
      .Require(mains_hz == 0.0 || (mains_hz >= 1.0 && mains_hz <= kMaxMainsHz), "mains_hz",
               "0 (no lamp) or in [1, 100000]")
      .Require(mains_depth >= 0.0 && mains_depth <= 1.0, "mains_depth", "in [0, 1]")
      .Require(mains_x_px >= 0 && mains_y_px >= 0 && mains_width_px >= 0 && mains_height_px >= 0,
               "the mains region", ">= 0 in every coordinate");
  return check.Passed(error);
}

bool InLedDisc(const FlickerOptions& options, int x, int y) {
  const double dx = x - options.led_x_px;
  const double dy = y - options.led_y_px;
  return dx * dx + dy * dy <= options.led_radius_px * options.led_radius_px;
}

bool InMainsRegion(const FlickerOptions& options, int x, int y) {
  if (options.mains_width_px == 0 || options.mains_height_px == 0) return true;
  return x >= options.mains_x_px && x < options.mains_x_px + options.mains_width_px &&
         y >= options.mains_y_px && y < options.mains_y_px + options.mains_height_px;
}

bool LedIsOn(const FlickerOptions& options, int64_t t_ns) {
  return options.led_hz > 0.0 && Phase(options.led_hz, t_ns) < options.led_duty;
}

double MainsGain(const FlickerOptions& options, int64_t t_ns) {
  if (options.mains_hz <= 0.0) return 1.0;
  return 1.0 + options.mains_depth * std::sin(kTwoPi * Phase(options.mains_hz, t_ns));
}

void AddLightSources(const FlickerOptions& options, int64_t t_ns, Image* scene) {
  if (options.mains_hz > 0.0) {
    const double gain = MainsGain(options, t_ns);
    for (int y = 0; y < scene->rows(); ++y) {
      for (int x = 0; x < scene->cols(); ++x) {
        if (InMainsRegion(options, x, y)) (*scene)(y, x) *= gain;
      }
    }
  }
  if (LedIsOn(options, t_ns)) {
    // Only the disc's bounding box is visited (clamped in double: the centre may lie far
    // outside the frame).
    const auto first = [&](double centre, Eigen::Index size) {
      return static_cast<int>(
          std::clamp(std::floor(centre - options.led_radius_px), 0.0, static_cast<double>(size)));
    };
    const auto last = [&](double centre, Eigen::Index size) {
      return static_cast<int>(std::clamp(std::ceil(centre + options.led_radius_px), -1.0,
                                         static_cast<double>(size - 1)));
    };
    const int x_begin = first(options.led_x_px, scene->cols());
    const int x_end = last(options.led_x_px, scene->cols());
    const int y_begin = first(options.led_y_px, scene->rows());
    const int y_end = last(options.led_y_px, scene->rows());
    for (int y = y_begin; y <= y_end; ++y) {
      for (int x = x_begin; x <= x_end; ++x) {
        if (InLedDisc(options, x, y)) (*scene)(y, x) += options.led_intensity;
      }
    }
  }
}

}  // namespace evfs
