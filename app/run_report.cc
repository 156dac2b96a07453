#include "evfs/app/run_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "evfs/core/error.h"
#include "evfs/io/image_io.h"

namespace evfs {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

// The plots are inline SVG written here rather than drawn by matplotlib or a JavaScript
// library: evfs then needs no Python at run time, the page makes no request and holds no
// script to load, and a plot of a few hundred windows costs a few kilobytes.
constexpr int kPlotWidth = 560;
constexpr int kPlotHeight = 220;
constexpr int kMarginLeft = 64;
constexpr int kMarginRight = 16;
constexpr int kMarginTop = 28;
constexpr int kMarginBottom = 40;
// Thumbnails of the confidence maps: enough to see how it changes along the run, few enough to
// keep the page light (each is a reference to a PNG in OUT, not a copy).
constexpr int kMaxConfidenceThumbnails = 6;
// Thumbnails of one reconstruction's frames, for the same reason.
constexpr int kMaxFrameThumbnails = 8;

std::string Format(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.4g", value);
  return buffer;
}

std::string Scalar(const Json& value) {
  if (value.is_string()) return value.get<std::string>();
  return value.dump();
}

double NumberOr(const Json& object, const char* key) {
  if (!object.is_object() || !object.contains(key) || !object[key].is_number())
    return std::numeric_limits<double>::quiet_NaN();
  return object[key].get<double>();
}

// A two-column table of every key of `object` whose value is not an array; nested objects are
// flattened as parent.child.
void AppendRows(const Json& object, const std::string& prefix, std::string* rows) {
  for (auto it = object.begin(); it != object.end(); ++it) {
    const std::string key = prefix.empty() ? it.key() : prefix + "." + it.key();
    if (it->is_object()) {
      AppendRows(*it, key, rows);
    } else if (!it->is_array()) {
      *rows +=
          "<tr><th>" + HtmlEscape(key) + "</th><td>" + HtmlEscape(Scalar(*it)) + "</td></tr>\n";
    }
  }
}

std::string Table(const Json& object) {
  std::string rows;
  AppendRows(object, "", &rows);
  return "<table>\n" + rows + "</table>\n";
}

// `count` of `files` evenly spread from the first to the last, as <figure>s.
std::string Thumbnails(const std::vector<std::string>& files, size_t count) {
  count = std::min(files.size(), count);
  std::string strip = "<div class=\"strip\">\n";
  for (size_t i = 0; i < count; ++i) {
    const size_t pick = count == 1 ? 0 : i * (files.size() - 1) / (count - 1);
    strip += "<figure><img src=\"" + HtmlEscape(files[pick]) + "\" alt=\"" +
             HtmlEscape(files[pick]) + "\"><figcaption>" + HtmlEscape(files[pick]) +
             "</figcaption></figure>\n";
  }
  return strip + "</div>\n";
}

// The confidence maps' thumbnails and what summary.json says of them; "" without maps.
std::string ConfidenceSection(const Json& summary, const std::vector<std::string>& files) {
  if (files.empty()) return "";
  std::string section = "<h2>Confidence maps</h2>\n" + Thumbnails(files, kMaxConfidenceThumbnails);
  if (summary.contains("confidence")) section += Table(summary["confidence"]);
  return section;
}

// The command line's settings, "name=value name=value ...", one key each; the event model's own
// (thresholds, log offset, model) also go to `model`.
Json SettingsFlags(const std::string& settings, Json* model) {
  Json flags = Json::object();
  std::istringstream words(settings);
  std::string word;
  while (words >> word) {
    const size_t equals = word.find('=');
    const std::string name = word.substr(0, equals);
    const std::string value = equals == std::string::npos ? "" : word.substr(equals + 1);
    flags[name] = value;
    for (const char* topic : {"threshold", "log_offset", "model", "contrast", "sigma_"}) {
      if (name.find(topic) != std::string::npos) (*model)[name] = value;
    }
  }
  return flags;
}

// The page up to its first section: `title` in the tab, `heading` on the page.
std::string PageStart(const std::string& title, const std::string& heading) {
  std::string page;
  page += "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n";
  page += "<title>" + HtmlEscape(title) + "</title>\n";
  page +=
      "<style>\nbody{font-family:sans-serif;margin:16px;max-width:1240px}\n"
      ".media,.plots,.strip{display:flex;flex-wrap:wrap;gap:12px}\n"
      "figure{margin:0}video{max-width:600px;width:100%;background:#000}\n"
      ".strip img{width:180px;image-rendering:pixelated;border:1px solid #ccc}\n"
      "table{border-collapse:collapse;font-size:13px}th,td{border:1px solid #ddd;"
      "padding:2px 6px;text-align:left;vertical-align:top}\n"
      "svg.plot{font-size:11px;border:1px solid #eee}\n#selfcheck{display:none}\n</style>\n";
  page += "</head>\n<body>\n<h1>" + HtmlEscape(heading) + "</h1>\n";
  return page;
}

// The event model and settings sections, the self-check and the page's end.
std::string PageEnd(const Json& model, const Json& settings) {
  std::string page;
  page += "<h2>Event model</h2>\n" +
          (model.empty() ? std::string("<p>not reported by this run</p>\n") : Table(model));
  page += "<h2>Settings</h2>\n" + Table(settings);
  // A self-check, run only when the page is opened as report.html#selfcheck or #selfcheck:MS (the
  // browser test does): plays the video if there is one, counts the plots and the pictures that
  // did not load and lists every resource the page loaded. It reports once the video has shown a
  // frame and its clock has moved, or after MS milliseconds (1500 unless given) if it never does.
  page += R"(<pre id="selfcheck"></pre>
<script>
var selfcheck = /^#selfcheck(?::([0-9]+))?$/.exec(location.hash);
if (selfcheck) {
  var wait_ms = selfcheck[1] ? Number(selfcheck[1]) : 1500;
  window.addEventListener('load', function () {
    var report = {plots: 0, empty_plots: 0, images: 0, broken_images: 0, video_ready: 0,
                  video_time: 0, resources: []};
    document.querySelectorAll('svg.plot').forEach(function (svg) {
      report.plots++;
      var drawn = svg.querySelector('polyline[points]:not([points=""])') ||
                  svg.querySelector('.no-data');
      if (!drawn || svg.getBoundingClientRect().width === 0) report.empty_plots++;
    });
    document.querySelectorAll('img').forEach(function (img) {
      report.images++;
      if (!img.complete || img.naturalWidth === 0) report.broken_images++;
    });
    var video = document.getElementById('video');
    var reported = false;
    var finish = function () {
      if (reported) return;
      reported = true;
      report.video_ready = video ? video.readyState : -1;
      report.video_time = video ? video.currentTime : -1;
      report.resources = performance.getEntriesByType('resource').map(function (e) {
        return e.name;
      });
      document.querySelectorAll('[src],[href]').forEach(function (element) {
        report.resources.push(element.src || element.href);
      });
      document.getElementById('selfcheck').textContent = 'SELFCHECK ' + JSON.stringify(report);
    };
    if (!video) { finish(); return; }
    video.muted = true;
    video.addEventListener('timeupdate', function () {
      if (video.readyState >= 2 && video.currentTime > 0) finish();
    });
    video.play().catch(function (e) { report.play_error = String(e); });
    setTimeout(finish, wait_ms);
  });
}
</script>
)";
  page += "</body>\n</html>\n";
  return page;
}

