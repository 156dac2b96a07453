#include "app/run_report.h"

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

#include "core/error.h"

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
  const Json summary = Json::parse(summary_json, nullptr, /*allow_exceptions=*/false);
  if (summary.is_discarded() || !summary.is_object()) {
    throw InputError(InputError::Kind::kMalformed, "summary.json", 0, "a JSON object");
  }
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

  std::string confidence;
  if (!confidence_files.empty()) {
    const size_t count =
        std::min(confidence_files.size(), static_cast<size_t>(kMaxConfidenceThumbnails));
    confidence += "<div class=\"strip\">\n";
    for (size_t i = 0; i < count; ++i) {
      const size_t pick = count == 1 ? 0 : i * (confidence_files.size() - 1) / (count - 1);
      const std::string& file = confidence_files[pick];
      confidence += "<figure><img src=\"" + HtmlEscape(file) + "\" alt=\"" + HtmlEscape(file) +
                    "\"><figcaption>" + HtmlEscape(file) + "</figcaption></figure>\n";
    }
    confidence += "</div>\n";
    if (summary.contains("confidence")) confidence += Table(summary["confidence"]);
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

  // The command line's settings, "name=value name=value ...", one row each; the event model's
  // own (thresholds, log offset, model) also go to the model's table.
  Json settings = Json::object();
  Json flags = Json::object();
  for (auto it = summary.begin(); it != summary.end(); ++it) {
    if (it.key() == "settings" && it->is_string()) {
      std::istringstream words(it->get<std::string>());
      std::string word;
      while (words >> word) {
        const size_t equals = word.find('=');
        const std::string name = word.substr(0, equals);
        const std::string value = equals == std::string::npos ? "" : word.substr(equals + 1);
        flags[name] = value;
        for (const char* topic : {"threshold", "log_offset", "model", "contrast", "sigma_"}) {
          if (name.find(topic) != std::string::npos) model[name] = value;
        }
      }
    } else if (it.key() != "windows" && it.key() != "exposures") {
      settings[it.key()] = *it;
    }
  }
  if (!flags.empty()) settings["flags"] = flags;

  std::string page;
  page += "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n";
  page += "<title>evfs run: " + HtmlEscape(Scalar(summary.value("data", Json("")))) + "</title>\n";
  page +=
      "<style>\nbody{font-family:sans-serif;margin:16px;max-width:1240px}\n"
      ".media,.plots,.strip{display:flex;flex-wrap:wrap;gap:12px}\n"
      "figure{margin:0}video{max-width:600px;width:100%;background:#000}\n"
      ".strip img{width:180px;image-rendering:pixelated;border:1px solid #ccc}\n"
      "table{border-collapse:collapse;font-size:13px}th,td{border:1px solid #ddd;"
      "padding:2px 6px;text-align:left;vertical-align:top}\n"
      "svg.plot{font-size:11px;border:1px solid #eee}\n#selfcheck{display:none}\n</style>\n";
  page += "</head>\n<body>\n";
  page += "<h1>evfs " + HtmlEscape(Scalar(summary.value("command", Json("run")))) + ": " +
          HtmlEscape(Scalar(summary.value("data", Json("")))) + "</h1>\n";
  page += "<h2>Video</h2>\n<div class=\"media\">\n" + media + "</div>\n";
  page += "<h2>Along the recording</h2>\n<div class=\"plots\">\n" + plots + "</div>\n";
  if (!confidence.empty()) page += "<h2>Confidence maps</h2>\n" + confidence;
  page += "<h2>Event model</h2>\n" +
          (model.empty() ? std::string("<p>not reported by this run</p>\n") : Table(model));
  page += "<h2>Settings</h2>\n" + Table(settings);
  // A self-check, run only when the page is opened as report.html#selfcheck (the browser test
  // does): plays the video, counts the plots and lists every resource the page loaded.
  page += R"(<pre id="selfcheck"></pre>
<script>
if (location.hash === '#selfcheck') {
  window.addEventListener('load', function () {
    var report = {plots: 0, empty_plots: 0, video_ready: 0, video_time: 0, resources: []};
    document.querySelectorAll('svg.plot').forEach(function (svg) {
      report.plots++;
      var drawn = svg.querySelector('polyline[points]:not([points=""])') ||
                  svg.querySelector('.no-data');
      if (!drawn || svg.getBoundingClientRect().width === 0) report.empty_plots++;
    });
    var video = document.getElementById('video');
    var finish = function () {
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
    video.play().catch(function (e) { report.play_error = String(e); });
    setTimeout(finish, 1500);
  });
}
</script>
)";
  page += "</body>\n</html>\n";
  return page;
}

void WriteRunReport(const std::string& out_folder) {
  const fs::path out(out_folder);
  const fs::path summary_path = out / "summary.json";
  std::ifstream in(summary_path, std::ios::binary);
  if (!in) throw InputError(InputError::Kind::kMissingFile, summary_path.string(), 0, "a file");
  std::ostringstream text;
  text << in.rdbuf();
  std::vector<std::string> confidence;
  std::error_code error;
  for (const auto& entry : fs::directory_iterator(out / "confidence", error)) {
    if (entry.path().extension() == ".png")
      confidence.push_back("confidence/" + entry.path().filename().string());
  }
  std::sort(confidence.begin(), confidence.end());
  const std::string page = RenderRunReport(text.str(), confidence);
  const fs::path path = out / "report.html";
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  file << page;
  file.close();
  if (!file) throw InputError(InputError::Kind::kUnwritable, path.string(), 0, "a writable file");
}

}  // namespace evfs
