#include "evfs/app/calibrate_job.h"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <fstream>
#include <nlohmann/json.hpp>
#include <vector>

#include "evfs/app/frame_lag.h"
#include "evfs/core/error.h"
#include "evfs/core/time.h"
#include "evfs/io/data_source.h"

namespace evfs {
namespace {

using Json = nlohmann::ordered_json;

// Events this long before the first frame are read too: they tell the polarity of each
// pixel's last event before it (EventCountResidual), which the fit uses.
constexpr double kEventsBeforeFirstFrameS = 0.05;
// Version of the file's layout, in its "evfs_calibration" field.
constexpr int kFileVersion = 1;

Json ValueJson(const CalibratedValue& value) {
  Json json;
  json["estimated"] = value.estimated;
  json["value"] = value.value;
  json["standard_error"] = value.standard_error;
  json["pixels"] = value.pixels;
  json["pairs"] = value.pairs;
  return json;
}

}  // namespace

CalibrateResult RunCalibration(const CalibrateRequest& request) {
  const auto start = std::chrono::steady_clock::now();
  const auto source = DataSource::Open(request.data_path);
  CalibrateResult result = RunCalibration(*source, request);
  result.time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

CalibrateResult RunCalibration(const DataSource& source, const CalibrateRequest& request) {
  const auto start = std::chrono::steady_clock::now();
  const int num_frames = static_cast<int>(source.frames().size());
  if (num_frames < 2) {
    throw InputError(
        InputError::Kind::kEmptyWindow, request.data_path, 0,
        "calibration needs two frames or more, the recording has " + std::to_string(num_frames));
  }
  if (!source.has_events()) {
    throw InputError(InputError::Kind::kEmptyWindow, request.data_path, 0,
                     "calibration needs events, the recording has none");
  }
  CalibrateResult result;
  result.first = request.first >= 0 ? request.first : 0;
  result.last = request.last >= 0 ? request.last : num_frames - 1;
  if (result.first >= num_frames || result.last >= num_frames) {
    throw InvalidArgumentError("--first/--last: the recording has frames 0 to " +
                               std::to_string(num_frames - 1));
  }
  if (result.last <= result.first) {
    throw InvalidArgumentError(
        "calibration needs two frames or more: --last must be after --first (got " +
        std::to_string(result.first) + " and " + std::to_string(result.last) + ")");
  }
  if (request.max_frames >= 2) {
    result.last = std::min(result.last, result.first + request.max_frames - 1);
  }
  std::vector<Image> frames;
  std::vector<int64_t> times_ns;
  std::vector<int> indices;
  for (int i = result.first; i <= result.last; ++i) {
    frames.push_back(source.ReadImage(i));
    times_ns.push_back(source.frames()[i].t_ns);
    indices.push_back(i);
  }
  const EventStream events = source.ReadEvents(
      times_ns.front() - SecondsToNanoseconds(kEventsBeforeFirstFrameS), times_ns.back() + 1);
  try {
    result.calibration = CalibrateEventModel(frames, times_ns, events, request.options);
  } catch (const InvalidArgumentError& error) {
    // What the data cannot tell is the recording's, not a flag's: named with its path.
    throw InputError(InputError::Kind::kEmptyWindow, request.data_path, 0, error.what());
  }
  if (request.estimate_frame_lag) {
    FrameLagOptions lag;
    lag.log_offset = result.calibration.log_offset.value;
    result.frame_lag = EstimateRecordingFrameLag(source, indices, lag);
  }
  result.time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

void PrintCalibration(const CalibrateRequest& request, const CalibrateResult& result,
                      const std::string& out_path, std::FILE* out) {
  std::fprintf(out, "event model of %s, frames %d to %d:\n", request.data_path.c_str(),
               result.first, result.last);
  std::fputs(result.calibration.description.c_str(), out);
  std::fprintf(out, "frame lag              %s\n", result.frame_lag.description.c_str());
  const EventModelParams model = ReadEventModelFile(out_path, EventModelEstimationOptions());
  std::fprintf(out,
               "--event_model=%s gives: log model, b %.4g, alpha %.3g, OFF/ON alpha ratio %.3g, "
               "saturation %.3g\n",
               out_path.c_str(), model.log_offset, model.alpha, model.off_alpha_ratio,
               model.saturation);
  std::fprintf(out, "calibrated in %.2f s into %s\n", result.time_s, out_path.c_str());
}

void WriteCalibration(const CalibrateRequest& request, const CalibrateResult& result,
                      const std::string& path) {
  const EventModelCalibration& c = result.calibration;
  Json json;
  json["evfs_calibration"] = kFileVersion;
  json["data"] = request.data_path;
  json["first"] = result.first;
  json["last"] = result.last;
  json["model"] = "log";
  json["log_offset"] = ValueJson(c.log_offset);
  json["threshold_on"] = ValueJson(c.threshold_on);
  json["threshold_off"] = ValueJson(c.threshold_off);
  json["thresholds_tied"] = c.thresholds_tied;
  json["threshold_sigma"] = ValueJson(c.threshold_sigma);
  json["background_rate_hz"] = ValueJson(c.background_rate_hz);
  json["frame_lag"] = {{"estimated", result.frame_lag.estimated},
                       {"lag_ms", result.frame_lag.lag_ns * 1e-6},
                       {"pairs", result.frame_lag.pairs},
                       {"pixels", result.frame_lag.pixels}};
  json["pixels_used"] = c.pixels_used;
  json["pixels_with_events"] = c.pixels_with_events;
  json["pairs_used"] = c.pairs_used;
  json["residual_rms_events"] = c.residual_rms_events;
  json["time_s"] = result.time_s;
  std::ofstream file(path);
  file << json.dump(2) << "\n";
  if (!file) throw InputError(InputError::Kind::kUnwritable, path, 0, "cannot write the file");
}

void PrintInfoCalibration(const DataSource& source, const std::string& data_path, int first,
                          int last, std::FILE* out) {
  CalibrateRequest request;
  request.data_path = data_path;
  request.first = first;
  request.last = last;
  request.max_frames = kInfoCalibrationFrames;
  request.options.max_fit_pixels = kInfoCalibrationPixels;
  request.estimate_frame_lag = false;
  CalibrateResult result;
  try {
    result = RunCalibration(source, request);
  } catch (const std::exception& error) {
    // InputError and InvalidArgumentError say what is missing in one line; the rest of info
    // stands without this section.
    std::fprintf(out, "event model: cannot tell: %s\n", error.what());
    return;
  }
  const int selected_last = last >= 0 ? last : static_cast<int>(source.frames().size()) - 1;
  std::fprintf(out, "event model (as evfs calibrate) on frames %d to %d", result.first,
               result.last);
  if (result.last < selected_last) {
    std::fprintf(out, ", the first %d of the selection (evfs calibrate fits them all)",
                 result.last - result.first + 1);
  }
  std::fprintf(out, ", %.2f s:\n", result.time_s);
  std::fputs(result.calibration.description.c_str(), out);
}

std::string EventModelFileFingerprint(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) return "unreadable";
  // FNV-1a, 64 bits: notices an edited file, no defence against a made-up collision.
  uint64_t hash = 14695981039346656037ull;
  for (char byte; file.get(byte);) {
    hash = (hash ^ static_cast<unsigned char>(byte)) * 1099511628211ull;
  }
  char text[17];
  std::snprintf(text, sizeof(text), "%016llx", static_cast<unsigned long long>(hash));
  return text;
}

bool IsEventModelFile(const std::string& value) {
  return value.size() > 5 && value.compare(value.size() - 5, 5, ".json") == 0;
}

EventModelParams ReadEventModelFile(const std::string& path,
                                    const EventModelEstimationOptions& estimation) {
  std::ifstream file(path);
  if (!file) {
    throw InputError(InputError::Kind::kMissingFile, path, 0,
                     "cannot read the event model file (written by evfs calibrate)");
  }
  const Json json = Json::parse(file, nullptr, /*allow_exceptions=*/false);
  const auto number = [&json](const char* key) {
    if (!json.is_object() || !json.contains(key) || !json[key].is_object() ||
        !json[key].contains("value") || !json[key]["value"].is_number()) {
      return -1.0;
    }
    return json[key]["value"].get<double>();
  };
  const double b = number("log_offset");
  const double on = number("threshold_on");
  const double off = number("threshold_off");
  if (json.is_discarded() || !json.contains("evfs_calibration") || !(b > 0.0) || !(on > 0.0) ||
      !(off > 0.0)) {
    throw InputError(InputError::Kind::kMalformed, path, 0,
                     "expected an event model file written by evfs calibrate (log_offset, "
                     "threshold_on and threshold_off, each with a positive value)");
  }
  EventModelParams params;
  params.model = EventModel::kLog;
  params.log_offset = b;
  params.alpha = estimation.alpha_times_change / on;
  params.off_alpha_ratio = on / off;
  params.saturation = estimation.measured_saturation;
  return params;
}

void ApplyEventModelFile(const std::string& path, const EventModelEstimationOptions& estimation,
                         bool keep_log_offset, bool keep_alpha, bool keep_saturation,
                         EventModelParams* model) {
  const EventModelParams calibrated = ReadEventModelFile(path, estimation);
  model->model = calibrated.model;
  if (!keep_log_offset) model->log_offset = calibrated.log_offset;
  if (!keep_alpha) {
    model->alpha = calibrated.alpha;
    model->off_alpha_ratio = calibrated.off_alpha_ratio;
  }
  if (!keep_saturation) model->saturation = calibrated.saturation;
}

}  // namespace evfs
