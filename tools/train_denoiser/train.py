#!/usr/bin/python3
"""Trains evfs's residual denoiser (paper §3.4, issue 17) and exports it to ONNX.

Reads the pairs of tools/make_denoiser_pairs (pair_*.npy, float32 (3, H, W): DMR latent frame,
ground truth, solver activity mask; pairs.tsv), trains a convolutional network (by default a
two-scale one with a half-resolution middle; --arch=dncnn for the paper's DnCNN) to predict the
residual R(H) = H - H_true on 48x48 patches with random flips and rotations, keeps the
checkpoint with the best PSNR on held-out pairs (every tenth sample of the training sources,
never the evfs validation recordings), and writes

  * the ONNX file (input `input`, output `output`, both 1x1xHxW float32, dynamic H and W,
    opset 11): the residual, so that the denoised frame is H - R(H). The two-scale network needs
    even H and W: a frame is padded at the bottom and right by repeating its last row and column
    (run_network), as the C++ inference module does;
  * reference_input.pfm / reference_output.pfm: a small input and torch's output for it, for
    the C++ equality test (PFM: OpenCV's cv::imread reads it as CV_32FC1);
  * a Markdown log with the data, schedule, timings and scores.

The loss is over the pixels the solver changed (the mask): the inference module gives the pixels
the solver skipped back unchanged, so nothing is learnt for them. By default (--loss=db) it is the
mean over patches of the change in dB that the denoiser makes to each patch's error,
10 log10((|D - T|^2 + e) / (|H - T|^2 + e)) with D the denoised patch, H the DMR, T the truth and
e a floor at 50 dB: what the evaluation scores (mean PSNR gain), so a patch the DMR already has
right counts as much as one it has wrong. With the mean squared error (--loss=mse) the few patches
with large errors dominate, and the network learnt to make accurate frames worse (held-out
frames down by up to 17 dB).

Run with Debian's /usr/bin/python3 (python3-torch, python3-onnx, python3-opencv); CPU only.
"""

import argparse
import glob
import hashlib
import json
import os
import random
import statistics
import sys
import time

import numpy as np
import torch
from torch import nn
from torch.nn.utils.fusion import fuse_conv_bn_eval


def parse_args(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--pairs", required=True, help="folder written by make_denoiser_pairs")
    parser.add_argument("--onnx", required=True, help="where to write the ONNX file")
    parser.add_argument("--log", default="", help="Markdown log to write ('' for none)")
    parser.add_argument("--reference_dir", default="",
                        help="folder for reference_input.pfm / reference_output.pfm ('' for none)")
    parser.add_argument("--arch", choices=["dncnn", "twoscale"], default="twoscale",
                        help="dncnn: --depth layers of --channels at full resolution; twoscale: "
                        "--channels at full resolution around --coarse_depth layers of "
                        "--coarse_channels at half resolution")
    parser.add_argument("--depth", type=int, default=8, help="dncnn: convolution layers, >= 2")
    parser.add_argument("--channels", type=int, default=8, help="full-resolution channels")
    parser.add_argument("--coarse_channels", type=int, default=24,
                        help="twoscale: channels at half resolution")
    parser.add_argument("--coarse_depth", type=int, default=5,
                        help="twoscale: 3x3 layers at half resolution")
    parser.add_argument("--bias_free", action="store_true",
                        help="twoscale: convolutions without biases, so that R(kx) = k R(x) "
                        "(Mohan et al. 2020); tried, not shipped (models/README.md, Limits)")
    parser.add_argument("--steps", type=int, default=12000, help="optimiser steps")
    parser.add_argument("--batch", type=int, default=64, help="patches per step")
    parser.add_argument("--patch", type=int, default=48, help="patch side in pixels")
    parser.add_argument("--lr", type=float, default=1e-3, help="initial Adam learning rate")
    parser.add_argument("--lr_drops", default="0.6,0.85",
                        help="fractions of --steps where the learning rate is divided by 10")
    parser.add_argument("--validate_every", type=int, default=600,
                        help="steps between evaluations on the held-out pairs")
    parser.add_argument("--held_out_every", type=int, default=10,
                        help="samples whose index is a multiple of this are held out")
    parser.add_argument("--loss", choices=["db", "mse"], default="db",
                        help="db: mean change of each patch's error in dB; mse: pixel MSE")
    parser.add_argument("--min_active", type=float, default=0.05,
                        help="fewest fraction of active pixels a training patch needs")
    parser.add_argument("--noise_free", action="store_true",
                        help="train and validate only on the pairs simulated without background "
                        "events and frame noise")
    parser.add_argument("--seed", type=int, default=17)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--opencv_runs", type=int, default=15,
                        help="OpenCV timing runs on a 240x180 frame (0: skip the OpenCV check)")
    return parser.parse_args(argv)


