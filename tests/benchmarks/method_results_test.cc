#include "evfs/benchmarks/method_results.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

namespace evfs {
namespace {

Checkpoint MakeCheckpoint(int iteration, double time_s, double psnr) {
  Checkpoint checkpoint;
  checkpoint.iteration = iteration;
  checkpoint.time_s = time_s;
  checkpoint.cost = 1.0 / (iteration + 1);
  checkpoint.psnr = psnr;
  checkpoint.ssim = psnr / 100.0;
  return checkpoint;
}

MethodCell MakeCell(const std::string& method, double build_s, double solve_s, double psnr,
                    std::vector<Checkpoint> checkpoints = {}) {
  MethodCell cell{method, kDefaultConfig, CellResult()};
  cell.result.build_s = build_s;
  cell.result.solve_s = solve_s;
  cell.result.psnr = psnr;
  cell.result.checkpoints = std::move(checkpoints);
  return cell;
}

TEST(CellResultText, RoundTripsEveryFieldTheChildMeasures) {
  CellResult cell;
  cell.status = "error: two\nlines";
  cell.build_s = 0.1;
  cell.solve_s = 1.0 / 3.0;
  cell.iterations = 7;
  cell.initial_cost = 2.5;
  cell.final_cost = 1e-7;
  cell.psnr = std::numeric_limits<double>::infinity();  // a perfect copy
  cell.ssim = 0.987654321;
  cell.sharpness_ratio = 1.25;
  cell.latent_frames = 14;
  cell.note = "Function tolerance reached. |cost_change|/cost: 3.9e-05";
  cell.checkpoints = {MakeCheckpoint(0, 0.0, 20.5), MakeCheckpoint(1, 0.25, 23.0)};

  const CellResult read = ParseCellResult(CellResultText(cell));
  EXPECT_EQ(read.status, "error: two lines");
  EXPECT_EQ(read.build_s, cell.build_s);
  EXPECT_EQ(read.solve_s, cell.solve_s);  // 17 digits: exact
  EXPECT_EQ(read.iterations, 7);
  EXPECT_EQ(read.initial_cost, 2.5);
  EXPECT_EQ(read.final_cost, 1e-7);
  EXPECT_TRUE(std::isinf(read.psnr));
  EXPECT_EQ(read.ssim, cell.ssim);
  EXPECT_EQ(read.sharpness_ratio, 1.25);
  EXPECT_EQ(read.latent_frames, 14);
  EXPECT_EQ(read.note, cell.note);
  ASSERT_EQ(read.checkpoints.size(), 2u);
  EXPECT_EQ(read.checkpoints[1].iteration, 1);
  EXPECT_EQ(read.checkpoints[1].time_s, 0.25);
  EXPECT_EQ(read.checkpoints[1].cost, 0.5);
  EXPECT_EQ(read.checkpoints[1].psnr, 23.0);
  EXPECT_EQ(read.checkpoints[1].ssim, 0.23);
}

TEST(ParseCellResult, AnEmptyFileIsADefaultResult) {
  const CellResult read = ParseCellResult("");
  EXPECT_TRUE(read.ok());
  EXPECT_TRUE(read.checkpoints.empty());
}

TEST(WriteCsv, WritesOneRowPerCellAndPerCheckpoint) {
  CaseReport report;
  report.summary = CaseSummary{"clip_deblur:nfs", "nfs", "deblur", "title", "mean \"0-7\"", true};
  report.cells.push_back(MakeCell("ceres_lm", 0.5, 1.5, 26.0, {MakeCheckpoint(0, 0.25, 25.0)}));
  report.cells.back().result.note = "a, \"quoted\" note";
  report.cells.push_back(MakeCell("edi", 0.0, 0.0, 0.0));
  report.cells.back().result.status = "timed out after 600 s";
  std::ostringstream methods, checkpoints;
  WriteCsv({report}, methods, checkpoints);
  EXPECT_EQ(methods.str(),
            "case,data,mode,score,method,config,status,time_s,build_s,solve_s,iterations,"
            "initial_cost,final_cost,psnr_db,ssim,sharpness_ratio,latent_frames,peak_memory_mb,"
            "cell_wall_s,cell_cpu_s,note\n"
            "clip_deblur:nfs,nfs,deblur,\"mean \"\"0-7\"\"\",ceres_lm,default,\"ok\",2,0.5,1.5,0,0,"
            "0,26,0,0,0,0,0,0,\"a, \"\"quoted\"\" note\"\n"
            "clip_deblur:nfs,nfs,deblur,\"mean \"\"0-7\"\"\",edi,default,"
            "\"timed out after 600 s\",0,0,0,0,0,0,0,0,0,0,0,0,0,\"\"\n");
  // The checkpoint's time counts the build, as methods.csv's time_s does.
  EXPECT_EQ(checkpoints.str(),
            "case,method,config,iteration,time_s,cost,psnr_db,ssim\n"
            "clip_deblur:nfs,ceres_lm,default,0,0.75,1,25,0.25\n");
}

TEST(TableRow, AFailedCellShowsWhyAndItsProcess) {
  MethodCell cell = MakeCell("ceres_lm", 0.0, 0.0, 0.0);
  cell.result.status = "timed out after 600 s";
  cell.result.peak_memory_mb = 812.4;
  cell.result.wall_s = 600.04;
  cell.result.cpu_s = 1190.0;
  EXPECT_EQ(TableRow(cell, true),
            "| ceres_lm | default | timed out after 600 s | | | | 812 MB | 600.0 s / 1190.0 s |\n");
}

TEST(TableRow, WithoutTruthTheSecondScoreIsTheSharpnessRatio) {
  MethodCell cell = MakeCell("edi", 0.25, 1.0, 30.126);
  cell.result.sharpness_ratio = 1.5;
  cell.result.ssim = 0.5;
  EXPECT_EQ(TableRow(cell, false),
            "| edi | default | 1.25 s | 0 | 30.13 dB | x1.50 | 0 MB | 0.0 s / 0.0 s |\n");
  EXPECT_EQ(TableRow(cell, true),
            "| edi | default | 1.25 s | 0 | 30.13 dB | 0.5000 | 0 MB | 0.0 s / 0.0 s |\n");
}

TEST(Headlines, CeresReachesAdamsPsnrAtItsFirstCheckpointAtOrAboveIt) {
  const std::vector<MethodCell> cells = {
      MakeCell("ceres_lm", 0.5, 2.0, 26.0,
               {MakeCheckpoint(0, 0.0, 20.0), MakeCheckpoint(1, 0.5, 24.0),
                MakeCheckpoint(2, 1.0, 27.0), MakeCheckpoint(3, 2.0, 26.0)}),
      MakeCell("adam", 0.0, 10.0, 24.0), MakeCell("adam_smooth", 0.0, 20.0, 27.5)};
  const std::vector<Headline> headlines = Headlines(cells, true);
  ASSERT_EQ(headlines.size(), 2u);
  EXPECT_EQ(headlines[0].against, "adam");
  EXPECT_DOUBLE_EQ(headlines[0].reach_s, 1.0);  // build 0.5 + checkpoint 0.5
  EXPECT_DOUBLE_EQ(headlines[0].ratio(), 0.1);
  EXPECT_DOUBLE_EQ(headlines[0].psnr_difference(), 2.0);
  EXPECT_FALSE(headlines[0].ceres_loses());
  EXPECT_EQ(headlines[1].against, "adam_smooth");
  EXPECT_LT(headlines[1].reach_s, 0.0);
  EXPECT_EQ(headlines[1].best_psnr, 27.0);
  EXPECT_TRUE(std::isinf(headlines[1].ratio()));
  EXPECT_TRUE(headlines[1].ceres_loses());
  EXPECT_EQ(DescribeHeadline(headlines[1]),
            "ceres_lm vs adam_smooth: adam_smooth ends at 27.50 dB after 20.00 s; ceres_lm never "
            "reaches it (best 27.00 dB); final PSNR ceres_lm - adam_smooth = -1.50 dB.  CERES "
            "LOSES: slower to Adam's PSNR and lower final PSNR");
}

TEST(Headlines, NoneWithoutTruthOrWithoutASuccessfulRun) {
  std::vector<MethodCell> cells = {MakeCell("ceres_lm", 0.5, 2.0, 26.0),
                                   MakeCell("adam", 0.0, 10.0, 24.0)};
  EXPECT_TRUE(Headlines(cells, false).empty());
  cells[1].result.status = "timed out after 600 s";
  EXPECT_TRUE(Headlines(cells, true).empty());
}

}  // namespace
}  // namespace evfs
