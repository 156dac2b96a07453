#include "evfs/io/aedat4/decompressor.h"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <new>
#include <string>
#include <vector>

#include "evfs/io/aedat4/format.h"

namespace evfs {
namespace aedat4 {
namespace {

// Decompression output starts at this many bytes (or a few times the input) and doubles.
constexpr size_t kInitialOutputBytes = size_t{64} << 10;

// Makes room in *out beyond `produced` bytes: doubles it, up to one byte past the limit (so
// that a frame exceeding it is seen to). False when it is already past the limit.
bool Grow(size_t produced, std::vector<uint8_t>* out) {
  if (produced < out->size()) return true;
  if (out->size() > kMaxPacketBytes) return false;
  out->resize(std::min(std::max(out->size() * 2, kInitialOutputBytes), kMaxPacketBytes + 1));
  return true;
}

std::string TooLarge() {
  return "decompresses to more than " + std::to_string(kMaxPacketBytes >> 20) +
         " MiB (corrupt, or not a packet evfs reads)";
}

// Sizes *out for a frame of `size` compressed bytes that declares `content_bytes` (0: none):
// one byte more than declared, so that the frame ends with room to spare (the decoders check
// the declared size themselves), but no more than kMaxDeclaredRatio times the input, so that a
// header declaring much more than its data holds does not allocate it.
void Start(size_t size, uint64_t content_bytes, std::vector<uint8_t>* out) {
  constexpr size_t kMaxDeclaredRatio = 256;  // LZ4 cannot exceed 255:1
  const size_t guess = content_bytes > 0
                           ? std::min(static_cast<size_t>(content_bytes) + 1,
                                      std::max(kInitialOutputBytes, kMaxDeclaredRatio * size))
                           : std::max(kInitialOutputBytes, 4 * size);
  out->resize(std::min(guess, kMaxPacketBytes + 1));
}

}  // namespace

Decompressor::~Decompressor() {
  if (lz4_ != nullptr) LZ4F_freeDecompressionContext(lz4_);
  if (zstd_ != nullptr) ZSTD_freeDCtx(zstd_);
}

std::string Decompressor::Decompress(Aedat4Compression compression, const uint8_t* data,
                                     size_t size, std::vector<uint8_t>* out) {
  switch (compression) {
    case Aedat4Compression::kNone:
      if (size > kMaxPacketBytes) return TooLarge();
      out->assign(data, data + size);
      return "";
    case Aedat4Compression::kLz4:
    case Aedat4Compression::kLz4High:
      return DecompressLz4(data, size, out);
    case Aedat4Compression::kZstd:
    case Aedat4Compression::kZstdHigh:
      return DecompressZstd(data, size, out);
  }
  return "unknown compression";
}

std::string Decompressor::DecompressLz4(const uint8_t* data, size_t size,
                                        std::vector<uint8_t>* out) {
  if (lz4_ == nullptr) {
    if (LZ4F_isError(LZ4F_createDecompressionContext(&lz4_, LZ4F_VERSION))) {
      lz4_ = nullptr;
      throw std::bad_alloc();
    }
  } else {
    LZ4F_resetDecompressionContext(lz4_);
  }
  // The frame header first: a frame declaring more than a packet may hold is refused before
  // anything is allocated for it.
  LZ4F_frameInfo_t info;
  size_t consumed = size;
  const size_t header_hint = LZ4F_getFrameInfo(lz4_, &info, data, &consumed);
  if (LZ4F_isError(header_hint)) {
    return std::string("corrupt LZ4 frame (") + LZ4F_getErrorName(header_hint) + ")";
  }
  if (info.contentSize > kMaxPacketBytes) return TooLarge();
  Start(size, info.contentSize, out);
  size_t produced = 0;
  for (;;) {
    if (!Grow(produced, out)) return TooLarge();
    size_t out_bytes = out->size() - produced;
    size_t in_bytes = size - consumed;
    const size_t hint = LZ4F_decompress(lz4_, out->data() + produced, &out_bytes, data + consumed,
                                        &in_bytes, nullptr);
    if (LZ4F_isError(hint)) {
      return std::string("corrupt LZ4 frame (") + LZ4F_getErrorName(hint) + ")";
    }
    produced += out_bytes;
    consumed += in_bytes;
    if (hint == 0) break;  // the frame is complete
    if (produced < out->size() && (consumed == size || (out_bytes == 0 && in_bytes == 0))) {
      return "truncated LZ4 frame";
    }
  }
  if (produced > kMaxPacketBytes) return TooLarge();
  if (consumed != size) {
    return std::to_string(size - consumed) + " bytes follow the LZ4 frame";
  }
  out->resize(produced);
  return "";
}

std::string Decompressor::DecompressZstd(const uint8_t* data, size_t size,
                                         std::vector<uint8_t>* out) {
  if (zstd_ == nullptr) {
    zstd_ = ZSTD_createDCtx();
    if (zstd_ == nullptr) throw std::bad_alloc();
  } else {
    ZSTD_DCtx_reset(zstd_, ZSTD_reset_session_only);
  }
  const unsigned long long content_bytes = ZSTD_getFrameContentSize(data, size);
  if (content_bytes == ZSTD_CONTENTSIZE_ERROR) return "corrupt Zstd frame (bad header)";
  const bool known = content_bytes != ZSTD_CONTENTSIZE_UNKNOWN;
  if (known && content_bytes > kMaxPacketBytes) return TooLarge();
  Start(size, known ? content_bytes : 0, out);
  ZSTD_inBuffer input = {data, size, 0};
  size_t produced = 0;
  for (;;) {
    if (!Grow(produced, out)) return TooLarge();
    ZSTD_outBuffer output = {out->data(), out->size(), produced};
    const size_t consumed_before = input.pos;
    const size_t hint = ZSTD_decompressStream(zstd_, &output, &input);
    if (ZSTD_isError(hint)) {
      return std::string("corrupt Zstd frame (") + ZSTD_getErrorName(hint) + ")";
    }
    const bool progressed = output.pos > produced || input.pos > consumed_before;
    produced = output.pos;
    if (hint == 0) break;  // the frame is complete and flushed
    if (produced < out->size() && (input.pos == input.size || !progressed)) {
      return "truncated Zstd frame";
    }
  }
  if (produced > kMaxPacketBytes) return TooLarge();
  if (input.pos != input.size) {
    return std::to_string(input.size - input.pos) + " bytes follow the Zstd frame";
  }
  out->resize(produced);
  return "";
}

}  // namespace aedat4
}  // namespace evfs