class ResidualDenoiser(nn.Module):
    """DnCNN (Zhang et al. 2017) as the paper's §3.4 uses it: conv+ReLU, (depth-2) x
    conv+BN+ReLU, conv; 3x3 kernels; predicts the residual."""

    def __init__(self, depth, channels):
        super().__init__()
        layers = [nn.Conv2d(1, channels, 3, padding=1), nn.ReLU(inplace=True)]
        for _ in range(depth - 2):
            layers += [nn.Conv2d(channels, channels, 3, padding=1, bias=False),
                       nn.BatchNorm2d(channels), nn.ReLU(inplace=True)]
        layers.append(nn.Conv2d(channels, 1, 3, padding=1))
        self.body = nn.Sequential(*layers)

    def forward(self, x):
        return self.body(x)

    def last_layer(self):
        return self.body[-1]

    def description(self):
        depth = sum(isinstance(m, nn.Conv2d) for m in self.body)
        return f"DnCNN-style, depth {depth}, {self.body[0].out_channels} channels, 3x3"


class TwoScaleDenoiser(nn.Module):
    """A residual network with a half-resolution middle: conv 3x3 (1 -> c) + ReLU at full
    resolution; conv 3x3 stride 2 (c -> C) + ReLU; `coarse_depth` x conv 3x3 (C -> C) + ReLU at
    half resolution; transposed conv 2x2 stride 2 (C -> c) added to the full-resolution features;
    ReLU, conv 3x3 (c -> c) + ReLU, conv 3x3 (c -> 1). The half-resolution layers cost a quarter
    of full-resolution ones per channel pair, so for a DnCNN's time it has about three times the
    parameters and twice the receptive field. Input height and width must be even (the
    inference module pads them)."""

    def __init__(self, channels, coarse_channels, coarse_depth, bias=True):
        super().__init__()
        self.head = nn.Sequential(nn.Conv2d(1, channels, 3, padding=1, bias=bias), nn.ReLU())
        coarse = [nn.Conv2d(channels, coarse_channels, 3, stride=2, padding=1, bias=bias),
                  nn.ReLU()]
        for _ in range(coarse_depth):
            coarse += [nn.Conv2d(coarse_channels, coarse_channels, 3, padding=1, bias=bias),
                       nn.ReLU()]
        coarse.append(nn.ConvTranspose2d(coarse_channels, channels, 2, stride=2, bias=bias))
        self.coarse = nn.Sequential(*coarse)
        self.tail = nn.Sequential(nn.ReLU(), nn.Conv2d(channels, channels, 3, padding=1, bias=bias),
                                  nn.ReLU(), nn.Conv2d(channels, 1, 3, padding=1, bias=bias))
        self.sizes = (channels, coarse_channels, coarse_depth)
        self.bias = bias

    def forward(self, x):
        features = self.head(x)
        return self.tail(self.coarse(features) + features)

    def last_layer(self):
        return self.tail[-1]

    def description(self):
        c, cc, depth = self.sizes
        return (f"two-scale residual network, {c} channels at full resolution, {depth} layers "
                f"of {cc} channels at half resolution, 3x3" + ("" if self.bias else ", bias-free"))


def make_model(args):
    if args.arch == "dncnn":
        return ResidualDenoiser(args.depth, args.channels)
    return TwoScaleDenoiser(args.channels, args.coarse_channels, args.coarse_depth,
                            bias=not args.bias_free)


