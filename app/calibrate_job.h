// `evfs calibrate`: the event model of a recording measured from its own frames and events
// (solver/event_model_calibration.h), written as a JSON file that `--event_model=FILE.json`
// reads back into the reconstruction's event model (docs/model.md, "Calibrating the event
// model").
#ifndef EVFS_APP_CALIBRATE_JOB_H_
#define EVFS_APP_CALIBRATE_JOB_H_

#include <cstdio>
#include <string>

#include "evfs/io/data_source.h"
#include "evfs/scene/event_model.h"
#include "evfs/scene/event_model_estimation.h"
#include "evfs/scene/frame_timing.h"
#include "evfs/solver/event_model_calibration.h"

namespace evfs {

struct CalibrateRequest {
  std::string data_path;
  int first = -1;  // first frame (images.txt line); -1: the first
  int last = -1;   // last frame; -1: the last
  /// At most this many frames from `first` are read and fitted, >= 2; 0: all of first..last.
  int max_frames = 0;
  /// Also estimate the frame lag with the calibrated b (a second pass over the frames).
  bool estimate_frame_lag = true;
  EventModelCalibrationOptions options;
};

struct CalibrateResult {
  EventModelCalibration calibration;
  /// The frame lag (scene/frame_timing.h), estimated with the calibrated b: reported, not
  /// part of the fit.
  FrameLagEstimate frame_lag;
  int first = 0;
  int last = 0;         // the last frame fitted (before request.last when max_frames cut it)
  double time_s = 0.0;  // reading and fitting, seconds
};

/// Reads frames first..last and their events and calibrates. Throws InputError (or
/// InvalidArgumentError) with one line when the recording cannot tell: fewer than two frames,
/// no events, frames outside the recording, nothing that changes.
CalibrateResult RunCalibration(const CalibrateRequest& request);

/// The same on a recording already open (request.data_path only names it in errors).
CalibrateResult RunCalibration(const DataSource& source, const CalibrateRequest& request);

/// `evfs info`'s section on the event model: b, C_on, C_off, their spread and the background
/// rate, each with its standard error, calibrated on frames first..last but no more than the
/// first kInfoCalibrationFrames of them (the section says which) and kInfoCalibrationPixels
/// pixels, without the frame lag; or
/// one line saying why the recording cannot tell. `first`/`last` as in CalibrateRequest.
void PrintInfoCalibration(const DataSource& source, const std::string& data_path, int first,
                          int last, std::FILE* out);

/// Frames `evfs info` calibrates on at most: few enough that the section costs about one
/// small calibration (well under a second at 240x180) whatever the recording's length.
constexpr int kInfoCalibrationFrames = 3;
/// Pixels `evfs info` fits at most (EventModelCalibrationOptions::max_fit_pixels), so that a
/// large sensor costs it no more than a 240x180 one.
constexpr int kInfoCalibrationPixels = 20000;

/// A fingerprint of a calibration file's bytes (FNV-1a, hexadecimal), for `video --resume` to
/// notice a file changed in place; "unreadable" when it cannot be read.
std::string EventModelFileFingerprint(const std::string& path);

/// Prints what was found: each value with its standard error and counts, the frame lag, and
/// the event model it gives.
void PrintCalibration(const CalibrateRequest& request, const CalibrateResult& result,
                      const std::string& out_path, std::FILE* out);

/// Writes `result` as the JSON file `path`.
void WriteCalibration(const CalibrateRequest& request, const CalibrateResult& result,
                      const std::string& path);

/// True when a --event_model value names a calibration file (it ends in .json) rather than a
/// model (log, linear).
bool IsEventModelFile(const std::string& value);

/// The event model a calibration file gives: the log model with its b; α so that one ON event
/// stands for C_on (α = estimation.alpha_times_change / C_on, as EstimateEventModel derives it
/// from a measured change); darkening steps α · C_on / C_off (off_alpha_ratio); and c =
/// estimation.measured_saturation, as for a change measured between frames. Throws InputError
/// for a missing or malformed file.
EventModelParams ReadEventModelFile(const std::string& path,
                                    const EventModelEstimationOptions& estimation);

/// Sets `model` from the calibration file `path` (ReadEventModelFile), as --event_model=FILE.json
/// does: the log model always; b, α with its OFF ratio, and the saturation each unless the
/// caller was given it explicitly (`keep_log_offset`, `keep_alpha`, `keep_saturation`).
void ApplyEventModelFile(const std::string& path, const EventModelEstimationOptions& estimation,
                         bool keep_log_offset, bool keep_alpha, bool keep_saturation,
                         EventModelParams* model);

}  // namespace evfs

#endif  // EVFS_APP_CALIBRATE_JOB_H_
