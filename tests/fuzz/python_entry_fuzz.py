#!/usr/bin/env python3
"""Fuzzes the Python module's entry points (evfs.reconstruct, evfs.read, evfs.simulate) with
arrays of random dtypes, shapes, strides and values, and other objects in their place.

The rule it checks: no argument may kill the interpreter. A call may return or raise an
ordinary Python exception (ValueError, TypeError, MemoryError, RuntimeError, OverflowError);
a crash, a hang, or any other exception type is a finding.

Every case is a pure function of (seed, case index): case I of seed S is rebuilt by
`python_entry_fuzz.py --seed=S --case=I`. The calls run in batches, each in a child process,
so that a crash ends only its batch; the batch is then replayed one case at a time to find and
print the case that crashed. Most cases are cheap (a refused argument); a few are small valid
recordings that run a short solve.

  PYTHONPATH=build/python python3 tests/fuzz/python_entry_fuzz.py --seed=1 --calls=1000000

Exit status: 0 when every case ended in a return or an allowed exception, 1 otherwise, 77
(ctest's "skipped") when NumPy or the evfs module cannot be imported.
"""
import argparse
import importlib.util
import os
import random
import subprocess
import sys
import tempfile
import time

SKIPPED = 77
ALLOWED = (ValueError, TypeError, MemoryError, RuntimeError, OverflowError)
# A call longer than this is reported as slow (it is no crash, but the fuzzed inputs are small).
SLOW_CALL_S = 20.0
# A batch's child gets this long per case, plus a start-up allowance, before it counts as hung.
BATCH_S_PER_CASE = 0.5
BATCH_START_S = 60.0

DTYPES = ["float64", "float32", "float16", "int8", "uint8", "int16", "uint16", "int32",
          "uint32", "int64", "uint64", "bool", "complex64", "object", ">f8", ">u2", "<U3",
          "V8", "datetime64[ns]"]
# Declared sizes far beyond memory, reached only through zero-stride (broadcast) views.
HUGE_SHAPES = [(2, 20000, 20000), (2, 8192, 8193), (2, 65537, 1), (2, 1, 70000),
               (3, 8192, 8192), (2**31, 1, 1), (10**9,), (2**40,), (2, 2**31, 2**31),
               (10**6, 100, 100)]
SPECIAL_VALUES = [float("nan"), float("inf"), -float("inf"), -0.0, 1e308, -1e308, 5e-324, 1.0,
                  0.0, 0.5, 2.0**63, -(2.0**63), 9e9, -9e9, 9.1e9]
MODES = ["predict", "interpolate", "deblur", "", "sideways", "predict\0x"]
INTS = [0, 1, -1, 2, 3, 7, 2**31 - 1, 2**31, -(2**31), -(2**31) - 1, 2**62, -(2**62), 2**64,
        10**30]


def random_values(rng, np, shape, dtype):
    """An array of `shape` and `dtype` with values drawn to hit edges: [0, 1], specials, big."""
    size = int(np.prod(shape)) if shape else 1
    kind = rng.random()
    if dtype in ("object",):
        return np.array([rng.choice([None, 1, "a", 0.5]) for _ in range(size)],
                        dtype=object).reshape(shape)
    if dtype in ("<U3",):
        return np.full(shape, "abc", dtype=dtype)
    if dtype == "V8":
        return np.zeros(shape, dtype=dtype)
    if dtype == "datetime64[ns]":
        return np.zeros(shape, dtype="int64").view(dtype)
    if kind < 0.5:
        values = np.array([rng.random() for _ in range(size)])
    elif kind < 0.75:
        values = np.array([rng.choice(SPECIAL_VALUES) for _ in range(size)])
    else:
        values = np.array([rng.uniform(-1e6, 1e6) for _ in range(size)])
    with np.errstate(all="ignore"):
        if np.dtype(dtype).kind in "iub":
            values = np.nan_to_num(values, nan=0, posinf=0, neginf=0)
            info = np.iinfo(dtype) if np.dtype(dtype).kind != "b" else None
            if info is not None:
                values = np.clip(values, info.min, info.max)
        return values.astype(dtype).reshape(shape)


def random_layout(rng, np, array):
    """`array` or a view of it with another layout: transposed, reversed, strided, unaligned,
    read-only or Fortran-ordered."""
    choice = rng.randrange(8)
    if array.ndim == 0:
        return array
    if choice == 0:
        return array[::-1]
    if choice == 1 and array.ndim >= 2:
        return array.swapaxes(0, array.ndim - 1)
    if choice == 2:
        return np.repeat(array, 2, axis=0)[::2]
    if choice == 3 and array.dtype.kind in "fiu" and array.dtype.itemsize > 1:
        # An unaligned copy: the same values one byte into a buffer.
        raw = np.zeros(array.nbytes + 1, dtype=np.uint8)
        view = raw[1:].view(array.dtype).reshape(array.shape)
        view[...] = array
        return view
    if choice == 4:
        array = array.copy()
        array.flags.writeable = False
        return array
    if choice == 5:
        return np.asfortranarray(array)
    return array


