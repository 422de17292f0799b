"""Rotation estimator benchmark: median ms per frame pair and mean angular error.

Settings follow the paper: flow 480×270, f = 413.75 px, a flow vector every 15 px
(576 vectors), rotations up to 2°. Four synthetic sets with exact truth come from
:mod:`rotation.synthetic`: pure rotation; pure + 60% random outliers + 0.5 px noise;
a street (walking translation, 12 people, 0.4 px noise, 10% gross errors); a crowd
(30 people, 0.6 px noise, 20% gross errors). A last row checks a 10° rotation per
frame with a 15° search range.

    python bench/rotation_bench.py            # 200 fields per set
    python bench/rotation_bench.py --quick    # 40 fields per set, a few seconds
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable

import numpy as np

from rotation import HoughEstimator, RotationEstimate, baselines, so3
from rotation.synthetic import SCENARIOS, FlowSet, make_set

SIZE = (270, 480)
FOCAL = 413.75


def run(method: Callable[[np.ndarray], RotationEstimate], data: FlowSet) -> tuple[float, float]:
    """(median ms per field, mean angular error in degrees) of one method on one set."""
    method(data.flows[0])  # warm-up: JIT compilation and caches
    times, errors = [], []
    for flow, R in zip(data.flows, data.rotations, strict=True):
        t0 = time.perf_counter()
        est = method(flow)
        times.append(time.perf_counter() - t0)
        errors.append(so3.angular_error_deg(est.matrix, R))
    return 1e3 * float(np.median(times)), float(np.mean(errors))


def run_many(estimator: HoughEstimator, data: FlowSet) -> tuple[float, float]:
    estimator.estimate_many(data.flows[:4])
    t0 = time.perf_counter()
    results = estimator.estimate_many(data.flows)
    ms = 1e3 * (time.perf_counter() - t0) / len(data.flows)
    pairs = zip(results, data.rotations, strict=True)
    return ms, float(np.mean([so3.angular_error_deg(r.matrix, R) for r, R in pairs]))


def methods(quick: bool) -> dict[str, Callable[[np.ndarray], RotationEstimate]]:
    hough = HoughEstimator(SIZE, FOCAL)
    table = {
        "hough (LH, refined)": hough.estimate,
        "hough (LH, bin centre)": HoughEstimator(SIZE, FOCAL, refine=False).estimate,
        "hough (perspective, refined)": HoughEstimator(SIZE, FOCAL, model="perspective").estimate,
        "hough (perspective, bin centre)": HoughEstimator(
            SIZE, FOCAL, model="perspective", refine=False
        ).estimate,
        "least squares (LH)": lambda f: baselines.least_squares(f, FOCAL),
        "ransac (LH, 500 it)": lambda f: baselines.ransac(f, FOCAL, iterations=500),
        "five-point (OpenCV)": lambda f: baselines.five_point(f, FOCAL),
    }
    if quick:
        table.pop("hough (perspective, bin centre)")
    return table


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="40 fields per set instead of 200")
    parser.add_argument("-n", type=int, default=None, help="fields per set")
    parser.add_argument("--seed", type=int, default=2023)
    args = parser.parse_args()
    n = args.n or (40 if args.quick else 200)

    sets = {name: make_set(name, n, seed=args.seed + i) for i, name in enumerate(SCENARIOS)}
    header = f"{'method':34s}" + "".join(f"{name:>20s}" for name in sets)
    print(f"{n} fields per set; each cell: median ms per pair / mean angular error (deg)")
    print(header)
    print("-" * len(header))
    for label, method in methods(args.quick).items():
        cells = [run(method, data) for data in sets.values()]
        print(f"{label:34s}" + "".join(f"{ms:9.2f} / {err:8.4f}" for ms, err in cells))

    hough = HoughEstimator(SIZE, FOCAL)
    cells = [run_many(hough, data) for data in sets.values()]
    print(f"{'hough estimate_many':34s}" + "".join(f"{ms:9.2f} / {err:8.4f}" for ms, err in cells))

    fast = make_set("pure", n, seed=args.seed, min_deg=10.0, max_deg=10.0)
    street = make_set("street", n, seed=args.seed, min_deg=10.0, max_deg=10.0)
    wide = HoughEstimator(SIZE, FOCAL, max_deg=15.0)
    (ms_p, err_p), (ms_s, err_s) = run(wide.estimate, fast), run(wide.estimate, street)
    print(
        f"\n10° per frame, max_deg=15: pure {ms_p:.2f} ms / {err_p:.4f}°, "
        f"street {ms_s:.2f} ms / {err_s:.4f}°"
    )

    many = make_set("street", 300, seed=args.seed + 7)
    ms, err = run_many(hough, many)
    print(f"estimate_many over 300 street fields: {ms:.3f} ms per field ({err:.4f}°)")


if __name__ == "__main__":
    main()
