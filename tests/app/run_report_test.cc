#include "app/run_report.h"

#include <gtest/gtest.h>

#include <string>

#include "core/error.h"

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

}  // namespace
}  // namespace evfs