def random_array(rng, np, ndim=None, dtype=None, max_side=6):
    if rng.random() < 0.03:
        shape = rng.choice(HUGE_SHAPES)
        dtype = dtype or rng.choice(["float64", "float32"])
        return np.broadcast_to(np.array(rng.choice(SPECIAL_VALUES[5:10]), dtype=dtype), shape)
    ndim = rng.randrange(5) if ndim is None else ndim
    shape = tuple(rng.randrange(max_side + 1) for _ in range(ndim))
    dtype = dtype or rng.choice(DTYPES)
    array = random_values(rng, np, shape, dtype)
    if rng.random() < 0.1 and array.ndim > 0 and array.size > 0:
        # A zero-stride view of the same shape.
        array = np.broadcast_to(array.reshape(-1)[:1].reshape((1,) * array.ndim), shape)
    return random_layout(rng, np, array)


def random_object(rng, np):
    """Anything but a well-formed argument."""
    return rng.choice([None, 0, 1.5, "frames", b"x", [0.5, 0.5], [[0.1]], {}, {"t": 1},
                       object(), np.float64(0.5), np.int64(3), (1, 2), float("nan")])


def valid_recording(rng, np):
    """A small recording every check accepts: 2-3 frames of up to 8x8 pixels, a few events."""
    frames_count = rng.choice([2, 2, 3])
    height, width = rng.randrange(1, 9), rng.randrange(1, 9)
    frames = np.array([[[rng.random() for _ in range(width)] for _ in range(height)]
                       for _ in range(frames_count)])
    times = np.array([0.01 * i for i in range(frames_count)])
    count = rng.randrange(0, 30)
    t = np.sort(np.array([rng.uniform(0.0, 0.01 * (frames_count - 1)) for _ in range(count)]))
    events = {"t": t,
              "x": np.array([rng.randrange(width) for _ in range(count)], dtype=np.uint16),
              "y": np.array([rng.randrange(height) for _ in range(count)], dtype=np.uint16),
              "p": np.array([rng.choice([1, -1]) for _ in range(count)], dtype=np.int8)}
    return frames, times, events


def random_events(rng, np):
    roll = rng.random()
    if roll < 0.15:
        return random_object(rng, np)
    keys = [k for k in "txyp" if rng.random() < 0.9] + (["z"] if rng.random() < 0.1 else [])
    dtypes = {"t": "float64", "x": "uint16", "y": "uint16", "p": "int8"}
    return {k: random_array(rng, np, ndim=rng.choice([1, 1, 1, 0, 2]),
                            dtype=dtypes.get(k) if rng.random() < 0.7 else None)
            for k in keys}


def random_options(rng, evfs, defaults):
    roll = rng.random()
    if roll < 0.6:
        return None
    if roll < 0.7:
        return rng.choice([[], "solver=adam", 3, {1: 2}])
    key = rng.choice(sorted(defaults) + ["nope"])
    value = rng.choice([None, "adam", "x", -1, 0, 2**70, float("nan"), float("inf"), 1e308,
                        -1e308, True, [1], defaults.get(key)])
    return {key: value}


def reconstruct_case(rng, np, evfs, defaults):
    """Arguments for evfs.reconstruct; a few form a valid small recording."""
    keywords = {}
    if rng.random() < 0.04:
        frames, times, events = valid_recording(rng, np)
        if rng.random() < 0.5:
            frames = random_layout(rng, np, frames.astype(rng.choice(["float32", "float64"])))
            if frames.shape[0] < 2 or frames.ndim != 3:
                frames = frames[:2] if frames.ndim == 3 else frames
        keywords["mode"] = rng.choice(["predict", "interpolate", "deblur"])
        keywords["first"] = rng.choice([0, 0, 1, -1])
        keywords["options"] = rng.choice([None, {"solver": "adam", "adam_iterations": 5},
                                          {"iterations": 3}, {"solver": "blend"}])
        if keywords["options"] is not None and "iterations" in keywords["options"]:
            if "iterations" not in defaults:
                keywords["options"] = None
        if rng.random() < 0.3:
            exposures = np.stack([times - 0.002, times + 0.002], axis=1)
            keywords["exposures"] = exposures
        return (frames, times, events), keywords
    frames = random_array(rng, np, ndim=rng.choice([3, 3, 3, 2, 4]),
                          dtype=rng.choice(["float64", "float32", None]))
    if rng.random() < 0.05:
        frames = random_object(rng, np)
    times = random_array(rng, np, ndim=rng.choice([1, 1, 0, 2]),
                         dtype=rng.choice(["float64", "float64", None]))
    events = random_events(rng, np)
    if rng.random() < 0.3:
        keywords["mode"] = rng.choice(MODES)
    for name in ("first", "last", "truth"):
        if rng.random() < 0.15:
            keywords[name] = rng.choice(INTS)
    if rng.random() < 0.15:
        keywords["exposures"] = random_array(rng, np, ndim=rng.choice([2, 2, 1]))
    options = random_options(rng, evfs, defaults)
    if options is not None:
        keywords["options"] = options
    if rng.random() < 0.05:
        keywords["dtype"] = rng.choice(["float16", "float64", ""])
    return (frames, times, events), keywords


