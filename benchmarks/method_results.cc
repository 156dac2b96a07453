#include "evfs/benchmarks/method_results.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <sstream>

namespace evfs {

namespace {

std::string Format(const char* format, double value) {
  char text[64];
  std::snprintf(text, sizeof(text), format, value);
  return text;
}

std::string OneLine(std::string text) {
  std::replace(text.begin(), text.end(), '\n', ' ');
  return text;
}

std::string CsvQuoted(const std::string& text) {
  std::string quoted = "\"";
  for (char ch : text) quoted += ch == '"' ? std::string("\"\"") : std::string(1, ch);
  return quoted + "\"";
}

std::string WallAndCpu(const CellResult& r) {
  return Format("%.1f s", r.wall_s) + " / " + Format("%.1f s", r.cpu_s);
}

const MethodCell* FindCell(const std::vector<MethodCell>& cells, const std::string& method,
                           const std::string& config) {
  for (const MethodCell& cell : cells) {
    if (cell.method == method && cell.config == config && cell.result.ok()) return &cell;
  }
  return nullptr;
}

}  // namespace

std::string CellResultText(const CellResult& cell) {
  std::ostringstream out;
  out.precision(17);
  out << "status " << OneLine(cell.status) << "\nbuild_s " << cell.build_s << "\nsolve_s "
      << cell.solve_s << "\niterations " << cell.iterations << "\ninitial_cost "
      << cell.initial_cost << "\nfinal_cost " << cell.final_cost << "\npsnr " << cell.psnr
      << "\nssim " << cell.ssim << "\nsharpness_ratio " << cell.sharpness_ratio
      << "\nlatent_frames " << cell.latent_frames << "\nnote " << OneLine(cell.note) << "\n";
  for (const Checkpoint& checkpoint : cell.checkpoints) {
    out << "checkpoint " << checkpoint.iteration << " " << checkpoint.time_s << " "
        << checkpoint.cost << " " << checkpoint.psnr << " " << checkpoint.ssim << "\n";
  }
  return out.str();
}

CellResult ParseCellResult(const std::string& text) {
  CellResult cell;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    const size_t space = line.find(' ');
    const std::string key = line.substr(0, space);
    const std::string value = space == std::string::npos ? "" : line.substr(space + 1);
    std::vector<double> numbers;
    std::istringstream fields(value);
    for (std::string field; fields >> field;) {
      numbers.push_back(std::strtod(field.c_str(), nullptr));
    }
    numbers.resize(5, 0.0);  // the most a line holds: a checkpoint's five numbers
    if (key == "status") cell.status = value;
    if (key == "note") cell.note = value;
    if (key == "build_s") cell.build_s = numbers[0];
    if (key == "solve_s") cell.solve_s = numbers[0];
    if (key == "iterations") cell.iterations = static_cast<int>(numbers[0]);
    if (key == "initial_cost") cell.initial_cost = numbers[0];
    if (key == "final_cost") cell.final_cost = numbers[0];
    if (key == "psnr") cell.psnr = numbers[0];
    if (key == "ssim") cell.ssim = numbers[0];
    if (key == "sharpness_ratio") cell.sharpness_ratio = numbers[0];
    if (key == "latent_frames") cell.latent_frames = static_cast<int>(numbers[0]);
    if (key == "checkpoint") {
      Checkpoint checkpoint;
      checkpoint.iteration = static_cast<int>(numbers[0]);
      checkpoint.time_s = numbers[1];
      checkpoint.cost = numbers[2];
      checkpoint.psnr = numbers[3];
      checkpoint.ssim = numbers[4];
      cell.checkpoints.push_back(checkpoint);
    }
  }
  return cell;
}

double Headline::ratio() const {
  return reach_s < 0 ? std::numeric_limits<double>::infinity() : reach_s / against_time_s;
}

std::vector<Headline> Headlines(const std::vector<MethodCell>& cells, bool has_truth) {
  std::vector<Headline> headlines;
  const MethodCell* ceres = FindCell(cells, MethodName(Method::kCeresLm), kDefaultConfig);
  if (ceres == nullptr || !has_truth) return headlines;
  for (Method adam : {Method::kAdam, Method::kAdamSmooth}) {
    const MethodCell* against = FindCell(cells, MethodName(adam), kDefaultConfig);
    if (against == nullptr) continue;
    Headline headline;
    headline.against = against->method;
    headline.target_psnr = against->result.psnr;
    headline.against_time_s = against->result.time_s();
    headline.ceres_psnr = ceres->result.psnr;
    headline.best_psnr = ceres->result.psnr;
    for (const Checkpoint& checkpoint : ceres->result.checkpoints) {
      headline.best_psnr = std::max(headline.best_psnr, checkpoint.psnr);
      if (headline.reach_s < 0 && checkpoint.psnr >= headline.target_psnr) {
        headline.reach_s = ceres->result.build_s + checkpoint.time_s;
      }
    }
    headlines.push_back(headline);
  }
  return headlines;
}

std::string DescribeHeadline(const Headline& h) {
  std::string text = "ceres_lm vs " + h.against + ": " + h.against + " ends at " +
                     Format("%.2f dB", h.target_psnr) + " after " +
                     Format("%.2f s", h.against_time_s) + "; ceres_lm ";
  if (h.reach_s < 0) {
    text += "never reaches it (best " + Format("%.2f dB", h.best_psnr) + ")";
  } else {
    text += "reaches it at " + Format("%.2f s", h.reach_s) + ": ratio " + Format("%.3f", h.ratio());
  }
  text += "; final PSNR ceres_lm - " + h.against + " = " + Format("%+.2f dB", h.psnr_difference());
  if (h.ceres_loses()) {
    text += ".  CERES LOSES:";
    if (h.ratio() > 1.0) text += " slower to Adam's PSNR";
    if (h.ratio() > 1.0 && h.psnr_difference() < 0.0) text += " and";
    if (h.psnr_difference() < 0.0) text += " lower final PSNR";
  }
  return text;
}

