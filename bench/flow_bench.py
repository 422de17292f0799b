"""Flow backend benchmark: ms per pair, endpoint error, and the rotation error it leads to.

Pairs are rendered by ``stabilize synth``'s renderer at 480×270 with exact ground-truth
flow: a street (ground, walls, far background) under a handheld camera's rotation and
walking translation, with walking people. For each backend it prints the median ms
per pair when streaming frames (``backend.many``), the mean endpoint error (EPE) over
all pixels with ground truth, the mean angular error of ``rotation.HoughEstimator`` on
that flow against the true R_t, and the peak memory of the process that ran it.
With RAFT weights it also prints RAFT-small's arithmetic per pair and the time that
arithmetic alone takes at this machine's float32 matrix-product peak: the floor under
any exact (float32, direct-convolution) implementation here.

    python bench/flow_bench.py                       # DIS presets, RAFT if weights found
    python bench/flow_bench.py --raft-weights ../shared/raft/raft-small.pth
"""

from __future__ import annotations

import argparse
import multiprocessing as mp
import os
import resource
import time
from pathlib import Path

import numpy as np

SIZE = (270, 480)


def clips(n_frames: int, seeds: list[int]):
    """[(frames, flows, rotations, focal)] for each seed."""
    from stabilize.synth import SynthOptions, render_frames, trajectory

    out = []
    for seed in seeds:
        opts = SynthOptions(
            seed=seed, seconds=n_frames / 30.0, size=SIZE, crowd=12, shake_deg=1.0, walk=1.2
        )
        frames, flows = zip(*render_frames(opts, with_flow=True), strict=True)
        times = np.arange(opts.n_frames) / opts.fps
        R = trajectory.relative_rotations(opts.motion, times)
        out.append((list(frames), list(flows[:-1]), R, opts.focal))
    return out


def run_backend(name: str, options: dict, n_frames: int, seeds: list[int], queue) -> None:
    import flow
    from rotation import HoughEstimator, so3

    data = clips(n_frames, seeds)
    backend = flow.get(name, **options)
    list(backend.many(data[0][0][:2]))  # warm-up
    times, epe, rot = [], [], []
    for frames, truth, R, focal in data:
        estimator = HoughEstimator(SIZE, focal)
        t0 = time.perf_counter()
        predicted = list(backend.many(frames))
        times.append((time.perf_counter() - t0) / len(predicted))
        for f, gt, r in zip(predicted, truth, R, strict=True):
            ok = np.isfinite(gt).all(axis=-1)
            epe.append(float(np.linalg.norm(f - gt, axis=-1)[ok].mean()))
            rot.append(float(so3.angular_error_deg(estimator.estimate(f).matrix, r)))
        # Rotation from the exact flow, for reference.
    peak_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    queue.put((1e3 * float(np.median(times)), float(np.mean(epe)), float(np.mean(rot)), peak_mb))


def exact_flow_rotation_error(n_frames: int, seeds: list[int]) -> float:
    from rotation import HoughEstimator, so3

    errs = []
    for _frames, truth, R, focal in clips(n_frames, seeds):
        estimator = HoughEstimator(SIZE, focal)
        errs += [
            so3.angular_error_deg(estimator.estimate(f).matrix, r)
            for f, r in zip(truth, R, strict=True)
        ]
    return float(np.mean(errs))


def raft_gflop_per_pair(weights: str | os.PathLike, iters: int = 12) -> float:
    """GFLOP (multiply-adds ×2) of one streamed pair: one frame's features and context,
    the correlation volume and ``iters`` updates, counted by torch's FlopCounterMode."""
    import torch
    from torch.utils.flop_counter import FlopCounterMode

    from flow.raft.backend import RaftFlow, padding

    model = RaftFlow("small", weights=weights, iters=iters, device="cpu").model
    left, right, top, bottom = padding(*SIZE)
    images = torch.rand(2, 3, SIZE[0] + top + bottom, SIZE[1] + left + right) * 255
    with torch.inference_mode():
        next_features = model.features(images[1:])  # the next pair's share
        with FlopCounterMode(display=False) as counter:
            features = model.features(images[:1])
            net, inp = model.context(images[:1])
            model.iterate(features, next_features, net, inp, iters)
    return counter.get_total_flops() / 1e9


def matmul_peak_gflops(n: int = 2048, repeats: int = 10) -> float:
    """float32 GFLOP/s of an n×n matrix product on all threads: the machine's practical peak."""
    import torch

    a, b = torch.randn(n, n), torch.randn(n, n)
    for _ in range(3):
        a @ b
    t0 = time.perf_counter()
    for _ in range(repeats):
        a @ b
    return 2 * n**3 * repeats / (time.perf_counter() - t0) / 1e9


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=16, help="frames per clip")
    parser.add_argument("--seeds", type=int, default=3, help="number of clips")
    parser.add_argument("--raft-weights", type=Path, default=None)
    args = parser.parse_args()
    seeds = list(range(args.seeds))
    weights = args.raft_weights or os.environ.get("STABILIZE_RAFT_WEIGHTS")
    if weights is None:
        shared = Path(__file__).resolve().parents[2] / "shared" / "raft" / "raft-small.pth"
        weights = shared if shared.is_file() else None

    runs = [("dis", {"preset": p}, f"dis ({p})") for p in ("ultrafast", "fast", "medium")]
    if weights:
        for iters in (12, 20):
            runs.append(
                (
                    "raft",
                    {"weights": str(weights), "iters": iters, "device": "cpu"},
                    f"raft small, {iters} it (cpu)",
                )
            )
    else:
        print("(no RAFT weights found: pass --raft-weights or set STABILIZE_RAFT_WEIGHTS)")

    print(f"{args.seeds} clips × {args.frames} frames at {SIZE[1]}×{SIZE[0]}")
    print(f"{'backend':28s}{'ms/pair':>10s}{'EPE px':>10s}{'rot err °':>12s}{'peak MB':>10s}")
    ctx = mp.get_context("spawn")  # a fresh process each, so peak memory is the backend's
    for name, options, label in runs:
        queue = ctx.Queue()
        proc = ctx.Process(target=run_backend, args=(name, options, args.frames, seeds, queue))
        proc.start()
        ms, epe, rot, peak = queue.get()
        proc.join()
        print(f"{label:28s}{ms:10.1f}{epe:10.3f}{rot:12.4f}{peak:10.0f}")
    print(
        f"{'exact flow (reference)':28s}{'':10s}{0.0:10.3f}"
        f"{exact_flow_rotation_error(args.frames, seeds):12.4f}"
    )
    if weights:
        gflop, peak = raft_gflop_per_pair(weights), matmul_peak_gflops()
        print(
            f"RAFT-small, 12 iterations: {gflop:.1f} GFLOP per pair; float32 matmul peak here "
            f"{peak:.0f} GFLOP/s, so the arithmetic alone takes {1e3 * gflop / peak:.0f} ms"
        )


if __name__ == "__main__":
    main()