def fused_copy(model):
    """The network in eval mode with every BatchNorm folded into its convolution: a graph of
    Conv and Relu only (and, for the two-scale network, ConvTranspose and Add), which OpenCV 4.6
    imports."""
    model = model.eval()
    if not isinstance(model, ResidualDenoiser):
        return model
    layers, modules, i = [], list(model.body), 0
    while i < len(modules):
        if (isinstance(modules[i], nn.Conv2d) and i + 1 < len(modules)
                and isinstance(modules[i + 1], nn.BatchNorm2d)):
            layers.append(fuse_conv_bn_eval(modules[i], modules[i + 1]))
            i += 2
        else:
            layers.append(modules[i])
            i += 1
    return nn.Sequential(*layers).eval()


def load_pairs(folder):
    manifest = os.path.join(folder, "pairs.tsv")
    rows = []
    with open(manifest) as f:
        header = f.readline().rstrip("\n").split("\t")
        for line in f:
            rows.append(dict(zip(header, line.rstrip("\n").split("\t"))))
    if not rows:
        sys.exit(f"train.py: {manifest} lists no pairs")
    pairs = []
    for row in rows:
        data = np.load(os.path.join(folder, row["file"]))
        if data.dtype != np.float32 or data.ndim != 3 or data.shape[0] != 3:
            sys.exit(f"train.py: {row['file']}: expected float32 (3, H, W), got "
                     f"{data.dtype} {data.shape}")
        pairs.append((row, data))
    return pairs


def psnr(estimate, truth):
    mse = float(np.mean((estimate.astype(np.float64) - truth) ** 2))
    return float("inf") if mse == 0 else 10 * np.log10(1.0 / mse)


class PatchSampler:
    """Random patches of the training pairs with at least `min_active` of their pixels active,
    under one of the 8 flips/rotations."""

    def __init__(self, pairs, patch, min_active, rng):
        self.pairs = [p for p in pairs if p.shape[1] >= patch and p.shape[2] >= patch]
        self.patch = patch
        self.min_active = min_active
        self.rng = rng

    def batch(self, size):
        out = np.empty((size, 3, self.patch, self.patch), np.float32)
        n = 0
        while n < size:
            data = self.pairs[self.rng.integers(len(self.pairs))]
            y = self.rng.integers(data.shape[1] - self.patch + 1)
            x = self.rng.integers(data.shape[2] - self.patch + 1)
            patch = data[:, y:y + self.patch, x:x + self.patch]
            if patch[2].mean() < self.min_active:
                continue
            k = self.rng.integers(4)
            patch = np.rot90(patch, k, axes=(1, 2))
            if self.rng.integers(2):
                patch = patch[:, :, ::-1]
            out[n] = patch
            n += 1
        return torch.from_numpy(out)


# The error floor of the db loss, as a mean squared error per active pixel (a PSNR of
# 10 · log10(1 / DB_LOSS_FLOOR)).
DB_LOSS_FLOOR = 1e-5


def masked_loss(model, batch, kind):
    """The loss of one batch (see the module's docstring) and the mean dB change of its
    patches' errors (negative: the denoiser helps)."""
    dmr, truth, mask = batch[:, 0:1], batch[:, 1:2], batch[:, 2:3]
    denoised = dmr - model(dmr)
    active = mask.sum(dim=(1, 2, 3)).clamp(min=1.0)
    after = ((denoised - truth) ** 2 * mask).sum(dim=(1, 2, 3)) + DB_LOSS_FLOOR * active
    before = ((dmr - truth) ** 2 * mask).sum(dim=(1, 2, 3)) + DB_LOSS_FLOOR * active
    change_db = 10 * torch.log10(after / before)
    if kind == "db":
        return change_db.mean(), float(change_db.mean())
    return after.sum() / active.sum(), float(change_db.mean())


def run_network(model, frame):
    """R(H) of one frame (H, W), as the inference module computes it: the frame padded at the
    bottom and right by replicating its last row and column to an even size, then cropped."""
    h, w = frame.shape
    x = torch.from_numpy(np.ascontiguousarray(frame)[None, None])
    if h % 2 or w % 2:
        x = torch.nn.functional.pad(x, (0, w % 2, 0, h % 2), mode="replicate")
    return model(x)[0, 0, :h, :w].numpy()