def read_case(rng, np, folder):
    """A path for evfs.read: missing, of the wrong type, or a small garbage file or folder."""
    roll = rng.random()
    if roll < 0.2:
        return random_object(rng, np)
    if roll < 0.3:
        return random_array(rng, np)
    if roll < 0.45:
        return os.path.join(folder, "missing" + rng.choice(["", ".h5", ".aedat4", "/x"]))
    name = os.path.join(folder, "case" + rng.choice(["", ".h5", ".aedat4", ".txt"]))
    if name.endswith("case"):
        os.makedirs(name, exist_ok=True)
        for file in ("images.txt", "events.txt", "exposures.txt"):
            path = os.path.join(name, file)
            if rng.random() < 0.7:
                with open(path, "wb") as out:
                    out.write(random_text(rng))
            elif os.path.exists(path):
                os.remove(path)
    else:
        if os.path.isdir(name):
            return name
        with open(name, "wb") as out:
            if name.endswith(".h5") and rng.random() < 0.5:
                out.write(b"\x89HDF\r\n\x1a\n" + bytes(rng.randrange(256) for _ in range(200)))
            elif name.endswith(".aedat4") and rng.random() < 0.5:
                out.write(b"#!AER-DAT4.0\r\n" + bytes(rng.randrange(256) for _ in range(200)))
            else:
                out.write(bytes(rng.randrange(256) for _ in range(rng.randrange(300))))
    return name


def random_text(rng):
    lines = []
    for _ in range(rng.randrange(6)):
        fields = [rng.choice(["0", "1", "-1", "0.5", "1e400", "nan", "x", "frame.png", "../x",
                              "65535", "99999999999999999999", "\ufeff0"])
                  for _ in range(rng.randrange(6))]
        lines.append(" ".join(fields))
    return "\n".join(lines).encode("utf-8", "surrogatepass")


def run_case(seed, index, np, evfs, defaults, folder, outcomes=None):
    """Runs case `index` of `seed`; returns a finding (str) or None. Counts the outcome
    ("returned" or the exception's type name) into `outcomes`."""
    rng = random.Random(seed * 1000003 + index)
    entry = rng.random()
    start = time.monotonic()
    try:
        if entry < 0.8:
            args, keywords = reconstruct_case(rng, np, evfs, defaults)
            evfs.reconstruct(*args, **keywords)
        elif entry < 0.95:
            evfs.read(read_case(rng, np, folder))
        else:
            if rng.random() < 0.3:
                frames, times, _ = valid_recording(rng, np)
            else:
                frames = random_array(rng, np, ndim=rng.choice([3, 3, 2]))
                times = random_array(rng, np, ndim=1)
            evfs.simulate(frames, times, rng.choice([None, {"threshold_pos": 0.0}, {}]))
        outcome = "returned"
    except ALLOWED as error:
        outcome = type(error).__name__
    except BaseException as error:  # anything else is a finding, KeyboardInterrupt included
        return f"case {index}: {type(error).__name__}: {error}"
    if outcomes is not None:
        outcomes[outcome] = outcomes.get(outcome, 0) + 1
    elapsed_s = time.monotonic() - start
    if elapsed_s > SLOW_CALL_S:
        return f"case {index}: slow, {elapsed_s:.1f} s"
    return None


def describe_case(seed, index, np, evfs, defaults, folder):
    """The arguments of case `index` as text, rebuilt from its seed."""
    rng = random.Random(seed * 1000003 + index)
    entry = rng.random()
    np.set_printoptions(threshold=20)
    if entry < 0.8:
        args, keywords = reconstruct_case(rng, np, evfs, defaults)

        def show(value):
            if isinstance(value, np.ndarray):
                return (f"array(shape={value.shape}, dtype={value.dtype}, "
                        f"strides={value.strides}, aligned={value.flags.aligned})")
            if isinstance(value, dict):
                return "{" + ", ".join(f"{k!r}: {show(v)}" for k, v in value.items()) + "}"
            return repr(value)
        return ("evfs.reconstruct(" + ", ".join(show(a) for a in args) + ", " +
                ", ".join(f"{k}={show(v)}" for k, v in keywords.items()) + ")")
    if entry < 0.95:
        return f"evfs.read({read_case(rng, np, folder)!r})"
    return "evfs.simulate(...)"


