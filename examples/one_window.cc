// One interpolation window through the library, with Ceres settings of our own: two frames of a
// recording and the events between them become a Scene, Reconstruct() solves it, and the latent
// frame nearest the middle of the window is written as a 16-bit PNG.
//
//   one_window DATA FIRST LAST OUT.png
//
// DATA is anything `evfs --data` takes (a data folder, .h5, .aedat4, ...); FIRST < LAST are frame
// numbers.
#include <cstdio>
#include <exception>
#include <string>

#include "evfs/core/error.h"
#include "evfs/core/time.h"
#include "evfs/io/data_source.h"
#include "evfs/io/image_io.h"
#include "evfs/scene/scene.h"
#include "evfs/solver/reconstructor.h"

namespace {

// Frame `index` of `source` as a sharp observation at its timestamp.
evfs::TimedFrame SharpFrame(const evfs::DataSource& source, int index) {
  evfs::TimedFrame frame;
  frame.image = source.ReadImage(index);
  frame.exposure_begin_ns = frame.exposure_end_ns = source.frames()[index].t_ns;
  frame.label = source.frames()[index].path;
  return frame;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 5) {
    std::fprintf(stderr, "usage: %s DATA FIRST LAST OUT.png\n", argv[0]);
    return 2;
  }
  try {
    const auto source = evfs::DataSource::Open(argv[1]);
    const int first = std::stoi(argv[2]), last = std::stoi(argv[3]);
    const int count = static_cast<int>(source->frames().size());
    if (first < 0 || last <= first || last >= count) {
      std::fprintf(stderr, "FIRST and LAST must satisfy 0 <= FIRST < LAST < %d\n", count);
      return 2;
    }
    const evfs::TimedFrame a = SharpFrame(*source, first);
    const evfs::TimedFrame b = SharpFrame(*source, last);
    const evfs::EventStream events = source->ReadEvents(a.exposure_end_ns, b.exposure_begin_ns);
    const evfs::Scene scene = evfs::MakeInterpolationScene(a, b, events, evfs::BinningOptions());

    // evfs' defaults for the objective and the event model; Ceres settings of our own.
    evfs::ReconstructionOptions options;
    options.solver.max_num_iterations = 10;
    options.solver.function_tolerance = 1e-5;
    options.solver.minimizer_progress_to_stdout = true;
    const evfs::Reconstruction result = evfs::Reconstruct(scene, options);

    const int64_t middle_ns = (a.exposure_end_ns + b.exposure_begin_ns) / 2;
    const int middle = result.video.NearestFrame(middle_ns);
    evfs::WriteGreyPng16(argv[4], result.video.frame(middle));
    std::printf(
        "%d events, %d latent frames, %d iterations, cost %.6g -> %.6g; wrote latent frame "
        "%d (t = %.6f s) to %s\n",
        static_cast<int>(scene.num_events), result.video.num_frames(), result.summary.iterations,
        result.summary.initial_cost, result.summary.final_cost, middle,
        evfs::NanosecondsToSeconds(result.video.timestamp_ns(middle)), argv[4]);
    return 0;
  } catch (const evfs::Error& error) {
    std::fprintf(stderr, "%s\n", error.what());
    return 2;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "%s\n", error.what());
    return 1;
  }
}
