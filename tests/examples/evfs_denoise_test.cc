// evfs reconstruct --denoise / --denoiser and evfs denoise, end to end, with the
// hand-checkable network of tests/denoiser/data (its values are checked in denoiser_test.cc).
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "evfs/denoiser/sha256.h"
#include "evfs/io/image_io.h"
#include "evfs/tests/examples/cli_test_util.h"
#include "evfs/tests/test_data.h"

namespace evfs {
namespace test {
namespace {

std::string NetworkPath(const std::string& name) {
  return (fs::path(EVFS_TEST_SOURCE_DIR) / ".." / "denoiser" / "data" / name)
      .lexically_normal()
      .string();
}

nlohmann::json ReadSummary(const std::string& folder) {
  return nlohmann::json::parse(ReadFile(fs::path(folder) / "summary.json"));
}

int CountFrames(const std::string& folder) {
  int pngs = 0;
  for (const auto& entry : fs::directory_iterator(fs::path(folder) / "frames")) {
    pngs += entry.is_regular_file();
  }
  return pngs;
}

Image Frame(const std::string& folder, int t) {
  char name[32];
  std::snprintf(name, sizeof(name), "%06d.png", t);
  return ReadGreyImage((fs::path(folder) / "frames" / name).string());
}

// The denoiser's effect alone: without the sharp frames met after it (--meet_sharp_frames), the
// output is the DMR's latent video minus the correction.
std::string Reconstruct(const std::string& data, const std::string& out, const std::string& flags) {
  const CommandResult run =
      RunEvfs("reconstruct --data=" + data +
              " --mode=interpolate --first=0 --last=2 --truth=1 --out=" + out +
              " --meet_sharp_frames=false " + flags);
  EXPECT_EQ(run.exit_code, 0) << run.output;
  return out;
}

TEST(EvfsDenoise, ReconstructOnceChangesOnlySolvedPixelsAndRecordsTheWeights) {
  const std::string scratch = ScratchDir("denoise_once");
  const std::string data = WriteSyntheticFolder(scratch);
  const std::string weights = NetworkPath("two_conv.onnx");
  const std::string plain = Reconstruct(data, scratch + "/plain", "--denoise=none");
  // The network's correction as it is (frame consistency is tested below).
  const std::string denoised =
      Reconstruct(data, scratch + "/denoised",
                  "--denoise=once --denoise_consistency=false --denoiser=" + weights);

  const nlohmann::json none = ReadSummary(plain);
  EXPECT_EQ(none["denoiser"]["mode"], "none");
  const nlohmann::json once = ReadSummary(denoised);
  const nlohmann::json& record = once["denoiser"];
  EXPECT_EQ(record["mode"], "once");
  EXPECT_EQ(record["weights"], weights);
  std::ifstream in(weights, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(record["sha256"], Sha256Hex(bytes));
  EXPECT_GE(record["time_s"].get<double>(), 0.0);
  EXPECT_EQ(record["psnr_before"].get<double>(), none["truth"]["psnr"].get<double>());

  // The same solve; the denoiser touches at most the active pixels of each frame.
  const int frames = CountFrames(plain);
  ASSERT_EQ(CountFrames(denoised), frames);
  const int64_t active = once["pixels"]["active"].get<int64_t>();
  ASSERT_GT(active, 0);
  int64_t changed_total = 0;
  for (int t = 0; t < frames; ++t) {
    const Image before = Frame(plain, t), after = Frame(denoised, t);
    const int64_t changed = (before != after).count();
    EXPECT_LE(changed, active) << "frame " << t;
    changed_total += changed;
  }
  EXPECT_GT(changed_total, 0);
  EXPECT_EQ(record["pixels_changed"].get<int64_t>(), active * frames);
}

TEST(EvfsDenoise, ReconstructSaysWhatTheDenoiserDid) {
  const std::string scratch = ScratchDir("denoise_line");
  const std::string data = WriteSyntheticFolder(scratch);
  const std::string common =
      "reconstruct --data=" + data +
      " --mode=interpolate --first=0 --last=2 --truth=1 --denoiser=" + NetworkPath("two_conv.onnx");
  const CommandResult once = RunEvfs(common + " --out=" + scratch + "/once");
  ASSERT_EQ(once.exit_code, 0) << once.output;
  EXPECT_NE(once.output.find("denoise: once (two_conv.onnx, sha256 "), std::string::npos)
      << once.output;
  EXPECT_NE(once.output.find("of its correction taken out to keep the frames; before it: "),
            std::string::npos)
      << once.output;
  const CommandResult none = RunEvfs(common + " --denoise=none --out=" + scratch + "/none");
  ASSERT_EQ(none.exit_code, 0) << none.output;
  EXPECT_EQ(none.output.find("denoise:"), std::string::npos) << none.output;
}

TEST(EvfsDenoise, OnceKeepsTheSharpFramesAndRecordsWhatItTookOut) {
  const std::string scratch = ScratchDir("denoise_consistent");
  const std::string data = WriteSyntheticFolder(scratch);
  const std::string weights = NetworkPath("two_conv.onnx");
  const std::string plain = Reconstruct(data, scratch + "/plain", "--denoise=none");
  const std::string full = Reconstruct(
      data, scratch + "/full", "--denoise=once --denoise_consistency=false --denoiser=" + weights);
  const std::string consistent =
      Reconstruct(data, scratch + "/consistent", "--denoise=once --denoiser=" + weights);

  EXPECT_TRUE(ReadSummary(full)["denoiser"]["consistency"].is_null());
  const nlohmann::json consistency = ReadSummary(consistent)["denoiser"]["consistency"];
  ASSERT_TRUE(consistency.is_object()) << consistency;
  EXPECT_EQ(consistency["observations"].get<int>(), 2);  // the two sharp frames
  EXPECT_GT(consistency["correction_energy"].get<double>(), 0.0);
  const double removed = consistency["removed_fraction"].get<double>();
  EXPECT_GT(removed, 0.0);
  EXPECT_LT(removed, 1.0);
  // The sharp frames' latent frames (the first and the last) keep the solve's values; every
  // frame between them takes the network's correction as it is. To the 16-bit PNG's step.
  const int frames = CountFrames(plain);
  ASSERT_EQ(CountFrames(consistent), frames);
  for (int t = 0; t < frames; ++t) {
    const bool sharp = t == 0 || t == frames - 1;
    const Image expected = Frame(sharp ? plain : full, t);
    EXPECT_LE((Frame(consistent, t) - expected).abs().maxCoeff(), 1.5 / 65535.0) << "frame " << t;
  }
  EXPECT_GT((Frame(full, 0) - Frame(plain, 0)).abs().maxCoeff(), 1e-3);
}

TEST(EvfsDenoise, VideoWindowsRecordWhatConsistencyTookOut) {
  const std::string scratch = ScratchDir("denoise_video");
  const std::string data = WriteSyntheticFolder(scratch);
  const std::string common = "video --data=" + data + " --fps=1000 --denoise=once --denoiser=" +
                             NetworkPath("two_conv.onnx");
  const CommandResult consistent = RunEvfs(common + " --out=" + scratch + "/consistent");
  ASSERT_EQ(consistent.exit_code, 0) << consistent.output;
  const CommandResult full =
      RunEvfs(common + " --denoise_consistency=false --out=" + scratch + "/full");
  ASSERT_EQ(full.exit_code, 0) << full.output;
  int solved = 0, denoised = 0, latent = 0;
  const nlohmann::json with = ReadSummary(scratch + "/consistent");
  for (const nlohmann::json& window : with["windows"]) {
    if (!window["solved"].get<bool>()) continue;
    ++solved;
    ASSERT_TRUE(window.contains("consistency_removed")) << window;
    EXPECT_GE(window["consistency_removed"].get<double>(), 0.0);
    EXPECT_LE(window["consistency_removed"].get<double>(), 1.0);
    // Only the latent frames the output reads (FramesTheOutputNeeds), never the sharp frames'.
    denoised += window["denoised_frames"].get<int>();
    latent += window["latent_frames"].get<int>();
  }
  EXPECT_GT(solved, 0);
  EXPECT_GT(denoised, 0);
  EXPECT_LT(denoised, latent);
  const nlohmann::json without = ReadSummary(scratch + "/full");
  for (const nlohmann::json& window : without["windows"]) {
    EXPECT_FALSE(window.contains("consistency_removed")) << window;
  }
}

TEST(EvfsDenoise, DenoiseCommandWritesAFolderLikeReconstruct) {
  const std::string scratch = ScratchDir("denoise_command");
  const std::string data = WriteSyntheticFolder(scratch);
  const std::string plain = Reconstruct(data, scratch + "/plain", "--denoise=none");
  const std::string out = scratch + "/denoised";
  const CommandResult run = RunEvfs("denoise --in=" + plain + " --out=" + out +
                                    " --denoiser=" + NetworkPath("two_conv.onnx"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_EQ(CountFrames(out), CountFrames(plain));
  EXPECT_EQ(ReadFile(fs::path(out) / "timestamps.txt"),
            ReadFile(fs::path(plain) / "timestamps.txt"));
  const nlohmann::json summary = ReadSummary(out);
  EXPECT_EQ(summary["denoiser"]["mode"], "once");
  EXPECT_EQ(summary["denoiser"]["frames"].get<int>(), CountFrames(plain));
  EXPECT_GT((Frame(out, 1) - Frame(plain, 1)).abs().maxCoeff(), 1e-3);
  EXPECT_TRUE(fs::exists(fs::path(out) / ".evfs-output"));

  // Run again onto its own earlier output: refused without --overwrite, replaced with it.
  const CommandResult again = RunEvfs("denoise --in=" + plain + " --out=" + out +
                                      " --denoiser=" + NetworkPath("two_conv.onnx"));
  EXPECT_EQ(again.exit_code, 2) << again.output;
  const CommandResult overwrite =
      RunEvfs("denoise --in=" + plain + " --out=" + out +
              " --overwrite --denoiser=" + NetworkPath("two_conv.onnx"));
  EXPECT_EQ(overwrite.exit_code, 0) << overwrite.output;
}

TEST(EvfsDenoise, BadWeightsAndFlagsAreUserErrors) {
  const std::string scratch = ScratchDir("denoise_errors");
  const std::string data = WriteSyntheticFolder(scratch);
  const std::string reconstruct =
      "reconstruct --data=" + data + " --mode=interpolate --first=0 --last=2 ";
  const std::string out = scratch + "/out";
  ExpectUserError(RunEvfs(reconstruct + "--denoise=twice --out=" + out), "--denoise", out);
  const std::string missing = scratch + "/missing.onnx";
  ExpectUserError(RunEvfs(reconstruct + "--denoise=once --denoiser=" + missing + " --out=" + out),
                  missing, out);
  const std::string wrong = NetworkPath("two_channels.onnx");
  ExpectUserError(RunEvfs(reconstruct + "--denoiser=" + wrong + " --out=" + out), wrong, out);
  const std::string corrupt = scratch + "/corrupt.onnx";
  std::ofstream(corrupt) << "not a network";
  ExpectUserError(RunEvfs(reconstruct + "--denoiser=" + corrupt + " --out=" + out), corrupt, out);

  const std::string plain = Reconstruct(data, scratch + "/plain", "--denoise=none");
  ExpectUserError(RunEvfs("denoise --in=" + plain + " --out=" + out + " --denoiser=" + corrupt),
                  corrupt, out);
  ExpectUserError(RunEvfs("denoise --in=" + scratch + "/nothing --out=" + out +
                          " --denoiser=" + NetworkPath("two_conv.onnx")),
                  "expected a reconstruction folder", out);
  ExpectUserError(RunEvfs("denoise --out=" + out), "--in", out);
  ExpectUserError(RunEvfs("denoise --in=" + plain), "--out", fs::path(scratch) / "none");
}

TEST(EvfsDenoise, PlugAndPlayRecordsItsIterationsAndDiffersFromOnce) {
  const std::string scratch = ScratchDir("denoise_pnp");
  const std::string data = WriteSyntheticFolder(scratch);
  const std::string weights = " --denoiser=" + NetworkPath("two_conv.onnx");
  const std::string once = Reconstruct(data, scratch + "/once", "--denoise=once" + weights);
  const std::string pnp = Reconstruct(data, scratch + "/pnp", "--denoise=pnp" + weights);

  const nlohmann::json summary = ReadSummary(pnp);
  const nlohmann::json& record = summary["denoiser"];
  EXPECT_EQ(record["mode"], "pnp");
  const int iterations = record["pnp"]["iterations"].get<int>();
  EXPECT_GE(iterations, 1);
  ASSERT_EQ(record["pnp"]["rho"].size(), static_cast<size_t>(iterations));
  // ρ grows (or stays) from one x-update to the next.
  EXPECT_LE(record["pnp"]["rho"][0].get<double>(), record["pnp"]["rho"].back().get<double>());
  EXPECT_GE(record["pnp"]["solve_time_s"].get<double>(), 0.0);
  // Before the ADMM iterations the reconstruction is the same as once's.
  EXPECT_EQ(record["psnr_before"].get<double>(),
            ReadSummary(once)["denoiser"]["psnr_before"].get<double>());
  // The denoiser runs once per iteration after the first application.
  EXPECT_EQ(record["pixels_changed"].get<int64_t>(),
            (iterations + 1) * ReadSummary(once)["denoiser"]["pixels_changed"].get<int64_t>());

  const int frames = CountFrames(once);
  ASSERT_EQ(CountFrames(pnp), frames);
  double max_difference = 0.0;
  for (int t = 0; t < frames; ++t) {
    max_difference = std::max(max_difference, (Frame(pnp, t) - Frame(once, t)).abs().maxCoeff());
  }
  // More than 16-bit PNG quantisation: the ADMM iterations changed the result.
  EXPECT_GT(max_difference, 1e-3);
}

TEST(EvfsDenoise, PlugAndPlayNeedsTheCeresProblem) {
  const std::string scratch = ScratchDir("denoise_pnp_errors");
  const std::string data = WriteSyntheticFolder(scratch);
  const std::string out = scratch + "/out";
  const std::string reconstruct = "reconstruct --data=" + data +
                                  " --mode=interpolate --first=0 --last=2 --denoise=pnp "
                                  "--denoiser=" +
                                  NetworkPath("two_conv.onnx") + " --out=" + out;
  ExpectUserError(RunEvfs(reconstruct + " --solver=blend"), "--denoise=pnp", out);
  ExpectUserError(RunEvfs(reconstruct + " --solver=adam"), "--denoise=pnp", out);
}

}  // namespace
}  // namespace test
}  // namespace evfs
