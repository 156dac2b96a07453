// evfs — event-driven video frame synthesis from the command line (docs/guide.md).
//
//   evfs info        --data=DIR [--first=I --last=J]
//   evfs reconstruct --data=DIR --mode=interpolate|predict|deblur --first=I [--last=J]
//                    [--truth=K] --out=OUT [solver and model flags]
//   evfs video       --data=DIR --out=OUT [--fps=N --first=I --last=J --jobs=N --resume
//                    --preview] [--report] [solver and model flags]
//   evfs denoise     --in=RECONSTRUCTION_DIR --out=DIR [--denoiser=FILE.onnx]
//   evfs simulate    --frames=DIR --out=DIR [--threshold_pos=… --threshold_neg=… --seed=…]
//                    [sensor effects, light sources and frame effects]
//   evfs convert     --data=DIR|FILE.h5|FILE.aedat4|FILE.bag --out=FILE.h5|FILE.aedat4|DIR
//   evfs calibrate   --data=DIR [--first=I --last=J] --out=MODEL.json
//   evfs demo        --out=DIR
//
// The flags are the option table of app/evfs_options.h, read here through it; every failure
// that is the user's (a bad file, a bad flag) prints one line and exits with status 2.
#include <gflags/gflags.h>
#include <glog/logging.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <new>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

#include "evfs/app/calibrate_job.h"
#include "evfs/app/demo.h"
#include "evfs/app/denoise_job.h"
#include "evfs/app/evfs_help.h"
#include "evfs/app/evfs_options.h"
#include "evfs/app/reconstruct_job.h"
#include "evfs/app/reports.h"
#include "evfs/app/run_report.h"
#include "evfs/app/simulate_job.h"
#include "evfs/app/version_report.h"
#include "evfs/app/video_job.h"
#include "evfs/app/video_mpi.h"
#include "evfs/app/video_work_folder.h"
#include "evfs/core/enum_names.h"
#include "evfs/core/error.h"
#include "evfs/core/time.h"
#include "evfs/core/version.h"
#include "evfs/events/binning.h"
#include "evfs/events/flicker.h"
#include "evfs/events/frame_effects.h"
#include "evfs/events/simulator.h"
#include "evfs/io/aedat4.h"
#include "evfs/io/data_source.h"
#include "evfs/io/frame_list.h"
#include "evfs/io/hdf5_io.h"
#include "evfs/io/output_target.h"
#include "evfs/io/text_folder.h"
#include "evfs/runtime/allocator_tuning.h"
#include "evfs/runtime/crash_guard.h"
#include "evfs/runtime/progress.h"
#include "evfs/scene/scene.h"