// The text of OUT/summary.json.
std::string ReadSummary(const fs::path& out) {
  const fs::path summary_path = out / "summary.json";
  std::ifstream in(summary_path, std::ios::binary);
  if (!in) throw InputError(InputError::Kind::kMissingFile, summary_path.string(), 0, "a file");
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// The PNGs of OUT/`folder`, as paths relative to OUT, sorted (their names are frame numbers).
std::vector<std::string> PngFiles(const fs::path& out, const std::string& folder) {
  std::vector<std::string> files;
  std::error_code error;
  for (const auto& entry : fs::directory_iterator(out / folder, error)) {
    if (entry.path().extension() == ".png")
      files.push_back(folder + "/" + entry.path().filename().string());
  }
  std::sort(files.begin(), files.end());
  return files;
}

void WritePage(const fs::path& out, const std::string& page) {
  const fs::path path = out / "report.html";
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  file << page;
  file.close();
  if (!file) throw InputError(InputError::Kind::kUnwritable, path.string(), 0, "a writable file");
}

Json ParseSummary(const std::string& summary_json) {
  Json summary = Json::parse(summary_json, nullptr, /*allow_exceptions=*/false);
  if (summary.is_discarded() || !summary.is_object()) {
    throw InputError(InputError::Kind::kMalformed, "summary.json", 0, "a JSON object");
  }
  return summary;
}

}  // namespace

