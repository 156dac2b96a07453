#include "evfs/io/mapped_file.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <utility>

#include "evfs/core/error.h"

namespace evfs {
namespace {

[[noreturn]] void ThrowCannotOpen(const std::string& path, const std::string& why) {
  throw InputError(InputError::Kind::kMissingFile, path, 0, "cannot read the file: " + why);
}

// Closes a file descriptor on every path out of the constructor.
class FileDescriptor {
 public:
  explicit FileDescriptor(int fd) : fd_(fd) {}
  ~FileDescriptor() {
    if (fd_ >= 0) ::close(fd_);
  }
  FileDescriptor(const FileDescriptor&) = delete;
  FileDescriptor& operator=(const FileDescriptor&) = delete;
  int get() const { return fd_; }

 private:
  int fd_;
};

}  // namespace

MappedFile::MappedFile(const std::string& path) : path_(path) {
  const FileDescriptor fd(::open(path.c_str(), O_RDONLY | O_CLOEXEC));
  if (fd.get() < 0) ThrowCannotOpen(path, std::strerror(errno));
  struct stat info;
  if (::fstat(fd.get(), &info) != 0) ThrowCannotOpen(path, std::strerror(errno));
  if (!S_ISREG(info.st_mode)) ThrowCannotOpen(path, "not a regular file");
  size_ = static_cast<size_t>(info.st_size);
  if (size_ == 0) return;  // mmap rejects a zero length; an empty buffer needs no mapping
  void* mapped = ::mmap(nullptr, size_, PROT_READ, MAP_PRIVATE, fd.get(), 0);
  if (mapped == MAP_FAILED) ThrowCannotOpen(path, std::strerror(errno));
  data_ = static_cast<const char*>(mapped);
  mapped_ = true;
}

MappedFile MappedFile::FromMemory(std::string path, const char* data, size_t size) {
  MappedFile file;
  file.path_ = std::move(path);
  file.data_ = data;
  file.size_ = size;
  return file;
}

MappedFile::~MappedFile() { Unmap(); }

void MappedFile::Release(size_t offset, size_t size) const {
  if (!mapped_ || offset >= size_) return;
  const size_t end = offset + std::min(size, size_ - offset);
  const size_t page = static_cast<size_t>(::sysconf(_SC_PAGESIZE));
  // Whole pages only: the pages at either end may hold bytes outside the range still in use.
  const size_t first = (offset + page - 1) / page * page;
  const size_t last = end == size_ ? end : end / page * page;
  if (first >= last) return;
  // Advice on a read-only private mapping of a file: its pages are read again from the file.
  ::madvise(const_cast<char*>(data_) + first, last - first, MADV_DONTNEED);
}

MappedFile::MappedFile(MappedFile&& other) noexcept
    : path_(std::move(other.path_)),
      data_(std::exchange(other.data_, nullptr)),
      size_(std::exchange(other.size_, 0)),
      mapped_(std::exchange(other.mapped_, false)) {}

MappedFile& MappedFile::operator=(MappedFile&& other) noexcept {
  if (this != &other) {
    Unmap();
    path_ = std::move(other.path_);
    data_ = std::exchange(other.data_, nullptr);
    size_ = std::exchange(other.size_, 0);
    mapped_ = std::exchange(other.mapped_, false);
  }
  return *this;
}

void MappedFile::Unmap() {
  if (mapped_) ::munmap(const_cast<char*>(data_), size_);
  data_ = nullptr;
  size_ = 0;
  mapped_ = false;
}

}  // namespace evfs
