#!/usr/bin/python3
"""Smoke tests of the denoiser's training pipeline (issue 17), run by ctest.

  denoiser_training_smoke_test.py pairs MAKE_DENOISER_PAIRS SCRATCH
      the pair generator on three small samples: the folder, the manifest and every .npy file
      (header and size) are as tools/make_denoiser_pairs.cc documents.
  denoiser_training_smoke_test.py train MAKE_DENOISER_PAIRS TRAIN_PY SCRATCH
      the same pairs, then two training steps and the ONNX export; exits 77 (ctest: skipped)
      with a message when torch or onnx cannot be imported (CI never trains).
"""

import ast
import os
import shutil
import struct
import subprocess
import sys

SKIP = 77


def make_pairs(generator, scratch):
    shutil.rmtree(scratch, ignore_errors=True)
    os.makedirs(scratch)
    out = os.path.join(scratch, "pairs")
    # Synthetic scenes only: the test needs no installed images or shared data.
    subprocess.run([generator, f"--out={out}", "--samples=4", "--seed=5", "--quiet"], check=True)
    with open(os.path.join(out, "pairs.tsv")) as f:
        header = f.readline().rstrip("\n").split("\t")
        rows = [dict(zip(header, line.rstrip("\n").split("\t"))) for line in f]
    assert header[:2] == ["file", "sample"], header
    assert len(rows) >= 4, f"expected pairs from most of the 4 samples, got {len(rows)}"
    files = sorted(name for name in os.listdir(out) if name.endswith(".npy"))
    assert files == sorted(row["file"] for row in rows), (files, rows)
    for row in rows:
        width, height = map(int, row["size"].split("x"))
        assert 0 <= int(row["latent_index"]) < int(row["latent_frames"]), row
        with open(os.path.join(out, row["file"]), "rb") as f:
            data = f.read()
        assert data[:8] == b"\x93NUMPY\x01\x00", row["file"]
        (length,) = struct.unpack("<H", data[8:10])
        assert (10 + length) % 64 == 0, "npy header not padded to 64 bytes"
        meta = ast.literal_eval(data[10:10 + length].decode("latin1"))
        assert meta == {"descr": "<f4", "fortran_order": False, "shape": (3, height, width)}, meta
        assert len(data) == 10 + length + 3 * height * width * 4, row["file"]
        values = struct.unpack(f"<{3 * height * width}f", data[10 + length:])
        plane = height * width
        assert all(0.0 <= v <= 1.0 for v in values[plane:2 * plane]), "truth outside [0, 1]"
        assert set(values[2 * plane:]) <= {0.0, 1.0}, "mask not binary"
        assert any(values[2 * plane:]), "a pair without an active pixel"
    return out


def main(argv):
    mode = argv[1]
    if mode == "pairs":
        make_pairs(argv[2], argv[3])
        print("pairs: ok")
        return 0
    if mode == "train":
        try:
            import onnx  # noqa: F401
            import torch  # noqa: F401
        except ImportError as error:
            print(f"skipped: training needs python3-torch and python3-onnx ({error}); "
                  "`make train-denoiser` installs them")
            return SKIP
        generator, train_py, scratch = argv[2], argv[3], argv[4]
        pairs = make_pairs(generator, scratch)
        onnx_path = os.path.join(scratch, "model.onnx")
        log = os.path.join(scratch, "log.md")
        subprocess.run([sys.executable, train_py, f"--pairs={pairs}", f"--onnx={onnx_path}",
                        f"--log={log}", f"--reference_dir={scratch}", "--steps=2",
                        "--held_out_every=2", "--validate_every=1", "--opencv_runs=1",
                        "--channels=4", "--coarse_channels=4", "--coarse_depth=1"], check=True)
        import onnx
        model = onnx.load(onnx_path)
        assert [i.name for i in model.graph.input] == ["input"]
        assert [o.name for o in model.graph.output] == ["output"]
        assert {n.op_type for n in model.graph.node} <= {"Conv", "Relu", "ConvTranspose", "Add"}
        with open(log) as f:
            text = f.read()
        assert "| 2 |" in text, "the log has no row for step 2"
        for name in ("reference_input.pfm", "reference_output.pfm"):
            with open(os.path.join(scratch, name), "rb") as f:
                assert f.read(3) == b"Pf\n", name
        # Every convolution has its bias input; with --bias_free none has.
        assert all(len(n.input) == 3 for n in model.graph.node if n.op_type.startswith("Conv"))
        subprocess.run([sys.executable, train_py, f"--pairs={pairs}", f"--onnx={onnx_path}",
                        f"--reference_dir={scratch}", "--steps=2", "--held_out_every=2",
                        "--validate_every=1", "--opencv_runs=1", "--channels=4",
                        "--coarse_channels=4", "--coarse_depth=1", "--bias_free"], check=True)
        convolutions = [n for n in onnx.load(onnx_path).graph.node if n.op_type.startswith("Conv")]
        assert convolutions and all(len(n.input) == 2 for n in convolutions), "biases exported"
        print("train: ok")
        return 0
    sys.exit(f"unknown mode {mode}")


if __name__ == "__main__":
    sys.exit(main(sys.argv))