namespace evfs {
namespace {

// The options' values (app/evfs_options.h), read once gflags has parsed the command line.
const OptionValues& Options() {
  static const OptionValues values = OptionValuesFromFlags();
  return values;
}

void Require(bool condition, const std::string& message) {
  if (!condition) throw InvalidArgumentError(message);
}

// --out of `command`, checked (and its staging folder made) before any input is read.
OutputOptions OutputFromFlags(const std::string& command, const std::string& input) {
  OutputOptions options;
  options.path = Options().String("out");
  options.command = command;
  options.overwrite = Options().Bool("overwrite");
  options.inputs = {input};
  return options;
}

// --events_topic, --frames_topic: how --data is read.
DataSourceOptions DataOptionsFromFlags() {
  DataSourceOptions options;
  options.events_topic = Options().String("events_topic");
  options.frames_topic = Options().String("frames_topic");
  return options;
}

int RunInfo() {
  const std::string& data = Options().String("data");
  const int first = Options().Int("first");
  const int last = Options().Int("last");
  Require(!data.empty(), "info needs --data=DIR or --data=FILE.h5");
  const auto source = DataSource::Open(data, DataOptionsFromFlags());
  PrintRecording(*source, stdout);
  if (first >= 0 && source->has_events()) {
    PrintWindow(*source, first, last >= 0 ? last : first + 1, BinningFromOptions(Options()),
                Options().String("binning"), stdout);
  }
  if (first >= 0) {
    PrintInfoCalibration(*source, data, first, last >= 0 ? last : first + 1, stdout);
  } else {
    PrintInfoCalibration(*source, data, 0, last, stdout);
  }
  return 0;
}

int RunConvert() {
  Require(!Options().String("data").empty() && !Options().String("out").empty(),
          "convert needs --data and --out");
  OutputOptions options = OutputFromFlags("convert", Options().String("data"));
  if (IsHdf5Path(Options().String("out"))) {
    options.kind = OutputOptions::Kind::kFile;
    options.is_own_file = IsHdf5WrittenByEvfs;
  } else if (IsAedat4Path(Options().String("out"))) {
    options.kind = OutputOptions::Kind::kFile;
    options.is_own_file = IsAedat4WrittenByEvfs;
  }
  OutputTarget out(options);
  ConvertRecording(Options().String("data"), out.staging(), DataOptionsFromFlags());
  out.Commit();
  std::printf("wrote %s\n", out.path().c_str());
  return 0;
}

int RunSimulate() {
  Require(!Options().String("frames").empty() && !Options().String("out").empty(),
          "simulate needs --frames=DIR and --out=DIR");
  const SimulatorOptions options = SimulatorFromOptions(Options());
  std::string error;
  if (!options.IsValid(&error)) throw InvalidArgumentError("simulator: " + error);

  FlickerOptions flicker = FlickerFromOptions(Options());
  if (flicker.led_hz != 0.0 || !Options().String("flicker_led_xy_px").empty()) {
    const std::vector<double> xy =
        ParseNumberList(Options().String("flicker_led_xy_px"), "--flicker_led_xy_px");
    Require(xy.size() == 2, "--flicker_led_hz needs --flicker_led_xy_px=X,Y (the LED's centre)");
    Require(flicker.led_hz != 0.0, "--flicker_led_xy_px needs --flicker_led_hz");
    flicker.led_x_px = xy[0];
    flicker.led_y_px = xy[1];
  }
  if (!Options().String("mains_region_px").empty()) {
    const std::vector<double> region =
        ParseNumberList(Options().String("mains_region_px"), "--mains_region_px");
    Require(
        region.size() == 4 &&
            std::all_of(region.begin(), region.end(),
                        [](double v) { return v >= 0.0 && v <= 65536.0 && v == std::floor(v); }),
        "--mains_region_px must be X,Y,WIDTH,HEIGHT: four whole numbers in [0, 65536]");
    flicker.mains_x_px = static_cast<int>(region[0]);
    flicker.mains_y_px = static_cast<int>(region[1]);
    flicker.mains_width_px = static_cast<int>(region[2]);
    flicker.mains_height_px = static_cast<int>(region[3]);
  }
  if (!flicker.IsValid(&error)) throw InvalidArgumentError("light sources: " + error);

  const FrameEffectsOptions frame_effects = FrameEffectsFromOptions(Options());
  if (!frame_effects.IsValid(&error)) throw InvalidArgumentError("frame effects: " + error);

  OutputTarget out(OutputFromFlags("simulate", Options().String("frames")));
  const SimulateSummary summary =
      SimulateRecording(Options().String("frames"), options, out.staging(), flicker, frame_effects);
  out.Commit();
  std::printf("simulated %lld events over %d frames (%dx%d) into %s\n",
              static_cast<long long>(summary.events), summary.frames, summary.width, summary.height,
              out.path().c_str());
  return 0;
}

int RunCalibrate() {
  Require(!Options().String("data").empty(), "calibrate needs --data=DIR or --data=FILE.h5");
  Require(!Options().String("out").empty(), "calibrate needs --out=MODEL.json");
  Require(IsEventModelFile(Options().String("out")), "calibrate: --out must name a .json file");
  CalibrateRequest request;
  request.data_path = Options().String("data");
  request.first = Options().Int("first");
  request.last = Options().Int("last");
  request.options.saturation_level = Options().Double("saturation_level");
  OutputOptions options = OutputFromFlags("calibrate", Options().String("data"));
  options.kind = OutputOptions::Kind::kFile;
  options.is_own_file = [](const std::string& path) {
    std::ifstream file(path);
    std::string text((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
    return text.find("\"evfs_calibration\"") != std::string::npos;
  };
  OutputTarget out(options);
  const CalibrateResult result = RunCalibration(request);
  WriteCalibration(request, result, out.staging());
  out.Commit();
  PrintCalibration(request, result, out.path(), stdout);
  return 0;
}

int RunDenoise() {
  Require(!Options().String("in").empty(), "denoise needs --in=RECONSTRUCTION_DIR");
  Require(!Options().String("out").empty(), "denoise needs --out=DIR");
  DenoiseRequest request;
  request.mode = DenoiseMode::kOnce;
  request.denoiser.weights_path = Options().String("denoiser");
  OutputTarget out(OutputFromFlags("denoise", Options().String("in")));
  const std::unique_ptr<Denoiser> denoiser = LoadDenoiser(request);
  const DenoiseRecord record =
      DenoiseReconstructionFolder(Options().String("in"), *denoiser, out.staging());
  out.Commit();
  std::printf("denoised %d frames with %s in %.3f s into %s\n", record.stats.frames,
              record.weights_path.c_str(), record.stats.time_s, out.path().c_str());
  return 0;
}

int RunReconstruct(ProgressReporter* progress) {
  Require(!Options().String("data").empty(), "reconstruct needs --data=DIR or --data=FILE.h5");
  Require(!Options().String("out").empty(), "reconstruct needs --out=DIR");
  Require(Options().Int("first") >= 0, "reconstruct needs --first=I (a 0-based images.txt line)");
  ReconstructRequest request = ReconstructRequestFromOptions(Options(), /*with_mode=*/true);
  OutputTarget out(OutputFromFlags("reconstruct", Options().String("data")));
  // A line per iteration on a terminal; elsewhere the solve keeps its speed (an iteration
  // callback solves independent parts one after another).
  if (Options().Bool("progress") || ::isatty(STDERR_FILENO))
    request.progress = progress->callback();
  request.stage = [progress](const char* stage) { progress->StartStage(stage); };
  ReconstructResult result = RunReconstruction(request);
  progress->StartStage("write");
  WriteReconstruction(request, &result, out.staging());
  if (Options().Bool("report")) {
    WriteReconstructionReport(result, out.staging(), VideoFingerprint(Options()));
  }
  out.Commit();

  PrintReconstruction(request, result, out.path(), stdout);
  return 0;
}

int RunVideoCommand(ProgressReporter* progress) {
  Require(!Options().String("data").empty(), "video needs --data=DIR or --data=FILE.h5");
  Require(!Options().String("out").empty(), "video needs --out=DIR");
  VideoRequest request = VideoRequestFromOptions(Options());
  request.notice = [](const std::string& line) {
    std::fprintf(stderr, "evfs video: %s\n", line.c_str());
  };
  std::string error;
  if (!request.IsValid(&error)) throw InvalidArgumentError(error);
  // Under mpirun: rank 0 writes, the other ranks solve the windows it hands out.
  std::unique_ptr<MpiVideoSession> mpi;
  if (LaunchedAsMpiJob()) mpi = std::make_unique<MpiVideoSession>();
  if (mpi != nullptr && mpi->rank() != 0) {
    const std::string out_path = mpi->Broadcast("");
    if (out_path.empty()) return kExitUserError;  // rank 0 refused --out and said why
    request.distribution = &mpi->distribution();
    try {
      RunVideo(request, out_path, "");
    } catch (const Error& failure) {
      std::fprintf(stderr, "evfs video: rank %d: %s\n", mpi->rank(), failure.what());
      std::fflush(stderr);
      mpi->WorkerFailed();  // rank 0 cleans up, then ends every rank
      return kExitUserError;
    }
    mpi->WorkerFinished();
    return 0;
  }
  std::unique_ptr<OutputTarget> target;
  try {
    target = std::make_unique<OutputTarget>(OutputFromFlags("video", Options().String("data")));
  } catch (const Error&) {
    if (mpi != nullptr) mpi->Broadcast("");
    throw;
  }
  OutputTarget& out = *target;
  if (mpi != nullptr) {
    mpi->Broadcast(out.path());
    request.distribution = &mpi->distribution();
  }
  const bool terminal = ::isatty(STDERR_FILENO);
  request.progress = [progress, terminal](const VideoProgress& state) {
    const std::string line = VideoProgressLine(state);
    if (terminal) {
      std::fprintf(stderr, "\r%s", line.c_str());
      if (state.windows_done == state.windows_total) std::fputc('\n', stderr);
    } else {
      progress->StartStage(line);
    }
  };
  progress->StartStage("windows");
  VideoResult result;
  try {
    result = RunVideo(request, out.path(), out.staging());
  } catch (const Error& failure) {
    if (mpi == nullptr) throw;
    // The workers wait for windows: one line, then every rank ends.
    std::fprintf(stderr, "evfs video: %s\n", failure.what());
    target.reset();
    mpi->Abort(kExitUserError);
  }
  out.Commit();
  RemoveVideoWorkFolder(out.path());
  for (const int frame : result.skipped_frames) {
    std::fprintf(stderr, "evfs video: left out unreadable frame %d\n", frame);
  }
  std::printf(
      "%d windows (%d resumed), %lld events, %lld frames at %g fps (%dx%d) into %s\n"
      "%.2f windows/s, %.0f events/s with %d jobs x %d threads; video.mp4 codec %s\n",
      result.windows, result.windows_resumed, static_cast<long long>(result.events),
      static_cast<long long>(result.output_frames), result.fps, result.width, result.height,
      out.path().c_str(), result.windows_per_s, result.events_per_s, result.jobs,
      result.threads_per_window, result.codec.c_str());
  if (result.log_offset_choice) {
    std::printf("log offset of the interpolations: %s\n",
                result.log_offset_choice->description.c_str());
  }
  if (result.truth_frames > 0) {
    std::printf(
        "%d withheld frames: PSNR mean %.2f dB (worst %.2f, blend %.2f), SSIM mean %.4f "
        "(worst %.4f, blend %.4f)\n",
        result.truth_frames, result.mean_psnr, result.worst_psnr, result.mean_blend_psnr,
        result.mean_ssim, result.worst_ssim, result.mean_blend_ssim);
  }
  return 0;
}

int RunCommand(const std::string& command) {
  SetFramePathsMayLeaveFolder(Options().Bool("allow_outside_paths"));
  // Lines on stderr while the command runs, only when it runs long (runtime/progress.h).
  ProgressOptions progress_options;
  progress_options.prefix = "evfs " + command;
  progress_options.interval_s = Options().Double("progress_interval_s");
  progress_options.every_iteration = Options().Bool("progress") || ::isatty(STDERR_FILENO);
  ProgressReporter progress(progress_options);
  if (command == "info") return RunInfo();
  if (command == "reconstruct") return RunReconstruct(&progress);
  if (command == "video") return RunVideoCommand(&progress);
  if (command == "simulate") return RunSimulate();
  if (command == "convert") return RunConvert();
  if (command == "calibrate") return RunCalibrate();
  if (command == "denoise") return RunDenoise();
  if (command == "demo") {
    Require(!Options().String("out").empty(), "demo needs --out=DIR");
    OutputTarget out(OutputFromFlags("demo", ""));
    const int status = RunDemo(out.staging(), out.path());
    out.Commit();
    std::printf("results written to %s\n", out.path().c_str());
    return status;
  }
  throw InvalidArgumentError(
      "unknown command '" + command +
      "': expected info, reconstruct, video, denoise, simulate, convert, calibrate or demo "
      "(evfs --help)");
}

// What a value of a flag of gflags type `type` must look like.
std::string ExpectedValue(const std::string& type) {
  if (type == "bool") return "true or false";
  if (type == "int32") return "a whole number (32-bit)";
  if (type == "int64") return "a whole number";
  if (type == "uint32" || type == "uint64") return "a whole number, 0 or more";
  if (type == "double") return "a number";
  return "a " + type;
}

// gflags reports a flag it cannot parse in its own words, possibly on several lines, and exits
// with status 1. This reads the command line as gflags will (--name=value, --name value,
// --name and --noname for booleans, "--" ending the flags) and tries each value in a
// FlagSaver's scope, which puts every flag back. Returns the first problem, "" when none.
// --flagfile is only checked for being readable; gflags reports what is inside it.
std::string FirstFlagError(int argc, char** argv) {
  const gflags::FlagSaver put_flags_back;
  for (int i = 1; i < argc; ++i) {
    const std::string argument = argv[i];
    if (argument.size() < 2 || argument[0] != '-') continue;  // the command, or "-"
    const size_t dashes = argument[1] == '-' ? 2 : 1;
    if (argument.size() == dashes) break;  // "--"
    const size_t equals = argument.find('=');
    const bool has_value = equals != std::string::npos;
    const std::string name =
        argument.substr(dashes, has_value ? equals - dashes : std::string::npos);
    gflags::CommandLineFlagInfo info;
    if (!gflags::GetCommandLineFlagInfo(name.c_str(), &info)) {
      gflags::CommandLineFlagInfo negated;
      if (!has_value && name.rfind("no", 0) == 0 &&
          gflags::GetCommandLineFlagInfo(name.substr(2).c_str(), &negated) &&
          negated.type == "bool") {
        continue;
      }
      return "unknown flag --" + name + " (evfs --help lists the flags)";
    }
    std::string value;
    if (has_value) {
      value = argument.substr(equals + 1);
    } else if (info.type == "bool") {
      value = "true";
    } else if (i + 1 < argc) {
      value = argv[++i];
    } else {
      return "--" + name + " needs a value";
    }
    if (name == "flagfile") {
      std::stringstream files(value);
      for (std::string file; std::getline(files, file, ',');) {
        if (!std::ifstream(file)) return "--flagfile=" + value + ": cannot read " + file;
      }
      continue;
    }
    if (gflags::SetCommandLineOption(name.c_str(), value.c_str()).empty()) {
      return "--" + name + "=" + value + ": expected " + ExpectedValue(info.type);
    }
  }
  return "";
}

std::string FlagValue(const char* name) {
  std::string value;
  gflags::GetCommandLineOption(name, &value);
  return value;
}

// evfs' help (app/evfs_help.h), its own flags being those registered with this file's name
// (RegisterEvfsFlags in main): a flag defined here outside the option table has no row, and the
// help says so.
const ProgramHelp& MainHelp() {
  static const ProgramHelp help = [] {
    ProgramHelp main_help = EvfsHelp();
    main_help.flags_file = __FILE__;
    return main_help;
  }();
  return help;
}

// gflags' help flags print and then exit with status 1; help asked for is a success. --help
// and --helpshort show evfs' own flags by group (app/evfs_help.h), only the command's when one
// is given; --helpfull shows every flag, glog's and gflags' too, as gflags does. Returns true
// when help was asked for and printed; throws InvalidArgumentError for an unknown command.
bool ShowHelpAskedFor(int argc, char** argv) {
  if (FlagValue("help") == "true" || FlagValue("helpshort") == "true") {
    const std::string text =
        argc >= 2 ? CommandHelpText(MainHelp(), argv[1]) : ProgramHelpText(MainHelp());
    std::fputs(text.c_str(), stdout);
  } else if (FlagValue("helpfull") == "true" || FlagValue("helppackage") == "true") {
    gflags::ShowUsageWithFlags(argv[0]);
  } else if (!FlagValue("helpon").empty()) {
    gflags::ShowUsageWithFlagsRestrict(argv[0], ("/" + FlagValue("helpon") + ".").c_str());
  } else if (!FlagValue("helpmatch").empty()) {
    gflags::ShowUsageWithFlagsRestrict(argv[0], FlagValue("helpmatch").c_str());
  } else {
    return false;
  }
  return true;
}

}  // namespace
}  // namespace evfs

int main(int argc, char** argv) {
  // The flags of the option table (app/evfs_options.h), as this file's own.
  evfs::RegisterEvfsFlags(__FILE__);
  evfs::KeepFreedMemoryForReuse();
  gflags::SetUsageMessage(evfs::EvfsHelp().summary + "\n\n" + evfs::UsageLines(evfs::EvfsHelp()) +
                          "\nRun 'evfs --help' for evfs' own flags by group.");
  gflags::SetVersionString(evfs::kVersion);
  // Libraries' log messages (Ceres' dump of a residual block it could not evaluate, its
  // "Terminating: ...") are for developers: shown with --minloglevel=0. What failed is evfs'
  // own one line.
  gflags::SetCommandLineOptionWithMode("minloglevel", "3", gflags::SET_FLAGS_DEFAULT);
  // A flag gflags cannot parse is a user error like any other: one line, status 2.
  const std::string flag_error = evfs::FirstFlagError(argc, argv);
  if (!flag_error.empty()) {
    std::fprintf(stderr, "evfs: %s\n", flag_error.c_str());
    return evfs::kExitUserError;
  }
  gflags::ParseCommandLineNonHelpFlags(&argc, &argv, true);
  try {
    if (evfs::ShowHelpAskedFor(argc, argv)) return evfs::kExitSuccess;
  } catch (const evfs::Error& error) {
    std::fprintf(stderr, "evfs: %s\n", error.what());
    return evfs::kExitUserError;
  }
  if (evfs::FlagValue("version") == "true") {
    std::fputs(evfs::VersionReport().c_str(), stdout);
    return evfs::kExitSuccess;
  }
  gflags::HandleCommandLineHelpFlags();  // --helpxml (status 1)
  FLAGS_logtostderr = true;
  google::InitGoogleLogging(argv[0]);
  if (argc != 2) {
    std::fprintf(stderr, "evfs: expected one command; see 'evfs --help'\n");
    return 2;
  }
  const std::string command = argv[1];
  // A failed CHECK is evfs' bug, not the user's: one line, status 3 (runtime/crash_guard.h).
  evfs::InstallInternalErrorReporting("evfs " + command);
  const auto run = [&command] {
    try {
      return evfs::RunCommand(command);
    } catch (const evfs::SolverError& error) {
      std::fprintf(stderr, "evfs %s: %s\n", command.c_str(), error.what());
      return static_cast<int>(evfs::kExitSolverFailure);
    } catch (const evfs::Error& error) {
      std::fprintf(stderr, "evfs %s: %s\n", command.c_str(), error.what());
      return 2;
    } catch (const std::bad_alloc&) {
      // Memory beyond what the machine (or ulimit -v) gives, past every limit checked from
      // the declared sizes: one line and kExitUnexpected (core/error.h).
      std::fprintf(stderr,
                   "evfs %s: out of memory (a smaller window, --fps, --jobs or input, or more "
                   "memory)\n",
                   command.c_str());
      return static_cast<int>(evfs::kExitUnexpected);
    } catch (const std::system_error& error) {
      std::fprintf(stderr, "evfs %s: the system refused a resource: %s\n", command.c_str(),
                   error.what());
      return static_cast<int>(evfs::kExitUnexpected);
    } catch (const std::exception& error) {
      std::fprintf(stderr, "evfs %s: unexpected error: %s\n", command.c_str(), error.what());
      return 1;
    }
  };
  // Every command runs in a worker process: a signal or a crash there leaves no unfinished
  // output (the parent removes it), and a corrupt .h5 file that crashes libhdf5 is a user error
  // (runtime/crash_guard.h). `convert --overwrite` opens the .h5 file it would replace.
  // A value outside its option's range is refused before any work, as gflags' own errors are.
  std::string hdf5_path;
  try {
    evfs::Options();
  } catch (const evfs::Error& error) {
    std::fprintf(stderr, "evfs %s: %s\n", command.c_str(), error.what());
    return evfs::kExitUserError;
  }
  const evfs::OptionValues& options = evfs::Options();
  if (evfs::IsHdf5Path(options.String("data"))) {
    hdf5_path = options.String("data");
  } else if (options.Bool("overwrite") && evfs::IsHdf5Path(options.String("out"))) {
    hdf5_path = options.String("out");
  }
  return evfs::RunInChildProcess(run, "evfs " + command, hdf5_path);
}