def evaluate(model, pairs):
    """Mean PSNR over the held-out pairs of the DMR frame and of the denoised one (the pixels the
    solver skipped kept, as the inference module does)."""
    model.eval()
    before, after = [], []
    with torch.no_grad():
        for data in pairs:
            dmr, truth, mask = data[0], data[1], data[2]
            residual = run_network(model, dmr)
            denoised = np.where(mask > 0, dmr - residual, dmr)
            before.append(psnr(dmr, truth))
            after.append(psnr(denoised, truth))
    model.train()
    finite = [(b, a) for b, a in zip(before, after) if np.isfinite(b) and np.isfinite(a)]
    gains = [a - b for b, a in finite]
    return {
        "pairs": len(finite),
        "psnr_dmr": statistics.mean(b for b, _ in finite),
        "psnr_denoised": statistics.mean(a for _, a in finite),
        "gain_mean": statistics.mean(gains),
        "gain_worst": min(gains),
        "share_worse": sum(g < 0 for g in gains) / len(gains),
    }


def export_onnx(model, path):
    import onnx

    fused = fused_copy(model)
    torch.onnx.export(fused, torch.rand(1, 1, 180, 240), path, input_names=["input"],
                      output_names=["output"], opset_version=11, do_constant_folding=True,
                      dynamic_axes={"input": {2: "H", 3: "W"}, "output": {2: "H", 3: "W"}})
    # torch shares equal initializers through Identity nodes, which OpenCV 4.6 cannot import:
    # give each such output its own copy of the tensor.
    graph = onnx.load(path)
    initializers = {t.name: t for t in graph.graph.initializer}
    for node in list(graph.graph.node):
        if node.op_type == "Identity" and node.input[0] in initializers:
            copy = onnx.TensorProto()
            copy.CopyFrom(initializers[node.input[0]])
            copy.name = node.output[0]
            graph.graph.initializer.append(copy)
            graph.graph.node.remove(node)
    onnx.checker.check_model(graph)
    onnx.save(graph, path)
    ops = sorted({node.op_type for node in graph.graph.node})
    return fused, ops


def write_pfm(path, image):
    """PFM, grey ('Pf'), little-endian (negative scale), rows stored bottom to top."""
    image = np.asarray(image, dtype="<f4")
    with open(path, "wb") as f:
        f.write(f"Pf\n{image.shape[1]} {image.shape[0]}\n-1.0\n".encode("ascii"))
        f.write(np.ascontiguousarray(image[::-1]).tobytes())


def read_pfm(path):
    with open(path, "rb") as f:
        assert f.readline().strip() == b"Pf"
        width, height = map(int, f.readline().split())
        scale = float(f.readline())
        data = np.frombuffer(f.read(), dtype="<f4" if scale < 0 else ">f4")
    return data.reshape(height, width)[::-1]


def opencv_check(path, fused, reference, runs):
    """Loads the ONNX file with OpenCV's DNN module, compares its output with torch's on
    `reference` and times a 240x180 frame (median of `runs`). None when python3-opencv is
    missing (the C++ test does the same check)."""
    try:
        import cv2
    except ImportError:
        return None
    cv2.setNumThreads(2)
    net = cv2.dnn.readNetFromONNX(path)
    net.setInput(reference[None, None])
    opencv_out = net.forward()[0, 0]
    with torch.no_grad():
        torch_out = run_network(fused, reference)
    frame = np.random.default_rng(0).random((1, 1, 180, 240), dtype=np.float32)
    times = []
    for _ in range(runs):
        start = time.perf_counter()
        net.setInput(frame)
        net.forward()
        times.append(1000 * (time.perf_counter() - start))
    return {"max_abs_diff_vs_torch": float(np.abs(opencv_out - torch_out).max()),
            "ms_per_240x180_median": statistics.median(times),
            "ms_per_240x180_min": min(times), "runs": runs}


