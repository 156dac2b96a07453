// What the CLI prints about a recording, a window of it and a finished reconstruction: plain
// text on a FILE (stdout for the CLI), one fact per line, the same for every data format.
#ifndef EVFS_APP_REPORTS_H_
#define EVFS_APP_REPORTS_H_

#include <cstdio>
#include <string>

#include "evfs/app/reconstruct_job.h"
#include "evfs/io/data_source.h"
#include "evfs/scene/scene.h"

namespace evfs {

/// The recording: path, resolution, event counts, time span and rate, and one line per frame
/// with its timestamp and exposure (`evfs info`).
void PrintRecording(const DataSource& source, std::FILE* out);

/// The events between frames `first` and `last` (counts, polarities, the pixels that fired,
/// the collision frames, hot pixels), the binning a reconstruction with `binning` would get
/// (decided from counts: no frame is allocated), and the frames' change of mean brightness
/// (`evfs info --first --last`). `binning_flag` is the --binning value as the user wrote it.
/// Throws InvalidArgumentError unless 0 <= first < last < frames, InputError on bad data.
void PrintWindow(const DataSource& source, int first, int last, const BinningOptions& binning,
                 const std::string& binning_flag, std::FILE* out);

/// What a reconstruction did: the case, the model and solve, the score against the truth, the
/// stage times and where it was written (`evfs reconstruct`).
void PrintReconstruction(const ReconstructRequest& request, const ReconstructResult& result,
                         const std::string& out_path, std::FILE* out);

}  // namespace evfs

#endif  // EVFS_APP_REPORTS_H_
