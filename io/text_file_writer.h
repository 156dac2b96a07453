// Buffered writing of text files with every failure reported as InputError(kUnwritable), for
// the writers of events.txt, images.txt, exposures.txt and timestamps.txt.
#ifndef EVFS_IO_TEXT_FILE_WRITER_H_
#define EVFS_IO_TEXT_FILE_WRITER_H_

#include <cstdio>
#include <string>

namespace evfs {

class TextFileWriter {
 public:
  /// Longest line that Reserve() makes room for.
  static constexpr size_t kMaxLineBytes = 96;

  /// Creates (truncates) `path`. Throws InputError(kUnwritable).
  explicit TextFileWriter(const std::string& path);
  /// Closes the file without reporting errors; call Close() to have them reported.
  ~TextFileWriter();

  TextFileWriter(const TextFileWriter&) = delete;
  TextFileWriter& operator=(const TextFileWriter&) = delete;

  /// Appends `text`.
  void Write(const std::string& text);

  /// Room for one line of at most kMaxLineBytes, written in place; then Commit(bytes used).
  /// Saves building a string per line in the hot loop of WriteEventsText.
  char* Reserve() {
    if (buffer_.size() >= kFlushBytes) Flush();
    reserved_at_ = buffer_.size();
    buffer_.resize(reserved_at_ + kMaxLineBytes);
    return &buffer_[reserved_at_];
  }
  void Commit(size_t bytes) { buffer_.resize(reserved_at_ + bytes); }

  /// Flushes and closes. Throws InputError(kUnwritable) when anything could not be written.
  void Close();

 private:
  static constexpr size_t kFlushBytes = 1 << 20;

  void Flush();
  [[noreturn]] void ThrowWriteError() const;

  std::string path_;
  std::FILE* file_;
  // Grows as written up to about kFlushBytes; not reserved up front, so that a small file
  // (images.txt, timestamps.txt) costs no megabyte allocation.
  std::string buffer_;
  size_t reserved_at_ = 0;
};

}  // namespace evfs

#endif  // EVFS_IO_TEXT_FILE_WRITER_H_
