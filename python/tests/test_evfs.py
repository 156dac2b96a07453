"""Tests of the Python module `evfs` (python/evfs_module.cc), run by ctest (python_pytest).

The module is found through PYTHONPATH (build/python), the evfs command through EVFS_BINARY and
the shared DAVIS snippets through EVFS_DATA_DIR; tests that need the snippets skip without them.
Every comparison with the command line runs the command on the same input and compares its
files with what the module returns.
"""
import glob
import json
import os
import re
import signal
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import evfs

SOURCE_DIR = os.environ.get(
    "EVFS_SOURCE_DIR", os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..")))
EVFS_BINARY = os.environ.get("EVFS_BINARY", os.path.join(SOURCE_DIR, "build", "examples", "evfs"))
DATA_DIR = os.environ.get("EVFS_DATA_DIR", "")

# evfs writes frames as 16-bit PNG: round(clamp(v, 0, 1) * 65535) (io/image_io.cc).
PNG_MAX = 65535.0


def shared_data(name):
    path = os.path.join(DATA_DIR, name)
    if not DATA_DIR or not os.path.exists(path):
        pytest.skip(f"shared data {name} not found (EVFS_DATA_DIR={DATA_DIR!r})")
    return path


def run_cli(*args):
    """Runs the evfs command; returns (exit status, stdout, stderr)."""
    if not os.path.isfile(EVFS_BINARY):
        pytest.skip(f"the evfs command is not built ({EVFS_BINARY})")
    done = subprocess.run([EVFS_BINARY, *args], capture_output=True, text=True, timeout=600)
    return done.returncode, done.stdout, done.stderr


def cli_error(command, *args):
    """The one-line message of a failing command, without its "evfs COMMAND: " prefix."""
    status, _, stderr = run_cli(command, *args)
    assert status == 2, stderr
    line = stderr.strip().splitlines()[-1]
    prefix = f"evfs {command}: "
    assert line.startswith(prefix), line
    return line[len(prefix):]


def quantize_like_png(frames):
    """The 16-bit values evfs writes for `frames` (std::lround of clamped v · 65535)."""
    scaled = np.clip(frames, 0.0, 1.0) * PNG_MAX
    whole = np.floor(scaled)
    # scaled - whole is exact, so this is round-half-away-from-zero without a rounding error.
    return (whole + (scaled - whole >= 0.5)).astype(np.uint16)


def read_cli_reconstruction(folder, images_folder="frames"):
    """Frames (as the 16-bit values written) and times of an `evfs reconstruct` output; with
    images_folder="confidence", its confidence maps instead of its frames."""
    names = sorted(glob.glob(os.path.join(folder, images_folder, "*.png")))
    # The frames are read back through evfs.read, as a data folder whose images.txt lists them.
    with open(os.path.join(folder, "images.txt"), "w") as images:
        for i, name in enumerate(names):
            images.write(f"{i} {images_folder}/{os.path.basename(name)}\n")
    recording = evfs.read(folder)
    # Not left in the output: a later --overwrite would find a file evfs did not write.
    os.remove(os.path.join(folder, "images.txt"))
    frames = np.rint(recording["frames"] * PNG_MAX).astype(np.uint16)
    times = []
    with open(os.path.join(folder, "timestamps.txt")) as lines:
        for line in lines:
            times.append(float(line.split()[1]))
    return frames, np.array(times)


@pytest.fixture(scope="session")
def demo(tmp_path_factory):
    """`evfs demo`'s synthetic recordings: data (sharp frames) and data_blur (with exposures)."""
    out = tmp_path_factory.mktemp("demo") / "demo"
    status, _, stderr = run_cli("demo", f"--out={out}")
    assert status == 0, stderr
    return out


def assert_same_recording(a, b, time_tolerance_s=0.0):
    assert (a["width"], a["height"]) == (b["width"], b["height"])
    np.testing.assert_array_equal(a["frames"], b["frames"])
    np.testing.assert_array_equal(a["frame_times"], b["frame_times"])
    for key in ("x", "y", "p"):
        np.testing.assert_array_equal(a["events"][key], b["events"][key])
    np.testing.assert_allclose(a["events"]["t"], b["events"]["t"], rtol=0, atol=time_tolerance_s)


# ---------------------------------------------------------------------------------------------
# read


def test_read_text_folder(demo):
    recording = evfs.read(str(demo / "data"))
    frames, times, events = recording["frames"], recording["frame_times"], recording["events"]
    assert frames.dtype == np.float64 and frames.ndim == 3 and frames.shape[0] == 5
    assert frames.shape[1:] == (recording["height"], recording["width"])
    assert frames.min() >= 0.0 and frames.max() <= 1.0
    np.testing.assert_array_equal(times, [0.0, 0.01, 0.02, 0.03, 0.04])
    assert np.isnan(recording["exposures"]).all()
    assert recording["frame_paths"][0] == "images/frame_00000000.png"
    assert events["t"].dtype == np.float64 and events["x"].dtype == np.uint16
    assert events["y"].dtype == np.uint16 and events["p"].dtype == np.int8
    # Against the text itself (events.txt: "t x y p", p 0/1).
    text = np.loadtxt(demo / "data" / "events.txt")
    np.testing.assert_array_equal(events["t"], text[:, 0])
    np.testing.assert_array_equal(events["x"], text[:, 1])
    np.testing.assert_array_equal(events["y"], text[:, 2])
    np.testing.assert_array_equal(events["p"], np.where(text[:, 3] > 0, 1, -1))


def test_read_exposures(demo):
    recording = evfs.read(str(demo / "data_blur"))
    lines = [line.split() for line in open(demo / "data_blur" / "exposures.txt")
             if not line.startswith("#")]
    assert len(lines) == recording["frames"].shape[0]
    for row, (_, begin, end) in zip(recording["exposures"], lines):
        np.testing.assert_array_equal(row, [float(begin), float(end)])


def test_read_hdf5_matches_text(demo, tmp_path):
    h5 = tmp_path / "demo.h5"
    status, _, stderr = run_cli("convert", f"--data={demo / 'data'}", f"--out={h5}")
    assert status == 0, stderr
    assert_same_recording(evfs.read(str(h5)), evfs.read(str(demo / "data")))


def test_read_shared_text_folder():
    path = shared_data("slider_depth_70_71")
    recording = evfs.read(path)
    assert recording["frames"].shape == (2, 180, 240)
    with open(os.path.join(path, "events.txt")) as lines:
        first = lines.readline().split()
        count = 1 + sum(1 for _ in lines)
    events = recording["events"]
    assert events["t"].shape == (count,)
    assert events["t"][0] == float(first[0])
    assert (events["x"][0], events["y"][0]) == (int(first[1]), int(first[2]))


def test_read_shared_aedat4_against_independent_decoding():
    path = os.path.join(shared_data("aedat4_dvxplorer_sample"), "sample.aedat4")
    decoder = os.path.join(SOURCE_DIR, "tests", "io", "aedat4_reference_decode.py")
    done = subprocess.run([sys.executable, decoder, path], capture_output=True, text=True)
    if done.returncode == 3:
        pytest.skip("the independent AEDAT 4 decoder needs python3-lz4 and python3-flatbuffers")
    assert done.returncode == 0, done.stderr
    reference = dict(line.split(" ", 1) for line in done.stdout.splitlines())
    recording = evfs.read(path)
    events = recording["events"]
    assert f"{recording['width']} {recording['height']}" == reference["sensor"].strip()
    assert events["t"].shape[0] == int(reference["events"])
    assert int((events["p"] > 0).sum()) == int(reference["positive"])
    # float64 seconds keep these microsecond clocks (~1.6e9 s) to well under 0.5 us.
    t_us = np.rint(events["t"] * 1e6).astype(np.int64)
    for key, i in (("first", 0), ("last", -1)):
        described = f"{t_us[i]} {events['x'][i]} {events['y'][i]} {1 if events['p'][i] > 0 else 0}"
        assert described == reference[key].strip()
    assert recording["frames"].shape[0] == 0


def test_read_ros_bag_as_the_folder(tmp_path):
    folder = shared_data("slider_depth_70_71")
    writer = os.path.join(SOURCE_DIR, "tests", "io", "write_rosbag.py")
    if subprocess.run(["/usr/bin/python3", "-c", "import rosbag"]).returncode != 0:
        pytest.skip("python3-rosbag is not installed: tests/io/write_rosbag.py cannot write bags")
    bag = str(tmp_path / "recording.bag")
    subprocess.run(["/usr/bin/python3", writer, folder, bag, "--compression", "lz4",
                    "--second_events_topic", "/dvs2/events"], check=True)
    expected = evfs.read(folder)
    recording = evfs.read(bag)
    np.testing.assert_array_equal(recording["frames"], expected["frames"])
    # The header stamps, not the bag's receive times (the writer makes them 10 ms later).
    np.testing.assert_array_equal(recording["frame_times"], expected["frame_times"])
    assert np.isnan(recording["exposures"]).all()
    for key in ("t", "x", "y", "p"):
        np.testing.assert_array_equal(recording["events"][key], expected["events"][key])
    flipped = evfs.read(bag, events_topic="/dvs2/events")
    np.testing.assert_array_equal(flipped["events"]["p"], -expected["events"]["p"])
    with pytest.raises(ValueError, match="no such topic"):
        evfs.read(bag, frames_topic="/nope")


@pytest.mark.parametrize("name", ["fuzz_aedat4_misaligned_events.aedat4",
                                  "fuzz_image_extent_wraps_int.h5"])
def test_read_malformed_file_raises_the_cli_message(name):
    path = os.path.join(SOURCE_DIR, "tests", "io", "data", name)
    expected = cli_error("info", f"--data={path}")
    with pytest.raises(ValueError) as raised:
        evfs.read(path)
    assert str(raised.value) == expected


@pytest.mark.parametrize("argument", ["first", "last", "truth"])
def test_reconstruct_index_beyond_32_bits_is_a_value_error(argument):
    # pybind11's own conversion would raise TypeError; a bad value is a ValueError naming it.
    frames = np.zeros((2, 4, 4))
    events = {"t": np.zeros(0), "x": np.zeros(0, np.uint16), "y": np.zeros(0, np.uint16),
              "p": np.zeros(0, np.int8)}
    with pytest.raises(ValueError, match=f"{argument}={2**62} is out of range"):
        evfs.reconstruct(frames, np.array([0.0, 1.0]), events, **{argument: 2**62})


def test_video_index_beyond_32_bits_is_a_value_error(tmp_path):
    with pytest.raises(ValueError, match=f"first={2**62} is out of range"):
        evfs.video(str(tmp_path / "no_data"), str(tmp_path / "out"), first=2**62)
    assert not (tmp_path / "out").exists()


def test_read_missing_path_raises_the_cli_message(tmp_path):
    path = str(tmp_path / "no_such_recording")
    expected = cli_error("info", f"--data={path}")
    with pytest.raises(ValueError, match=re.escape(expected)):
        evfs.read(path)


# ---------------------------------------------------------------------------------------------
# reconstruct: identical to the command line


def reconstruct_both(data, tmp_path, mode, first, last, cli_flags=(), options=None):
    out = tmp_path / f"cli_{mode}"
    status, _, stderr = run_cli("reconstruct", f"--data={data}", f"--mode={mode}",
                                f"--first={first}", f"--last={last}", f"--out={out}", *cli_flags)
    assert status == 0, stderr
    cli_frames, cli_times = read_cli_reconstruction(str(out))
    recording = evfs.read(str(data))
    exposures = recording["exposures"] if mode == "deblur" else None
    result = evfs.reconstruct(recording["frames"], recording["frame_times"], recording["events"],
                              mode=mode, first=first, last=last, exposures=exposures,
                              options=options, dtype="float64")
    return cli_frames, cli_times, result


@pytest.mark.parametrize("mode,first,last", [("predict", 0, 1), ("interpolate", 1, 3)])
def test_reconstruct_identical_to_cli(demo, tmp_path, mode, first, last):
    cli_frames, cli_times, result = reconstruct_both(demo / "data", tmp_path, mode, first, last)
    assert result["frames"].dtype == np.float64
    np.testing.assert_array_equal(result["times"], cli_times)
    np.testing.assert_array_equal(quantize_like_png(result["frames"]), cli_frames)
    assert result["summary"]["mode"] == mode
    assert result["summary"]["latent_frames"] == cli_frames.shape[0]
    cli_confidence, _ = read_cli_reconstruction(str(tmp_path / f"cli_{mode}"), "confidence")
    assert result["confidence"].shape == result["frames"].shape
    np.testing.assert_array_equal(quantize_like_png(result["confidence"]), cli_confidence)


def test_reconstruct_deblur_with_options_identical_to_cli(demo, tmp_path):
    cli_frames, cli_times, result = reconstruct_both(
        demo / "data_blur", tmp_path, "deblur", 0, -1,
        cli_flags=("--event_weight=0.4", "--spatial_tv=isotropic", "--denoise=none",
                   "--max_iterations=8"),
        options={"event_weight": 0.4, "spatial_tv": "isotropic", "denoise": "none",
                 "max_iterations": 8})
    assert result["summary"]["model"]["event_weight"] == 0.4
    assert result["summary"]["model"]["spatial_tv"] == "isotropic"
    assert result["summary"]["iterations"] <= 8
    np.testing.assert_array_equal(result["times"], cli_times)
    np.testing.assert_array_equal(quantize_like_png(result["frames"]), cli_frames)


def test_reconstruct_shared_data_identical_to_cli(tmp_path):
    data = shared_data("slider_depth_70_71")
    cli_frames, cli_times, result = reconstruct_both(data, tmp_path, "predict", 0, 1)
    np.testing.assert_array_equal(result["times"], cli_times)
    np.testing.assert_array_equal(quantize_like_png(result["frames"]), cli_frames)


def test_reconstruct_reads_a_calibration_file_as_the_cli(demo, tmp_path):
    """options={"event_model": "MODEL.json"} is --event_model=MODEL.json: the same frames, the
    model the file gives (alpha = 1/C_on, OFF ratio C_on/C_off), options beside it winning."""
    model = tmp_path / "model.json"
    status, _, stderr = run_cli("calibrate", f"--data={demo / 'data'}", f"--out={model}")
    assert status == 0, stderr
    with open(model) as file:
        calibration = json.load(file)
    on = calibration["threshold_on"]["value"]
    off = calibration["threshold_off"]["value"]
    cli_frames, cli_times, result = reconstruct_both(
        demo / "data", tmp_path, "interpolate", 1, 3, cli_flags=(f"--event_model={model}",),
        options={"event_model": str(model)})
    np.testing.assert_array_equal(result["times"], cli_times)
    np.testing.assert_array_equal(quantize_like_png(result["frames"]), cli_frames)
    summary = result["summary"]["model"]
    assert summary["event_model"] == "log"
    assert summary["alpha"] == pytest.approx(1.0 / on, rel=1e-9)
    assert summary["off_alpha_ratio"] == pytest.approx(on / off, rel=1e-9)

    # b given beside the file wins, as --log_offset does on the command line.
    (tmp_path / "given").mkdir()
    cli_frames, cli_times, given = reconstruct_both(
        demo / "data", tmp_path / "given", "interpolate", 1, 3,
        cli_flags=(f"--event_model={model}", "--log_offset=0.5"),
        options={"event_model": str(model), "log_offset": 0.5})
    np.testing.assert_array_equal(quantize_like_png(given["frames"]), cli_frames)
    assert given["summary"]["model"]["alpha"] == pytest.approx(1.0 / on, rel=1e-9)
    assert not np.array_equal(given["frames"], result["frames"])

    recording = evfs.read(str(demo / "data"))

    missing = str(tmp_path / "none.json")
    with pytest.raises(ValueError, match="none.json"):
        evfs.reconstruct(recording["frames"], recording["frame_times"], recording["events"],
                         mode="interpolate", first=1, last=3, options={"event_model": missing})
    with pytest.raises(ValueError, match="--event_model"):
        evfs.reconstruct(recording["frames"], recording["frame_times"], recording["events"],
                         mode="interpolate", first=1, last=3, options={"event_model": "cubic"})


def test_reconstruct_float32_is_the_float64_result_rounded(demo):
    recording = evfs.read(str(demo / "data"))
    args = (recording["frames"], recording["frame_times"], recording["events"])
    options = {"denoise": "none", "threads": 1}
    wide = evfs.reconstruct(*args, options=options, dtype="float64")
    narrow = evfs.reconstruct(*args, options=options)
    assert narrow["frames"].dtype == np.float32
    np.testing.assert_array_equal(narrow["frames"], wide["frames"].astype(np.float32))
    # float32 input frames give the same result when they hold the same values (these are
    # 16-bit PNG values, but float32 rounds most of them: compare against the rounded input).
    rounded = recording["frames"].astype(np.float32)
    from_float32 = evfs.reconstruct(rounded, *args[1:], options=options, dtype="float64")
    from_rounded = evfs.reconstruct(rounded.astype(np.float64), *args[1:], options=options,
                                    dtype="float64")
    np.testing.assert_array_equal(from_float32["frames"], from_rounded["frames"])


def test_reconstruct_non_contiguous_frames(demo):
    recording = evfs.read(str(demo / "data"))
    frames = np.asfortranarray(recording["frames"])
    assert not frames.flags["C_CONTIGUOUS"]
    args = (recording["frame_times"], recording["events"])
    options = {"solver": "copy"}
    a = evfs.reconstruct(frames, *args, options=options, dtype="float64")
    b = evfs.reconstruct(recording["frames"], *args, options=options, dtype="float64")
    np.testing.assert_array_equal(a["frames"], b["frames"])


def test_reconstruct_truth_scores(demo):
    recording = evfs.read(str(demo / "data"))
    result = evfs.reconstruct(recording["frames"], recording["frame_times"], recording["events"],
                              mode="predict", first=0, last=1, truth=1,
                              options={"denoise": "none"})
    truth = result["summary"]["truth"]
    assert truth["index"] == 1 and truth["psnr"] > truth["baseline_psnr"]


# ---------------------------------------------------------------------------------------------
# options: the command line's flags and defaults


def cli_flag_defaults(command):
    """{flag: (type, default text)} from `evfs COMMAND --help`."""
    status, stdout, stderr = run_cli(command, "--help")
    assert status == 0, stderr
    flags = {}
    for name, kind, default in re.findall(r"^  --(\w+) \((\w+), default: (.*)\)$", stdout,
                                          re.MULTILINE):
        flags[name] = (kind, default)
    return flags


def same_default(kind, text, value):
    if kind == "bool":
        return value is (text == "true")
    if kind == "string":
        text = text.strip('"')
        if isinstance(value, str):
            return value == text
        # A list of numbers: the same numbers (the CLI writes 5 where Python holds 5.0).
        return [float(x) for x in text.split(",") if x] == [float(v) for v in value]
    return float(text) == float(value)


# Flags of `evfs reconstruct` that are arguments of evfs.reconstruct, or that have no meaning
# without files and a terminal (--allow_outside_paths guards the frame paths of a recording's
# images.txt, --report writes a page into OUT; evfs.reconstruct takes and returns arrays).
RECONSTRUCT_ARGUMENTS = {"data", "mode", "first", "last", "truth", "out", "overwrite",
                         "progress", "progress_interval_s", "allow_outside_paths", "report"}
# evfs.simulate returns the events of the frames as given: the light sources and the frame
# effects of `evfs simulate` (which writes the frames it records) are the command's alone.
SIMULATE_ARGUMENTS = {"frames", "out", "overwrite", "progress_interval_s", "exposure_s",
                      "allow_outside_paths",
                      "flicker_led_hz", "flicker_led_xy_px", "flicker_led_radius_px",
                      "flicker_led_intensity", "flicker_led_duty", "mains_hz", "mains_depth",
                      "mains_region_px", "frame_gain", "read_noise_dn", "fpn_offset_dn",
                      "fpn_gain_sigma"}


@pytest.mark.parametrize("command,defaults,arguments", [
    ("reconstruct", evfs.reconstruct_defaults, RECONSTRUCT_ARGUMENTS),
    ("simulate", evfs.simulate_defaults, SIMULATE_ARGUMENTS),
])
def test_options_are_the_cli_flags_with_their_defaults(command, defaults, arguments):
    flags = cli_flag_defaults(command)
    values = defaults()
    assert set(values) == set(flags) - arguments
    for key, value in values.items():
        kind, text = flags[key]
        assert same_default(kind, text, value), f"{key}: CLI {text}, Python {value!r}"


# ---------------------------------------------------------------------------------------------
# bad inputs: clear errors, the command line's messages where it has the same check


@pytest.fixture(scope="module")
def small(demo):
    return evfs.read(str(demo / "data"))


def reconstruct(small, **changes):
    args = {"frames": small["frames"], "frame_times": small["frame_times"],
            "events": dict(small["events"])}
    args.update(changes)
    return evfs.reconstruct(args.pop("frames"), args.pop("frame_times"), args.pop("events"),
                            **args)


def test_bad_frames(small):
    with pytest.raises(ValueError, match="frames must be a 3-D float32 or float64 array"):
        reconstruct(small, frames=small["frames"].astype(np.uint16))
    with pytest.raises(ValueError, match=r"frames must be a 3-D float64 array, not 2-D"):
        reconstruct(small, frames=small["frames"][0])
    with pytest.raises(ValueError, match="frames must be a NumPy array"):
        reconstruct(small, frames=small["frames"].tolist())
    bright = small["frames"].copy()
    bright[1, 2, 3] = 1.5
    with pytest.raises(ValueError, match=r"intensities in \[0, 1\]: \[1, 2, 3\] is 1.5"):
        reconstruct(small, frames=bright)


def test_bad_frame_times(small):
    with pytest.raises(ValueError, match="frame_times must increase strictly"):
        reconstruct(small, frame_times=small["frame_times"][::-1].copy())
    with pytest.raises(ValueError, match="one time per frame"):
        reconstruct(small, frame_times=small["frame_times"][:3])
    with pytest.raises(ValueError, match=r"frame_times must be a 1-D float64 array, not int64"):
        reconstruct(small, frame_times=np.arange(5))


def test_bad_events(small):
    events = dict(small["events"])
    unsorted = dict(events, t=events["t"][::-1].copy())
    with pytest.raises(ValueError, match=r"events\['t'\] must be sorted"):
        reconstruct(small, events=unsorted)
    with pytest.raises(ValueError, match=r"events\['x'\] must be a 1-D uint16 array, not int64"):
        reconstruct(small, events=dict(events, x=events["x"].astype(np.int64)))
    outside = events["x"].copy()
    outside[7] = small["width"]
    with pytest.raises(ValueError, match=r"event 7 at x=120, .* lies outside the 120x96 frames"):
        reconstruct(small, events=dict(events, x=outside))
    zero = events["p"].copy()
    zero[4] = 0
    with pytest.raises(ValueError, match=r"events\['p'\]\[4\] is 0"):
        reconstruct(small, events=dict(events, p=zero))
    with pytest.raises(ValueError, match="must have the same length"):
        reconstruct(small, events=dict(events, y=events["y"][1:]))
    with pytest.raises(ValueError, match="events has no 'p'"):
        reconstruct(small, events={k: events[k] for k in "txy"})


def test_bad_arguments_raise_the_cli_messages(small, demo, tmp_path):
    data = str(demo / "data")
    out = f"--out={tmp_path / 'never_written'}"
    expected = cli_error("reconstruct", f"--data={data}", "--mode=predict", "--first=7", out)
    with pytest.raises(ValueError) as raised:
        reconstruct(small, first=7)
    assert str(raised.value) == expected.replace(data, "the frames array")
    expected = cli_error("reconstruct", f"--data={data}", "--mode=sideways", "--first=0", out)
    with pytest.raises(ValueError) as raised:
        reconstruct(small, mode="sideways")
    assert str(raised.value) == expected
    for flag, value in (("solver", "newton"), ("spatial_tv", "diagonal"),
                        ("linear_solver", "MAGIC"), ("frame_weight", "-1")):
        expected = cli_error("reconstruct", f"--data={data}", "--mode=predict", "--first=0",
                             f"--{flag}={value}", out)
        option = float(value) if flag == "frame_weight" else value
        with pytest.raises(ValueError) as raised:
            reconstruct(small, options={flag: option})
        assert str(raised.value) == expected


def test_bad_options(small):
    with pytest.raises(ValueError, match="unknown option 'iterations': expected one of"):
        reconstruct(small, options={"iterations": 3})
    with pytest.raises(ValueError, match="option 'max_iterations' must be an integer, not float"):
        reconstruct(small, options={"max_iterations": 2.5})
    with pytest.raises(ValueError, match="option 'bounds' must be True or False, not int"):
        reconstruct(small, options={"bounds": 1})
    with pytest.raises(ValueError, match="option 'event_weight' must be a number, not str"):
        reconstruct(small, options={"event_weight": "0.3"})
    # A number outside its option's range, as the command line refuses it.
    with pytest.raises(ValueError, match=r"^--hot_pixel_factor must be >= 0, not -1$"):
        reconstruct(small, options={"hot_pixel_factor": -1.0})
    with pytest.raises(ValueError, match=r"^--smoothing_scale must be > 0, not nan$"):
        reconstruct(small, options={"smoothing_scale": float("nan")})
    with pytest.raises(ValueError, match="dtype must be 'float32' or 'float64'"):
        reconstruct(small, dtype="float16")


# ---------------------------------------------------------------------------------------------
# simulate


def test_simulate_identical_to_cli(demo, tmp_path):
    frames_dir = demo / "data"
    out = tmp_path / "simulated"
    status, _, stderr = run_cli("simulate", f"--frames={frames_dir}", f"--out={out}",
                                "--threshold_pos=0.15", "--seed=7")
    assert status == 0, stderr
    expected = evfs.read(str(out))["events"]
    recording = evfs.read(str(frames_dir))
    events = evfs.simulate(recording["frames"], recording["frame_times"],
                           {"threshold_pos": 0.15, "seed": 7})
    assert events["t"].shape[0] > 1000
    for key in "txyp":
        np.testing.assert_array_equal(events[key], expected[key])


def test_simulate_bad_input(small):
    with pytest.raises(ValueError, match=r"simulate needs at least 2 frames \(1 found\)"):
        evfs.simulate(small["frames"][:1], small["frame_times"][:1])
    with pytest.raises(ValueError, match=r"^--threshold_pos must be > 0, not -1$"):
        evfs.simulate(small["frames"], small["frame_times"], {"threshold_pos": -1.0})


# ---------------------------------------------------------------------------------------------
# the GIL is released while evfs works


def test_gil_released_during_solve(small):
    ticks = []
    stop = threading.Event()

    def count():
        while not stop.is_set():
            ticks.append(time.perf_counter())

    # Enough work to take a while on any machine: Adam's full schedule on one thread.
    options = {"solver": "adam", "adam_iterations": 1000, "threads": 1, "denoise": "none"}
    counter = threading.Thread(target=count)
    counter.start()
    try:
        begin = time.perf_counter()
        reconstruct(small, options=options)
        end = time.perf_counter()
    finally:
        stop.set()
        counter.join()
    during = np.array([t for t in ticks if begin <= t <= end])
    duration = end - begin
    assert duration > 0.2, "the solve was too short to tell"
    # Holding the GIL, the solve would stop the counter for its whole duration; released, the
    # counter runs on (gaps only where the OS or the interpreter's switch interval pauses it).
    gaps = np.diff(np.concatenate([[begin], during, [end]]))
    assert gaps.max() < 0.5 * duration, f"longest pause {gaps.max():.3f} s of {duration:.3f} s"


# ---------------------------------------------------------------------------------------------
# video


def read_frame_folder(folder):
    """The 16-bit frames (as written) and the timestamps.txt lines of a video output."""
    frames, _ = read_cli_reconstruction(str(folder))
    with open(os.path.join(folder, "timestamps.txt")) as lines:
        return frames, lines.read()


def test_video_identical_to_cli(demo, tmp_path):
    data = str(demo / "data")
    status, _, stderr = run_cli("video", f"--data={data}", f"--out={tmp_path / 'cli'}",
                                "--fps=400", "--jobs=1")
    assert status == 0, stderr
    result = evfs.video(data, str(tmp_path / "py"), fps=400, jobs=1)
    assert result["frames"] > 0 and result["windows"] > 0
    assert os.path.samefile(result["path"], tmp_path / "py")
    cli_frames, cli_times = read_frame_folder(tmp_path / "cli")
    py_frames, py_times = read_frame_folder(tmp_path / "py")
    assert py_times == cli_times
    np.testing.assert_array_equal(py_frames, cli_frames)
    # An earlier output is replaced only with overwrite=True; a folder evfs did not write never.
    with pytest.raises(ValueError, match="overwrite"):
        evfs.video(data, str(tmp_path / "py"), fps=400, jobs=1)
    evfs.video(data, str(tmp_path / "py"), fps=400, jobs=1, overwrite=True)
    foreign = tmp_path / "foreign"
    foreign.mkdir()
    (foreign / "keep.txt").write_text("user data")
    with pytest.raises(ValueError):
        evfs.video(data, str(foreign), fps=400, overwrite=True)
    assert (foreign / "keep.txt").read_text() == "user data"


def test_video_takes_the_command_lines_window_flags(demo, tmp_path):
    """predict_max_s, min_blur_exposure_s, blur_from_data, skip_bad_frames and the options'
    exposure_s reach the windows as the command line's flags do."""
    data = str(demo / "data_blur")
    flags = {"min_blur_exposure_s": 1.0, "blur_from_data": False, "predict_max_s": 0.01,
             "skip_bad_frames": True}
    status, _, stderr = run_cli("video", f"--data={data}", f"--out={tmp_path / 'cli'}",
                                "--fps=400", "--jobs=1", "--exposure_s=0.004",
                                *[f"--{k}={str(v).lower()}" for k, v in flags.items()])
    assert status == 0, stderr
    evfs.video(data, str(tmp_path / "py"), fps=400, jobs=1, options={"exposure_s": 0.004},
               **flags)
    cli_frames, cli_times = read_frame_folder(tmp_path / "cli")
    py_frames, py_times = read_frame_folder(tmp_path / "py")
    assert py_times == cli_times
    np.testing.assert_array_equal(py_frames, cli_frames)
    # The flags change the result: with the defaults the blurred frames are deblurred.
    evfs.video(data, str(tmp_path / "default"), fps=400, jobs=1)
    default_frames, _ = read_frame_folder(tmp_path / "default")
    assert default_frames.shape != py_frames.shape or not np.array_equal(default_frames, py_frames)


# ---------------------------------------------------------------------------------------------
# No array may crash the interpreter: layouts, sizes, counts


def test_zero_stride_view_of_a_huge_shape_is_refused_before_it_is_read(small):
    huge = np.broadcast_to(0.5, (2, 20000, 20000))
    with pytest.raises(ValueError, match=r"20000x20000 pixels are larger than the 67108864"):
        reconstruct(small, frames=huge, frame_times=np.array([0.0, 0.1]))
    with pytest.raises(ValueError, match=r"more than the 1000000 an array recording may hold"):
        reconstruct(small, frames=np.broadcast_to(0.5, (2**31, 1, 1)),
                    frame_times=np.array([0.0, 0.1]))
    with pytest.raises(ValueError, match="one time per frame: 2 frames, 1000000000 times"):
        reconstruct(small, frames=np.broadcast_to(0.5, (2, 4, 4)),
                    frame_times=np.broadcast_to(0.0, (10**9,)))
    events = dict(small["events"], t=np.broadcast_to(0.0, (2**40,)))
    with pytest.raises(ValueError, match="must have the same length"):
        reconstruct(small, events=events)


# A process under a 4 GB address-space limit (as a shared machine or a batch scheduler sets one)
# must end every call with an exception, never a signal.
MEMORY_LIMITED_SCRIPT = r"""
import resource, sys
import numpy as np
import evfs
limit = 4_000_000 * 1024
resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
times = np.array([0.0, 0.1])
events = {"t": np.zeros(0), "x": np.zeros(0, np.uint16), "y": np.zeros(0, np.uint16),
          "p": np.zeros(0, np.int8)}
for shape in [(2, 20000, 20000), (2, 15000, 15000), (2, 8192, 8192)]:
    try:
        evfs.reconstruct(np.broadcast_to(0.5, shape), times, events, options={"solver": "copy"})
        print(shape, "returned")
    except (ValueError, MemoryError) as error:
        print(shape, type(error).__name__)
"""


def child_env():
    """This environment, with the folder of the evfs module under test first on PYTHONPATH."""
    module_folder = os.path.dirname(os.path.abspath(evfs.__file__))
    return dict(os.environ, PYTHONPATH=os.pathsep.join(
        [module_folder] + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p]))


