// The Python module `evfs`: recordings read into NumPy arrays, and the reconstruction and the
// event simulator run on NumPy arrays, through the same application library as the command
// line (app/). Errors that are the user's become ValueError with the command line's one-line
// message, a failed solve RuntimeError. The GIL is released while evfs reads, solves and
// simulates, and Ctrl-C stops each of these within a solver iteration (RunInterruptibly).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "evfs/app/calibrate_job.h"
#include "evfs/app/reconstruct_job.h"
#include "evfs/app/video_job.h"
#include "evfs/app/video_work_folder.h"
#include "evfs/core/error.h"
#include "evfs/core/event_stream.h"
#include "evfs/core/time.h"
#include "evfs/core/version.h"
#include "evfs/core/video.h"
#include "evfs/events/simulator.h"
#include "evfs/io/data_source.h"
#include "evfs/io/image_io.h"
#include "evfs/io/output_target.h"
#include "evfs/python/array_source.h"
#include "evfs/python/reconstruct_options.h"

namespace evfs {
namespace {

namespace py = pybind11;

// How summaries and messages name a recording given as arrays.
constexpr char kArraysLabel[] = "the frames array";

std::string TypeName(py::handle object) {
  return py::str(py::type::handle_of(object).attr("__name__"));
}

std::string DtypeName(const py::array& array) { return py::str(array.dtype()); }

// Whether `object` is a NumPy array of exactly dtype T with `ndim` dimensions; throws
// InvalidArgumentError naming `name` otherwise. Any other dtype (a byte-swapped one included) is
// refused rather than converted, so that no value is silently changed.
template <typename T>
py::array CheckedDtypeAndRank(py::handle object, int ndim, const std::string& name) {
  const std::string expected =
      std::to_string(ndim) + "-D " + std::string(py::str(py::dtype::of<T>()));
  if (!py::isinstance<py::array>(object)) {
    throw InvalidArgumentError(name + " must be a NumPy array (" + expected + "), not " +
                               TypeName(object));
  }
  const py::array array = py::reinterpret_borrow<py::array>(object);
  if (!array.dtype().is(py::dtype::of<T>())) {
    throw InvalidArgumentError(name + " must be a " + expected + " array, not " + DtypeName(array) +
                               ": convert it with .astype(numpy." +
                               std::string(py::str(py::dtype::of<T>())) + ")");
  }
  if (array.ndim() != ndim) {
    throw InvalidArgumentError(name + " must be a " + expected + " array, not " +
                               std::to_string(array.ndim()) + "-D");
  }
  return array;
}

// `object` as a C-contiguous, aligned NumPy array of exactly dtype T with `ndim` dimensions:
// the array itself when it is one, else a copy (numpy.require). A copy that cannot be made
// raises NumPy's MemoryError; pybind11's array_t::ensure would return an empty handle instead,
// and reading through it would crash the interpreter.
template <typename T>
py::array_t<T, py::array::c_style> CheckedArray(py::handle object, int ndim,
                                                const std::string& name) {
  const py::array array = CheckedDtypeAndRank<T>(object, ndim, name);
  const py::object required = py::module_::import("numpy").attr("require")(
      array, py::dtype::of<T>(), py::make_tuple("C_CONTIGUOUS", "ALIGNED"));
  return py::reinterpret_borrow<py::array_t<T, py::array::c_style>>(required);
}

// A checked 1-D array (CheckedDtypeAndRank) as a StridedArray over its memory.
template <typename T>
StridedArray<T> Strided(const py::array& array) {
  StridedArray<T> strided;
  strided.data = static_cast<const char*>(array.data());
  strided.stride = array.strides(0);
  return strided;
}

// Inputs of reconstruct and simulate, kept alive (and referenced by `recording`) for the call.
struct RecordingInput {
  py::array frames;
  py::array_t<double, py::array::c_style> frame_times;
  py::array event_t, event_x, event_y, event_p;
  RecordingArrays recording;
};

// The frames are read where they lie, through their strides (RecordingArrays): a view of any
// layout, a broadcast one of a huge shape included, costs no copy. Its sizes are checked here,
// before anything reads it.
void SetFrames(py::handle frames_object, RecordingInput* input) {
  if (!py::isinstance<py::array>(frames_object)) {
    throw InvalidArgumentError("frames must be a NumPy array (3-D float32 or float64), not " +
                               TypeName(frames_object));
  }
  const py::array frames = py::reinterpret_borrow<py::array>(frames_object);
  RecordingArrays& recording = input->recording;
  if (frames.dtype().is(py::dtype::of<float>())) {
    CheckedDtypeAndRank<float>(frames, 3, "frames");
    recording.frames_float32 = true;
  } else if (frames.dtype().is(py::dtype::of<double>())) {
    CheckedDtypeAndRank<double>(frames, 3, "frames");
    recording.frames_float32 = false;
  } else {
    throw InvalidArgumentError(
        "frames must be a 3-D float32 or float64 array (frames x height "
        "x width, intensities in [0, 1]), not " +
        DtypeName(frames));
  }
  const py::ssize_t count = frames.shape(0), height = frames.shape(1), width = frames.shape(2);
  if (count < 1 || height < 1 || width < 1) {
    throw InvalidArgumentError("frames must hold at least one frame of at least 1x1 pixels, not " +
                               std::to_string(count) + "x" + std::to_string(height) + "x" +
                               std::to_string(width));
  }
  if (height > kMaxSensorSide || width > kMaxSensorSide ||
      static_cast<int64_t>(height) * width > kMaxSensorPixels) {
    throw InvalidArgumentError("frames of " + std::to_string(width) + "x" + std::to_string(height) +
                               " pixels are larger than the " + std::to_string(kMaxSensorPixels) +
                               " pixels (8192x8192) evfs reads");
  }
  if (count > kMaxArrayFrames) {
    throw InvalidArgumentError("frames holds " + std::to_string(count) + " frames, more than the " +
                               std::to_string(kMaxArrayFrames) + " an array recording may hold");
  }
  input->frames = frames;
  recording.frames_data = static_cast<const char*>(frames.data());
  recording.frame_stride = frames.strides(0);
  recording.row_stride = frames.strides(1);
  recording.column_stride = frames.strides(2);
  recording.num_frames = static_cast<int>(count);
  recording.height = static_cast<int>(height);
  recording.width = static_cast<int>(width);
}

// After SetFrames: the length is checked against the frames before anything is copied.
void SetFrameTimes(py::handle times_object, RecordingInput* input) {
  const py::array times_array = CheckedDtypeAndRank<double>(times_object, 1, "frame_times");
  if (times_array.shape(0) != input->recording.num_frames) {
    throw InvalidArgumentError(
        "frame_times must hold one time per frame: " + std::to_string(input->recording.num_frames) +
        " frames, " + std::to_string(times_array.shape(0)) + " times");
  }
  input->frame_times = CheckedArray<double>(times_array, 1, "frame_times");
  const auto times = input->frame_times.unchecked<1>();
  for (py::ssize_t i = 0; i < times.shape(0); ++i) {
    input->recording.frame_t_ns.push_back(
        CheckedNanoseconds(times(i), "frame_times[" + std::to_string(i) + "]"));
  }
}

// exposures: None, or frames × 2 (begin, end) in seconds with NaN rows for frames without one.
void SetExposures(py::handle exposures_object, RecordingInput* input) {
  if (exposures_object.is_none()) return;
  const py::array unchecked = CheckedDtypeAndRank<double>(exposures_object, 2, "exposures");
  RecordingArrays& recording = input->recording;
  if (unchecked.shape(0) != recording.num_frames || unchecked.shape(1) != 2) {
    throw InvalidArgumentError(
        "exposures must be a frames x 2 array (begin, end in seconds; NaN "
        "where a frame has none): " +
        std::to_string(recording.num_frames) + " x 2 here");
  }
  const auto exposures = CheckedArray<double>(unchecked, 2, "exposures");
  const auto view = exposures.unchecked<2>();
  for (int i = 0; i < recording.num_frames; ++i) {
    const bool known = !std::isnan(view(i, 0)) || !std::isnan(view(i, 1));
    const std::string what = "exposures[" + std::to_string(i) + "]";
    recording.has_exposure.push_back(known);
    recording.exposure_begin_ns.push_back(known ? CheckedNanoseconds(view(i, 0), what) : 0);
    recording.exposure_end_ns.push_back(known ? CheckedNanoseconds(view(i, 1), what) : 0);
  }
}

// events: a dict of 1-D arrays t (float64 seconds), x, y (uint16), p (int8, ±1), as evfs.read
// returns them.
void SetEvents(py::handle events_object, RecordingInput* input) {
  if (!py::isinstance<py::dict>(events_object)) {
    throw InvalidArgumentError(
        "events must be a dict of arrays 't' (float64 seconds), 'x', 'y' "
        "(uint16) and 'p' (int8, +1 or -1), not " +
        TypeName(events_object));
  }
  const py::dict events = py::reinterpret_borrow<py::dict>(events_object);
  for (const char* key : {"t", "x", "y", "p"}) {
    if (!events.contains(key)) {
      throw InvalidArgumentError(std::string("events has no '") + key +
                                 "': expected arrays 't', 'x', 'y' and 'p'");
    }
  }
  // Read where they lie, through their strides (StridedArray): no layout costs a copy.
  input->event_t = CheckedDtypeAndRank<double>(events["t"], 1, "events['t']");
  input->event_x = CheckedDtypeAndRank<uint16_t>(events["x"], 1, "events['x']");
  input->event_y = CheckedDtypeAndRank<uint16_t>(events["y"], 1, "events['y']");
  input->event_p = CheckedDtypeAndRank<int8_t>(events["p"], 1, "events['p']");
  const py::ssize_t count = input->event_t.shape(0);
  if (input->event_x.shape(0) != count || input->event_y.shape(0) != count ||
      input->event_p.shape(0) != count) {
    throw InvalidArgumentError("events['t'], ['x'], ['y'] and ['p'] must have the same length");
  }
  RecordingArrays& recording = input->recording;
  if (count > kMaxArrayEvents) {
    throw InvalidArgumentError("events holds " + std::to_string(count) + " events, more than the " +
                               std::to_string(kMaxArrayEvents) + " an array recording may hold");
  }
  recording.event_t_s = Strided<double>(input->event_t);
  recording.event_x = Strided<uint16_t>(input->event_x);
  recording.event_y = Strided<uint16_t>(input->event_y);
  recording.event_polarity = Strided<int8_t>(input->event_p);
  recording.num_events = static_cast<size_t>(count);
}

// How often the calling thread looks for a signal while a job runs.
constexpr auto kSignalPollInterval = std::chrono::milliseconds(20);

// Runs `job` without the GIL on a thread of its own, while the calling thread looks for a
// signal every kSignalPollInterval. Python runs its signal handlers only in the main thread,
// between bytecodes: a job that held the calling thread would keep Ctrl-C waiting until it
// ended. When a handler raises (KeyboardInterrupt on SIGINT), `cancel` is set, and the job
// stops at its next check (a solver iteration, a window, a frame); the handler's exception is
// raised once the job has ended, since the job reads the caller's arrays and writes staging
// folders that must not be released under it. `job` must not touch Python objects.
void RunInterruptibly(const std::function<void(const std::atomic<bool>& cancel)>& job) {
  std::atomic<bool> cancel(false);
  std::mutex mutex;
  std::condition_variable finished_changed;
  bool finished = false;
  std::exception_ptr job_error;
  PyObject* signal_type = nullptr;
  PyObject* signal_value = nullptr;
  PyObject* signal_traceback = nullptr;
  {
    py::gil_scoped_release release;
    std::thread worker([&] {
      try {
        job(cancel);
      } catch (...) {
        job_error = std::current_exception();
      }
      const std::lock_guard<std::mutex> lock(mutex);
      finished = true;
      finished_changed.notify_all();
    });
    std::unique_lock<std::mutex> lock(mutex);
    while (!finished_changed.wait_for(lock, kSignalPollInterval, [&] { return finished; })) {
      if (cancel) continue;
      lock.unlock();
      {
        const py::gil_scoped_acquire acquire;
        if (PyErr_CheckSignals() != 0) {
          PyErr_Fetch(&signal_type, &signal_value, &signal_traceback);
          cancel = true;
        }
      }
      lock.lock();
    }
    lock.unlock();
    worker.join();
  }
  if (signal_type != nullptr) {
    PyErr_Restore(signal_type, signal_value, signal_traceback);
    throw py::error_already_set();
  }
  if (job_error) std::rethrow_exception(job_error);
}

// A NumPy array over `values`, which it keeps alive: no copy.
template <typename T>
py::array_t<T> OwningArray(std::vector<T>&& values) {
  auto* owned = new std::vector<T>(std::move(values));
  const py::capsule free_when_done(owned, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  return py::array_t<T>(static_cast<py::ssize_t>(owned->size()), owned->data(), free_when_done);
}

py::array_t<double> Seconds(const std::vector<int64_t>& t_ns) {
  py::array_t<double> seconds(static_cast<py::ssize_t>(t_ns.size()));
  double* out = seconds.mutable_data();
  for (size_t i = 0; i < t_ns.size(); ++i) out[i] = NanosecondsToSeconds(t_ns[i]);
  return seconds;
}

py::dict EventsDict(EventStream events) {
  py::dict dict;
  dict["t"] = Seconds(events.t_ns());
  std::vector<uint16_t> x = events.x(), y = events.y();
  std::vector<int8_t> p = events.polarity();
  events.clear();
  dict["x"] = OwningArray(std::move(x));
  dict["y"] = OwningArray(std::move(y));
  dict["p"] = OwningArray(std::move(p));
  return dict;
}

// The frames of `video` as a frames × height × width array of `dtype` ("float32": converted;
// "float64": the video's own values, without a copy).
py::array VideoArray(Video&& video, const std::string& dtype) {
  const std::vector<py::ssize_t> shape = {video.num_frames(), video.height(), video.width()};
  if (dtype == "float64") {
    auto* owned = new Video(std::move(video));
    const py::capsule free_when_done(owned, [](void* p) { delete static_cast<Video*>(p); });
    return py::array_t<double>(shape, owned->data(), free_when_done);
  }
  py::array_t<float> frames(shape);
  float* out = frames.mutable_data();
  const size_t values = static_cast<size_t>(video.num_frames()) * video.pixels_per_frame();
  for (size_t i = 0; i < values; ++i) out[i] = static_cast<float>(video.data()[i]);
  return std::move(frames);
}

py::dict ReadArrays(const std::string& path, const std::string& events_topic,
                    const std::string& frames_topic) {
  DataSourceOptions options;
  options.events_topic = events_topic;
  options.frames_topic = frames_topic;
  std::unique_ptr<DataSource> source;
  {
    py::gil_scoped_release release;
    source = DataSource::Open(path, options);
  }
  const std::vector<FrameInfo>& frames = source->frames();
  const int num_frames = static_cast<int>(frames.size());
  py::array_t<double> images(
      std::vector<py::ssize_t>{num_frames, source->height(), source->width()});
  py::array_t<double> exposures(std::vector<py::ssize_t>{num_frames, 2});
  std::vector<int64_t> frame_t_ns;
  py::list frame_paths;
  auto exposure_view = exposures.mutable_unchecked<2>();
  for (int i = 0; i < num_frames; ++i) {
    frame_t_ns.push_back(frames[i].t_ns);
    frame_paths.append(frames[i].path);
    const double nan = std::numeric_limits<double>::quiet_NaN();
    exposure_view(i, 0) =
        frames[i].has_exposure ? NanosecondsToSeconds(frames[i].exposure_begin_ns) : nan;
    exposure_view(i, 1) =
        frames[i].has_exposure ? NanosecondsToSeconds(frames[i].exposure_end_ns) : nan;
  }
  double* image_data = images.mutable_data();
  EventStream events(source->width(), source->height());
  RunInterruptibly([&](const std::atomic<bool>& cancel) {
    const size_t pixels = static_cast<size_t>(source->width()) * source->height();
    for (int i = 0; i < num_frames; ++i) {
      if (cancel) throw InterruptedError();
      const Image image = source->ReadImage(i);
      std::copy(image.data(), image.data() + pixels, image_data + i * pixels);
    }
    if (source->has_events()) events = source->ReadAllEvents();
  });
  py::dict result;
  result["path"] = path;
  result["width"] = source->width();
  result["height"] = source->height();
  result["frames"] = images;
  result["frame_times"] = Seconds(frame_t_ns);
  result["exposures"] = exposures;
  result["frame_paths"] = frame_paths;
  result["events"] = EventsDict(std::move(events));
  return result;
}

// A Python int argument as a C++ int. One beyond int's range is a bad value like any other
// (ValueError, naming the argument), not pybind11's TypeError of a failed conversion.
int IntArgument(const py::int_& value, const char* name) {
  int overflow = 0;
  const long long number = PyLong_AsLongLongAndOverflow(value.ptr(), &overflow);
  if (overflow != 0 || number < std::numeric_limits<int>::min() ||
      number > std::numeric_limits<int>::max()) {
    const std::string text = value.attr("__str__")().cast<std::string>();
    throw InvalidArgumentError(std::string(name) + "=" + text +
                               " is out of range: it must fit in 32 bits");
  }
  return static_cast<int>(number);
}

py::dict ReconstructArrays(py::handle frames, py::handle frame_times, py::handle events,
                           const std::string& mode, const py::int_& first, const py::int_& last,
                           const py::int_& truth, py::handle exposures, py::handle options,
                           const std::string& dtype) {
  if (dtype != "float32" && dtype != "float64") {
    throw InvalidArgumentError("dtype must be 'float32' or 'float64', not '" + dtype + "'");
  }
  OptionValues values;
  ApplyPythonOptions(options, kReconstructKey, &values);
  ReconstructRequest request = ReconstructRequestFromOptions(values, /*with_mode=*/false);
  request.data_label = kArraysLabel;
  request.mode = ParseMode(mode);
  request.first = IntArgument(first, "first");
  request.last = IntArgument(last, "last");
  request.truth = IntArgument(truth, "truth");

  RecordingInput input;
  SetFrames(frames, &input);
  SetFrameTimes(frame_times, &input);
  SetExposures(exposures, &input);
  SetEvents(events, &input);
  ReconstructResult result;
  std::string summary;
  RunInterruptibly([&](const std::atomic<bool>& cancel) {
    CheckRecordingArrays(input.recording, "frames", "events", &cancel);
    const ArraySource source(input.recording, kArraysLabel);
    // An interrupted solve returns its current iterate; the next stage, or the check after the
    // job, turns it into InterruptedError, so that it is never returned as a result.
    ReconstructRequest interruptible = request;
    interruptible.method.interrupt = &cancel;
    interruptible.stage = [&cancel](const char*) {
      if (cancel) throw InterruptedError();
    };
    result = RunReconstruction(interruptible, source);
    if (cancel) throw InterruptedError();
    summary = SummaryJson(request, result);
  });
  py::dict output;
  output["times"] = Seconds(result.output.timestamps_ns());
  output["frames"] = VideoArray(std::move(result.output), dtype);
  output["confidence"] = VideoArray(std::move(result.confidence), dtype);
  output["summary"] = py::module_::import("json").attr("loads")(summary);
  return output;
}

py::dict SimulateArrays(py::handle frames, py::handle frame_times, py::handle options) {
  OptionValues values;
  ApplyPythonOptions(options, kSimulateKey, &values);
  const SimulatorOptions simulator = SimulatorFromOptions(values);
  std::string error;
  if (!simulator.IsValid(&error)) throw InvalidArgumentError("simulator: " + error);
  RecordingInput input;
  SetFrames(frames, &input);
  SetFrameTimes(frame_times, &input);
  EventStream events;
  RunInterruptibly([&](const std::atomic<bool>& cancel) {
    const RecordingArrays& recording = input.recording;
    CheckRecordingArrays(recording, "frames", "events", &cancel);
    if (recording.num_frames < 2) {
      throw InvalidArgumentError("simulate needs at least 2 frames (" +
                                 std::to_string(recording.num_frames) + " found)");
    }
    const ArraySource source(recording, kArraysLabel);
    Video video;
    for (int i = 0; i < recording.num_frames; ++i) {
      if (cancel) throw InterruptedError();
      video.AppendFrame(source.ReadImage(i), recording.frame_t_ns[i]);
    }
    events = SimulateEvents(video, simulator);
  });
  return EventsDict(std::move(events));
}

// evfs.video: `evfs video` without MPI, into a folder through the same OutputTarget (so the
// same refusals and the same atomic replacement). Unlike the command line it runs in this
// process; Ctrl-C stops it through RunInterruptibly.
py::dict VideoFromPath(const std::string& data, const std::string& out, const py::int_& first,
                       const py::int_& last, double fps, const py::int_& jobs,
                       const py::int_& frame_step, bool predict_tail, double predict_max_s,
                       double min_blur_exposure_s, bool blur_from_data, bool skip_bad_frames,
                       bool preview, bool report, bool resume, bool overwrite, py::handle options) {
  // The command line's flags of these names, over the options: the same request, and the same
  // settings for resume to compare, as `evfs video` makes.
  OptionValues values;
  ApplyPythonOptions(options, kReconstructKey, &values);
  const int first_frame = IntArgument(first, "first");
  const int last_frame = IntArgument(last, "last");
  const int step = IntArgument(frame_step, "frame_step");
  const int windows_at_once = IntArgument(jobs, "jobs");
  values.Set("data", data);
  values.Set("first", first_frame);
  values.Set("last", last_frame);
  values.Set("fps", fps);
  values.Set("jobs", windows_at_once);
  values.Set("frame_step", step);
  values.Set("predict_tail", predict_tail);
  values.Set("predict_max_s", predict_max_s);
  values.Set("min_blur_exposure_s", min_blur_exposure_s);
  values.Set("blur_from_data", blur_from_data);
  values.Set("skip_bad_frames", skip_bad_frames);
  values.Set("preview", preview);
  values.Set("report", report);
  values.Set("resume", resume);
  VideoRequest request = VideoRequestFromOptions(values);
  // The command line reads --first=-1 as 0; Python's first has no such value.
  request.windows.first = first_frame;
  std::string error;
  if (!request.IsValid(&error)) throw InvalidArgumentError(error);
  OutputOptions output;
  output.path = out;
  output.command = "video";
  output.overwrite = overwrite;
  output.inputs = {data};
  VideoResult result;
  std::string path;
  // Interrupted, the staging folder goes with the OutputTarget (nothing is committed) and the
  // work folder stays for resume, as after the command line's Ctrl-C.
  RunInterruptibly([&](const std::atomic<bool>& cancel) {
    VideoRequest interruptible = request;
    interruptible.method.interrupt = &cancel;
    OutputTarget target(output);
    result = RunVideo(interruptible, target.path(), target.staging());
    if (cancel) throw InterruptedError();
    target.Commit();
    RemoveVideoWorkFolder(target.path());
    path = target.path();
  });
  py::dict summary;
  summary["path"] = path;
  summary["windows"] = result.windows;
  summary["windows_resumed"] = result.windows_resumed;
  summary["frames"] = result.output_frames;
  summary["fps"] = result.fps;
  summary["width"] = result.width;
  summary["height"] = result.height;
  summary["events"] = result.events;
  summary["windows_per_s"] = result.windows_per_s;
  summary["events_per_s"] = result.events_per_s;
  summary["codec"] = result.codec;
  if (result.truth_frames > 0) {
    summary["truth_frames"] = result.truth_frames;
    summary["mean_psnr"] = result.mean_psnr;
    summary["worst_psnr"] = result.worst_psnr;
    summary["mean_blend_psnr"] = result.mean_blend_psnr;
    summary["mean_ssim"] = result.mean_ssim;
  }
  return summary;
}

}  // namespace
}  // namespace evfs

PYBIND11_MODULE(evfs, m) {
  namespace py = pybind11;
  m.doc() =
      "evfs: event-driven video frame synthesis (Wang et al.) over NumPy arrays.\n\n"
      "read(path) loads a recording; reconstruct(...) synthesises latent frames from frames and "
      "events; simulate(...) makes events from frames. Options are the command line's flags "
      "(reconstruct_defaults(), simulate_defaults()). User errors raise ValueError with the "
      "command line's message, a failed solve RuntimeError, an input too large for memory "
      "MemoryError. Ctrl-C stops a running call with KeyboardInterrupt and keeps nothing it "
      "was writing (video keeps its work folder for resume=True).";
  m.attr("__version__") = evfs::kVersion;

  py::register_exception_translator([](std::exception_ptr error) {
    try {
      if (error) std::rethrow_exception(error);
    } catch (const evfs::SolverError& e) {
      PyErr_SetString(PyExc_RuntimeError, e.what());
    } catch (const evfs::Error& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    }
  });

  m.def("read", &evfs::ReadArrays, py::arg("path"), py::kw_only(), py::arg("events_topic") = "",
        py::arg("frames_topic") = "",
        "Reads a recording: a data folder (Event Camera Dataset layout), an HDF5 file (.h5), an "
        "AEDAT 4 file (.aedat4), an AEDAT 2.0/3.1 file (jAER, cAER, v2e) or a ROS 1 bag (.bag; "
        "events_topic, frames_topic: its dvs_msgs/EventArray and sensor_msgs/Image topics, by "
        "default the first of each). Returns a dict: "
        "'frames' (frames x height x width float64 "
        "intensities in [0, 1]), 'frame_times' (float64 seconds), 'exposures' (frames x 2 float64 "
        "seconds, begin and end; NaN where unknown), 'frame_paths' (list of str), 'events' (dict "
        "of 't' float64 seconds, 'x', 'y' uint16, 'p' int8 +1/-1), 'width', 'height', 'path'.");
  m.def("reconstruct", &evfs::ReconstructArrays, py::arg("frames"), py::arg("frame_times"),
        py::arg("events"), py::kw_only(), py::arg("mode") = "predict", py::arg("first") = 0,
        py::arg("last") = -1, py::arg("truth") = -1, py::arg("exposures") = py::none(),
        py::arg("options") = py::none(), py::arg("dtype") = "float32",
        "Synthesises the latent frames of `mode` ('interpolate', 'predict' or 'deblur') from frame "
        "`first` (and `last`; -1: first + 1) and the events, as `evfs reconstruct` does. frames: "
        "frames x height x width float32 or float64 in [0, 1]; frame_times: float64 seconds, "
        "increasing; events: as read() returns them (sorted by time); exposures: None or as "
        "read() returns them; truth: a frame to score against (-1: none); options: a dict of the "
        "command line's flags (reconstruct_defaults()). Returns a dict: 'frames' (latent frames, "
        "frames x height x width of `dtype`: 'float32', or 'float64' for the solver's own "
        "values), 'times' (float64 seconds), 'confidence' (the predicted one-sigma error of every "
        "pixel of 'frames', same shape and dtype, intensity units) and 'summary' (summary.json as "
        "a dict).");
  m.def("simulate", &evfs::SimulateArrays, py::arg("frames"), py::arg("frame_times"),
        py::arg("options") = py::none(),
        "Simulates the events of a sequence of frames (at least 2; frames x height x width "
        "float32 or float64 in [0, 1], float64 seconds), as `evfs simulate` does. options: "
        "simulate_defaults()'s keys. Returns the events as a dict like read()'s 'events'.");
  m.def("video", &evfs::VideoFromPath, py::arg("data"), py::arg("out"), py::kw_only(),
        py::arg("first") = 0, py::arg("last") = evfs::OptionDefault<int32_t>("last"),
        py::arg("fps") = evfs::OptionDefault<double>("fps"),
        py::arg("jobs") = evfs::OptionDefault<int32_t>("jobs"),
        py::arg("frame_step") = evfs::OptionDefault<int32_t>("frame_step"),
        py::arg("predict_tail") = evfs::OptionDefault<bool>("predict_tail"),
        py::arg("predict_max_s") = evfs::OptionDefault<double>("predict_max_s"),
        py::arg("min_blur_exposure_s") = evfs::OptionDefault<double>("min_blur_exposure_s"),
        py::arg("blur_from_data") = evfs::OptionDefault<bool>("blur_from_data"),
        py::arg("skip_bad_frames") = evfs::OptionDefault<bool>("skip_bad_frames"),
        py::arg("preview") = evfs::OptionDefault<bool>("preview"),
        py::arg("report") = evfs::OptionDefault<bool>("report"),
        py::arg("resume") = evfs::OptionDefault<bool>("resume"),
        py::arg("overwrite") = evfs::OptionDefault<bool>("overwrite"),
        py::arg("options") = py::none(),
        "A whole recording (`data`: a path read() accepts) to one high-framerate video in the "
        "folder `out`, as `evfs video` does (without MPI): out/frames/NNNNNN.png at a uniform "
        "`fps` (0: 10x the frame rate), timestamps.txt, summary.json, video.mp4 (report: also "
        "report.html). first/last "
        "select frames (-1: the last), jobs windows run at once (0: every core), frame_step > 1 "
        "withholds frames and scores them; predict_max_s, min_blur_exposure_s, blur_from_data and "
        "skip_bad_frames are the command line's --flags of those names (options' exposure_s too); "
        "resume reuses an interrupted run's windows, "
        "overwrite replaces an earlier evfs video output. options: reconstruct_defaults()'s "
        "keys. Returns a dict: 'path', 'windows', 'frames', 'fps', 'events', 'codec', ... ");
  m.def(
      "reconstruct_defaults", [] { return evfs::PythonOptionDefaults(evfs::kReconstructKey); },
      "Every key reconstruct's options accept, with its default (that of the command line).");
  m.def(
      "simulate_defaults", [] { return evfs::PythonOptionDefaults(evfs::kSimulateKey); },
      "Every key simulate's options accept, with its default (that of the command line).");
}
