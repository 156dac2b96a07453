#include "evfs/events/scene_synthesizer.h"

#include <algorithm>
#include <cmath>

#include "evfs/core/error.h"
#include "evfs/core/option_checker.h"
#include "evfs/core/time.h"
#include "evfs/events/random.h"

namespace evfs {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kMaxImageSide = 65536;

/// A range [low, high) the synthesizer draws a parameter from.
struct DrawRange {
  double low;
  double high;
  double Draw(Random* random) const { return random->Uniform(low, high); }
};

// Texture ranges: mean in [0.35, 0.65] and three waves of amplitude <= 0.1 keep every value in
// [0.05, 0.95], away from the log's steep end and from saturation. Wavelengths of 10–40 px are
// smooth at 1 px yet give edges inside the shapes that fire events as they move.
constexpr DrawRange kTextureMean = {0.35, 0.65};
constexpr DrawRange kWaveAmplitude = {0.03, 0.10};
constexpr DrawRange kWavelengthPx = {10.0, 40.0};
// Shapes move at [0.3, 1] of the maximum speed, so none sits still; rectangles are no thinner
// than 0.4 of their width.
constexpr DrawRange kSpeedFraction = {0.3, 1.0};
constexpr DrawRange kRectangleAspect = {0.4, 1.0};

}  // namespace

bool SceneOptions::IsValid(std::string* error) const {
  OptionChecker check;
  check.InRange("width", width, 1, kMaxImageSide)
      .InRange("height", height, 1, kMaxImageSide)
      .Require(num_shapes >= 0, "num_shapes", ">= 0")
      .Positive("duration_s", duration_s)
      .Positive("min_shape_size_px", min_shape_size_px)
      .Positive("max_shape_size_px", max_shape_size_px)
      .Require(max_shape_size_px >= min_shape_size_px, "max_shape_size_px", ">= min_shape_size_px")
      .NonNegative("max_speed_px_per_s", max_speed_px_per_s)
      .NonNegative("max_rotation_rad_per_s", max_rotation_rad_per_s)
      .NonNegative("background_speed_px_per_s", background_speed_px_per_s)
      .Positive("edge_width_px", edge_width_px);
  return check.Passed(error);
}

double SceneSynthesizer::Texture::Evaluate(double u, double v) const {
  double value = mean;
  for (const Wave& wave : waves) {
    value += wave.amplitude * std::sin(wave.k_u * u + wave.k_v * v + wave.phase);
  }
  return value;
}

SceneSynthesizer::SceneSynthesizer(const SceneOptions& options) : options_(options) {
  std::string error;
  if (!options.IsValid(&error)) throw InvalidArgumentError("SceneSynthesizer: " + error);
  Random random(options.seed);
  const auto draw_texture = [&random]() {
    Texture texture;
    texture.mean = kTextureMean.Draw(&random);
    for (Wave& wave : texture.waves) {
      const double wavenumber = 2.0 * kPi / kWavelengthPx.Draw(&random);
      const double direction = random.Uniform(0.0, 2.0 * kPi);
      wave.k_u = wavenumber * std::cos(direction);
      wave.k_v = wavenumber * std::sin(direction);
      wave.amplitude = kWaveAmplitude.Draw(&random);
      wave.phase = random.Uniform(0.0, 2.0 * kPi);
    }
    return texture;
  };

  // The background is drawn first, so scenes that differ only in num_shapes share it.
  background_ = draw_texture();
  const double pan_direction = random.Uniform(0.0, 2.0 * kPi);
  background_velocity_x_ = options.background_speed_px_per_s * std::cos(pan_direction);
  background_velocity_y_ = options.background_speed_px_per_s * std::sin(pan_direction);

  shapes_.resize(options.num_shapes);
  for (int i = 0; i < options.num_shapes; ++i) {
    Shape& shape = shapes_[i];
    shape.kind = static_cast<ShapeKind>(i % 3);
    shape.size = random.Uniform(options.min_shape_size_px, options.max_shape_size_px);
    shape.center_x = random.Uniform(0.0, options.width);
    shape.center_y = random.Uniform(0.0, options.height);
    const double speed = options.max_speed_px_per_s * kSpeedFraction.Draw(&random);
    const double heading = random.Uniform(0.0, 2.0 * kPi);
    shape.velocity_x = speed * std::cos(heading);
    shape.velocity_y = speed * std::sin(heading);
    shape.angle = random.Uniform(0.0, 2.0 * kPi);
    shape.angular_velocity =
        random.Uniform(-options.max_rotation_rad_per_s, options.max_rotation_rad_per_s);
    shape.aspect = kRectangleAspect.Draw(&random);
    shape.texture = draw_texture();
  }
}

