// A whole file mapped read-only into memory, so that parsers walk one contiguous buffer and a
// windowed read touches only the pages it looks at. FromMemory wraps bytes that are already in
// memory instead, so that a parser can be handed them directly (the fuzz targets do: a buffer
// of exactly the input's size lets AddressSanitizer catch any read past its end, which a
// mapping rounded up to whole pages would hide).
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
  /// The `size` bytes at `data`, standing for the file `path` (used in messages); nothing is
  /// mapped or copied, so the bytes must outlive the object.
  static MappedFile FromMemory(std::string path, const char* data, size_t size);
  ~MappedFile();

  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;
  MappedFile(MappedFile&& other) noexcept;
  MappedFile& operator=(MappedFile&& other) noexcept;

  const std::string& path() const { return path_; }
  const char* data() const { return data_; }
  size_t size() const { return size_; }

  /// Drops the whole pages inside bytes [offset, offset + size) from this process's resident
  /// memory (madvise MADV_DONTNEED; the kernel's page cache keeps them and a later read maps them
  /// in again), so that one pass over a file larger than memory holds only the pages in use.
  /// Nothing to do for FromMemory's bytes. The range is clamped to the file.
  void Release(size_t offset, size_t size) const;

 private:
  MappedFile() = default;
  void Unmap();

  std::string path_;
  const char* data_ = nullptr;
  size_t size_ = 0;
  bool mapped_ = false;  // false for an empty file and for FromMemory
};

}  // namespace evfs

#endif  // EVFS_IO_MAPPED_FILE_H_
