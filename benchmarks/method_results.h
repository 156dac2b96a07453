// The results of method_benchmark and their written forms: the result file a cell's process
// hands its parent, methods.csv and methods_checkpoints.csv (which benchmarks/plot_methods.py
// plots), the Markdown tables, and the headline: the time ceres_lm (default) needs to first
// reach an Adam run's final PSNR over that run's time.
#ifndef EVFS_BENCHMARKS_METHOD_RESULTS_H_
#define EVFS_BENCHMARKS_METHOD_RESULTS_H_

#include <ostream>
#include <string>
#include <vector>

#include "evfs/app/method.h"

namespace evfs {

/// The configuration every method runs in; ceres_lm also runs in others.
constexpr char kDefaultConfig[] = "default";

/// One cell: a method in one configuration on one case.
struct CellResult {
  std::string status = "ok";  // or why the cell has no result
  double build_s = 0.0;       // problem construction / objective set-up
  double solve_s = 0.0;       // the solve or the baseline, without checkpoint scoring
  int iterations = 0;
  double initial_cost = 0.0, final_cost = 0.0;
  double psnr = 0.0, ssim = 0.0;  // CaseSummary::score; without truth psnr only
  double sharpness_ratio = 0.0;   // without truth: Laplacian variance of latent / of input
  int latent_frames = 0;
  std::string note;  // how a baseline chose its threshold, or why a solve stopped
  std::vector<Checkpoint> checkpoints;  // time_s: solve time so far, without build_s
  // Measured by the parent.
  double wall_s = 0.0;  // the whole child: start, reading, simulation, checkpoints
  double cpu_s = 0.0;   // the child's user + system time: other load on the machine barely moves it
  double peak_memory_mb = 0.0;

  double time_s() const { return build_s + solve_s; }
  bool ok() const { return status == "ok"; }
};

/// The result file: one "key value" line per field the child measures, then one "checkpoint
/// iteration time_s cost psnr ssim" line per checkpoint; newlines in texts become spaces.
std::string CellResultText(const CellResult& cell);
/// Reads CellResultText's form back (numbers with strtod, which also reads "inf", the PSNR of a
/// perfect copy); missing keys keep their defaults.
CellResult ParseCellResult(const std::string& text);

/// A case as the tables describe it.
struct CaseSummary {
  std::string id;     // "slider_predict", "clip_deblur:nfs_basketball_7"
  std::string data;   // its folder under --data
  std::string mode;   // ModeName: "interpolate", "predict" or "deblur"
  std::string title;  // what is reconstructed from what
  std::string score;  // what the PSNR and SSIM columns measure
  bool has_truth = false;
};

struct MethodCell {
  std::string method, config;
  CellResult result;
};

/// ceres_lm (default) against an Adam run of the same case.
struct Headline {
  std::string against;        // "adam" or "adam_smooth"
  double target_psnr = 0.0;   // the Adam run's final PSNR
  double against_time_s = 0;  // its build + solve
  double reach_s = -1.0;      // ceres_lm's build + solve time to first reach it; < 0: never
  double best_psnr = 0.0;     // ceres_lm's best checkpoint
  double ceres_psnr = 0.0;    // ceres_lm's final PSNR
  double ratio() const;       // reach_s / against_time_s; infinite when never reached
  double psnr_difference() const { return ceres_psnr - target_psnr; }
  bool ceres_loses() const { return ratio() > 1.0 || psnr_difference() < 0.0; }
};

/// The headlines of a case's cells, against adam and adam_smooth where both runs succeeded;
/// none without truth.
std::vector<Headline> Headlines(const std::vector<MethodCell>& cells, bool has_truth);
/// One sentence, ending with "CERES LOSES: ..." where it does.
std::string DescribeHeadline(const Headline& headline);

struct CaseReport {
  CaseSummary summary;
  std::vector<MethodCell> cells;
  std::vector<std::string> not_run;  // "method: why not"
  std::vector<Headline> headlines;
  std::string plot;  // file name of its PSNR-against-time plot; empty: none
};

/// The Markdown table of a case: the header, then one row per cell.
std::string TableHeader(bool has_truth);
std::string TableRow(const MethodCell& cell, bool has_truth);

/// methods.csv (one row per cell) and methods_checkpoints.csv (one row per checkpoint, its time
/// as methods.csv's: build + solve so far).
void WriteCsv(const std::vector<CaseReport>& reports, std::ostream& methods,
              std::ostream& checkpoints);

/// methods.md: the title, the machine and total time, `about` (the command and what the columns
/// mean), a section per case and the headline table.
std::string Markdown(const std::vector<CaseReport>& reports, const std::string& machine,
                     double total_s, const std::string& about);

}  // namespace evfs

#endif  // EVFS_BENCHMARKS_METHOD_RESULTS_H_
