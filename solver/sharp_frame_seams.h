// The video meets its sharp frames: after the solve, each sharp frame's latent frame takes the
// frame's values, and the correction fades out towards the neighbouring observations
// (ReconstructionOptions::meet_sharp_frames).
//
// The solve treats a sharp frame as one observation among many event and TV terms, so the
// latent frame at its time ends where those terms balance, not at the frame, even where the
// frames are exact (simulated). The latent frames next to a sharp frame inherit that offset. A
// video made of consecutive windows, which shows each observed frame as it is, then jumps at
// every observed frame, and the frames just after or before one are worse than event
// integration from it (benchmarks/results/model_choices.md, "Shared-structure TV and sharp
// frames met as defaults").
//
// MeetSharpFrames() adds each sharp frame's offset δ = F − H(τ) to the latent frames around it,
// with a weight of 1 at the frame that falls linearly in time to 0 half-way to the neighbouring
// observation on each side (another sharp frame, or the nearer edge of a blurred frame's
// exposure) or, on a side with none, at the window's end. Two sharp frames' corrections thus
// end where they meet, in the middle of the gap, which keeps the values the solve gave it from
// the events and both frames together. Since H + w·δ = (1 − w)·H + w·F, a video within the
// intensity bounds stays within them.
#ifndef EVFS_SOLVER_SHARP_FRAME_SEAMS_H_
#define EVFS_SOLVER_SHARP_FRAME_SEAMS_H_

#include "evfs/core/video.h"
#include "evfs/scene/scene.h"

namespace evfs {

/// What MeetSharpFrames() changed.
struct SharpFrameSeams {
  int frames_met = 0;       // sharp frames whose offset was spread
  double offset_rms = 0.0;  // RMS over their pixels of δ = F − H(τ) before the correction
};

/// Spreads every sharp frame's offset from the solved video (above) over the latent frames
/// around it. A sharp frame that shares its latent frame with another observation (another
/// sharp frame at the same latent index, or a blurred frame whose exposure covers it) is left:
/// the solve balanced them there. `latent` must be on the scene's latent timeline; throws
/// InvalidArgumentError otherwise.
SharpFrameSeams MeetSharpFrames(const Scene& scene, Video* latent);

}  // namespace evfs

#endif  // EVFS_SOLVER_SHARP_FRAME_SEAMS_H_