def test_huge_frames_under_an_address_space_limit_raise(tmp_path):
    done = subprocess.run([sys.executable, "-c", MEMORY_LIMITED_SCRIPT], capture_output=True,
                          text=True, timeout=600, cwd=tmp_path, env=child_env())
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert lines[0] == "(2, 20000, 20000) ValueError"
    assert lines[1] == "(2, 15000, 15000) ValueError"
    # Within the sensor cap: refused by the latent-voxel cap, or out of memory, or solved.
    assert lines[2].split(")")[1].strip() in ("returned", "MemoryError", "ValueError")


def test_any_layout_gives_the_contiguous_result(small):
    """Frames and events read through their strides: reversed, strided, unaligned, broadcast
    and Fortran-ordered views give what their contiguous copies give."""
    options = {"solver": "copy"}
    expected = reconstruct(small, options=options)["frames"]
    frames = small["frames"]

    def unaligned(array):
        raw = np.zeros(array.nbytes + 1, dtype=np.uint8)
        view = raw[1:].view(array.dtype).reshape(array.shape)
        view[...] = array
        assert not view.flags.aligned
        return view

    reversed_frames = frames[::-1].copy()[::-1]
    assert reversed_frames.strides[0] < 0
    for layout in (reversed_frames, np.asfortranarray(frames), unaligned(frames),
                   np.repeat(frames, 2, axis=2)[:, :, ::2]):
        np.testing.assert_array_equal(reconstruct(small, frames=layout, options=options)["frames"],
                                      expected)
    events = {key: unaligned(value) if value.dtype.itemsize > 1 else
              np.repeat(value, 3)[::3] for key, value in small["events"].items()}
    np.testing.assert_array_equal(reconstruct(small, events=events, options=options)["frames"],
                                  expected)
    # A zero-stride frame stack: every frame the same grey.
    grey = np.broadcast_to(0.5, frames.shape)
    np.testing.assert_array_equal(
        reconstruct(small, frames=grey, options=options)["frames"],
        reconstruct(small, frames=np.full(frames.shape, 0.5), options=options)["frames"])


