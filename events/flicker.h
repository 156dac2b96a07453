// Flickering light sources added to a simulated scene: a blinking LED and a mains-powered lamp.
//
// Both are the kind of scene content that breaks the simulator's assumption of a log intensity
// linear between frames: a 1 kHz LED blinks four times between two 240 fps frames. The
// simulator therefore samples the scene (frames interpolated, light sources evaluated exactly)
// at sub-steps no longer than FlickerOptions::MaxStepNs(), a sixteenth of the shortest period,
// so that every on and off edge and every half-wave of the lamp lands in the events.
//
// LED: a disc whose intensity is raised by `led_intensity` during the first `led_duty` of every
// period (a square wave in phase with t = 0). Event cameras see such markers as ON/OFF bursts
// at the blink rate (A. Censi et al., "Low-latency localization by active LED markers tracking
// using a dynamic vision sensor", IROS 2013); with led_intensity > 1 the disc saturates the
// frames while it is on.
//
// Mains lamp: the intensity of a region is multiplied by 1 + depth · sin(2π f t). A lamp on
// 50 Hz (60 Hz) mains flickers at f = 100 Hz (120 Hz), twice the line frequency; the depth
// ("percent flicker" / 100 in IEEE Std 1789-2015) is a few percent for incandescent lamps and
// tens of percent for magnetic-ballast fluorescent and cheaply driven LED lamps.
#ifndef EVFS_EVENTS_FLICKER_H_
#define EVFS_EVENTS_FLICKER_H_

#include <cstdint>
#include <string>

#include "evfs/core/video.h"

namespace evfs {

/// The light sources of the scene; by default there are none and the scene is the frames.
struct FlickerOptions {
  double led_hz = 0.0;         // LED blink frequency in Hz: 0 (no LED) or in [1, 100000]
  double led_x_px = 0.0;       // LED disc centre, column (pixel centres at integers)
  double led_y_px = 0.0;       // LED disc centre, row
  double led_radius_px = 4.0;  // LED disc radius in pixels, > 0: the pixels within it are lit
  double led_intensity = 4.0;  // linear intensity added while on (1 is white), > 0
  double led_duty = 0.5;       // fraction of each period the LED is on, in (0, 1)
  double mains_hz = 0.0;       // lamp flicker frequency in Hz (100 or 120); 0: no lamp
  double mains_depth = 0.3;    // modulation depth of the lamp, in [0, 1]
  /// The region the lamp lights (x, y of the top-left pixel, width, height); a width or height
  /// of 0 means the whole frame.
  int mains_x_px = 0;
  int mains_y_px = 0;
  int mains_width_px = 0;
  int mains_height_px = 0;

  /// Whether any light source is on.
  bool enabled() const { return led_hz > 0.0 || mains_hz > 0.0; }

  /// The longest sub-step that resolves every light source: a sixteenth of the shortest period,
  /// at least 1 ns. Only meaningful when enabled().
  int64_t MaxStepNs() const;

  /// False (with a reason in `error`, which may be null) when a field is out of range.
  bool IsValid(std::string* error) const;
};

/// Whether pixel (x, y) lies within the LED disc.
bool InLedDisc(const FlickerOptions& options, int x, int y);

/// Whether pixel (x, y) lies within the lamp's region of a width × height frame.
bool InMainsRegion(const FlickerOptions& options, int x, int y);

/// Whether the LED is lit at `t_ns`.
bool LedIsOn(const FlickerOptions& options, int64_t t_ns);

/// The lamp's gain 1 + depth · sin(2π f t) at `t_ns` (1 without a lamp).
double MainsGain(const FlickerOptions& options, int64_t t_ns);

/// Adds the light sources at `t_ns` to the linear intensities of `scene` in place.
void AddLightSources(const FlickerOptions& options, int64_t t_ns, Image* scene);

}  // namespace evfs

#endif  // EVFS_EVENTS_FLICKER_H_
