// `evfs demo`: the whole pipeline on a built-in synthetic scene with known ground truth.
#ifndef EVFS_APP_DEMO_H_
#define EVFS_APP_DEMO_H_

#include <string>

namespace evfs {

/// Synthesises a scene, simulates its events, writes it as data folders under `folder`, runs
/// interpolation, prediction and deblurring on it with the default options, writes each
/// result under `folder` and prints (and saves as results.md) a table of PSNR and SSIM
/// against the blend/copy baseline. `folder` is new or empty (an OutputTarget's staging
/// folder); `shown_as` is how messages and summaries name it (the final --out).
/// Returns the process exit status.
int RunDemo(const std::string& folder, const std::string& shown_as);

}  // namespace evfs

#endif  // EVFS_APP_DEMO_H_