std::string HtmlEscape(const std::string& text) {
  std::string escaped;
  escaped.reserve(text.size());
  for (const char c : text) {
    switch (c) {
      case '&':
        escaped += "&amp;";
        break;
      case '<':
        escaped += "&lt;";
        break;
      case '>':
        escaped += "&gt;";
        break;
      case '"':
        escaped += "&quot;";
        break;
      case '\'':
        escaped += "&#39;";
        break;
      default:
        escaped += c;
    }
  }
  return escaped;
}

std::string LinePlotSvg(const std::string& title, const std::string& x_label,
                        const std::string& y_label, const std::vector<PlotSeries>& series) {
  double x_min = std::numeric_limits<double>::infinity(), x_max = -x_min;
  double y_min = x_min, y_max = -x_min;
  for (const PlotSeries& s : series) {
    for (size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      x_min = std::min(x_min, s.x[i]);
      x_max = std::max(x_max, s.x[i]);
      y_min = std::min(y_min, s.y[i]);
      y_max = std::max(y_max, s.y[i]);
    }
  }
  const bool has_data = x_min <= x_max;
  if (has_data) {
    // A flat series or a single point still gets a visible range.
    if (x_max == x_min) x_max = x_min + 1.0;
    if (y_max == y_min) {
      y_min -= 0.5;
      y_max += 0.5;
    }
  }
  const double plot_w = kPlotWidth - kMarginLeft - kMarginRight;
  const double plot_h = kPlotHeight - kMarginTop - kMarginBottom;
  const auto px = [&](double x) { return kMarginLeft + (x - x_min) / (x_max - x_min) * plot_w; };
  const auto py = [&](double y) {
    return kMarginTop + plot_h - (y - y_min) / (y_max - y_min) * plot_h;
  };
  std::ostringstream svg;
  svg << "<svg class=\"plot\" width=\"" << kPlotWidth << "\" height=\"" << kPlotHeight
      << "\" viewBox=\"0 0 " << kPlotWidth << ' ' << kPlotHeight << "\" role=\"img\" aria-label=\""
      << HtmlEscape(title) << "\">\n";
  svg << "<text x=\"" << kPlotWidth / 2 << "\" y=\"18\" text-anchor=\"middle\" "
      << "font-weight=\"bold\">" << HtmlEscape(title) << "</text>\n";
  svg << "<rect x=\"" << kMarginLeft << "\" y=\"" << kMarginTop << "\" width=\"" << plot_w
      << "\" height=\"" << plot_h << "\" fill=\"none\" stroke=\"#888\"/>\n";
  svg << "<text x=\"" << kMarginLeft + plot_w / 2 << "\" y=\"" << kPlotHeight - 6
      << "\" text-anchor=\"middle\">" << HtmlEscape(x_label) << "</text>\n";
  svg << "<text transform=\"translate(14," << kMarginTop + plot_h / 2
      << ") rotate(-90)\" text-anchor=\"middle\">" << HtmlEscape(y_label) << "</text>\n";
  if (!has_data) {
    svg << "<text class=\"no-data\" x=\"" << kMarginLeft + plot_w / 2 << "\" y=\""
        << kMarginTop + plot_h / 2 << "\" text-anchor=\"middle\">no data</text>\n</svg>\n";
    return svg.str();
  }
  // Ticks at both ends of each axis: the range is what a reader needs from a run's plot.
  const int bottom = kMarginTop + static_cast<int>(plot_h);
  svg << "<text x=\"" << kMarginLeft << "\" y=\"" << bottom + 14 << "\" text-anchor=\"start\">"
      << Format(x_min) << "</text>\n";
  svg << "<text x=\"" << kMarginLeft + plot_w << "\" y=\"" << bottom + 14
      << "\" text-anchor=\"end\">" << Format(x_max) << "</text>\n";
  svg << "<text x=\"" << kMarginLeft - 4 << "\" y=\"" << bottom << "\" text-anchor=\"end\">"
      << Format(y_min) << "</text>\n";
  svg << "<text x=\"" << kMarginLeft - 4 << "\" y=\"" << kMarginTop + 10
      << "\" text-anchor=\"end\">" << Format(y_max) << "</text>\n";
  int legend_y = kMarginTop + 14;
  for (const PlotSeries& s : series) {
    std::ostringstream points;
    int count = 0;
    for (size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      points << (count++ == 0 ? "" : " ") << Format(px(s.x[i])) << ',' << Format(py(s.y[i]));
    }
    const std::string colour = HtmlEscape(s.colour);
    svg << "<polyline fill=\"none\" stroke=\"" << colour << "\" stroke-width=\"1.5\" points=\""
        << points.str() << "\"/>\n";
    if (count == 1) {
      svg << "<circle r=\"3\" fill=\"" << colour << "\" cx=\"" << Format(px(s.x[0])) << "\" cy=\""
          << Format(py(s.y[0])) << "\"/>\n";
    }
    svg << "<text x=\"" << kMarginLeft + plot_w - 6 << "\" y=\"" << legend_y
        << "\" text-anchor=\"end\" fill=\"" << colour << "\">" << HtmlEscape(s.name) << "</text>\n";
    legend_y += 14;
  }
  svg << "</svg>\n";
  return svg.str();
}

