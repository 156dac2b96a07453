// images.txt (`t path` per line) and the optional exposures.txt (`path t_start t_end` per
// line) of the Event Camera Dataset layout. Times are decimal seconds parsed exactly into
// nanoseconds; blank lines and lines starting with '#' are skipped, CRLF is accepted.
#ifndef EVFS_IO_FRAME_LIST_H_
#define EVFS_IO_FRAME_LIST_H_

#include <string>
#include <vector>

#include "io/data_source.h"

namespace evfs {

/// Reads images.txt. Timestamps must increase strictly (kNotMonotonic otherwise) and paths must
/// be unique. Throws InputError naming the file and line.
std::vector<FrameInfo> ReadFrameList(const std::string& images_txt);

/// Reads exposures.txt and sets the exposure of the frames it names (matched by path). A path
/// not in `frames`, a path named twice, or t_end <= t_start is an InputError.
void ReadExposures(const std::string& exposures_txt, std::vector<FrameInfo>* frames);

/// Writes images.txt with the fewest fractional digits that keep every timestamp exact.
void WriteFrameList(const std::string& images_txt, const std::vector<FrameInfo>& frames);

/// Writes exposures.txt: a header comment, then one line per frame with a known exposure.
void WriteExposures(const std::string& exposures_txt, const std::vector<FrameInfo>& frames);

}  // namespace evfs

#endif  // EVFS_IO_FRAME_LIST_H_
