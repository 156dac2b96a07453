// The options of `evfs`, each declared once (COLMAP's OptionManager binds each option to its
// member the same way): name, help group, the commands that read it, default, the values it
// accepts, help text, the Python key it is and the field of the requests it sets. From this one
// table come
//
//   * the command-line flags (RegisterEvfsFlags: gflags parses them, their help is the row's),
//   * the flag rows of `evfs --help` (EvfsFlagHelp, app/evfs_help.h),
//   * the keys and defaults of Python's options (python/reconstruct_options.h),
//   * the requests of reconstruct, video and simulate (the builders below, which the command
//     line and Python share), and
//   * the settings `evfs video --resume` compares, echoed in its summary.json (VideoFingerprint),
//     and the options `evfs reconstruct` echoes in its summary.json (OptionsReadBy).
//
// A new option is one row in evfs_options.cc; tests/app/evfs_options_test.cc fails for a flag
// defined elsewhere in evfs or a request field the table does not set.
#ifndef EVFS_APP_EVFS_OPTIONS_H_
#define EVFS_APP_EVFS_OPTIONS_H_

#include <cstdint>
#include <functional>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "evfs/app/command_line_help.h"
#include "evfs/app/reconstruct_job.h"
#include "evfs/app/video_job.h"
#include "evfs/core/value_range.h"
#include "evfs/events/flicker.h"
#include "evfs/events/frame_effects.h"
#include "evfs/events/simulator.h"

namespace evfs {

/// The value of an option. The alternative is the option's type, that of its gflags flag
/// (int32_t: int32, int64_t: int64, uint64_t: uint64).
using OptionValue = std::variant<bool, int32_t, int64_t, uint64_t, double, std::string>;

/// What the options set: the requests of the commands, and the few texts a request is made of
/// only once every option is known (--denoise=auto needs --denoiser).
struct EvfsSettings {
  ReconstructRequest reconstruct;  // reconstruct, and video's method, binning and denoiser
  std::string denoise = "auto";    // auto | none | once | pnp, resolved by the builders
  std::string event_model_file;    // --event_model=FILE.json; "" for a model name
  VideoRequest video;              // video's own: windows, jobs, resume, preview, report
  SimulatorOptions simulator;
  FlickerOptions flicker;
  FrameEffectsOptions frame_effects;
};

/// Where an option goes beyond the command line (OptionDefinition::uses, bits).
enum OptionUse : unsigned {
  kReconstructKey = 1u << 0,    // a key of evfs.reconstruct's options (reconstruct_defaults())
  kSimulateKey = 1u << 1,       // a key of evfs.simulate's options (simulate_defaults())
  kNotInFingerprint = 1u << 2,  // says only where, how fast or how verbosely video runs
  kNumberList = 1u << 3,        // a string of comma-separated numbers; a list in Python
};

/// Sets the bound field of `settings` from `value`; `flag` names the option in messages
/// ("--binning"). Throws InvalidArgumentError for a value the option does not accept.
using OptionSetter =
    std::function<void(const OptionValue& value, const std::string& flag, EvfsSettings* settings)>;

/// One option, declared once.
struct OptionDefinition {
  std::string name;      // the flag without dashes: "max_latent_frames"
  std::string group;     // the help group: one of EvfsOptionGroups()
  std::string commands;  // the commands that read it, separated by spaces; "*" for all
  unsigned uses = 0;     // OptionUse bits
  OptionValue default_value;
  /// The values a numeric option accepts (a value outside never enters OptionValues); Any()
  /// for a text or a switch.
  ValueRange range = ValueRange::Any();
  std::string help;  // the flag's help text, ending with the range of a bounded option
  /// The field of EvfsSettings it sets ("reconstruct.binning.max_latent_frames"); "" for an
  /// option a command reads itself (--out, --progress).
  std::string field;
  OptionSetter set;  // empty when `field` is ""

