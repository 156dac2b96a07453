#include "evfs/app/evfs_help.h"

#include "evfs/app/evfs_options.h"
#include "evfs/core/version.h"

namespace evfs {
namespace {

ProgramHelp MakeEvfsHelp() {
  ProgramHelp help;
  help.program = "evfs";
  help.summary = "event-driven video frame synthesis.";
  help.version = kVersion;
  help.commands = {
      {"info", "--data=DIR [--first=I --last=J]",
       "Describe a recording: size, events, frames and exposures; with --first, the window "
       "between two frames and the binning a reconstruction would get; and the event model "
       "evfs calibrate finds on the first frames of the selection."},
      {"reconstruct",
       "--data=DIR --mode=interpolate|predict|deblur --first=I [--last=J] [--truth=K] --out=OUT "
       "[--fps=N] [--report] [method, binning, model and solver flags]",
       "Synthesise the latent frames between frames I and J from the frames and the events "
       "(paper §3), into OUT with their timestamps and a summary."},
      {"video",
       "--data=DIR --out=OUT [--fps=N] [--first=I --last=J] [--jobs=N] [--resume] [--preview] "
       "[--report] "
       "[method, binning, model and solver flags]",
       "Reconstruct a whole recording, window by window and in parallel, into one video at a "
       "uniform rate: OUT/frames, timestamps.txt, summary.json and video.mp4."},
      {"denoise", "--in=RECONSTRUCTION_DIR --out=DIR [--denoiser=FILE.onnx]",
       "Apply the residual denoiser (paper §3.4) to every frame of an earlier reconstruction."},
      {"simulate",
       "--frames=DIR --out=DIR [--threshold_pos=0.2 --threshold_neg=0.2 --seed=42] [sensor "
       "effects, light sources and frame effects]",
       "Simulate the events of a sequence of frames, written as a data folder; optionally with "
       "leak, hot pixels, a photoreceptor bandwidth, a blinking LED, a mains lamp and the "
       "frames' exposure, saturation and noise (all off by default)."},
      {"convert", "--data=DIR|FILE.h5|FILE.aedat4|FILE.bag --out=FILE.h5|FILE.aedat4|DIR",
       "Convert a recording between a data folder, HDF5 and AEDAT 4 (or from AEDAT 2.0/3.1 or a "
       "ROS bag)."},
      {"calibrate", "--data=DIR [--first=I --last=J] --out=MODEL.json",
       "Measure the event model of a recording from its own frames and events (the offset b, "
       "the ON and OFF thresholds, their spread, the background event rate), each with its "
       "standard error, into MODEL.json for --event_model=MODEL.json."},
      {"demo", "--out=DIR",
       "Run a synthetic scene through the whole pipeline and score every mode against its "
       "ground truth."},
  };
  help.notes =
      "DIR is a folder in the Event Camera Dataset layout (events.txt 't x y p', images.txt\n"
      "'t path', images/, optional exposures.txt 'path t_start t_end'), an .h5 file or an\n"
      ".aedat4 recording (iniVation DV: events and frames), an AEDAT 2.0/3.1 file (jAER,\n"
      "cAER, v2e: DAVIS events and APS frames; read only), or a ROS 1 .bag (dvs_msgs/EventArray\n"
      "and sensor_msgs/Image topics, chosen by --events_topic/--frames_topic; read only).\n"
      "I, J, K are 0-based lines of images.txt. Example:\n"
      "  evfs reconstruct --data=../shared/data/slider_depth_70_71 --mode=predict --first=0 "
      "--last=1 \\\n      --truth=1 --out=out/slider\n";
  help.groups = EvfsOptionGroups();
  help.flags = EvfsFlagHelp();
  return help;
}

}  // namespace

const ProgramHelp& EvfsHelp() {
  static const ProgramHelp* const help = new ProgramHelp(MakeEvfsHelp());
  return *help;
}

}  // namespace evfs