std::string RenderRunReport(const std::string& summary_json,
                            const std::vector<std::string>& confidence_files) {
  const Json summary = ParseSummary(summary_json);
  const Json windows =
      summary.contains("windows") && summary["windows"].is_array() ? summary["windows"] : Json();

  // Per window, at the middle of its time span.
  std::vector<double> t, events, iterations, solve_s;
  std::vector<double> truth_t, psnr, blend_psnr;
  for (const Json& window : windows) {
    const double time = 0.5 * (NumberOr(window, "t_begin_s") + NumberOr(window, "t_end_s"));
    t.push_back(time);
    events.push_back(NumberOr(window, "events"));
    iterations.push_back(NumberOr(window, "iterations"));
    solve_s.push_back(window.contains("time_s") ? NumberOr(window["time_s"], "solve")
                                                : std::numeric_limits<double>::quiet_NaN());
    if (window.contains("truth") && window["truth"].is_array()) {
      for (const Json& score : window["truth"]) {
        truth_t.push_back(time);
        psnr.push_back(NumberOr(score, "psnr"));
        blend_psnr.push_back(NumberOr(score, "blend_psnr"));
      }
    }
  }
  std::string plots;
  plots +=
      LinePlotSvg("Events per window", "time (s)", "events", {{"events", "#1f77b4", t, events}});
  plots += LinePlotSvg("Solver iterations per window", "time (s)", "iterations",
                       {{"iterations", "#2ca02c", t, iterations}});
  plots += LinePlotSvg("Solve time per window", "time (s)", "solve (s)",
                       {{"solve", "#d62728", t, solve_s}});
  // PSNR against the frames left out (--frame_step); only a run that left frames out has it.
  if (!truth_t.empty()) {
    plots += LinePlotSvg(
        "PSNR against the held-out frames", "time (s)", "PSNR (dB)",
        {{"evfs", "#1f77b4", truth_t, psnr}, {"blend", "#ff7f0e", truth_t, blend_psnr}});
  }

  std::string media;
  const auto video_tag = [](const std::string& file, const std::string& id,
                            const std::string& caption) {
    return "<figure><video id=\"" + id + "\" src=\"" + HtmlEscape(file) +
           "\" controls loop muted playsinline preload=\"auto\"></video><figcaption>" +
           HtmlEscape(caption) + "</figcaption></figure>\n";
  };
  // The videos are referenced beside the page, not embedded as data: URIs: an MP4 of a long run
  // is megabytes, base64 would add a third, and the page already lives in OUT with them.
  if (summary.contains("video") && summary["video"].contains("file")) {
    media += video_tag(Scalar(summary["video"]["file"]), "video",
                       "video (" + Scalar(summary["video"].value("codec", Json("?"))) + ")");
  }
  if (summary.contains("preview") && summary["preview"].is_string()) {
    media += video_tag(summary["preview"].get<std::string>(), "preview",
                       "preview: last observed frame | reconstruction | events");
  }

  // The event model: what the first solved window used (each window reports its own).
  Json model = Json::object();
  for (const Json& window : windows) {
    for (const char* key : {"model", "contrast_threshold", "threshold_pos", "threshold_neg",
                            "log_offset", "event_model"}) {
      if (window.contains(key)) model[key] = window[key];
    }
    if (!model.empty()) break;
  }
  if (summary.contains("model")) model["run"] = summary["model"];

  // The command line's settings, one row each; the event model's own also in its table.
  Json settings = Json::object();
  Json flags = Json::object();
  for (auto it = summary.begin(); it != summary.end(); ++it) {
    if (it.key() == "settings" && it->is_string()) {
      flags = SettingsFlags(it->get<std::string>(), &model);
    } else if (it.key() != "windows" && it.key() != "exposures") {
      settings[it.key()] = *it;
    }
  }
  if (!flags.empty()) settings["flags"] = flags;

  const std::string data = Scalar(summary.value("data", Json("")));
  std::string page = PageStart(
      "evfs run: " + data, "evfs " + Scalar(summary.value("command", Json("run"))) + ": " + data);
  page += "<h2>Video</h2>\n<div class=\"media\">\n" + media + "</div>\n";
  page += "<h2>Along the recording</h2>\n<div class=\"plots\">\n" + plots + "</div>\n";
  page += ConfidenceSection(summary, confidence_files);
  return page + PageEnd(model, settings);
}

