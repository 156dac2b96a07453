#include "evfs/app/run_report.h"

#include <gtest/gtest.h>

#include <string>

#include "evfs/core/error.h"

namespace evfs {
namespace {

int Count(const std::string& text, const std::string& needle) {
  int count = 0;
  for (size_t at = text.find(needle); at != std::string::npos; at = text.find(needle, at + 1))
    ++count;
  return count;
}

// A summary.json as evfs video writes it, with --frame_step (truth scores) and a setting whose
// value a page must not read as markup.
const char kSummary[] = R"({
  "command": "video",
  "data": "<script>alert('x')</script>&rec",
  "video": {"file": "video.mp4", "codec": "avc1"},
  "preview": "preview.mp4",
  "settings": "log_offset=0.5 threshold_pos=0.2 solver=ceres_lm denoiser=\"<b>\"",
  "windows": [
    {"t_begin_s": 0.0, "t_end_s": 0.1, "events": 100, "iterations": 5, "model": "log, C=0.2",
     "time_s": {"solve": 0.5}, "truth": [{"psnr": 30.0, "blend_psnr": 25.0}]},
    {"t_begin_s": 0.1, "t_end_s": 0.2, "events": 300, "iterations": 7,
     "time_s": {"solve": 0.7}, "truth": [{"psnr": 31.0, "blend_psnr": 24.0}]}
  ]
})";

TEST(RunReport, FourPlotsWithTruthThreeWithout) {
  const std::string page = RenderRunReport(kSummary, {"confidence/000000.png"});
  EXPECT_EQ(Count(page, "<svg class=\"plot\""), 4);
  EXPECT_EQ(Count(page, "<polyline"), 5);  // events, iterations, solve, PSNR: evfs and blend
  std::string without(kSummary);
  for (const char* key : {"\"truth\": [{\"psnr\": 30.0, \"blend_psnr\": 25.0}]",
                          "\"truth\": [{\"psnr\": 31.0, \"blend_psnr\": 24.0}]"}) {
    without.replace(without.find(key), std::string(key).size(), "\"x\": 0");
  }
  EXPECT_EQ(Count(RenderRunReport(without, {}), "<svg class=\"plot\""), 3);
}

TEST(RunReport, MakesNoRequestOutsideItsFolder) {
  const std::string page = RenderRunReport(kSummary, {"confidence/000000.png"});
  EXPECT_EQ(page.find("http://"), std::string::npos);
  EXPECT_EQ(page.find("https://"), std::string::npos);
  EXPECT_EQ(page.find("//cdn"), std::string::npos);
  EXPECT_NE(page.find("src=\"video.mp4\""), std::string::npos);
  EXPECT_NE(page.find("src=\"preview.mp4\""), std::string::npos);
  EXPECT_NE(page.find("src=\"confidence/000000.png\""), std::string::npos);
}

TEST(RunReport, EscapesEverythingFromTheSummary) {
  const std::string page = RenderRunReport(kSummary, {});
  // The page's only <script> is its own self-check.
  EXPECT_EQ(Count(page, "<script>"), 1);
  EXPECT_EQ(page.find("<script>alert"), std::string::npos);
  EXPECT_NE(page.find("&lt;script&gt;alert(&#39;x&#39;)&lt;/script&gt;&amp;rec"),
            std::string::npos);
  EXPECT_EQ(page.find("<b>"), std::string::npos);
  EXPECT_NE(page.find("&quot;&lt;b&gt;&quot;"), std::string::npos);
}

TEST(RunReport, ShowsTheEventModel) {
  const std::string page = RenderRunReport(kSummary, {});
  EXPECT_NE(page.find("<th>model</th><td>log, C=0.2</td>"), std::string::npos);
  EXPECT_NE(page.find("<th>log_offset</th><td>0.5</td>"), std::string::npos);
}

TEST(LinePlotSvg, EmptyPlotSaysNoData) {
  const std::string svg = LinePlotSvg("t", "x", "y", {{"s", "#000", {}, {}}});
  EXPECT_NE(svg.find("no data"), std::string::npos);
  EXPECT_EQ(svg.find("<polyline"), std::string::npos);
}

TEST(RunReport, RejectsNonJson) { EXPECT_THROW(RenderRunReport("not json", {}), InputError); }

