// Steps rendered as ramps: a pixel's change at an event spread over the time the scene takes to
// move across it (ReconstructionOptions::step_ramp_px).
//
// With merged quiet steps a solved pixel is constant between its events and jumps at each of
// them, within one latent step. A pixel integrates light over its area, so even a perfectly
// sharp edge crossing it changes its value over the time the edge takes to move one pixel, and
// a blurred edge over longer: the change is a ramp whose length is set by the local speed, not
// a jump. Where the scene moves slowly (the quiet windows) that time is a large part
// of the window, and the step model puts the pixel at one of its two values where the truth is
// between them.
//
// The local speed comes from the events alone, as event-based optical flow reads it from the
// surface of event times (Benosman et al., 2014): an edge moving at v pixels per second fires
// the neighbouring pixel along its motion 1/v later, so at each event the time to the nearest
// event of the same sign at the left or right neighbour, and at the one above or below, are the
// two components of the gradient of that surface, |∇t| = 1/v (seconds per pixel).
// EventTimeSlope() takes each fired pixel's median over its events.
//
// RampSteps() then replaces each step of a solved pixel, at the boundary between two of its
// segments, by a linear ramp that ends at the step and lasts ramp_px · |∇t|. A sensor fires when
// the change since its last event reaches the threshold: at the event the change is complete,
// before it the change was under way. The ramp never begins before the middle of the segment
// before the step, so each segment holds its solved value over its first half, and every sharp
// frame's voxel keeps its value: the frames are met exactly as before.
//
// Steps inside a blurred frame's exposure stay jumps. A blurred frame observes the mean of the
// latent frames over its exposure, which the solve fitted and a ramp would move, and deblurring
// asks for the sharpest latent frames it allows: on the real eslnet_cups_blur recording even
// ramps that kept every segment's mean (an earlier form, centred on the step) lowered the latent
// frames' sharpness (variance of the Laplacian ×1e3, 6.94 → 5.73 at 2 px) at the same re-blur
// PSNR (benchmarks/results/model_choices.md, "Steps as ramps").
#ifndef EVFS_SOLVER_STEP_RAMPS_H_
#define EVFS_SOLVER_STEP_RAMPS_H_

#include <cstdint>
#include <vector>

#include "evfs/core/video.h"
#include "evfs/scene/scene.h"
#include "evfs/solver/latent_layout.h"

namespace evfs {

/// Per pixel (row-major), |∇t| in nanoseconds per pixel: the median over the pixel's event
/// frames of hypot(dx, dy), where dx is the time from that frame to the nearest event frame of
/// the same sign at the left or the right neighbour (at most the latent window's length), dy
/// the same above and below; an event frame's time is the midpoint of its first and last
/// event. A pixel without events takes the mean of the fired pixels' values in its 5×5
/// neighbourhood, or the window's length when none fired there (no motion seen: slower than
/// one pixel per window).
std::vector<double> EventTimeSlope(const Scene& scene);

/// Replaces every step of every pixel the layout solves (segments held constant excepted) by a
/// linear ramp of ramp_px · EventTimeSlope() that ends at the step, begun no earlier than the
/// middle of the segment before it; steps inside a blurred frame's exposure are left (above).
/// `latent` holds the solved video, expanded (LatentLayout::Expand). Returns the number of steps
/// ramped over at least one latent frame. ramp_px <= 0 changes nothing.
int64_t RampSteps(const Scene& scene, const LatentLayout& layout, double ramp_px, Video* latent);

}  // namespace evfs

#endif  // EVFS_SOLVER_STEP_RAMPS_H_
