#include "python/reconstruct_options.h"

#include <Python.h>
#include <ceres/types.h>

#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "app/calibrate_job.h"
#include "app/denoise_job.h"
#include "app/initialization.h"
#include "core/enum_names.h"
#include "core/error.h"
#include "core/time.h"
#include "scene/event_model.h"
#include "scene/frame_timing.h"
#include "scene/scene.h"

namespace evfs {
namespace {

namespace py = pybind11;

// The command line's defaults that are not the structs' own (examples/evfs_main.cc).
constexpr double kCliMaxSolverTimeS = 1e6;

[[noreturn]] void WrongType(const std::string& key, const char* expected, py::handle value) {
  throw InvalidArgumentError("option '" + key + "' must be " + expected + ", not " +
                             std::string(py::str(py::type::handle_of(value).attr("__name__"))));
}

// Python bools are ints: numbers and counts refuse them explicitly.
bool IsBool(py::handle value) { return PyBool_Check(value.ptr()) != 0; }

double ToDouble(const std::string& key, py::handle value) {
  if (IsBool(value) || PyNumber_Check(value.ptr()) == 0 || PyUnicode_Check(value.ptr()) != 0) {
    WrongType(key, "a number", value);
  }
  return py::cast<double>(value);
}

int64_t ToInteger(const std::string& key, py::handle value, int64_t min, int64_t max) {
  if (IsBool(value) || PyIndex_Check(value.ptr()) == 0) WrongType(key, "an integer", value);
  const py::int_ integer = py::reinterpret_steal<py::int_>(PyNumber_Index(value.ptr()));
  int overflow = 0;
  const long long result = PyLong_AsLongLongAndOverflow(integer.ptr(), &overflow);
  if (overflow != 0 || result < min || result > max) {
    throw InvalidArgumentError("option '" + key + "' must be between " + std::to_string(min) +
                               " and " + std::to_string(max));
  }
  return result;
}

bool ToBool(const std::string& key, py::handle value) {
  if (!IsBool(value)) WrongType(key, "True or False", value);
  return value.ptr() == Py_True;
}

std::string ToString(const std::string& key, py::handle value) {
  if (PyUnicode_Check(value.ptr()) == 0) WrongType(key, "a string", value);
  return py::cast<std::string>(value);
}

// One key of an options dictionary: how to read its value from the settings and set it.
template <typename Settings>
struct Option {
  std::string key;
  std::function<py::object(const Settings&)> get;
  std::function<void(py::handle, Settings*)> set;
};

// Options whose value is one field of the settings, given by `field` (Settings& → T&).
template <typename Settings, typename Field>
Option<Settings> DoubleOption(const char* key, Field field) {
  return {key, [field](const Settings& s) { return py::cast(field(const_cast<Settings&>(s))); },
          [key, field](py::handle v, Settings* s) { field(*s) = ToDouble(key, v); }};
}

template <typename Settings, typename Field>
Option<Settings> IntOption(const char* key, Field field) {
  return {key, [field](const Settings& s) { return py::cast(field(const_cast<Settings&>(s))); },
          [key, field](py::handle v, Settings* s) {
            using Int = std::remove_reference_t<decltype(field(*s))>;
            field(*s) = static_cast<Int>(ToInteger(key, v, std::numeric_limits<Int>::min(),
                                                   std::numeric_limits<Int>::max()));
          }};
}

template <typename Settings, typename Field>
Option<Settings> BoolOption(const char* key, Field field) {
  return {key, [field](const Settings& s) { return py::cast(field(const_cast<Settings&>(s))); },
          [key, field](py::handle v, Settings* s) { field(*s) = ToBool(key, v); }};
}

template <typename Settings, typename Field>
Option<Settings> StringOption(const char* key, Field field) {
  return {key, [field](const Settings& s) { return py::cast(field(const_cast<Settings&>(s))); },
          [key, field](py::handle v, Settings* s) { field(*s) = ToString(key, v); }};
}

template <typename Settings, typename Enum, std::size_t N, typename Field>
Option<Settings> EnumOption(const char* key, const EnumName<Enum> (&table)[N], Field field) {
  return {key,
          [&table, field](const Settings& s) {
            return py::cast(std::string(NameOf(table, field(const_cast<Settings&>(s)))));
          },
          [key, &table, field](py::handle v, Settings* s) {
            field(*s) = ParseName(table, ToString(key, v), std::string("--") + key);
          }};
}

using R = ReconstructSettings;

ReconstructionOptions& Rec(R& s) { return s.request.method.reconstruction; }
ObjectiveOptions& Objective(R& s) { return Rec(s).objective; }
ceres::Solver::Options& Ceres(R& s) { return Rec(s).solver; }

const std::vector<Option<R>>& ReconstructOptionTable() {
  static const std::vector<Option<R>> table = {
      // Data and output. The topics of a ROS bag (evfs.video; evfs.read takes them itself).
      StringOption<R>("events_topic",
                      [](R& s) -> std::string& { return s.request.data_options.events_topic; }),
      StringOption<R>("frames_topic",
                      [](R& s) -> std::string& { return s.request.data_options.frames_topic; }),
      DoubleOption<R>("exposure_s", [](R& s) -> double& { return s.request.exposure_s; }),
      DoubleOption<R>("fps", [](R& s) -> double& { return s.request.fps; }),
      {"frame_time",
       [](const R& s) {
         return py::cast(FrameTimeName(s.request.frame_time, s.request.frame_lag_s));
       },
       [](py::handle v, R* s) {
         if (!ParseFrameTime(ToString("frame_time", v), &s->request.frame_time,
                             &s->request.frame_lag_s)) {
           throw InvalidArgumentError(
               "--frame_time: expected instant, auto, start, middle, end "
               "or a lag in ms");
         }
       }},
      // Method.
      {"solver",
       [](const R& s) { return py::cast(std::string(MethodName(s.request.method.method))); },
       [](py::handle v, R* s) { s->request.method.method = ParseMethod(ToString("solver", v)); }},
      {"init",
       [](const R& s) {
         return py::cast(std::string(InitializationName(s.request.method.initialization)));
       },
       [](py::handle v, R* s) {
         s->request.method.initialization = ParseInitialization(ToString("init", v));
       }},
      BoolOption<R>("checkpoints", [](R& s) -> bool& { return s.request.checkpoints; }),
      IntOption<R>("adam_iterations",
                   [](R& s) -> int& { return s.request.method.adam.max_iterations; }),
      DoubleOption<R>("adam_learning_rate",
                      [](R& s) -> double& { return s.request.method.adam.learning_rate; }),
      DoubleOption<R>("contrast_threshold",
                      [](R& s) -> double& { return s.request.method.baseline.contrast_threshold; }),
      DoubleOption<R>("blur_sigma_px",
                      [](R& s) -> double& { return s.request.method.baseline.blur_sigma_px; }),
      DoubleOption<R>("cf_cutoff_rad_per_s",
                      [](R& s) -> double& { return s.request.method.baseline.cutoff_rad_per_s; }),
      // Binning.
      EnumOption<R>("binning", kBinningMethodNames,
                    [](R& s) -> BinningOptions::Method& { return s.request.binning.method; }),
      IntOption<R>("max_latent_frames",
                   [](R& s) -> int& { return s.request.binning.max_latent_frames; }),
      IntOption<R>("min_latent_steps",
                   [](R& s) -> int& { return s.request.binning.min_latent_steps; }),
      IntOption<R>("max_latent_voxels",
                   [](R& s) -> int64_t& { return s.request.binning.max_latent_voxels; }),
      DoubleOption<R>("hot_pixel_factor",
                      [](R& s) -> double& { return s.request.binning.hot_pixel_factor; }),
      DoubleOption<R>("saturation_level",
                      [](R& s) -> double& { return s.request.binning.saturation_level; }),
      BoolOption<R>("leave_out_saturated",
                    [](R& s) -> bool& { return s.request.binning.leave_out_saturated; }),
      IntOption<R>("flicker_min_reversals",
                   [](R& s) -> int& { return s.request.binning.flicker_min_reversals; }),
      DoubleOption<R>("noise_filter_ms",
                      [](R& s) -> double& { return s.request.binning.noise_filter_ms; }),
      IntOption<R>("stacked_frames",
                   [](R& s) -> int& { return s.request.binning.stacked.num_frames; }),
      // Model.
      DoubleOption<R>("frame_weight", [](R& s) -> double& { return Objective(s).frame_weight; }),
      DoubleOption<R>("event_weight", [](R& s) -> double& { return Objective(s).event_weight; }),
      DoubleOption<R>("spatial_tv_weight",
                      [](R& s) -> double& { return Objective(s).spatial_tv_weight; }),
      DoubleOption<R>("temporal_tv_weight",
                      [](R& s) -> double& { return Objective(s).temporal_tv_weight; }),
      DoubleOption<R>("alpha", [](R& s) -> double& { return Objective(s).event_model.alpha; }),
      DoubleOption<R>("event_saturation",
                      [](R& s) -> double& { return Objective(s).event_model.saturation; }),
      BoolOption<R>("per_polarity_alpha",
                    [](R& s) -> bool& { return Rec(s).estimation.per_polarity; }),
      // A model name, or a calibration file read once every option is set
      // (ApplyReconstructOptions).
      {"event_model",
       [](const R& s) {
         return s.event_model_file.empty()
                    ? py::cast(std::string(
                          NameOf(kEventModelNames,
                                 s.request.method.reconstruction.objective.event_model.model)))
                    : py::cast(s.event_model_file);
       },
       [](py::handle v, R* s) {
         const std::string value = ToString("event_model", v);
         s->event_model_file.clear();
         if (IsEventModelFile(value)) {
           s->event_model_file = value;
         } else {
           Objective(*s).event_model.model = ParseName(kEventModelNames, value, "--event_model");
         }
       }},
      DoubleOption<R>("log_offset",
                      [](R& s) -> double& { return Objective(s).event_model.log_offset; }),
      EnumOption<R>("spatial_tv", kSpatialTvNames,
                    [](R& s) -> SpatialTv& { return Objective(s).spatial_tv; }),
      BoolOption<R>("shared_structure_tv",
                    [](R& s) -> bool& { return Objective(s).shared_structure_tv; }),
      DoubleOption<R>("smoothing_scale",
                      [](R& s) -> double& { return Objective(s).smoothing_scale; }),
      {"smoothing_continuation",
       [](const R& s) { return py::cast(s.request.method.reconstruction.smoothing_continuation); },
       [](py::handle v, R* s) {
         if (PyUnicode_Check(v.ptr()) != 0 || PySequence_Check(v.ptr()) == 0) {
           WrongType("smoothing_continuation", "a sequence of numbers", v);
         }
         std::vector<double> scales;
         for (const py::handle item : v) {
           scales.push_back(ToDouble("smoothing_continuation", item));
         }
         Rec(*s).smoothing_continuation = scales;
       }},
      // Skipping and bounds.
      BoolOption<R>("bounds", [](R& s) -> bool& { return Rec(s).bound_intensities; }),
      IntOption<R>("activity_radius_px", [](R& s) -> int& { return Rec(s).activity_radius_px; }),
      BoolOption<R>("merge_quiet_steps", [](R& s) -> bool& { return Rec(s).merge_quiet_steps; }),
      BoolOption<R>("unfired_pixel_changes",
                    [](R& s) -> bool& { return Rec(s).unfired_pixel_changes; }),
      BoolOption<R>("split_independent_parts",
                    [](R& s) -> bool& { return Rec(s).split_independent_parts; }),
      IntOption<R>("max_problem_mb", [](R& s) -> int64_t& { return Rec(s).max_problem_mb; }),
      DoubleOption<R>("quiet_blend_fraction",
                      [](R& s) -> double& { return Rec(s).quiet_blend_fraction; }),
      DoubleOption<R>("step_ramp_px", [](R& s) -> double& { return Rec(s).step_ramp_px; }),
      BoolOption<R>("meet_sharp_frames", [](R& s) -> bool& { return Rec(s).meet_sharp_frames; }),
      // Ceres.
      {"linear_solver",
       [](const R& s) {
         return py::cast(std::string(ceres::LinearSolverTypeToString(
             s.request.method.reconstruction.solver.linear_solver_type)));
       },
       [](py::handle v, R* s) {
         const std::string name = ToString("linear_solver", v);
         if (!ceres::StringToLinearSolverType(name, &Ceres(*s).linear_solver_type)) {
           throw InvalidArgumentError("unknown --linear_solver " + name);
         }
       }},
      {"preconditioner",
       [](const R& s) {
         return py::cast(std::string(ceres::PreconditionerTypeToString(
             s.request.method.reconstruction.solver.preconditioner_type)));
       },
       [](py::handle v, R* s) {
         const std::string name = ToString("preconditioner", v);
         if (!ceres::StringToPreconditionerType(name, &Ceres(*s).preconditioner_type)) {
           throw InvalidArgumentError("unknown --preconditioner " + name);
         }
       }},
      DoubleOption<R>("eta", [](R& s) -> double& { return Ceres(s).eta; }),
      IntOption<R>("max_iterations", [](R& s) -> int& { return Ceres(s).max_num_iterations; }),
      IntOption<R>("max_linear_iterations",
                   [](R& s) -> int& { return Ceres(s).max_linear_solver_iterations; }),
      DoubleOption<R>("max_time_s",
                      [](R& s) -> double& { return Ceres(s).max_solver_time_in_seconds; }),
      IntOption<R>("bounds_line_search_iterations",
                   [](R& s) -> int& { return Ceres(s).max_num_line_search_step_size_iterations; }),
      DoubleOption<R>("function_tolerance",
                      [](R& s) -> double& { return Ceres(s).function_tolerance; }),
      // One thread count for every solver, as --threads.
      {"threads",
       [](const R& s) { return py::cast(s.request.method.reconstruction.solver.num_threads); },
       [](py::handle v, R* s) {
         const int threads = static_cast<int>(ToInteger(
             "threads", v, std::numeric_limits<int>::min(), std::numeric_limits<int>::max()));
         Ceres(*s).num_threads = threads;
         s->request.method.adam.num_threads = threads;
         s->request.method.lbfgs.num_threads = threads;
       }},
      // Denoiser.
      {"denoise", [](const R& s) { return py::cast(s.denoise); },
       [](py::handle v, R* s) {
         const std::string mode = ToString("denoise", v);
         if (mode != "auto") ParseName(kDenoiseModeNames, mode, "--denoise");
         s->denoise = mode;
       }},
      {"denoiser", [](const R& s) { return py::cast(s.request.denoise.denoiser.weights_path); },
       [](py::handle v, R* s) {
         s->request.denoise.denoiser.weights_path = ToString("denoiser", v);
       }},
      {"denoise_consistency", [](const R& s) { return py::cast(s.request.denoise.consistency); },
       [](py::handle v, R* s) {
         s->request.denoise.consistency = ToBool("denoise_consistency", v);
       }},
      {"denoise_gate", [](const R& s) { return py::cast(s.request.denoise.gate); },
       [](py::handle v, R* s) { s->request.denoise.gate = ToBool("denoise_gate", v); }},
      {"denoise_gate_tau", [](const R& s) { return py::cast(s.request.denoise.gate_tau); },
       [](py::handle v, R* s) { s->request.denoise.gate_tau = ToDouble("denoise_gate_tau", v); }},
  };
  return table;
}

using S = SimulatorOptions;

const std::vector<Option<S>>& SimulateOptionTable() {
  static const std::vector<Option<S>> table = {
      DoubleOption<S>("threshold_pos", [](S& s) -> double& { return s.contrast_threshold_pos; }),
      DoubleOption<S>("threshold_neg", [](S& s) -> double& { return s.contrast_threshold_neg; }),
      DoubleOption<S>("threshold_sigma", [](S& s) -> double& { return s.threshold_sigma; }),
      DoubleOption<S>("log_eps", [](S& s) -> double& { return s.log_eps; }),
      {"refractory_s",
       [](const S& s) { return py::cast(NanosecondsToSeconds(s.refractory_period_ns)); },
       [](py::handle v, S* s) {
         s->refractory_period_ns = SecondsToNanoseconds(ToDouble("refractory_s", v));
       }},
      DoubleOption<S>("noise_rate_hz", [](S& s) -> double& { return s.noise_rate_hz; }),
      DoubleOption<S>("leak_rate_hz", [](S& s) -> double& { return s.leak_rate_hz; }),
      DoubleOption<S>("leak_jitter_fraction",
                      [](S& s) -> double& { return s.leak_jitter_fraction; }),
      DoubleOption<S>("cutoff_hz", [](S& s) -> double& { return s.cutoff_hz; }),
      DoubleOption<S>("hot_pixel_fraction", [](S& s) -> double& { return s.hot_pixel_fraction; }),
      DoubleOption<S>("hot_pixel_rate_hz", [](S& s) -> double& { return s.hot_pixel_rate_hz; }),
      {"seed", [](const S& s) { return py::cast(s.seed); },
       [](py::handle v, S* s) {
         s->seed =
             static_cast<uint64_t>(ToInteger("seed", v, 0, std::numeric_limits<int64_t>::max()));
       }},
  };
  return table;
}

template <typename Settings>
void Apply(const std::vector<Option<Settings>>& table, const py::handle& options,
           Settings* settings) {
  if (options.is_none()) return;
  if (!py::isinstance<py::dict>(options)) {
    throw InvalidArgumentError("options must be a dict of flag names and values, not " +
                               std::string(py::str(py::type::handle_of(options).attr("__name__"))));
  }
  for (const auto& [key_object, value] : py::reinterpret_borrow<py::dict>(options)) {
    const std::string key = py::str(key_object);
    const Option<Settings>* option = nullptr;
    for (const Option<Settings>& candidate : table) {
      if (candidate.key == key) option = &candidate;
    }
    if (option == nullptr) {
      std::string known;
      for (const Option<Settings>& candidate : table) {
        known += (known.empty() ? "" : ", ") + candidate.key;
      }
      throw InvalidArgumentError("unknown option '" + key + "': expected one of " + known);
    }
    option->set(value, settings);
  }
}

template <typename Settings>
py::dict Values(const std::vector<Option<Settings>>& table, const Settings& settings) {
  py::dict values;
  for (const Option<Settings>& option : table) values[option.key.c_str()] = option.get(settings);
  return values;
}

}  // namespace

ReconstructSettings DefaultReconstructSettings() {
  ReconstructSettings settings;
  settings.request.method.reconstruction.solver.max_solver_time_in_seconds = kCliMaxSolverTimeS;
  return settings;
}

void ApplyReconstructOptions(const py::handle& options, ReconstructSettings* settings) {
  Apply(ReconstructOptionTable(), options, settings);
  if (settings->event_model_file.empty()) return;
  // As --event_model=FILE.json: the options given beside it win over the file.
  const auto given = [&options](const char* key) {
    return py::reinterpret_borrow<py::dict>(options).contains(key);
  };
  ReconstructionOptions& reconstruction = settings->request.method.reconstruction;
  ApplyEventModelFile(settings->event_model_file, reconstruction.estimation, given("log_offset"),
                      given("alpha"), given("event_saturation"),
                      &reconstruction.objective.event_model);
}

void ResolveDenoise(ReconstructSettings* settings) {
  DenoiseRequest& denoise = settings->request.denoise;
  if (settings->denoise == "auto") {
    denoise.mode = AutoDenoiseMode(denoise.denoiser.weights_path);
  } else {
    denoise.mode = ParseName(kDenoiseModeNames, settings->denoise, "--denoise");
  }
}

py::dict ReconstructOptionValues(const ReconstructSettings& settings) {
  return Values(ReconstructOptionTable(), settings);
}

void ApplySimulateOptions(const py::handle& options, SimulatorOptions* simulator) {
  Apply(SimulateOptionTable(), options, simulator);
}

py::dict SimulateOptionValues(const SimulatorOptions& simulator) {
  return Values(SimulateOptionTable(), simulator);
}

}  // namespace evfs
