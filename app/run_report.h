// report.html: one page that shows a finished `evfs video` run (its video and preview, the
// windows' events, iterations, solve time and PSNR along the recording, the confidence maps, the
// event model and the settings), or one `evfs reconstruct` window (its frames, the truth and
// the baseline when scored, the solve, the confidence maps, the event model and the settings),
// read from the run's summary.json. The two pages share their layout, tables and self-check.
#ifndef EVFS_APP_RUN_REPORT_H_
#define EVFS_APP_RUN_REPORT_H_

#include <string>
#include <vector>

#include "evfs/app/reconstruct_job.h"

namespace evfs {

/// One series of a line plot: y against x, both in the units the plot's labels name.
struct PlotSeries {
  std::string name;       // the legend's text
  std::string colour;     // an SVG colour, e.g. "#1f77b4"
  std::vector<double> x;  // abscissae, same length as y
  std::vector<double> y;  // ordinates; non-finite values are left out
};

/// An inline <svg> line plot with axes, ticks at both ends of each axis and a legend. Every
/// string is HTML-escaped. An empty or all non-finite plot still draws its frame and says "no
/// data", so a page always has the same number of plots.
std::string LinePlotSvg(const std::string& title, const std::string& x_label,
                        const std::string& y_label, const std::vector<PlotSeries>& series);

/// `text` with & < > " ' replaced by their HTML entities.
std::string HtmlEscape(const std::string& text);

/// The page for the run whose summary.json holds `summary_json`; `confidence_files` are paths
/// relative to OUT of the confidence maps to show. Media are referenced by paths relative to
/// OUT, so the page is read beside its run. Throws InputError when `summary_json` is not JSON.
std::string RenderRunReport(const std::string& summary_json,
                            const std::vector<std::string>& confidence_files);

/// Writes OUT/report.html from OUT/summary.json and OUT/confidence/*.png.
void WriteRunReport(const std::string& out_folder);

/// The pictures of one reconstruction's page, as paths relative to OUT.
struct ReconstructionPictures {
  std::vector<std::string> frames;      // the synthesised frames, in time order
  std::vector<std::string> confidence;  // their confidence maps
  /// Scored (--truth): the truth frame, the output frame nearest it and the baseline (blend or
  /// copy) at that time; "" otherwise.
  std::string truth, estimate, baseline;
};

/// The page for the reconstruction whose summary.json holds `summary_json`; `settings` is the
/// command line's "name=value name=value ..." (evfs' own flags). Throws InputError when
/// `summary_json` is not JSON.
std::string RenderReconstructionReport(const std::string& summary_json,
                                       const ReconstructionPictures& pictures,
                                       const std::string& settings);

/// Writes OUT/report.html for the reconstruction `result` written into `out_folder` (by
/// WriteReconstruction: frames/, confidence/, summary.json), and with a truth OUT/report/
/// truth.png and baseline.png, 8-bit.
void WriteReconstructionReport(const ReconstructResult& result, const std::string& out_folder,
                               const std::string& settings);

}  // namespace evfs

#endif  // EVFS_APP_RUN_REPORT_H_
