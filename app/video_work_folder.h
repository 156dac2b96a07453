// The work folder of `evfs video`: where the windows of a run are kept until the output is
// committed, so that an interrupted run can be resumed (app/video_job.h, "Resuming").
//
//   .NAME.evfs-video-work/      beside the output folder NAME (VideoWorkFolder)
//     .evfs-video-work          the marker: "evfs video work folder", then the run's fingerprint
//     frames/NNNNNN.png         the output frames, each written under a temporary name first
//     confidence/NNNNNN.png     their predicted errors
//     windows/WWWWWW.json       a window's record, written last: a window with one is complete
//
// Only a folder with the marker is evfs': anything else at that path is refused, and whatever a
// user puts inside a work folder is neither reused nor deleted.
#ifndef EVFS_APP_VIDEO_WORK_FOLDER_H_
#define EVFS_APP_VIDEO_WORK_FOLDER_H_

#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>

namespace evfs {

/// A window's record (windows/WWWWWW.json).
using VideoWindowRecord = nlohmann::ordered_json;

/// The work folder of the video written to `out_path` (absolute, as OutputTarget::path()).
std::string VideoWorkFolder(const std::string& out_path);

/// Makes `folder` ready for a run whose settings are `fingerprint` and returns the records of the
/// windows it already holds: with `resume`, those of an earlier run of the same settings (an
/// unreadable record is left out, to be solved again); otherwise none, an earlier work folder
/// being replaced. Throws InvalidArgumentError when `folder` is not evfs' or holds what evfs did
/// not write, or with `resume` when the settings differ; InputError when it cannot be created.
std::map<int, VideoWindowRecord> PrepareVideoWorkFolder(const std::filesystem::path& folder,
                                                        const std::string& fingerprint,
                                                        bool resume);

/// Whether `folder` is a work folder evfs marked (not a link, the marker a regular file).
bool IsVideoWorkFolder(const std::filesystem::path& folder);

/// Removes what a video run wrote in `folder`, and the folder when nothing else is left in it;
/// nothing when `folder` is not a work folder evfs marked (IsVideoWorkFolder).
void ClearVideoWorkFolder(const std::filesystem::path& folder);

/// Deletes the work folder of `out_path` (after its output was committed), if evfs marked it.
void RemoveVideoWorkFolder(const std::string& out_path);

/// Writes `text` to `path` under a temporary name, then renames it: the file appears whole.
/// Throws InputError when it cannot.
void WriteFileAtomically(const std::filesystem::path& path, const std::string& text);

}  // namespace evfs

#endif  // EVFS_APP_VIDEO_WORK_FOLDER_H_