std::string TableHeader(bool has_truth) {
  return has_truth ? "| method | config | time | iterations | PSNR | SSIM | peak memory | "
                     "cell wall / CPU |\n|---|---|---|---|---|---|---|---|\n"
                   : "| method | config | time | iterations | mean vs input PSNR | "
                     "Laplacian variance ratio | peak memory | cell wall / CPU |\n"
                     "|---|---|---|---|---|---|---|---|\n";
}

std::string TableRow(const MethodCell& cell, bool has_truth) {
  const CellResult& r = cell.result;
  if (!r.ok()) {
    return "| " + cell.method + " | " + cell.config + " | " + r.status + " | | | | " +
           Format("%.0f MB", r.peak_memory_mb) + " | " + WallAndCpu(r) + " |\n";
  }
  const std::string second =
      has_truth ? Format("%.4f", r.ssim) : Format("x%.2f", r.sharpness_ratio);
  return "| " + cell.method + " | " + cell.config + " | " + Format("%.2f s", r.time_s()) + " | " +
         std::to_string(r.iterations) + " | " + Format("%.2f dB", r.psnr) + " | " + second + " | " +
         Format("%.0f MB", r.peak_memory_mb) + " | " + WallAndCpu(r) + " |\n";
}

void WriteCsv(const std::vector<CaseReport>& reports, std::ostream& methods,
              std::ostream& checkpoints) {
  methods << "case,data,mode,score,method,config,status,time_s,build_s,solve_s,iterations,"
             "initial_cost,final_cost,psnr_db,ssim,sharpness_ratio,latent_frames,peak_memory_mb,"
             "cell_wall_s,cell_cpu_s,note\n";
  checkpoints << "case,method,config,iteration,time_s,cost,psnr_db,ssim\n";
  for (const CaseReport& report : reports) {
    const CaseSummary& c = report.summary;
    for (const MethodCell& cell : report.cells) {
      const CellResult& r = cell.result;
      methods << c.id << "," << c.data << "," << c.mode << "," << CsvQuoted(c.score) << ","
              << cell.method << "," << cell.config << "," << CsvQuoted(r.status) << ","
              << r.time_s() << "," << r.build_s << "," << r.solve_s << "," << r.iterations << ","
              << r.initial_cost << "," << r.final_cost << "," << r.psnr << "," << r.ssim << ","
              << r.sharpness_ratio << "," << r.latent_frames << "," << r.peak_memory_mb << ","
              << r.wall_s << "," << r.cpu_s << "," << CsvQuoted(r.note) << "\n";
      for (const Checkpoint& checkpoint : r.checkpoints) {
        checkpoints << c.id << "," << cell.method << "," << cell.config << ","
                    << checkpoint.iteration << "," << r.build_s + checkpoint.time_s << ","
                    << checkpoint.cost << "," << checkpoint.psnr << "," << checkpoint.ssim << "\n";
      }
    }
  }
}

std::string Markdown(const std::vector<CaseReport>& reports, const std::string& machine,
                     double total_s, const std::string& about) {
  std::string md = "# Reconstruction methods on the shared data\n\n";
  md += "Machine: " + machine + ". Total " + Format("%.0f s", total_s) + " for the run below.\n\n";
  md += about;
  for (const CaseReport& report : reports) {
    const CaseSummary& c = report.summary;
    md += "\n## " + c.title + "\n\n";
    md += "Case `" + c.id + "`; PSNR/SSIM: " + c.score + ".\n\n";
    md += TableHeader(c.has_truth);
    for (const MethodCell& cell : report.cells) md += TableRow(cell, c.has_truth);
    if (!report.not_run.empty()) {
      md += "\nNot supported: ";
      for (const std::string& line : report.not_run) md += line + "; ";
      md += "\n";
    }
    if (!report.plot.empty()) md += "\n![PSNR against time](" + report.plot + ")\n";
  }
  md +=
      "\n## Headline: ceres_lm (default) against Adam\n\n"
      "ratio: the time ceres_lm needs to first reach the Adam run's final PSNR (its build + "
      "solve time at that checkpoint) over the Adam run's build + solve time; below 1 Ceres is "
      "faster.\n\n"
      "| case | against | Adam final PSNR | Adam time | ceres_lm reaches it at | ratio | "
      "ceres_lm final PSNR | difference | verdict |\n|---|---|---|---|---|---|---|---|---|\n";
  for (const CaseReport& report : reports) {
    for (const Headline& h : report.headlines) {
      md += "| " + report.summary.id + " | " + h.against + " | " +
            Format("%.2f dB", h.target_psnr) + " | " + Format("%.2f s", h.against_time_s) + " | " +
            (h.reach_s < 0 ? "never (best " + Format("%.2f dB)", h.best_psnr)
                           : Format("%.2f s", h.reach_s)) +
            " | " + (h.reach_s < 0 ? std::string("∞") : Format("%.3f", h.ratio())) + " | " +
            Format("%.2f dB", h.ceres_psnr) + " | " + Format("%+.2f dB", h.psnr_difference()) +
            " | " + (h.ceres_loses() ? "**Ceres loses**" : "Ceres wins") + " |\n";
    }
  }
  return md;
}

}  // namespace evfs
