#include "evfs/denoiser/denoiser.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <mutex>
#include <opencv2/core.hpp>
#include <opencv2/core/utils/logger.hpp>
#include <opencv2/dnn.hpp>
#include <opencv2/dnn/all_layers.hpp>
#include <set>
#include <sstream>
#include <thread>

#include "evfs/core/error.h"
#include "evfs/core/option_checker.h"
#include "evfs/core/parallel.h"
#include "evfs/denoiser/sha256.h"

namespace evfs {
namespace {

namespace fs = std::filesystem;

// Bounds of the options: a tile must hold a few network receptive fields to be worth a run,
// and neither a tile nor a margin may exceed what any frame evfs writes could need.
constexpr int kMinTileSizePx = 8;
constexpr int kMaxTileSizePx = 1 << 14;
constexpr int kMaxMarginPx = 1024;
constexpr int kMaxThreads = 1024;
// The probe that checks a network's shape at load: an odd, non-square size, so that a network
// that swaps, crops or resamples the axes is caught.
constexpr int kProbeHeight = 19;
constexpr int kProbeWidth = 26;

// Where a network's output pixels look (DeriveGeometry).
struct NetworkGeometry {
  int radius_px;          // receptive radius in input pixels; -1: unknown
  int input_multiple_px;  // input sides and tile offsets are kept multiples of this
};

// Layers that act on each pixel alone (no spatial extent): they add nothing to the receptive
// field. OpenCV's names for what ONNX exports of DnCNN-style networks contain.
const std::set<std::string>& PointwiseLayerTypes() {
  static const std::set<std::string> types = {
      "ReLU",  "ReLU6", "ELU",   "PReLU", "TanH",     "Sigmoid",     "BatchNorm", "Scale",
      "Power", "Clip",  "Const", "Split", "Identity", "NaryEltwise", "Eltwise",   "Concat"};
  return types;
}

// The first line of an OpenCV error, without its source location: OpenCV's messages span lines
// and name its own files, and evfs reports one line.
std::string ShortCvMessage(const cv::Exception& error) {
  std::string message = error.err.empty() ? error.what() : error.err;
  message = message.substr(0, message.find('\n'));
  if (message.size() > 200) message = message.substr(0, 200) + "...";
  return message;
}

std::string ShapeText(const cv::MatSize& size) {
  std::ostringstream text;
  for (int i = 0; i < size.dims(); ++i) text << (i > 0 ? "x" : "") << size[i];
  return text.str();
}

// OpenCV's own logging would print extra lines on a bad file; evfs reports the error itself.
class QuietOpenCvLog {
 public:
  QuietOpenCvLog()
      : previous_(cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT)) {}
  ~QuietOpenCvLog() { cv::utils::logging::setLogLevel(previous_); }