def test_byte_swapped_and_non_finite_arrays_are_refused(small):
    with pytest.raises(ValueError, match="frames must be a 3-D float32 or float64 array"):
        reconstruct(small, frames=small["frames"].astype(">f8"))
    with pytest.raises(ValueError, match=r"events\['t'\] must be a 1-D float64 array, not >f8"):
        reconstruct(small, events=dict(small["events"], t=small["events"]["t"].astype(">f8")))
    for bad in (np.nan, np.inf, -np.inf):
        frames = small["frames"].copy()
        frames[0, 0, 0] = bad
        with pytest.raises(ValueError, match=r"intensities in \[0, 1\]: \[0, 0, 0\]"):
            reconstruct(small, frames=frames)
        times = small["frame_times"].copy()
        times[1] = bad
        with pytest.raises(ValueError, match=r"frame_times\[1\]"):
            reconstruct(small, frame_times=times)
        t = small["events"]["t"].copy()
        t[2] = bad
        with pytest.raises(ValueError, match=r"events\['t'\]\[2\]"):
            reconstruct(small, events=dict(small["events"], t=t))
    with pytest.raises(ValueError, match="at least one frame of at least 1x1 pixels"):
        reconstruct(small, frames=np.zeros((2, 0, 5)))


# ---------------------------------------------------------------------------------------------
# Ctrl-C: KeyboardInterrupt within a second or two, nothing half-written