void WriteRunReport(const std::string& out_folder) {
  const fs::path out(out_folder);
  WritePage(out, RenderRunReport(ReadSummary(out), PngFiles(out, "confidence")));
}

std::string RenderReconstructionReport(const std::string& summary_json,
                                       const ReconstructionPictures& pictures,
                                       const std::string& settings_text) {
  const Json summary = ParseSummary(summary_json);
  const std::string mode = Scalar(summary.value("mode", Json("")));
  const std::string data = Scalar(summary.value("data", Json("")));
  std::string page =
      PageStart("evfs reconstruct: " + data, "evfs reconstruct " + mode + ": " + data);

  page += "<h2>Synthesised frames</h2>\n";
  page += pictures.frames.empty() ? std::string("<p>no frames</p>\n")
                                  : Thumbnails(pictures.frames, kMaxFrameThumbnails);
  page += "<p>" + std::to_string(pictures.frames.size()) +
          " frames in frames/, their times in timestamps.txt</p>\n";

  // The scored frame beside the truth and the baseline the score compares against.
  if (summary.contains("truth") && summary["truth"].is_object() && !pictures.truth.empty()) {
    const Json& truth = summary["truth"];
    const std::string baseline = Scalar(truth.value("baseline", Json("baseline")));
    const auto figure = [](const std::string& file, const std::string& caption) {
      return "<figure><img src=\"" + HtmlEscape(file) + "\" alt=\"" + HtmlEscape(caption) +
             "\"><figcaption>" + HtmlEscape(caption) + "</figcaption></figure>\n";
    };
    page += "<h2>Against the truth</h2>\n<div class=\"strip\">\n";
    page += figure(pictures.truth, "truth: frame " + Scalar(truth.value("index", Json(-1))));
    page += figure(pictures.estimate, "evfs: PSNR " + Format(NumberOr(truth, "psnr")) + " dB");
    page += figure(pictures.baseline,
                   baseline + ": PSNR " + Format(NumberOr(truth, "baseline_psnr")) + " dB");
    page += "</div>\n" + Table(truth);
  }

  // The solve: its iterations and times, and with --checkpoints its cost (and PSNR) per
  // iteration.
  page += "<h2>Solve</h2>\n";
  Json solve = Json::object();
  for (const char* key : {"solved", "iterations", "initial_cost", "final_cost", "time_s"}) {
    if (summary.contains(key)) solve[key] = summary[key];
  }
  if (summary.contains("solver")) solve["solver"] = summary["solver"];
  page += Table(solve);
  if (summary.contains("checkpoints") && summary["checkpoints"].is_array()) {
    std::vector<double> iteration, cost, psnr;
    for (const Json& checkpoint : summary["checkpoints"]) {
      iteration.push_back(NumberOr(checkpoint, "iteration"));
      cost.push_back(NumberOr(checkpoint, "cost"));
      psnr.push_back(NumberOr(checkpoint, "psnr"));
    }
    page += "<div class=\"plots\">\n";
    page += LinePlotSvg("Cost per iteration", "iteration", "cost",
                        {{"cost", "#1f77b4", iteration, cost}});
    if (summary.contains("truth")) {
      page += LinePlotSvg("PSNR against the truth per iteration", "iteration", "PSNR (dB)",
                          {{"evfs", "#2ca02c", iteration, psnr}});
    }
    page += "</div>\n";
  }
  page += ConfidenceSection(summary, pictures.confidence);

  Json model = summary.contains("model") ? summary["model"] : Json::object();
  Json settings = Json::object();
  for (auto it = summary.begin(); it != summary.end(); ++it) {
    if (it.key() != "checkpoints" && it.key() != "model") settings[it.key()] = *it;
  }
  const Json flags = SettingsFlags(settings_text, &model);
  if (!flags.empty()) settings["flags"] = flags;
  return page + PageEnd(model, settings);
}

