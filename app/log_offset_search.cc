#include "evfs/app/log_offset_search.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>

#include "evfs/core/parallel.h"

namespace evfs {

std::vector<ValidationTriplet> ValidationTriplets(int num_frames, const std::vector<int>& excluded,
                                                  const std::function<int64_t(int)>& time_ns,
                                                  int64_t near_ns, int max_triplets) {
  std::vector<int> usable;
  for (int i = 0; i < num_frames; ++i) {
    if (std::find(excluded.begin(), excluded.end(), i) == excluded.end()) usable.push_back(i);
  }
  std::vector<ValidationTriplet> triplets;
  for (size_t i = 0; i + 2 < usable.size(); ++i) {
    triplets.push_back({usable[i], usable[i + 1], usable[i + 2]});
  }
  const auto distance = [&](const ValidationTriplet& triplet) {
    const int64_t t = time_ns(triplet.middle);
    return t > near_ns ? t - near_ns : near_ns - t;
  };
  std::stable_sort(triplets.begin(), triplets.end(),
                   [&](const ValidationTriplet& a, const ValidationTriplet& b) {
                     return distance(a) < distance(b);
                   });
  if (static_cast<int>(triplets.size()) > max_triplets) triplets.resize(std::max(0, max_triplets));
  std::sort(
      triplets.begin(), triplets.end(),
      [](const ValidationTriplet& a, const ValidationTriplet& b) { return a.middle < b.middle; });
  return triplets;
}

LogOffsetChoice ChooseLogOffset(const std::vector<double>& candidates,
                                const std::vector<ValidationTriplet>& triplets, double fallback,
                                const std::function<double(int triplet, double b)>& squared_error,
                                int workers, const std::string& without_triplets) {
  LogOffsetChoice choice;
  choice.candidates = candidates;
  choice.triplets = triplets;
  choice.chosen = fallback;
  if (candidates.empty() || triplets.empty()) {
    char line[160];
    std::snprintf(line, sizeof(line), "b %.3g (%s)", fallback, without_triplets.c_str());
    choice.description = line;
    return choice;
  }
  // Candidates in increasing order; the search starts at the one nearest `fallback` (in log b)
  // and walks towards the lower error while it falls, taking the error as having one minimum
  // over b: the candidates beyond it are not solved.
  std::vector<double> sorted = candidates;
  std::sort(sorted.begin(), sorted.end());
  sorted.erase(std::unique(sorted.begin(), sorted.end()), sorted.end());
  choice.candidates = sorted;
  if (sorted.size() == 1) {
    choice.chosen = sorted[0];
    char line[96];
    std::snprintf(line, sizeof(line), "b %.3g (the only candidate: nothing solved)", sorted[0]);
    choice.description = line;
    return choice;
  }
  choice.psnr.assign(sorted.size(), std::numeric_limits<double>::quiet_NaN());
  std::vector<double> error(sorted.size(), -1.0);
  // Solves every triplet of the candidates not solved yet, up to `workers` solves at once.
  const int num_triplets = static_cast<int>(triplets.size());
  const auto evaluate = [&](const std::vector<size_t>& wanted) {
    std::vector<size_t> fresh;
    for (const size_t i : wanted) {
      if (error[i] < 0.0) fresh.push_back(i);
    }
    std::vector<double> errors(fresh.size() * num_triplets);  // candidate-major
    ParallelForEach(static_cast<int>(errors.size()), workers, [&](int n) {
      errors[n] = squared_error(n % num_triplets, sorted[fresh[n / num_triplets]]);
    });
    for (size_t f = 0; f < fresh.size(); ++f) {
      const auto first = errors.begin() + static_cast<std::ptrdiff_t>(f * num_triplets);
      const size_t i = fresh[f];
      error[i] = std::accumulate(first, first + num_triplets, 0.0) / num_triplets;
      choice.psnr[i] = error[i] > 0.0 ? -10.0 * std::log10(error[i]) : 99.0;
    }
  };
  // The candidate and its neighbours, solved together.
  const auto around = [&](size_t i) {
    std::vector<size_t> wanted = {i};
    if (i > 0) wanted.push_back(i - 1);
    if (i + 1 < sorted.size()) wanted.push_back(i + 1);
    return wanted;
  };
  size_t best = 0;
  for (size_t i = 1; i < sorted.size(); ++i) {
    if (std::abs(std::log(sorted[i] / fallback)) < std::abs(std::log(sorted[best] / fallback))) {
      best = i;
    }
  }
  for (;;) {
    const std::vector<size_t> wanted = around(best);
    evaluate(wanted);
    size_t next = best;
    for (const size_t i : wanted) {
      if (error[i] < error[next]) next = i;
    }
    if (next == best) break;
    best = next;
  }
  choice.chosen = sorted[best];
  std::string scores;
  for (size_t i = 0; i < sorted.size(); ++i) {
    if (error[i] < 0.0) continue;
    char item[48];
    std::snprintf(item, sizeof(item), "%s%.3g: %.2f dB", scores.empty() ? "" : ", ", sorted[i],
                  choice.psnr[i]);
    scores += item;
  }
  char line[120];
  std::snprintf(line, sizeof(line),
                "b %.3g (chosen on %zu frame%s interpolated from their neighbours: ", choice.chosen,
                triplets.size(), triplets.size() == 1 ? "" : "s");
  choice.description = line + scores + ")";
  return choice;
}

PixelBox BusiestSquare(const EventStream& events, int width, int height, int side) {
  PixelBox box;
  box.width = std::max(1, std::min(side, width));
  box.height = std::max(1, std::min(side, height));
  if (box.width == width && box.height == height) return box;
  // Events per pixel, summed over the sensor (integral image with a zero border).
  std::vector<int64_t> sum(static_cast<size_t>(width + 1) * (height + 1), 0);
  const auto at = [&](int x, int y) -> int64_t& {
    return sum[static_cast<size_t>(y) * (width + 1) + x];
  };
  for (size_t i = 0; i < events.size(); ++i) {
    if (events.x(i) < width && events.y(i) < height) ++at(events.x(i) + 1, events.y(i) + 1);
  }
  for (int y = 1; y <= height; ++y) {
    for (int x = 1; x <= width; ++x) at(x, y) += at(x - 1, y) + at(x, y - 1) - at(x - 1, y - 1);
  }
  const int stride = std::max(1, side / 4);
  int64_t best = -1;
  for (int y = 0;; y = std::min(y + stride, height - box.height)) {
    for (int x = 0;; x = std::min(x + stride, width - box.width)) {
      const int64_t count = at(x + box.width, y + box.height) - at(x, y + box.height) -
                            at(x + box.width, y) + at(x, y);
      if (count > best) {
        best = count;
        box.x = x;
        box.y = y;
      }
      if (x == width - box.width) break;
    }
    if (y == height - box.height) break;
  }
  return box;
}

namespace {

Image Crop(const Image& image, const PixelBox& box) {
  return image.block(box.y, box.x, box.height, box.width);
}

}  // namespace

ValidationScene MakeValidationScene(const TimedFrame& first, const TimedFrame& last,
                                    const Image& middle, int64_t middle_ns,
                                    const EventStream& events, int64_t begin_ns, int64_t end_ns,
                                    const BinningOptions& binning, int side) {
  const int width = static_cast<int>(first.image.cols());
  const int height = static_cast<int>(first.image.rows());
  const PixelBox box = BusiestSquare(events, width, height, side);
  EventStream cropped(box.width, box.height);
  for (size_t i = 0; i < events.size(); ++i) {
    const int x = events.x(i) - box.x, y = events.y(i) - box.y;
    if (x < 0 || y < 0 || x >= box.width || y >= box.height) continue;
    cropped.push_back(events.t_ns(i), static_cast<uint16_t>(x), static_cast<uint16_t>(y),
                      events.polarity(i));
  }
  std::vector<TimedFrame> frames = {first, last};
  for (TimedFrame& frame : frames) frame.image = Crop(frame.image, box);
  ValidationScene validation;
  validation.scene = MakeScene(frames, cropped, begin_ns, end_ns, binning);
  validation.middle = Crop(middle, box);
  validation.middle_ns = middle_ns;
  return validation;
}

double ValidationError(const ValidationScene& validation, const MethodOptions& method,
                       double log_offset) {
  MethodOptions trial = method;
  trial.reconstruction.objective.event_model.log_offset = log_offset;
  StartSolveClock(&trial);
  const MethodResult run = RunMethod(validation.scene, trial, IterationCallback(), false, nullptr);
  const Image& estimate = run.video.frame(run.video.NearestFrame(validation.middle_ns));
  return (estimate - validation.middle).square().mean();
}

bool SearchesLogOffset(const MethodOptions& method) {
  return IsIterative(method.method) &&
         method.reconstruction.objective.event_model.model == EventModel::kLog;
}

LogOffsetChoice ChooseLogOffsetOn(const std::vector<double>& candidates,
                                  const std::vector<ValidationTriplet>& triplets,
                                  const std::vector<ValidationScene>& scenes,
                                  const MethodOptions& method, int threads,
                                  const std::string& without_triplets) {
  // One thread a solve: a 64 px problem gains nothing from a second one (shapes 18,20→19's
  // search took 2.2 s with two threads a solve, 0.9 s with its two triplets side by side).
  MethodOptions trial = method;
  trial.reconstruction.solver.num_threads = 1;
  int& iterations = trial.reconstruction.solver.max_num_iterations;
  iterations = std::min(iterations, kValidationMaxIterations);
  return ChooseLogOffset(
      candidates, triplets, method.reconstruction.objective.event_model.log_offset,
      [&](int k, double b) { return ValidationError(scenes[k], trial, b); }, threads,
      without_triplets);
}

}  // namespace evfs