def main(argv):
    args = parse_args(argv)
    torch.set_num_threads(args.threads)
    torch.manual_seed(args.seed)
    random.seed(args.seed)
    np_rng = np.random.default_rng(args.seed)
    torch.use_deterministic_algorithms(True)
    started = time.time()

    pairs = load_pairs(args.pairs)
    if args.noise_free:
        pairs = [(r, d) for r, d in pairs
                 if " noise_hz=0 " in f" {r['configuration']} "
                 and " frame_noise=0 " in f" {r['configuration']} "]
    held_out = [d for r, d in pairs if int(r["sample"]) % args.held_out_every == 0]
    training = [d for r, d in pairs if int(r["sample"]) % args.held_out_every != 0]
    if not held_out or not training:
        sys.exit("train.py: need pairs both in training and held out (more samples)")
    sources = {}
    for row, _ in pairs:
        kind = row["source"].split(":")[0]
        sources[kind] = sources.get(kind, 0) + 1
    cases = {}
    for row, _ in pairs:
        cases[row["case"]] = cases.get(row["case"], 0) + 1
    print(f"train.py: {len(training)} training and {len(held_out)} held-out pairs; "
          f"sources {sources}; cases {cases}", flush=True)

    model = make_model(args)
    # Start as the identity: the last layer's weights near zero, so the first steps do not
    # make the DMR worse (the residual is small).
    nn.init.normal_(model.last_layer().weight, std=1e-3)
    if model.last_layer().bias is not None:
        nn.init.zeros_(model.last_layer().bias)
    parameters = sum(p.numel() for p in model.parameters())
    optimiser = torch.optim.Adam(model.parameters(), lr=args.lr, betas=(0.9, 0.999))
    drops = [int(float(f) * args.steps) for f in args.lr_drops.split(",") if f]
    scheduler = torch.optim.lr_scheduler.MultiStepLR(optimiser, milestones=drops, gamma=0.1)
    sampler = PatchSampler(training, args.patch, args.min_active, np_rng)

    initial = evaluate(model, held_out)
    print(f"step 0: held-out PSNR DMR {initial['psnr_dmr']:.3f} dB", flush=True)
    best = {"step": 0, "scores": initial, "state": {k: v.clone() for k, v in
                                                    model.state_dict().items()}}
    history = []
    train_start = time.time()
    running = []
    for step in range(1, args.steps + 1):
        batch = sampler.batch(args.batch)
        loss, change_db = masked_loss(model, batch, args.loss)
        optimiser.zero_grad()
        loss.backward()
        optimiser.step()
        scheduler.step()
        running.append(change_db)
        if step % args.validate_every == 0 or step == args.steps:
            scores = evaluate(model, held_out)
            train_change = statistics.mean(running)
            running = []
            history.append({"step": step, "train_patch_change_db": train_change,
                            "elapsed_s": time.time() - train_start, **scores})
            print(f"step {step}: train patches {train_change:+.3f} dB, held-out DMR "
                  f"{scores['psnr_dmr']:.3f} -> {scores['psnr_denoised']:.3f} dB "
                  f"(gain {scores['gain_mean']:+.3f}, worst {scores['gain_worst']:+.3f}), "
                  f"{time.time() - train_start:.0f} s", flush=True)
            if scores["gain_mean"] > best["scores"]["gain_mean"]:
                best = {"step": step, "scores": scores,
                        "state": {k: v.clone() for k, v in model.state_dict().items()}}
    train_s = time.time() - train_start
    model.load_state_dict(best["state"])
    model.eval()

    os.makedirs(os.path.dirname(os.path.abspath(args.onnx)), exist_ok=True)
    fused, ops = export_onnx(model, args.onnx)
    with open(args.onnx, "rb") as f:
        onnx_bytes = f.read()
    sha256 = hashlib.sha256(onnx_bytes).hexdigest()

    # The reference: a 48x64 crop of the held-out pair with the most active pixels, so that the
    # residual there is far from zero.
    crop_h, crop_w = 48, 64
    candidates = [d for d in held_out if d.shape[1] >= crop_h and d.shape[2] >= crop_w]
    chosen = max(candidates, key=lambda d: d[2, :crop_h, :crop_w].sum())
    reference = np.ascontiguousarray(chosen[0, :crop_h, :crop_w])
    with torch.no_grad():
        reference_out = run_network(fused, reference)
    if args.reference_dir:
        os.makedirs(args.reference_dir, exist_ok=True)
        write_pfm(os.path.join(args.reference_dir, "reference_input.pfm"), reference)
        write_pfm(os.path.join(args.reference_dir, "reference_output.pfm"), reference_out)
        assert np.array_equal(read_pfm(os.path.join(args.reference_dir,
                                                    "reference_output.pfm")), reference_out)
    opencv = opencv_check(args.onnx, fused, reference, args.opencv_runs) \
        if args.opencv_runs > 0 else None
    if opencv is not None and opencv["max_abs_diff_vs_torch"] > 1e-4:
        sys.exit(f"train.py: OpenCV's output differs from torch's by "
                 f"{opencv['max_abs_diff_vs_torch']:.2e} (> 1e-4)")

    summary = {
        "architecture": model.description(),
        "parameters": parameters, "onnx_ops": ops, "onnx_bytes": len(onnx_bytes),
        "sha256": sha256, "pairs_training": len(training), "pairs_held_out": len(held_out),
        "sources": sources, "cases": cases, "loss": args.loss, "steps": args.steps,
        "batch": args.batch,
        "patch": args.patch, "lr": args.lr, "lr_drops_at": drops, "seed": args.seed,
        "threads": args.threads, "train_s": train_s, "total_s": time.time() - started,
        "best_step": best["step"], "held_out_initial": initial,
        "held_out_best": best["scores"], "opencv": opencv, "history": history,
        "torch": torch.__version__,
    }
    print(json.dumps({k: v for k, v in summary.items() if k != "history"}, indent=1))
    if args.log:
        write_log(args, summary)
    return 0