# From SIGINT to KeyboardInterrupt: one Adam iteration (milliseconds) or one window's stop, plus
# the poll interval, on a machine shared with other builds.
INTERRUPT_LATENCY_S = 2.0


def interrupt_after(delay_s):
    """Sends this process SIGINT after `delay_s`; returns a list that receives the send time."""
    sent = []

    def fire():
        sent.append(time.perf_counter())
        os.kill(os.getpid(), signal.SIGINT)
    timer = threading.Timer(delay_s, fire)
    timer.start()
    return sent, timer


def test_ctrl_c_stops_reconstruct(small):
    # Adam for far longer than the test waits: only the interrupt ends it in time.
    options = {"solver": "adam", "adam_iterations": 10**7, "denoise": "none"}
    sent, timer = interrupt_after(1.0)
    try:
        with pytest.raises(KeyboardInterrupt):
            reconstruct(small, options=options)
        raised = time.perf_counter()
    finally:
        timer.cancel()
    assert sent, "the solve ended before the signal"
    assert raised - sent[0] < INTERRUPT_LATENCY_S
    # The module is usable afterwards.
    assert reconstruct(small, options={"solver": "copy"})["frames"].shape[0] > 0


def test_ctrl_c_stops_reconstruct_of_the_shared_cups_deblur():
    data = evfs.read(shared_data("eslnet_cups_blur"))
    sent, timer = interrupt_after(2.0)
    try:
        with pytest.raises(KeyboardInterrupt):
            evfs.reconstruct(data["frames"], data["frame_times"], data["events"], mode="deblur",
                             exposures=data["exposures"],
                             options={"solver": "adam", "adam_iterations": 10**7})
        raised = time.perf_counter()
    finally:
        timer.cancel()
    assert sent and raised - sent[0] < INTERRUPT_LATENCY_S


def test_ctrl_c_stops_video_and_commits_nothing(demo, tmp_path):
    out = tmp_path / "video"
    options = {"solver": "adam", "adam_iterations": 10**7, "denoise": "none"}
    sent, timer = interrupt_after(1.5)
    try:
        with pytest.raises(KeyboardInterrupt):
            evfs.video(str(demo / "data"), str(out), fps=400, jobs=2, options=options)
        raised = time.perf_counter()
    finally:
        timer.cancel()
    assert sent and raised - sent[0] < INTERRUPT_LATENCY_S
    assert not out.exists()
    left = sorted(p.name for p in tmp_path.iterdir())
    # Only the work folder stays (for resume=True), as after the command line's Ctrl-C; no
    # staging folder.
    assert left in ([], [".video.evfs-video-work"]), left
    assert not any("evfs-tmp" in name for name in left)


def test_video_fps_beyond_one_per_nanosecond_is_refused(demo, tmp_path):
    # Output times are whole nanoseconds: a faster rate's step rounds to zero, and the output
    # clock would never advance.
    with pytest.raises(ValueError, match="--fps must be at most 1e9 frames per second"):
        evfs.video(str(demo / "data"), str(tmp_path / "v"), fps=1e308)
    assert not any(tmp_path.iterdir())