 private:
  cv::utils::logging::LogLevel previous_;
};

std::string ReadWeightsFile(const std::string& path) {
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (ec || !fs::exists(status)) {
    throw InputError(InputError::Kind::kMissingFile, path, 0,
                     "denoiser weights not found (expected an ONNX file)");
  }
  if (!fs::is_regular_file(status)) {
    throw InputError(InputError::Kind::kMissingFile, path, 0,
                     "denoiser weights must be an ONNX file, not a folder or device");
  }
  std::ifstream in(path, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (!in.good() && !in.eof()) {
    throw InputError(InputError::Kind::kMissingFile, path, 0, "denoiser weights cannot be read");
  }
  if (!in.is_open()) {
    throw InputError(InputError::Kind::kMissingFile, path, 0, "denoiser weights cannot be read");
  }
  if (bytes.empty()) {
    throw InputError(InputError::Kind::kMalformed, path, 0,
                     "denoiser weights file is empty (expected an ONNX network)");
  }
  return bytes;
}

cv::dnn::Net LoadNetwork(const std::string& bytes, const std::string& path) {
  cv::dnn::Net net;
  try {
    QuietOpenCvLog quiet;
    net = cv::dnn::readNetFromONNX(bytes.data(), bytes.size());
  } catch (const cv::Exception& error) {
    throw InputError(InputError::Kind::kMalformed, path, 0,
                     "not an ONNX network OpenCV can load: " + ShortCvMessage(error));
  }
  if (net.empty()) {
    throw InputError(InputError::Kind::kMalformed, path, 0,
                     "not an ONNX network OpenCV can load: the graph is empty");
  }
  net.setPreferableBackend(cv::dnn::DNN_BACKEND_OPENCV);
  net.setPreferableTarget(cv::dnn::DNN_TARGET_CPU);
  return net;
}

// How far one output pixel of a convolution (or transposed convolution) layer reaches into its
// input along one axis, in units of the finer of the two grids: the window [−pad, (k−1)·d − pad]
// around the pixel's own position.
int HalfExtent(const cv::dnn::BaseConvolutionLayer& conv, size_t axis) {
  const int kernel = static_cast<int>(conv.kernel_size[axis]);
  const int dilation = axis < conv.dilations.size() ? static_cast<int>(conv.dilations[axis]) : 1;
  const int pad = axis < conv.pads_begin.size() ? static_cast<int>(conv.pads_begin[axis]) : 0;
  const int span = (kernel - 1) * dilation;
  return std::max(pad, span - pad);
}

// The receptive radius and the input multiple of a network made of convolutions (strided or
// not), transposed convolutions and pointwise layers, taken in order as one chain: each layer's
// reach, in input pixels at the resolution it works at, is summed (an upper bound when the graph
// branches, as a skip connection does). `multiple` is the largest total stride: an input whose
// sides and offsets are multiples of it keeps the same sampling grid. {-1, 1} when a layer of
// another kind (pooling, resizing) or a stride the chain cannot undo makes the radius unknown.
NetworkGeometry DeriveGeometry(cv::dnn::Net& net) {
  const NetworkGeometry unknown{-1, 1};
  NetworkGeometry geometry{0, 1};
  int scale = 1;  // input pixels per pixel at the current layer's input
  for (const std::string& name : net.getLayerNames()) {
    const cv::Ptr<cv::dnn::Layer> layer = net.getLayer(name);
    const auto* conv = dynamic_cast<const cv::dnn::BaseConvolutionLayer*>(layer.get());
    if (conv == nullptr) {
      if (PointwiseLayerTypes().count(layer->type) == 0) return unknown;
      continue;
    }
    const bool transposed = layer->type == "Deconvolution";
    int stride = 1, half_extent = 0;
    for (size_t axis = 0; axis < conv->kernel_size.size(); ++axis) {
      const int axis_stride =
          axis < conv->strides.size() ? static_cast<int>(conv->strides[axis]) : 1;
      if (axis > 0 && axis_stride != stride) return unknown;  // one stride for both axes
      stride = axis_stride;
      half_extent = std::max(half_extent, HalfExtent(*conv, axis));
    }
    if (stride < 1) return unknown;
    if (transposed) {
      if (scale % stride != 0) return unknown;
      scale /= stride;
      geometry.radius_px += half_extent * scale;
    } else {
      geometry.radius_px += half_extent * scale;
      scale *= stride;
      geometry.input_multiple_px = std::max(geometry.input_multiple_px, scale);
    }
  }
  if (scale != 1) return unknown;
  return geometry;
}

// `input` (1×1×h×w) padded at the bottom and right to multiples of `multiple` by repeating its
// last row and column, as the trainer does (tools/train_denoiser/train.py, run_network).
cv::Mat PadToMultiple(const cv::Mat& input, int multiple) {
  const int height = input.size[2], width = input.size[3];
  const int pad_bottom = (multiple - height % multiple) % multiple;
  const int pad_right = (multiple - width % multiple) % multiple;
  if (pad_bottom == 0 && pad_right == 0) return input;
  const cv::Mat plane(height, width, CV_32F, const_cast<float*>(input.ptr<float>()));
  const int shape[] = {1, 1, height + pad_bottom, width + pad_right};
  cv::Mat padded(4, shape, CV_32F);
  cv::Mat padded_plane(shape[2], shape[3], CV_32F, padded.ptr<float>());
  cv::copyMakeBorder(plane, padded_plane, 0, pad_bottom, 0, pad_right, cv::BORDER_REPLICATE);
  return padded;
}

// Runs `net` on `input` (1×1×h×w) and returns its output, which must have the same shape.
cv::Mat Forward(cv::dnn::Net& net, const cv::Mat& input) {
  net.setInput(input, "input");
  return net.forward();
}

// Checks the contract of denoiser.h on a probe input (padded to multiples of `multiple`): the
// input is named `input` and takes one channel, and the output has the input's shape.
void CheckShape(cv::dnn::Net& net, int multiple, const std::string& path) {
  const std::vector<std::string> outputs = net.getUnconnectedOutLayersNames();
  if (outputs.size() != 1) {
    throw InputError(
        InputError::Kind::kMalformed, path, 0,
        "expected a network with one output (1x1xHxW), found " + std::to_string(outputs.size()));
  }
  const int shape[] = {1, 1, kProbeHeight, kProbeWidth};
  cv::Mat probe(4, shape, CV_32F);
  cv::randu(probe, 0.0f, 1.0f);
  probe = PadToMultiple(probe, multiple);
  const int probe_height = probe.size[2], probe_width = probe.size[3];
  cv::Mat output;
  try {
    QuietOpenCvLog quiet;
    output = Forward(net, probe);
  } catch (const cv::Exception& error) {
    throw InputError(InputError::Kind::kMalformed, path, 0,
                     "expected a network mapping a 1x1xHxW input named 'input' to 1x1xHxW; "
                     "running it on 1x1x" +
                         std::to_string(probe_height) + "x" + std::to_string(probe_width) +
                         " failed: " + ShortCvMessage(error));
  }
  if (output.dims != 4 || output.size[0] != 1 || output.size[1] != 1 ||
      output.size[2] != probe_height || output.size[3] != probe_width || output.type() != CV_32F) {
    throw InputError(InputError::Kind::kMalformed, path, 0,
                     "expected a network mapping 1x1xHxW to 1x1xHxW (float); it maps 1x1x" +
                         std::to_string(probe_height) + "x" + std::to_string(probe_width) + " to " +
                         ShapeText(output.size));
  }
}

// The residual of `input` (1×1×h×w) as an h×w plane: the network run on the input padded to
// multiples of `multiple` (NetworkGeometry), its output cropped back. A copy, continuous and
// owned: the network's output buffer is overwritten by its next run, which another thread may
// start as soon as the network is released.
cv::Mat Residual(cv::dnn::Net& net, const cv::Mat& input, int multiple) {
  const cv::Mat output = Forward(net, PadToMultiple(input, multiple));
  const cv::Mat plane(output.size[2], output.size[3], CV_32F,
                      const_cast<float*>(output.ptr<float>()));
  return plane(cv::Rect(0, 0, input.size[3], input.size[2])).clone();
}

// One network run: the rectangle `core` of frame `frame`, with `context` (core plus margin,
// clipped to the frame) as the network's input.
struct TileTask {
  int frame = 0;
  cv::Rect core;
  cv::Rect context;
};

}  // namespace

bool DenoiserOptions::IsValid(std::string* error) const {
  OptionChecker check;
  check.Require(!weights_path.empty(), "the denoiser weights path", "given")
      .InRange("denoiser num_threads", num_threads, 0, kMaxThreads)
      .InRange("denoiser tile_size_px", tile_size_px, kMinTileSizePx, kMaxTileSizePx)
      .InRange("denoiser margin_px", margin_px, -1, kMaxMarginPx);
  return check.Passed(error);
}

// One copy of the network per thread (a cv::dnn::Net runs one forward at a time), handed out
// to tasks from a free list. Several Apply calls at once (evfs video's windows) share the
// copies: a task waits until one is free.
struct Denoiser::Networks {
  std::mutex mutex;
  std::condition_variable released;
  std::vector<cv::dnn::Net> nets;
  std::vector<int> free;