void WriteReconstructionReport(const ReconstructResult& result, const std::string& out_folder,
                               const std::string& settings) {
  const fs::path out(out_folder);
  ReconstructionPictures pictures;
  pictures.frames = PngFiles(out, "frames");
  pictures.confidence = PngFiles(out, "confidence");
  if (result.has_truth && result.output.num_frames() > 0) {
    // The truth and the baseline are not among the outputs: the page gets its own copies,
    // 8-bit, in OUT/report/; the estimate is the output frame nearest the truth's time.
    const fs::path folder = out / "report";
    std::error_code error;
    fs::create_directories(folder, error);
    if (error) {
      throw InputError(InputError::Kind::kUnwritable, folder.string(), 0, "a writable folder");
    }
    WriteGreyPng8((folder / "truth.png").string(), result.truth.image);
    WriteGreyPng8((folder / "baseline.png").string(),
                  result.baseline.frame(result.truth.latent_index));
    const int nearest = result.output.NearestFrame(result.truth.timestamp_ns);
    pictures.truth = "report/truth.png";
    pictures.baseline = "report/baseline.png";
    if (nearest >= 0 && nearest < static_cast<int>(pictures.frames.size())) {
      pictures.estimate = pictures.frames[static_cast<size_t>(nearest)];
    }
  }
  WritePage(out, RenderReconstructionReport(ReadSummary(out), pictures, settings));
}

}  // namespace evfs
