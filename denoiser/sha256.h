// SHA-256 (FIPS 180-4), so that summaries and the model card can name the exact weights file
// without a dependency on a crypto library.
#ifndef EVFS_DENOISER_SHA256_H_
#define EVFS_DENOISER_SHA256_H_

#include <string>

namespace evfs {

/// SHA-256 of `bytes`, as 64 lower-case hex digits.
std::string Sha256Hex(const std::string& bytes);

}  // namespace evfs

#endif  // EVFS_DENOISER_SHA256_H_
