// images.txt (`t path` per line) and the optional exposures.txt (`path t_start t_end` per
// line) of the Event Camera Dataset layout. Times are decimal seconds parsed exactly into
// nanoseconds; blank lines and lines starting with '#' are skipped, CRLF is accepted.
#ifndef EVFS_IO_FRAME_LIST_H_
#define EVFS_IO_FRAME_LIST_H_

#include <istream>
#include <string>
#include <vector>

#include "evfs/io/data_source.h"

namespace evfs {

/// Whether a frame path in images.txt may lead outside the folder that holds it (an absolute
/// path, or one that climbs out with ".."). No by default: a recording names its own frames,
/// and a list that reaches elsewhere reads files the user did not hand to evfs. Process-wide,
/// set once by the CLI from --allow_outside_paths before any recording is opened.
void SetFramePathsMayLeaveFolder(bool allow);
bool FramePathsMayLeaveFolder();

/// Reads images.txt. Timestamps must increase strictly (kNotMonotonic otherwise) and paths must
/// be unique and usable (ImagePathProblem), and stay inside the folder of images.txt unless
/// FramePathsMayLeaveFolder(). Throws InputError naming the file and line.
std::vector<FrameInfo> ReadFrameList(const std::string& images_txt);
/// The same from `stream`, named `images_txt` in errors (for text already in memory).
std::vector<FrameInfo> ReadFrameList(std::istream& stream, const std::string& images_txt);

/// Why `path` cannot name an image file (it holds a control character, or is longer than any
/// path the system opens), or "" when it can.
std::string ImagePathProblem(const std::string& path);

/// Reads exposures.txt and sets the exposure of the frames it names (matched by path). A path
/// not in `frames`, a path named twice, or t_end <= t_start is an InputError.
void ReadExposures(const std::string& exposures_txt, std::vector<FrameInfo>* frames);
/// The same from `stream`, named `exposures_txt` in errors.
void ReadExposures(std::istream& stream, const std::string& exposures_txt,
                   std::vector<FrameInfo>* frames);

/// Writes images.txt with the fewest fractional digits that keep every timestamp exact.
void WriteFrameList(const std::string& images_txt, const std::vector<FrameInfo>& frames);

/// Writes exposures.txt: a header comment, then one line per frame with a known exposure.
void WriteExposures(const std::string& exposures_txt, const std::vector<FrameInfo>& frames);

}  // namespace evfs

#endif  // EVFS_IO_FRAME_LIST_H_
