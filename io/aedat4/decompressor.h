// Decompression of AEDAT 4.0 packets: each packet body (and the file data table) is one LZ4 or
// Zstd frame, or raw bytes. What a frame may decompress to is bounded by kMaxPacketBytes.
#ifndef EVFS_IO_AEDAT4_DECOMPRESSOR_H_
#define EVFS_IO_AEDAT4_DECOMPRESSOR_H_

#include <lz4frame.h>
#include <zstd.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "evfs/io/aedat4.h"

namespace evfs {
namespace aedat4 {

// One decompression context of each kind, made on first use and reused. Not thread-safe.
class Decompressor {
 public:
  Decompressor() = default;
  ~Decompressor();
  Decompressor(const Decompressor&) = delete;
  Decompressor& operator=(const Decompressor&) = delete;

  // Decompresses the one frame [data, data + size) into *out; returns what is wrong, or "".
  std::string Decompress(Aedat4Compression compression, const uint8_t* data, size_t size,
                         std::vector<uint8_t>* out);

 private:
  std::string DecompressLz4(const uint8_t* data, size_t size, std::vector<uint8_t>* out);
  std::string DecompressZstd(const uint8_t* data, size_t size, std::vector<uint8_t>* out);

  LZ4F_dctx* lz4_ = nullptr;
  ZSTD_DCtx* zstd_ = nullptr;
};

}  // namespace aedat4
}  // namespace evfs

#endif  // EVFS_IO_AEDAT4_DECOMPRESSOR_H_