def worker(seed, first, count, trace):
    """Runs cases first..first+count-1 in this process; prints findings."""
    import numpy as np
    import evfs
    defaults = evfs.reconstruct_defaults()
    findings = 0
    outcomes = {}
    with tempfile.TemporaryDirectory(prefix="evfs-pyfuzz-") as folder:
        for index in range(first, first + count):
            if trace:
                print(f"running {index}", flush=True)
            finding = run_case(seed, index, np, evfs, defaults, folder, outcomes)
            if finding is not None:
                findings += 1
                print("FINDING " + finding, flush=True)
    print("OUTCOMES " + " ".join(f"{k}={v}" for k, v in sorted(outcomes.items())), flush=True)
    return 1 if findings else 0


def run_batch(seed, first, count, trace=False):
    command = [sys.executable, os.path.abspath(__file__), f"--seed={seed}", "--worker",
               f"--first={first}", f"--calls={count}"] + (["--trace"] if trace else [])
    try:
        done = subprocess.run(command, capture_output=True, text=True,
                              timeout=BATCH_START_S + BATCH_S_PER_CASE * count)
        return done.returncode, done.stdout, done.stderr
    except subprocess.TimeoutExpired as expired:
        stdout = expired.stdout.decode() if isinstance(expired.stdout, bytes) else expired.stdout
        return None, stdout or "", ""


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--calls", type=int, default=5000, help="cases to run")
    parser.add_argument("--first", type=int, default=0, help="index of the first case")
    parser.add_argument("--batch", type=int, default=20000, help="cases per child process")
    parser.add_argument("--case", type=int, help="run (and describe) this one case here")
    parser.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument("--trace", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.worker:
        return worker(args.seed, args.first, args.calls, args.trace)
    if args.case is not None:
        import numpy as np
        import evfs
        defaults = evfs.reconstruct_defaults()
        with tempfile.TemporaryDirectory(prefix="evfs-pyfuzz-") as folder:
            print(describe_case(args.seed, args.case, np, evfs, defaults, folder), flush=True)
            finding = run_case(args.seed, args.case, np, evfs, defaults, folder)
        print(finding or "no finding")
        return 1 if finding else 0

    missing = [m for m in ("numpy", "evfs") if importlib.util.find_spec(m) is None]
    if missing:
        print("skipped: " + ", ".join(missing) + " not importable by " + sys.executable)
        return SKIPPED
    start = time.monotonic()
    done = crashes = findings = 0
    outcomes = {}
    index = args.first
    end = args.first + args.calls
    while index < end:
        count = min(args.batch, end - index)
        status, stdout, stderr = run_batch(args.seed, index, count)
        for line in stdout.splitlines():
            if line.startswith("OUTCOMES "):
                for item in line.split()[1:]:
                    key, value = item.split("=")
                    outcomes[key] = outcomes.get(key, 0) + int(value)
            if line.startswith("FINDING"):
                findings += 1
                print(f"seed {args.seed} {line}", flush=True)
        if status not in (0, 1):
            # Replays the batch case by case to name the one that crashed or hung.
            _, traced, traced_err = run_batch(args.seed, index, count, trace=True)
            ran = [int(l.split()[1]) for l in traced.splitlines() if l.startswith("running ")]
            culprit = ran[-1] if ran else index
            crashes += 1
            what = "hung" if status is None else f"exit status {status}"
            print(f"CRASH seed {args.seed} case {culprit}: {what}; reproduce with "
                  f"{os.path.basename(__file__)} --seed={args.seed} --case={culprit}\n"
                  f"{(stderr or traced_err)[-2000:]}", flush=True)
            done += culprit - index + 1
            index = culprit + 1
            continue
        done += count
        index += count
        elapsed_s = time.monotonic() - start
        print(f"seed {args.seed}: {done} calls, {crashes} crashes, {findings} other findings, "
              f"{elapsed_s:.0f} s ({done / max(elapsed_s, 1e-9):.0f} calls/s)", flush=True)
    print(f"done: seed {args.seed}, cases {args.first}..{end - 1}: {done} calls, {crashes} "
          f"crashes, {findings} other findings; outcomes: " +
          ", ".join(f"{k} {v}" for k, v in sorted(outcomes.items())))
    return 1 if crashes or findings else 0


if __name__ == "__main__":
    sys.exit(main())