def write_log(args, s):
    o = s["opencv"]
    lines = [
        "# Residual denoiser: training log",
        "",
        "Written by `tools/train_denoiser/train.py` (run by `make train-denoiser`); the model card",
        "is `models/README.md`.",
        "",
        f"- command: `train.py {' '.join(sys.argv[1:])}`",
        f"- network: {s['architecture']}, {s['parameters']} parameters; ONNX "
        f"{s['onnx_bytes']} bytes, ops {', '.join(s['onnx_ops'])}, opset 11",
        f"- sha256: `{s['sha256']}`",
        f"- pairs: {s['pairs_training']} training, {s['pairs_held_out']} held out (samples "
        f"whose index is a multiple of {args.held_out_every}); by source "
        f"{json.dumps(s['sources'])}; by case {json.dumps(s['cases'])}",
        f"- schedule: {s['steps']} Adam steps ({s['loss']} loss) of {s['batch']} patches "
        f"{s['patch']}x{s['patch']} "
        f"(random flips and rotations), learning rate {s['lr']} divided by 10 at steps "
        f"{s['lr_drops_at']}; seed {s['seed']}; {s['threads']} threads, torch {s['torch']}",
        f"- time: {s['train_s'] / 60:.1f} min training, {s['total_s'] / 60:.1f} min in all "
        "(this script)",
        f"- kept: step {s['best_step']} (best mean held-out gain)",
        f"- held-out PSNR (whole frames, skipped pixels kept): DMR "
        f"{s['held_out_best']['psnr_dmr']:.3f} dB, DMR + RD "
        f"{s['held_out_best']['psnr_denoised']:.3f} dB; gain mean "
        f"{s['held_out_best']['gain_mean']:+.3f} dB, worst {s['held_out_best']['gain_worst']:+.3f}"
        f" dB, {100 * s['held_out_best']['share_worse']:.1f} % of frames worse",
    ]
    if o:
        lines.append(f"- OpenCV 4.6 DNN (python3-opencv, 2 threads): loads it; output vs torch "
                     f"max |diff| {o['max_abs_diff_vs_torch']:.2e} on the reference input; "
                     f"{o['ms_per_240x180_median']:.1f} ms per 240x180 frame (median of "
                     f"{o['runs']}, min {o['ms_per_240x180_min']:.1f}) while training jobs "
                     "shared the machine")
    lines += ["", "| step | train patches' error change dB | held-out DMR | held-out DMR + RD | gain | worst "
              "| frames worse | minutes |", "|---|---|---|---|---|---|---|---|"]
    for h in s["history"]:
        lines.append(f"| {h['step']} | {h['train_patch_change_db']:+.3f} | {h['psnr_dmr']:.3f} | "
                     f"{h['psnr_denoised']:.3f} | {h['gain_mean']:+.3f} | "
                     f"{h['gain_worst']:+.3f} | {100 * h['share_worse']:.1f} % | "
                     f"{h['elapsed_s'] / 60:.1f} |")
    with open(args.log, "w") as f:
        f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