double SceneSynthesizer::SignedDistance(const Shape& shape, double u, double v) {
  switch (shape.kind) {
    case ShapeKind::kDisc:
      return std::hypot(u, v) - shape.size;
    case ShapeKind::kRectangle: {
      // Exact inside and along the sides; corners are slightly rounded, which only shapes the
      // one-pixel anti-aliasing ramp.
      const double half_width = shape.size / std::sqrt(1.0 + shape.aspect * shape.aspect);
      const double half_height = shape.aspect * half_width;
      return std::max(std::abs(u) - half_width, std::abs(v) - half_height);
    }
    case ShapeKind::kTriangle: {
      // Equilateral: the largest distance to the three side lines; the inradius is half the
      // circumradius.
      constexpr double kCos30 = 0.86602540378443864676;
      const double inradius = 0.5 * shape.size;
      const double to_side_0 = v;
      const double to_side_1 = kCos30 * u - 0.5 * v;
      const double to_side_2 = -kCos30 * u - 0.5 * v;
      return std::max({to_side_0, to_side_1, to_side_2}) - inradius;
    }
  }
  return 0.0;
}

void SceneSynthesizer::DrawShape(const Shape& shape, double t_s, Image* image) const {
  const double center_x = shape.center_x + shape.velocity_x * t_s;
  const double center_y = shape.center_y + shape.velocity_y * t_s;
  const double angle = shape.angle + shape.angular_velocity * t_s;
  const double cos_angle = std::cos(angle);
  const double sin_angle = std::sin(angle);
  const double reach = shape.size + options_.edge_width_px;
  const int x_begin = std::max(0, static_cast<int>(std::floor(center_x - reach)));
  const int x_end = std::min(options_.width, static_cast<int>(std::ceil(center_x + reach)) + 1);
  const int y_begin = std::max(0, static_cast<int>(std::floor(center_y - reach)));
  const int y_end = std::min(options_.height, static_cast<int>(std::ceil(center_y + reach)) + 1);
  for (int y = y_begin; y < y_end; ++y) {
    const double dy = y - center_y;
    for (int x = x_begin; x < x_end; ++x) {
      const double dx = x - center_x;
      // The shape's own frame, in which its outline and texture are fixed.
      const double u = cos_angle * dx + sin_angle * dy;
      const double v = -sin_angle * dx + cos_angle * dy;
      const double coverage =
          std::clamp(0.5 - SignedDistance(shape, u, v) / options_.edge_width_px, 0.0, 1.0);
      if (coverage <= 0.0) continue;
      double& pixel = (*image)(y, x);
      pixel += coverage * (shape.texture.Evaluate(u, v) - pixel);
    }
  }
}

Image SceneSynthesizer::Render(double t_s) const {
  Image image(options_.height, options_.width);
  const double offset_x = background_velocity_x_ * t_s;
  const double offset_y = background_velocity_y_ * t_s;
  for (int y = 0; y < options_.height; ++y) {
    for (int x = 0; x < options_.width; ++x) {
      image(y, x) = background_.Evaluate(x - offset_x, y - offset_y);
    }
  }
  for (const Shape& shape : shapes_) DrawShape(shape, t_s, &image);
  return image;
}

Video SceneSynthesizer::RenderVideo(const std::vector<int64_t>& timestamps_ns) const {
  Video video;
  for (const int64_t t_ns : timestamps_ns)
    video.AppendFrame(Render(NanosecondsToSeconds(t_ns)), t_ns);
  return video;
}

Video SceneSynthesizer::RenderAtRate(double fps) const {
  if (!(fps > 0.0) || !std::isfinite(fps)) {
    throw InvalidArgumentError("SceneSynthesizer::RenderAtRate: fps must be finite and > 0");
  }
  const int64_t duration_ns = SecondsToNanoseconds(options_.duration_s);
  std::vector<int64_t> timestamps_ns;
  for (int64_t i = 0;; ++i) {
    const int64_t t_ns = SecondsToNanoseconds(static_cast<double>(i) / fps);
    if (t_ns > duration_ns + 1) break;
    timestamps_ns.push_back(t_ns);
  }
  return RenderVideo(timestamps_ns);
}

}  // namespace evfs
