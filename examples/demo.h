// `evfs demo`: the whole pipeline on a built-in synthetic scene with known ground truth.
#ifndef EVFS_EXAMPLES_DEMO_H_
#define EVFS_EXAMPLES_DEMO_H_

#include <string>

namespace evfs {

/// Synthesises a scene, simulates its events, writes it as data folders under `out_dir`, runs
/// interpolation, prediction and deblurring on it with the default options, writes each
/// result under `out_dir` and prints (and saves as results.md) a table of PSNR and SSIM
/// against the blend/copy baseline. Returns the process exit status.
int RunDemo(const std::string& out_dir);

}  // namespace evfs

#endif  // EVFS_EXAMPLES_DEMO_H_
