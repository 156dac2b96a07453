// A whole file mapped read-only into memory, so that parsers walk one contiguous buffer and a
// windowed read touches only the pages it looks at.
#ifndef EVFS_IO_MAPPED_FILE_H_
#define EVFS_IO_MAPPED_FILE_H_

#include <cstddef>
#include <string>

namespace evfs {

class MappedFile {
 public:
  /// Maps `path` read-only. Throws InputError(kMissingFile) when it is missing, is a folder or
  /// cannot be opened or mapped. An empty file maps to an empty buffer.
  explicit MappedFile(const std::string& path);
  ~MappedFile();

  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;
  MappedFile(MappedFile&& other) noexcept;
  MappedFile& operator=(MappedFile&& other) noexcept;

  const std::string& path() const { return path_; }
  const char* data() const { return data_; }
  size_t size() const { return size_; }

 private:
  void Unmap();

  std::string path_;
  const char* data_ = nullptr;
  size_t size_ = 0;
};

}  // namespace evfs

#endif  // EVFS_IO_MAPPED_FILE_H_