  int Acquire() {
    std::unique_lock<std::mutex> lock(mutex);
    released.wait(lock, [this] { return !free.empty(); });
    const int index = free.back();
    free.pop_back();
    return index;
  }
  void Release(int index) {
    {
      std::lock_guard<std::mutex> lock(mutex);
      free.push_back(index);
    }
    released.notify_one();
  }
};

Denoiser::Denoiser(const DenoiserOptions& options) : options_(options) {
  std::string error;
  if (!options.IsValid(&error)) throw InvalidArgumentError("invalid denoiser options: " + error);
  const std::string& path = options.weights_path;
  const std::string bytes = ReadWeightsFile(path);
  sha256_ = Sha256Hex(bytes);

  networks_ = std::make_unique<Networks>();
  cv::dnn::Net first = LoadNetwork(bytes, path);
  const NetworkGeometry geometry = DeriveGeometry(first);
  receptive_radius_px_ = geometry.radius_px;
  input_multiple_px_ = geometry.input_multiple_px;
  CheckShape(first, input_multiple_px_, path);
  if (options.margin_px >= 0) {
    margin_px_ = options.margin_px;
  } else if (receptive_radius_px_ >= 0) {
    margin_px_ = receptive_radius_px_;
  } else {
    throw InvalidArgumentError(path +
                               ": the network's receptive field cannot be derived from its "
                               "layers; give the tile margin (margin_px) explicitly");
  }

  int threads = options.num_threads;
  if (threads == 0) threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  networks_->nets.push_back(first);
  for (int i = 1; i < threads; ++i) networks_->nets.push_back(LoadNetwork(bytes, path));
  for (int i = threads - 1; i >= 0; --i) networks_->free.push_back(i);
}

Denoiser::~Denoiser() = default;

Video Denoiser::Apply(const Video& video, const DenoiseRegion& region, DenoiseStats* stats) const {
  const auto start = std::chrono::steady_clock::now();
  const int height = video.height(), width = video.width();
  if (!region.pixels.empty() &&
      static_cast<int64_t>(region.pixels.size()) != video.pixels_per_frame()) {
    throw InvalidArgumentError("denoiser region has " + std::to_string(region.pixels.size()) +
                               " pixel flags for frames of " + std::to_string(height) + "x" +
                               std::to_string(width));
  }
  if (!region.frames.empty() && static_cast<int>(region.frames.size()) != video.num_frames()) {
    throw InvalidArgumentError("denoiser region has " + std::to_string(region.frames.size()) +
                               " frame flags for a video of " + std::to_string(video.num_frames()) +
                               " frames");
  }
  const auto pixel_selected = [&region](int64_t p) {
    return region.pixels.empty() || region.pixels[p] != 0;
  };

  // Tiles holding a pixel to denoise, merged along each row of tiles into runs, and a run
  // continued down the next rows of tiles while they hold a run of the same columns (fewer
  // margins and fewer network calls); the same for every frame.
  const int tile = options_.tile_size_px;
  // A tile's context starts at a multiple of the network's input multiple, so that a strided
  // network samples it on the whole frame's grid.
  const int multiple = input_multiple_px_;
  const auto expand = [&](const cv::Rect& core) {
    const int x0 = std::max(0, core.x - margin_px_) / multiple * multiple;
    const int y0 = std::max(0, core.y - margin_px_) / multiple * multiple;
    const int x1 = std::min(width, core.x + core.width + margin_px_);
    const int y1 = std::min(height, core.y + core.height + margin_px_);
    return cv::Rect(x0, y0, x1 - x0, y1 - y0);
  };
  std::vector<cv::Rect> cores;
  int64_t selected_pixels = 0;
  std::map<std::pair<int, int>, size_t> above;  // (x, width) of the previous row's runs → core
  for (int y0 = 0; y0 < height; y0 += tile) {
    const int rows = std::min(tile, height - y0);
    const int columns = (width + tile - 1) / tile;
    std::map<std::pair<int, int>, size_t> here;
    const auto add_run = [&](int x, int run_width) {
      const std::pair<int, int> key(x, run_width);
      const auto it = above.find(key);
      if (it != above.end()) {
        cores[it->second].height += rows;
        here[key] = it->second;
      } else {
        here[key] = cores.size();
        cores.emplace_back(x, y0, run_width, rows);
      }
    };
    int run_begin = -1;
    for (int column = 0; column <= columns; ++column) {  // the last pass closes an open run
      const int x0 = column * tile;
      bool any = false;
      if (column < columns) {
        const int cols = std::min(tile, width - x0);
        for (int y = y0; y < y0 + rows && !any; ++y) {
          for (int x = x0; x < x0 + cols; ++x) {
            if (pixel_selected(static_cast<int64_t>(y) * width + x)) {
              any = true;
              break;
            }
          }
        }
      }
      if (any && run_begin < 0) run_begin = x0;
      if (!any && run_begin >= 0) {
        add_run(run_begin, std::min(x0, width) - run_begin);
        run_begin = -1;
      }
    }
    above = std::move(here);
  }
  for (int64_t p = 0; p < video.pixels_per_frame(); ++p) selected_pixels += pixel_selected(p);
  int64_t tiles_cost = 0;
  for (const cv::Rect& core : cores) tiles_cost += expand(core).area();
  if (tiles_cost >= video.pixels_per_frame()) {
    // Margins would cost more than the whole frame: one run per frame.
    cores.assign(1, cv::Rect(0, 0, width, height));
  }

  std::vector<TileTask> tasks;
  DenoiseStats local;
  for (int t = 0; t < video.num_frames(); ++t) {
    if (!region.frames.empty() && region.frames[t] == 0) continue;
    if (cores.empty() || height == 0 || width == 0) continue;
    ++local.frames;
    local.pixels_changed += selected_pixels;
    for (const cv::Rect& core : cores) {
      tasks.push_back({t, core, expand(core)});
      local.network_pixels += tasks.back().context.area();
    }
  }
  local.tiles = static_cast<int64_t>(tasks.size());
  std::stable_sort(tasks.begin(), tasks.end(), [](const TileTask& a, const TileTask& b) {
    return a.context.area() > b.context.area();
  });

  Video output = video;
  Networks& networks = *networks_;
  const int workers = static_cast<int>(networks.nets.size());
  ParallelForEach(static_cast<int>(tasks.size()), workers, [&](int index) {
    const TileTask& task = tasks[index];
    const cv::Rect& context = task.context;
    const int shape[] = {1, 1, context.height, context.width};
    cv::Mat input(4, shape, CV_32F);
    float* in = input.ptr<float>();
    const double* frame = video.frame_data(task.frame);
    for (int y = 0; y < context.height; ++y) {
      const double* row = frame + static_cast<int64_t>(context.y + y) * width + context.x;
      for (int x = 0; x < context.width; ++x)
        in[y * context.width + x] = static_cast<float>(row[x]);
    }
    const int net_index = networks.Acquire();
    cv::Mat residual;
    try {
      residual = Residual(networks.nets[net_index], input, multiple);
    } catch (...) {
      networks.Release(net_index);
      throw;
    }
    networks.Release(net_index);
    const float* r = residual.ptr<float>();  // context.height × context.width, continuous
    double* out = output.frame_data(task.frame);
    for (int y = task.core.y; y < task.core.y + task.core.height; ++y) {
      for (int x = task.core.x; x < task.core.x + task.core.width; ++x) {
        const int64_t p = static_cast<int64_t>(y) * width + x;
        if (!pixel_selected(p)) continue;
        out[p] =
            frame[p] - static_cast<double>(r[(y - context.y) * context.width + (x - context.x)]);
      }
    }
  });
  local.time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (stats != nullptr) *stats = local;
  return output;
}

Video GateCorrection(const Video& input, const Video& corrected, const Video& sigma, double tau) {
  if (!(tau > 0.0) || !std::isfinite(tau)) {
    throw InvalidArgumentError("the denoiser gate's tau must be positive and finite, not " +
                               std::to_string(tau));
  }
  const auto same_size = [&input](const Video& other) {
    return other.num_frames() == input.num_frames() && other.height() == input.height() &&
           other.width() == input.width();
  };
  if (!same_size(corrected) || !same_size(sigma)) {
    throw InvalidArgumentError(
        "the denoiser gate needs the input, the correction and sigma of one size");
  }
  Video gated = input;
  const double tau_squared = tau * tau;
  for (int t = 0; t < input.num_frames(); ++t) {
    const double* in = input.frame_data(t);
    const double* out = corrected.frame_data(t);
    const double* error = sigma.frame_data(t);
    double* result = gated.frame_data(t);
    for (int64_t p = 0; p < input.pixels_per_frame(); ++p) {
      const double variance = error[p] * error[p];
      if (variance == 0.0) continue;  // a sure pixel keeps its value exactly
      result[p] = in[p] + variance / (variance + tau_squared) * (out[p] - in[p]);
    }
  }
  return gated;
}

}  // namespace evfs
