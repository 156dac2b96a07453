// A data folder in the Event Camera Dataset text layout:
//   events.txt      `t x y p` per line (see event_text.h)
//   images.txt      `t path` per line (see frame_list.h); optional when there are no frames
//   images/…png     the frames, 8- or 16-bit grey
//   exposures.txt   optional, `path t_start t_end` per line
#ifndef EVFS_IO_TEXT_FOLDER_H_
#define EVFS_IO_TEXT_FOLDER_H_

#include <memory>
#include <string>
#include <vector>

#include "evfs/io/data_source.h"
#include "evfs/io/event_text.h"

namespace evfs {

/// Reads a data folder. The sensor size is that of the first image (every image must match
/// it); a folder without frames takes it from the largest event coordinates.
class TextFolderDataSource : public DataSource {
 public:
  /// Reads images.txt and exposures.txt and maps events.txt. A folder without events.txt but
  /// with frames is a frames-only recording: has_events() is false, Summarize() counts nothing
  /// and reading events throws InputError saying how to simulate them. Throws InputError.
  explicit TextFolderDataSource(const std::string& folder);
  ~TextFolderDataSource() override;

  bool has_events() const override { return events_ != nullptr; }

  Image ReadImage(int index) const override;
  EventStream ReadEvents(int64_t t_begin_ns, int64_t t_end_ns) const override;
  EventStream ReadAllEvents() const override;
  EventSummary Summarize() const override;

 private:
  TextFolderDataSource(const std::string& folder, std::vector<FrameInfo> frames);
  const EventTextReader& events() const;  // throws for a frames-only folder

  std::unique_ptr<EventTextReader> events_;
};

/// Writes a data folder (created when missing): events.txt, images.txt, one PNG per frame
/// (8-bit when the image holds exactly 8-bit values, else 16-bit) and exposures.txt when any
/// frame has an exposure. A frame keeps its `path` when it is a relative .png path inside the
/// folder; otherwise (for instance an HDF5 dataset name) it becomes images/frame_XXXXXXXX.png
/// with XXXXXXXX the frame index. `images[i]` is the pixel data of `frames[i]`. Throws
/// InputError(kUnwritable), or InvalidArgumentError when the sizes disagree. `with_events` false
/// writes a recording of frames only: no events.txt (`events` must be empty).
void WriteDataFolder(const std::string& folder, const EventStream& events,
                     const std::vector<FrameInfo>& frames, const std::vector<Image>& images,
                     bool with_events = true);

}  // namespace evfs

#endif  // EVFS_IO_TEXT_FOLDER_H_
