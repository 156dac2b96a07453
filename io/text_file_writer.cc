#include "evfs/io/text_file_writer.h"

#include <cerrno>
#include <cstring>

#include "evfs/core/error.h"

namespace evfs {

TextFileWriter::TextFileWriter(const std::string& path)
    : path_(path), file_(std::fopen(path.c_str(), "wb")) {
  if (file_ == nullptr) {
    throw InputError(InputError::Kind::kUnwritable, path, 0,
                     std::string("cannot create the file: ") + std::strerror(errno));
  }
}

TextFileWriter::~TextFileWriter() {
  if (file_ != nullptr) std::fclose(file_);
}

void TextFileWriter::Write(const std::string& text) {
  buffer_ += text;
  if (buffer_.size() >= kFlushBytes) Flush();
}

void TextFileWriter::Close() {
  Flush();
  const int result = std::fclose(file_);
  file_ = nullptr;
  if (result != 0) ThrowWriteError();
}

void TextFileWriter::Flush() {
  if (!buffer_.empty() && std::fwrite(buffer_.data(), 1, buffer_.size(), file_) != buffer_.size()) {
    ThrowWriteError();
  }
  buffer_.clear();
}

void TextFileWriter::ThrowWriteError() const {
  throw InputError(InputError::Kind::kUnwritable, path_, 0,
                   std::string("cannot write the file: ") + std::strerror(errno));
}

}  // namespace evfs
