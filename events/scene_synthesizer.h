// Synthetic scenes with ground truth at every instant: textured shapes moving over a textured
// background, rendered as a pure function of time. Fed to EventSimulator they give event data
// whose latent video is known exactly at any latent timestamp.
#ifndef EVFS_EVENTS_SCENE_SYNTHESIZER_H_
#define EVFS_EVENTS_SCENE_SYNTHESIZER_H_

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "evfs/core/video.h"

namespace evfs {

/// What a synthetic scene holds and how it moves. The defaults give a DAVIS240-sized scene with
/// a few shapes moving a couple of pixels per frame at 240 fps.
struct SceneOptions {
  int width = 240;                         // image width in pixels, in [1, 65536]
  int height = 180;                        // image height in pixels, in [1, 65536]
  int num_shapes = 4;                      // discs, rectangles and triangles, >= 0
  double duration_s = 0.04;                // length of the clip RenderAtRate renders, > 0
  double min_shape_size_px = 12.0;         // smallest shape radius (circumradius), > 0
  double max_shape_size_px = 36.0;         // largest shape radius, >= min_shape_size_px
  double max_speed_px_per_s = 400.0;       // shape speeds are drawn in [0.3, 1] of this, >= 0
  double max_rotation_rad_per_s = 3.0;     // angular speeds are drawn in [-this, this], >= 0
  double background_speed_px_per_s = 0.0;  // camera pan: background speed in a random direction
  double edge_width_px = 1.0;              // width of the anti-aliased edge ramp, > 0
  uint64_t seed = 7;                       // seeds shapes, motions and textures

  /// False (with a reason in `error`, which may be null) when a field is out of range.
  bool IsValid(std::string* error) const;
};

/// A deterministic synthetic scene. Shapes are drawn in a fixed depth order (later ones in
/// front), each carrying a smooth texture that moves and rotates with it; the background texture
/// translates at the pan velocity. Edges are a linear coverage ramp `edge_width_px` wide, so the
/// rendered intensity is continuous in time. Values lie in [0.05, 0.95].
class SceneSynthesizer {
 public:
  /// Throws InvalidArgumentError for invalid options.
  explicit SceneSynthesizer(const SceneOptions& options);

  /// The scene at time `t_s` (seconds from the start of the clip; any real t is allowed).
  /// A pure function of t: the same t always gives the same image.
  Image Render(double t_s) const;

  /// Frames at the given timestamps (ns from the start of the clip), in the given order.
  Video RenderVideo(const std::vector<int64_t>& timestamps_ns) const;

  /// Frames at t = i / fps for i = 0, 1, … while t <= duration_s (the last frame within 1 ns of
  /// duration_s included). Throws InvalidArgumentError unless fps > 0 and finite.
  Video RenderAtRate(double fps) const;

  const SceneOptions& options() const { return options_; }

 private:
  /// One plane wave of a texture: amplitude · sin(k_u · u + k_v · v + phase).
  struct Wave {
    double k_u = 0.0;
    double k_v = 0.0;
    double amplitude = 0.0;
    double phase = 0.0;
  };

  /// A smooth texture: mean + a sum of plane waves, in [0.05, 0.95] by construction.
  struct Texture {
    double mean = 0.5;
    std::array<Wave, 3> waves;
    double Evaluate(double u, double v) const;
  };

  enum class ShapeKind { kDisc, kRectangle, kTriangle };

  struct Shape {
    ShapeKind kind = ShapeKind::kDisc;
    double center_x = 0.0;  // at t = 0, pixels
    double center_y = 0.0;
    double velocity_x = 0.0;  // pixels per second
    double velocity_y = 0.0;
    double angle = 0.0;             // at t = 0, radians
    double angular_velocity = 0.0;  // radians per second
    double size = 0.0;              // radius (disc), circumradius (rectangle, triangle)
    double aspect = 1.0;            // rectangle half-height / half-width
    Texture texture;
  };

  /// Signed distance (pixels, negative inside) of a point in the shape's own frame.
  static double SignedDistance(const Shape& shape, double u, double v);
  /// Draws `shape` over `image` at time t_s, touching only its bounding box.
  void DrawShape(const Shape& shape, double t_s, Image* image) const;

  SceneOptions options_;
  Texture background_;
  double background_velocity_x_ = 0.0;
  double background_velocity_y_ = 0.0;
  std::vector<Shape> shapes_;  // back to front
};

}  // namespace evfs

#endif  // EVFS_EVENTS_SCENE_SYNTHESIZER_H_