// A summary.json as evfs reconstruct writes it with --truth and --checkpoints (shortened), with a
// data path a page must not read as markup.
const char kReconstructionSummary[] = R"({
  "mode": "interpolate",
  "data": "<img src=x onerror=alert(1)>",
  "events": 1234,
  "solver": {"name": "ceres_lm", "termination": "CONVERGENCE"},
  "model": {"event_model": "log", "alpha": 0.21},
  "solved": true,
  "iterations": 3,
  "initial_cost": 10.0,
  "final_cost": 2.0,
  "time_s": {"read": 0.1, "solve": 0.25, "total": 0.5},
  "confidence": {"folder": "confidence"},
  "truth": {"index": 1, "psnr": 31.5, "baseline": "blend", "baseline_psnr": 27.25},
  "checkpoints": [{"iteration": 0, "cost": 10.0, "psnr": 27.0},
                  {"iteration": 1, "cost": 4.0, "psnr": 30.0},
                  {"iteration": 3, "cost": 2.0, "psnr": 31.5}]
})";

ReconstructionPictures Pictures(int frames) {
  ReconstructionPictures pictures;
  for (int i = 0; i < frames; ++i) {
    pictures.frames.push_back("frames/00000" + std::to_string(i) + ".png");
    pictures.confidence.push_back("confidence/00000" + std::to_string(i) + ".png");
  }
  pictures.truth = "report/truth.png";
  pictures.estimate = pictures.frames.empty() ? "" : pictures.frames[frames / 2];
  pictures.baseline = "report/baseline.png";
  return pictures;
}

TEST(ReconstructionReport, ShowsTheFramesTheTruthAndTheSolve) {
  const std::string page = RenderReconstructionReport(kReconstructionSummary, Pictures(3),
                                                      "max_iterations=5 threshold_pos=0.2");
  for (const char* file : {"frames/000000.png", "frames/000002.png", "report/truth.png",
                           "report/baseline.png", "confidence/000001.png"}) {
    EXPECT_NE(page.find(std::string("src=\"") + file + "\""), std::string::npos) << file;
  }
  EXPECT_NE(page.find("evfs: PSNR 31.5 dB"), std::string::npos);
  EXPECT_NE(page.find("blend: PSNR 27.25 dB"), std::string::npos);
  // Cost and PSNR per iteration, one line each.
  EXPECT_EQ(Count(page, "<svg class=\"plot\""), 2);
  EXPECT_EQ(Count(page, "<polyline"), 2);
  EXPECT_NE(page.find("<th>iterations</th><td>3</td>"), std::string::npos);
  EXPECT_NE(page.find("<th>time_s.solve</th><td>0.25</td>"), std::string::npos);
  EXPECT_NE(page.find("<th>event_model</th><td>log</td>"), std::string::npos);
  EXPECT_NE(page.find("<th>threshold_pos</th><td>0.2</td>"), std::string::npos);
  EXPECT_NE(page.find("<th>flags.max_iterations</th><td>5</td>"), std::string::npos);
}

TEST(ReconstructionReport, WithoutTruthOrCheckpointsHasNeither) {
  std::string summary(kReconstructionSummary);
  const size_t truth = summary.find("  \"truth\"");
  summary = summary.substr(0, truth) + "  \"x\": 0\n}";
  const std::string page = RenderReconstructionReport(summary, Pictures(2), "");
  EXPECT_EQ(page.find("Against the truth"), std::string::npos);
  EXPECT_EQ(page.find("report/truth.png"), std::string::npos);
  EXPECT_EQ(Count(page, "<svg class=\"plot\""), 0);
  EXPECT_NE(page.find("frames/000001.png"), std::string::npos);
}

TEST(ReconstructionReport, ThumbnailsAreFewAndSpanTheWindow) {
  const ReconstructionPictures pictures = Pictures(9 * 3);
  const std::string page = RenderReconstructionReport(kReconstructionSummary, pictures, "");
  // Eight frame thumbnails from the first to the last, six confidence maps, three scored.
  EXPECT_EQ(Count(page, "<img "), 8 + 6 + 3);
  EXPECT_NE(page.find("src=\"" + pictures.frames.front() + "\""), std::string::npos);
  EXPECT_NE(page.find("src=\"" + pictures.frames.back() + "\""), std::string::npos);
}

TEST(ReconstructionReport, MakesNoRequestOutsideItsFolderAndEscapes) {
  const std::string page = RenderReconstructionReport(kReconstructionSummary, Pictures(2), "");
  EXPECT_EQ(page.find("http://"), std::string::npos);
  EXPECT_EQ(page.find("https://"), std::string::npos);
  EXPECT_EQ(page.find("<img src=x"), std::string::npos);
  EXPECT_NE(page.find("&lt;img src=x onerror=alert(1)&gt;"), std::string::npos);
  EXPECT_EQ(Count(page, "<script>"), 1);
  EXPECT_THROW(RenderReconstructionReport("[1, 2]", Pictures(1), ""), InputError);
}

}  // namespace
}  // namespace evfs
