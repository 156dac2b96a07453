// `evfs simulate`: the frames of a recording (a folder in the text layout, typically with
// images.txt only, or any file DataSource opens) through the event simulator, written as a
// data folder with the simulated events and the same frames, or, with light sources or frame
// effects, the frames a camera would record of that scene (events/frame_effects.h).
#ifndef EVFS_APP_SIMULATE_JOB_H_
#define EVFS_APP_SIMULATE_JOB_H_

#include <cstdint>
#include <string>

#include "evfs/events/flicker.h"
#include "evfs/events/frame_effects.h"
#include "evfs/events/simulator.h"

namespace evfs {

struct SimulateSummary {
  int64_t events = 0;
  int frames = 0;
  int width = 0, height = 0;
};

/// Reads every frame of `frames_path` (at least 2), simulates events with `options` of the scene
/// lit by `flicker`, records its frames with `frame_effects` and writes the data folder
/// `out_folder` (io/text_folder.h's WriteDataFolder), with exposures.txt when
/// frame_effects.exposure_s > 0. Throws InvalidArgumentError for invalid options, InputError for
/// unreadable or inconsistent frames.
SimulateSummary SimulateRecording(const std::string& frames_path, const SimulatorOptions& options,
                                  const std::string& out_folder,
                                  const FlickerOptions& flicker = FlickerOptions(),
                                  const FrameEffectsOptions& frame_effects = FrameEffectsOptions());

}  // namespace evfs

#endif  // EVFS_APP_SIMULATE_JOB_H_