  bool ReadBy(const std::string& command) const;
};

/// Every option of `evfs`, in the order of the help within each group.
const std::vector<OptionDefinition>& EvfsOptions();

/// The help groups, in the order `evfs --help` shows them.
const std::vector<std::string>& EvfsOptionGroups();

/// The option named `name`, or nullptr.
const OptionDefinition* FindEvfsOption(const std::string& name);

/// The default of option `name`, of its type T (int32_t, double, ...): the Python functions'
/// arguments that are flags of the command line take it as theirs.
template <typename T>
T OptionDefault(const std::string& name) {
  return std::get<T>(FindEvfsOption(name)->default_value);
}

/// The help rows of the options (app/command_line_help.h), in table order.
std::vector<FlagHelp> EvfsFlagHelp();

/// An option's value as text, as gflags shows it ("%.17g" for a double, true/false).
std::string OptionValueText(const OptionValue& value);

/// The value of every option: its default, or what the command line or Python gave.
class OptionValues {
 public:
  /// Every option at its default.
  OptionValues();

  /// Gives option `name` (which must be registered, and `value` of its type). Throws
  /// InvalidArgumentError for a value outside the option's range.
  void Set(const std::string& name, OptionValue value);
  /// Whether `name` was given rather than left at its default.
  bool Given(const std::string& name) const { return given_.count(name) > 0; }

  const OptionValue& Get(const std::string& name) const;
  bool Bool(const std::string& name) const { return std::get<bool>(Get(name)); }
  int Int(const std::string& name) const { return std::get<int32_t>(Get(name)); }
  double Double(const std::string& name) const { return std::get<double>(Get(name)); }
  const std::string& String(const std::string& name) const {
    return std::get<std::string>(Get(name));
  }

  /// Sets the bound field of every option whose field starts with `prefix` (in table order),
  /// skipping those named in `skip`.
  void Apply(const std::string& prefix, EvfsSettings* settings,
             const std::set<std::string>& skip = {}) const;

 private:
  std::map<std::string, OptionValue> values_;
  std::set<std::string> given_;
};

/// The binning options (reconstruct, video, and info's window).
BinningOptions BinningFromOptions(const OptionValues& values);

/// The request of reconstruct's options; `with_mode` false for video, which has no --mode.
/// The denoiser's mode and the calibrated event model are resolved as the command line does.
ReconstructRequest ReconstructRequestFromOptions(const OptionValues& values, bool with_mode);

/// The request of video's options (evfs video and evfs.video), settings included; no callback
/// is set.
VideoRequest VideoRequestFromOptions(const OptionValues& values);

/// Every option `command` reads (OptionDefinition::ReadBy) but those that say only where, how
/// fast or how verbosely it runs (kNotInFingerprint), by name, with its value as text.
std::vector<std::pair<std::string, std::string>> OptionsReadBy(const OptionValues& values,
                                                               const std::string& command);

/// "name=value " for every option not kNotInFingerprint, by name, then the bytes of a
/// calibration file given as --event_model: what `evfs video --resume` compares.
std::string VideoFingerprint(const OptionValues& values);

/// The simulator's, light sources' (but the LED's place and the lamp's region, parsed by the
/// command) and frames' options of `evfs simulate`.
SimulatorOptions SimulatorFromOptions(const OptionValues& values);
FlickerOptions FlickerFromOptions(const OptionValues& values);
FrameEffectsOptions FrameEffectsFromOptions(const OptionValues& values);

/// "0.2,0.1" → {0.2, 0.1}; "" → {}. Throws InvalidArgumentError naming `flag` for a non-number.
std::vector<double> ParseNumberList(const std::string& list, const std::string& flag);

/// Registers every option as a gflags flag defined in `filename` (the program's source, so
/// that gflags and the help see them as the program's own). Call once, before parsing.
void RegisterEvfsFlags(const char* filename);

/// The options' values after gflags parsed the command line (given: not at gflags' default).
OptionValues OptionValuesFromFlags();

}  // namespace evfs

#endif  // EVFS_APP_EVFS_OPTIONS_H_
