// Choosing b of g = log(I + b) for interpolation windows from the recording's own frames.
//
// The offset the events' counts measure (evfs calibrate) is not the one a reconstruction between
// two frames wants: on the shared recordings the count fit finds b ≈ 0.1 on both the DAVIS240
// shapes clip and the DAVIS346 street clip, while the first interpolates best near 0.05 and the
// second at 1.5 or more (docs/model.md, "Choosing b by the recording's own frames"). So the offset
// is chosen as a user would check it: each candidate interpolates frames of the recording that the
// window does not use from their neighbours, and the one with the least squared error is kept.
#ifndef EVFS_APP_LOG_OFFSET_SEARCH_H_
#define EVFS_APP_LOG_OFFSET_SEARCH_H_

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "evfs/app/method.h"
#include "evfs/core/event_stream.h"
#include "evfs/core/video.h"
#include "evfs/events/binning.h"
#include "evfs/scene/scene.h"

namespace evfs {

/// Three usable frames, consecutive among the usable ones: `middle` is interpolated from `first`
/// and `last` (images.txt lines).
struct ValidationTriplet {
  int first = 0;
  int middle = 0;
  int last = 0;
};

/// The triplets of consecutive frames among 0..num_frames-1 without `excluded`, at most
/// `max_triplets` of them, those whose middle frame's time (time_ns) lies nearest `near_ns`
/// first; returned in frame order.
std::vector<ValidationTriplet> ValidationTriplets(int num_frames, const std::vector<int>& excluded,
                                                  const std::function<int64_t(int)>& time_ns,
                                                  int64_t near_ns, int max_triplets);

/// What the search found: the candidates in increasing order, each once, each one's PSNR over the
/// triplets (their mean squared error over all pixels, as one PSNR; NaN where it was not solved)
/// and the chosen b.
struct LogOffsetChoice {
  std::vector<double> candidates;
  std::vector<ValidationTriplet> triplets;
  std::vector<double> psnr;  // per candidate; empty when no triplet was scored
  double chosen = 0.0;       // the best candidate, or `fallback` without triplets
  std::string description;   // one line for logs
  double seconds = 0.0;      // the whole search: reading, cropping and solving the triplets
};

/// Scores candidates on every triplet with `squared_error(k, b)` (the mean squared error of the
/// middle frame of triplets[k] interpolated with b) and keeps the least total. It starts at the
/// candidate nearest `fallback` and moves to a neighbour while that one has less error (the error
/// taken to have one minimum over b), so a minimum at one end is found after the candidates
/// between. Without triplets or candidates `fallback` is kept, the description saying
/// `without_triplets`; a single candidate is chosen without a solve. Each step solves the
/// candidates around the current one that are not solved yet (three at the start, then one),
/// every triplet of each, up to `workers` solves at once (squared_error must allow it).
LogOffsetChoice ChooseLogOffset(
    const std::vector<double>& candidates, const std::vector<ValidationTriplet>& triplets,
    double fallback, const std::function<double(int triplet, double b)>& squared_error,
    int workers = 1, const std::string& without_triplets = "no three frames to choose it from");

/// A square of the sensor, in pixels.
struct PixelBox {
  int x = 0, y = 0, width = 0, height = 0;
};

/// The square of side min(side, width, height) inside a width × height sensor that holds the
/// most events (its corner on a grid of a quarter side; the first of equals).
PixelBox BusiestSquare(const EventStream& events, int width, int height, int side);

/// One triplet's scene, cropped to the square where its events are busiest (the part of the
/// sensor that tells candidates apart, at a cost that does not grow with the sensor), and the
/// middle frame to score it against.
struct ValidationScene {
  Scene scene;
  Image middle;           // cropped like the scene
  int64_t middle_ns = 0;  // the moment it shows
};

/// The scene of `first` and `last` and the events between begin_ns and end_ns, cropped to the
/// busiest square of side `side` px.
ValidationScene MakeValidationScene(const TimedFrame& first, const TimedFrame& last,
                                    const Image& middle, int64_t middle_ns,
                                    const EventStream& events, int64_t begin_ns, int64_t end_ns,
                                    const BinningOptions& binning, int side);

/// The mean squared error of the middle frame solved by `method` with b = `log_offset`.
/// Safe to call from several threads at once.
double ValidationError(const ValidationScene& validation, const MethodOptions& method,
                       double log_offset);

/// Whether `method` reads events through b, so that a search can choose it: the iterative solvers
/// with the log model.
bool SearchesLogOffset(const MethodOptions& method);

/// ChooseLogOffset on `scenes` (one per triplet, the same order) with ValidationError, starting
/// from the b of `method`, each solve on one thread and of at most kValidationMaxIterations
/// iterations, up to `threads` solves at once; `without_triplets` says why there is nothing to
/// choose on when `triplets` is empty. The caller sets `seconds`.
LogOffsetChoice ChooseLogOffsetOn(const std::vector<double>& candidates,
                                  const std::vector<ValidationTriplet>& triplets,
                                  const std::vector<ValidationScene>& scenes,
                                  const MethodOptions& method, int threads,
                                  const std::string& without_triplets);

/// The values of b the command line tries by default (--log_offset_search): the model's default
/// 0.5 and two on each side of it, each about three times the one before.
inline constexpr char kDefaultLogOffsetSearch[] = "0.05,0.15,0.5,1.5,5";

/// Triplets a search solves per candidate, at most.
constexpr int kLogOffsetSearchTriplets = 2;

/// Levenberg–Marquardt iterations of a validation solve, at most: the candidates rank as after
/// 10 (the solve's default) on every real interpolation but the street clip's, where b = 5
/// overtakes 1.5 and the windows gain, at about two thirds of the search's time.
constexpr int kValidationMaxIterations = 5;

/// Side of the square the validation solves are cropped to, in pixels.
constexpr int kValidationSquarePx = 64;

}  // namespace evfs

#endif  // EVFS_APP_LOG_OFFSET_SEARCH_H_
