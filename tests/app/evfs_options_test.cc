// The option table of evfs (app/evfs_options.h): one row per flag, and every consumer — the
// command line's flags, --help, Python's keys, the requests, video's fingerprint — made from it.
#include "evfs/app/evfs_options.h"

#include <gflags/gflags.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "evfs/app/command_line_help.h"
#include "evfs/app/evfs_help.h"
#include "evfs/core/error.h"
#include "evfs/core/option_checker.h"

namespace evfs {
namespace {

// The repository root, where the sources are read.
const std::string kSourceDir = EVFS_SOURCE_DIR;

std::string ReadSource(const std::string& path) {
  std::ifstream file(kSourceDir + "/" + path);
  EXPECT_TRUE(file) << "cannot read " << path;
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

std::set<std::string> Names(unsigned use) {
  std::set<std::string> names;
  for (const OptionDefinition& option : EvfsOptions()) {
    if (option.uses & use) names.insert(option.name);
  }
  return names;
}

// The flags of the table registered with gflags once per test process, as `evfs` does.
void RegisterOnce() {
  static const bool registered = [] {
    RegisterEvfsFlags("evfs_options_test.cc");
    return true;
  }();
  (void)registered;
}

TEST(EvfsOptionsTest, EveryRowIsComplete) {
  std::set<std::string> names;
  const std::vector<std::string>& groups = EvfsOptionGroups();
  for (const OptionDefinition& option : EvfsOptions()) {
    SCOPED_TRACE("--" + option.name);
    EXPECT_TRUE(names.insert(option.name).second) << "two rows";
    EXPECT_NE(std::find(groups.begin(), groups.end(), option.group), groups.end());
    EXPECT_FALSE(option.help.empty());
    EXPECT_EQ(option.field.empty(), option.set == nullptr);
    if (option.commands != "*") {
      std::istringstream commands(option.commands);
      int count = 0;
      for (std::string command; commands >> command; ++count) {
        EXPECT_TRUE(IsCommand(EvfsHelp(), command)) << command;
      }
      EXPECT_GT(count, 0);
    }
    // A key of Python's options is read by the command whose options they are.
    if (option.uses & kReconstructKey) {
      EXPECT_TRUE(option.ReadBy("reconstruct"));
    }
    if (option.uses & kSimulateKey) {
      EXPECT_TRUE(option.ReadBy("simulate"));
    }
    if (option.uses & kNumberList) {
      EXPECT_TRUE(std::holds_alternative<std::string>(option.default_value));
    }
  }
}

// Every flag reaches --help from the table, with the table's group and commands, and gflags
// knows it with the table's help text and default.
TEST(EvfsOptionsTest, HelpShowsEveryOptionFromTheTable) {
  RegisterOnce();
  const ProgramHelp& help = EvfsHelp();
  ASSERT_EQ(help.flags.size(), EvfsOptions().size());
  for (size_t i = 0; i < help.flags.size(); ++i) {
    const OptionDefinition& option = EvfsOptions()[i];
    EXPECT_EQ(help.flags[i].flag, option.name);
    EXPECT_EQ(help.flags[i].group, option.group);
    EXPECT_EQ(help.flags[i].commands, option.commands);
  }
  EXPECT_EQ(help.groups, EvfsOptionGroups());
  EXPECT_TRUE(CheckHelpTables(help).empty());
  const std::string text = ProgramHelpText(help);
  for (const OptionDefinition& option : EvfsOptions()) {
    EXPECT_NE(text.find("\n  --" + option.name + " ("), std::string::npos) << option.name;
    gflags::CommandLineFlagInfo info;
    ASSERT_TRUE(gflags::GetCommandLineFlagInfo(option.name.c_str(), &info)) << option.name;
    EXPECT_EQ(info.description, option.help);
    // The text video's fingerprint records is gflags' own text of the value.
    EXPECT_EQ(info.default_value, OptionValueText(option.default_value)) << option.name;
  }
}

// Each option of `evfs reconstruct` is a key of evfs.reconstruct's options, but for those that
// are arguments of the Python functions or have no meaning without files and a terminal; each
// of `evfs video` alone is an argument of evfs.video (python/tests/test_evfs.py holds the same
// to the module).
TEST(EvfsOptionsTest, EveryReconstructOptionReachesPython) {
  const std::set<std::string> arguments = {"data",
                                           "mode",
                                           "first",
                                           "last",
                                           "truth",
                                           "out",
                                           "overwrite",
                                           "progress",
                                           "progress_interval_s",
                                           "allow_outside_paths",
                                           "report"};
  const std::set<std::string> video_arguments = {"jobs",
                                                 "resume",
                                                 "preview",
                                                 "report",
                                                 "predict_tail",
                                                 "predict_max_s",
                                                 "min_blur_exposure_s",
                                                 "blur_from_data",
                                                 "frame_step",
                                                 "skip_bad_frames"};
  for (const OptionDefinition& option : EvfsOptions()) {
    SCOPED_TRACE("--" + option.name);
    if (option.ReadBy("reconstruct") && option.commands != "*") {
      EXPECT_NE(arguments.count(option.name) > 0, (option.uses & kReconstructKey) != 0);
    } else if (option.ReadBy("video") && option.commands != "*") {
      EXPECT_EQ(video_arguments.count(option.name), 1u);
    }
  }
}

TEST(EvfsOptionsTest, FingerprintLeavesOutOnlyWhereHowFastAndHowVerbosely) {
  EXPECT_EQ(Names(kNotInFingerprint),
            (std::set<std::string>{"out", "overwrite", "resume", "jobs", "threads", "progress",
                                   "progress_interval_s", "report"}));
  const OptionValues defaults;
  const std::string fingerprint = VideoFingerprint(defaults);
  EXPECT_NE(fingerprint.find("binning=auto "), std::string::npos);
  EXPECT_NE(fingerprint.find("max_time_s=1000000 "), std::string::npos);
  EXPECT_EQ(fingerprint.find("jobs="), std::string::npos);
  OptionValues faster = defaults;
  faster.Set("jobs", 3);
  faster.Set("threads", 1);
  EXPECT_EQ(VideoFingerprint(faster), fingerprint);
  OptionValues other = defaults;
  other.Set("max_iterations", 7);
  EXPECT_NE(VideoFingerprint(other), fingerprint);
}

TEST(EvfsOptionsTest, ReconstructEchoesEveryOptionItReadsFromTheTable) {
  OptionValues values;
  values.Set("mode", std::string("predict"));
  values.Set("max_iterations", 7);
  values.Set("jobs", 3);
  const ReconstructRequest request = ReconstructRequestFromOptions(values, true);
  std::set<std::string> echoed;
  for (const auto& [name, value] : request.options) {
    echoed.insert(name);
    EXPECT_EQ(value, OptionValueText(values.Get(name))) << name;
  }
  for (const OptionDefinition& option : EvfsOptions()) {
    const bool expected = option.ReadBy("reconstruct") && !(option.uses & kNotInFingerprint);
    EXPECT_EQ(echoed.count(option.name), expected ? 1u : 0u) << option.name;
  }
  EXPECT_EQ(echoed.count("jobs"), 0u);  // video's only
  EXPECT_EQ(echoed.count("out"), 0u);   // where, not what
  EXPECT_TRUE(std::is_sorted(request.options.begin(), request.options.end()));
  const auto max_iterations =
      std::find_if(request.options.begin(), request.options.end(),
                   [](const auto& option) { return option.first == "max_iterations"; });
  ASSERT_NE(max_iterations, request.options.end());
  EXPECT_EQ(max_iterations->second, "7");
  // Video's request is made from the same table and carries its settings instead.
  EXPECT_TRUE(ReconstructRequestFromOptions(values, false).options.empty());
}

TEST(EvfsOptionsTest, BuildersSetTheBoundFields) {
  OptionValues values;
  values.Set("mode", std::string("interpolate"));
  values.Set("threads", 3);
  values.Set("max_latent_voxels", int64_t{12345});
  values.Set("smoothing_continuation", std::string("0.2,0.1"));
  values.Set("linear_solver", std::string("DENSE_QR"));
  values.Set("denoise", std::string("none"));
  const ReconstructRequest request = ReconstructRequestFromOptions(values, true);
  EXPECT_EQ(request.mode, Mode::kInterpolate);
  EXPECT_EQ(request.method.reconstruction.solver.num_threads, 3);
  EXPECT_EQ(request.method.adam.num_threads, 3);
  EXPECT_EQ(request.method.lbfgs.num_threads, 3);
  EXPECT_EQ(request.binning.max_latent_voxels, 12345);
  EXPECT_EQ(request.method.reconstruction.smoothing_continuation, (std::vector<double>{0.2, 0.1}));
  EXPECT_EQ(request.method.reconstruction.solver.linear_solver_type, ceres::DENSE_QR);
  EXPECT_EQ(request.denoise.mode, DenoiseMode::kNone);
  EXPECT_EQ(request.method.reconstruction.solver.max_solver_time_in_seconds, 1e6);

  const VideoRequest video = VideoRequestFromOptions(values);
  EXPECT_EQ(video.threads_per_window, 3);  // given: every window uses it
  EXPECT_EQ(video.windows.first, 0);       // --first=-1: from the first frame
  EXPECT_EQ(VideoRequestFromOptions(OptionValues()).threads_per_window, 0);

  OptionValues bad;
  bad.Set("binning", std::string("sideways"));
  EXPECT_THROW(ReconstructRequestFromOptions(bad, false), InvalidArgumentError);
  // Every value of b to search is a finite positive number.
  for (const char* list : {"0.5,inf", "0,1", "nan", "-1"}) {
    OptionValues search;
    search.Set("log_offset_search", std::string(list));
    EXPECT_THROW(ReconstructRequestFromOptions(search, false), InvalidArgumentError) << list;
  }
  // A command that reads no binning option is not stopped by one.
  EXPECT_NO_THROW(SimulatorFromOptions(bad));
}

// A numeric option's value of the option's own type holding `number`; false when that type
// cannot hold it (a negative unsigned seed, an int32 beyond its range).
bool ValueOfType(const OptionValue& like, double number, OptionValue* value) {
  return std::visit(
      [&](const auto& v) {
        using T = std::decay_t<decltype(v)>;
        if constexpr (std::is_same_v<T, bool> || std::is_same_v<T, std::string>) {
          return false;
        } else {
          if constexpr (std::is_integral_v<T>) {
            if (!(number >= static_cast<double>(std::numeric_limits<T>::lowest()) &&
                  number <= static_cast<double>(std::numeric_limits<T>::max()))) {
              return false;
            }
          }
          *value = static_cast<T>(number);
          return true;
        }
      },
      like);
}

bool IsIntegral(const OptionValue& value) {
  return std::holds_alternative<int32_t>(value) || std::holds_alternative<int64_t>(value) ||
         std::holds_alternative<uint64_t>(value);
}

// Values just inside and just outside each finite end of an option's range.
// Each probe is a number and the option's value holding it; numbers the option's type cannot
// hold (a negative unsigned seed) are left out.
struct RangeProbes {
  std::vector<std::pair<double, OptionValue>> inside;
  std::vector<std::pair<double, OptionValue>> outside;
};

RangeProbes ProbesOf(const OptionDefinition& option) {
  const ValueRange& range = option.range;
  const bool integral = IsIntegral(option.default_value);
  const auto step = [&](double at) { return integral ? 1.0 : std::max(1e-9, std::abs(at) * 1e-9); };
  RangeProbes probes;
  const auto add = [&](double number, std::vector<std::pair<double, OptionValue>>* to) {
    OptionValue value;
    if (ValueOfType(option.default_value, number, &value)) to->emplace_back(number, value);
  };
  const auto add_outside = [&](double value, double away) {
    if (range.has_also() && value == range.also()) value += away;
    add(value, &probes.outside);
  };
  if (std::isfinite(range.low())) {
    const double low = range.low();
    add(range.low_open() ? low + step(low) : low, &probes.inside);
    add_outside(range.low_open() ? low : low - step(low), -step(low));
  }
  if (std::isfinite(range.high())) {
    const double high = range.high();
    add(range.high_open() ? high - step(high) : high, &probes.inside);
    add_outside(range.high_open() ? high : high + step(high), step(high));
  }
  if (range.has_also()) add(range.also(), &probes.inside);
  return probes;
}

// Every number an option takes is declared with the values it accepts; the default is one of
// them and the help says which.
TEST(EvfsOptionsTest, EveryNumericOptionDeclaresItsRange) {
  // Any number means something: a contrast threshold <= 0 is derived from the data.
  const std::set<std::string> any_number = {"contrast_threshold"};
  for (const OptionDefinition& option : EvfsOptions()) {
    SCOPED_TRACE("--" + option.name);
    OptionValue probe;
    if (!ValueOfType(option.default_value, 0.0, &probe)) {
      EXPECT_FALSE(option.range.Bounded()) << "a range on a text or a switch";
      continue;
    }
    EXPECT_NE(option.range.Bounded(), any_number.count(option.name) > 0);
    OptionValues values;
    EXPECT_NO_THROW(values.Set(option.name, option.default_value)) << "the default is refused";
    if (option.range.Bounded()) {
      const std::string said = " Values: " + option.range.Text() + ".";
      EXPECT_EQ(option.help.substr(option.help.size() - std::min(option.help.size(), said.size())),
                said);
    }
  }
}

// A value outside its option's range is refused where it enters (the command line and Python
// both set OptionValues), naming the flag; NaN is no number of any range.
TEST(EvfsOptionsTest, AValueOutsideItsRangeIsRefused) {
  int probed = 0;
  for (const OptionDefinition& option : EvfsOptions()) {
    SCOPED_TRACE("--" + option.name);
    const RangeProbes probes = ProbesOf(option);
    for (const auto& [number, value] : probes.outside) {
      OptionValues values;
      try {
        values.Set(option.name, value);
        ADD_FAILURE() << number << " accepted";
      } catch (const InvalidArgumentError& error) {
        EXPECT_NE(std::string(error.what()).find("--" + option.name + " must be"),
                  std::string::npos)
            << error.what();
      }
      ++probed;
    }
    for (const auto& [number, value] : probes.inside) {
      OptionValues values;
      EXPECT_NO_THROW(values.Set(option.name, value)) << number;
    }
    if (std::holds_alternative<double>(option.default_value)) {
      OptionValues values;
      EXPECT_THROW(values.Set(option.name, std::nan("")), InvalidArgumentError);
    }
  }
  EXPECT_GT(probed, 60);
}

// What the library's own checks (each request's IsValid) refuse in `settings`, "" if nothing:
// the settings as the builders hand them over (video's windows and rates from reconstruct's).
std::string LibraryRefusal(const EvfsSettings& settings) {
  const ReconstructRequest& reconstruct = settings.reconstruct;
  std::string error;
  OptionChecker check;
  BinningOptions stacked = reconstruct.binning;
  stacked.method = BinningOptions::Method::kStacked;
  VideoRequest video = settings.video;
  video.windows.first = std::max(reconstruct.first, 0);
  video.windows.last = reconstruct.last;
  video.windows.exposure_s = reconstruct.exposure_s;
  video.fps = reconstruct.fps;
  video.threads_per_window = reconstruct.method.reconstruction.solver.num_threads;
  video.method = reconstruct.method;
  video.binning = reconstruct.binning;
  FlickerOptions flicker = settings.flicker;
  flicker.led_x_px = flicker.led_y_px = 1.0;
  check.Valid(reconstruct.method.reconstruction)
      .Valid(stacked)
      .Valid(reconstruct.method.adam)
      .Valid(reconstruct.method.baseline)
      .Valid(video)
      .Valid(settings.simulator)
      .Valid(flicker)
      .Valid(settings.frame_effects);
  check.Passed(&error);
  return error;
}

// The table's ranges are those the library's checks hold to: set past the table (as a library
// user sets a field), a value just outside its range is refused by the request's IsValid, and
// one just inside is not. The options checked only by the table say why.
TEST(EvfsOptionsTest, RangesAgreeWithTheLibrarysChecks) {
  const std::map<std::string, std::string> table_only = {
      {"first", "reconstruct reads -1 as unset; video from the first frame"},
      {"truth", "-1: none; the recording's frame count bounds the rest"},
      {"activity_radius_px", "any negative radius solves every pixel in the library"},
      {"denoise_gate_tau", "checked when the denoiser runs (app/denoise_job.cc)"},
      {"progress_interval_s", "read by the command itself"},
  };
  for (const OptionDefinition& option : EvfsOptions()) {
    if (option.set == nullptr || !option.range.Bounded()) continue;
    SCOPED_TRACE("--" + option.name);
    const RangeProbes probes = ProbesOf(option);
    for (const auto& [number, value] : probes.inside) {
      EvfsSettings settings;
      option.set(value, "--" + option.name, &settings);
      EXPECT_EQ(LibraryRefusal(settings), "") << number << " is inside the table's range";
    }
    int library_refused = 0;
    int outside = 0;
    for (const auto& [number, value] : probes.outside) {
      EvfsSettings settings;
      option.set(value, "--" + option.name, &settings);
      ++outside;
      if (!LibraryRefusal(settings).empty()) {
        ++library_refused;
      } else {
        EXPECT_TRUE(table_only.count(option.name)) << number << " is outside the table's range";
      }
    }
    // The list stays true: an option it names passes some value the table refuses.
    if (table_only.count(option.name)) {
      EXPECT_LT(library_refused, outside) << "checked twice";
    }
  }
}

// The field names of `struct name` in `header`: the last word before '=', ';' or '{' of each
// declaration at the struct's own level (functions and types left out).
std::vector<std::string> StructFields(const std::string& header, const std::string& name) {
  const std::string text = ReadSource(header);
  const size_t start = text.find("\nstruct " + name + " {");
  EXPECT_NE(start, std::string::npos) << name << " in " << header;
  if (start == std::string::npos) return {};
  std::vector<std::string> fields;
  std::string statement;
  int depth = 0;
  std::istringstream lines(text.substr(text.find('{', start) + 1));
  for (std::string line; std::getline(lines, line);) {
    const size_t comment = line.find("//");
    if (comment != std::string::npos) line.resize(comment);
    for (const char c : line) {
      if (c == '{') ++depth;
      if (c == '}') --depth;
      if (depth < 0) return fields;  // the struct's end
      if (depth == 0 && c == ';') {
        const size_t paren = statement.find('(');
        const size_t end = statement.find_first_of("={");
        const bool is_field = (paren == std::string::npos || paren > end) &&
                              statement.find("using ") == std::string::npos &&
                              statement.find("static ") == std::string::npos &&
                              statement.find("enum ") == std::string::npos &&
                              statement.find("struct ") == std::string::npos;
        if (is_field) {
          std::string declaration = statement.substr(0, std::min(end, statement.size()));
          while (!declaration.empty() && !std::isalnum(declaration.back()) &&
                 declaration.back() != '_') {
            declaration.pop_back();
          }
          size_t word = declaration.size();
          while (word > 0 &&
                 (std::isalnum(declaration[word - 1]) || declaration[word - 1] == '_')) {
            --word;
          }
          fields.push_back(declaration.substr(word));
        }
        statement.clear();
      } else {
        statement += c;
      }
    }
    statement += ' ';
  }
  return fields;
}

// Every field of the requests the options fill is set by an option, or is listed here with why
// it is not. A field added to one of these structs fails here until it has a row or a reason.
TEST(EvfsOptionsTest, EveryRequestFieldIsAnOptionOrSaysWhyNot) {
  struct Struct {
    const char* header;
    const char* name;
    const char* path;  // its place in EvfsSettings
  };
  const Struct structs[] = {
      {"app/reconstruct_job.h", "ReconstructRequest", "reconstruct"},
      {"scene/scene.h", "BinningOptions", "reconstruct.binning"},
      {"solver/reconstruction_options.h", "ObjectiveOptions",
       "reconstruct.method.reconstruction.objective"},
      {"app/video_job.h", "VideoRequest", "video"},
      {"app/video_windows.h", "VideoWindowOptions", "video.windows"},
      {"events/simulator.h", "SimulatorOptions", "simulator"},
      {"events/flicker.h", "FlickerOptions", "flicker"},
      {"events/frame_effects.h", "FrameEffectsOptions", "frame_effects"},
  };
  const std::set<std::string> not_options = {
      // Set by the caller, not by a flag.
      "reconstruct.data_label",
      "reconstruct.progress",
      "reconstruct.stage",
      "reconstruct.options",  // the table's own echo of the options (OptionsReadBy)
      "video.data_label",
      "video.settings",
      "video.notice",
      "video.progress",
      "video.distribution",
      "reconstruct.frame_lag",    // --frame_time=auto's estimator keeps its own defaults
      "reconstruct.frame_lag_s",  // set with frame_time by --frame_time=MS
      // Copied from the reconstruct options by VideoRequestFromOptions.
      "video.data_path",
      "video.data_options",
      "video.fps",
      "video.threads_per_window",
      "video.binning",
      "video.method",
      "video.log_offset_search",
      "video.denoise",
      "video.windows.first",
      "video.windows.last",
      "video.windows.exposure_s",
      // Chosen by evfs video from the recording and --frame_step, not by the user.
      "video.windows.excluded_frames",
      "video.windows.sharp_frames",
      // Set by the calibration file of --event_model=FILE.json, or derived from the data.
      "reconstruct.method.reconstruction.objective.event_model",
      // simulate: the LED's place and the lamp's region, parsed from --flicker_led_xy_px and
      // --mains_region_px by the command.
      "flicker.led_x_px",
      "flicker.led_y_px",
      "flicker.mains_x_px",
      "flicker.mains_y_px",
      "flicker.mains_width_px",
      "flicker.mains_height_px",
      // Plug & play's prior, set by its ADMM iterations (--denoise=pnp).
      "reconstruct.method.reconstruction.objective.prior_weight",
      "reconstruct.method.reconstruction.objective.prior_target",
      // The simulator's memory bound, a limit of the library rather than a setting.
      "simulator.max_events",
      // simulate: --exposure_s and --seed, shared with the other commands' options.
      "frame_effects.exposure_s",
      "frame_effects.seed",
  };
  std::set<std::string> fields;
  for (const OptionDefinition& option : EvfsOptions()) fields.insert(option.field);
  const auto covered = [&](const std::string& path) {
    if (fields.count(path) || not_options.count(path)) return true;
    // A struct of its own (reconstruct.method): covered when an option sets a field inside it.
    const auto inside = fields.lower_bound(path + ".");
    return inside != fields.end() && inside->compare(0, path.size() + 1, path + ".") == 0;
  };
  for (const Struct& s : structs) {
    const std::vector<std::string> names = StructFields(s.header, s.name);
    EXPECT_GT(names.size(), 1u) << s.name;
    for (const std::string& name : names) {
      const std::string path = std::string(s.path) + "." + name;
      EXPECT_TRUE(covered(path)) << s.name << "::" << name << " (" << path
                                 << "): no option sets it (app/evfs_options.cc)";
    }
  }
}

// A flag is a row of the table: evfs defines none of its own with gflags' macros, which would
// bypass Python, the fingerprint and the builders.
TEST(EvfsOptionsTest, NoFlagIsDefinedOutsideTheTable) {
  for (const char* path : {"examples/evfs_main.cc", "app/evfs_options.cc", "app/evfs_help.cc",
                           "app/command_line_help.cc", "python/evfs_module.cc"}) {
    const std::string text = ReadSource(path);
    for (const char* macro : {"DEFINE_bool(", "DEFINE_int32(", "DEFINE_int64(", "DEFINE_uint64(",
                              "DEFINE_double(", "DEFINE_string("}) {
      EXPECT_EQ(text.find(macro), std::string::npos) << path << " defines a flag with " << macro;
    }
  }
}

}  // namespace
}  // namespace evfs
