"""``stridefix-lab bench native-solver``: the Ceres coordinate solver (``stridefix_native``) against its
scipy twin (``stridefix_native_reference``) on one synthetic walk: the same problem (anchors every 4th
point), the same start, the same tolerances. Times are wall seconds around each call (the problem is
built beforehand); ``max_diff_m`` is the largest coordinate difference between the two solutions,
``*_rmse_m`` the error against the truth.

On a walk the minimum is flat (a free point's cross-track position on a straight stretch is only
second-order observable), so both solvers crawl near the end and may stop metres apart at nearly equal
cost: compare ``ceres_cost`` with ``scipy_cost`` as well as ``max_diff_m``. No target: the figures are
for reading (Kannan 2024, section 4).
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path
from typing import Any

import numpy as np
from stridefix_analyzer.firmware import Firmware

from stridefix_lab.bench.registry import Bench


def benchmark(n: int = 5000, seed: int = 0, tol: float = 1e-6, max_iterations: int = 1000) -> dict[str, Any]:
    """Ceres vs scipy (sparse Jacobian, LSMR) on :func:`stridefix_native_reference.make_problem`."""
    import stridefix_native  # the built modules (build/analyzer/native, analyzer/native/CMakeLists.txt)
    import stridefix_native_reference as reference

    pb = reference.make_problem(n=n, seed=seed)
    xy_gt = pb.pop("xy_gt")
    tols = {
        "function_tolerance": tol,
        "gradient_tolerance": tol,
        "parameter_tolerance": tol,
        "max_iterations": max_iterations,
    }
    t0 = time.perf_counter()
    ceres = stridefix_native.solve_coordinates(**pb, **tols)
    t_ceres = time.perf_counter() - t0
    t0 = time.perf_counter()
    ref = reference.solve_coordinates_ref(**pb, use_sparse=True, **tols)
    t_scipy = time.perf_counter() - t0

    def rmse(xy: np.ndarray) -> float:
        return float(np.sqrt(np.mean(np.sum((xy - xy_gt) ** 2, axis=1))))

    return {
        "n_points": n,
        "seed": seed,
        "n_anchors": int(pb["anchors_idx"].size),
        "n_pairs": int(pb["ranges_m"].size),
        "ceres_s": t_ceres,
        "scipy_s": t_scipy,
        "speedup": t_scipy / t_ceres,
        "ceres_iterations": ceres["iterations"],
        "scipy_iterations": ref["iterations"],
        "ceres_converged": ceres["converged"],
        "scipy_converged": ref["converged"],
        "initial_cost": ceres["initial_cost"],
        "ceres_cost": ceres["cost"],
        "scipy_cost": ref["cost"],
        "max_diff_m": float(np.max(np.abs(ceres["xy"] - ref["xy"]))),
        "ceres_rmse_m": rmse(ceres["xy"]),
        "scipy_rmse_m": rmse(ref["xy"]),
        "init_rmse_m": rmse(reference.default_init(n, pb["anchors_idx"], pb["anchors_xy"])),
    }


def _add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--n", type=int, default=5000, help="points in the synthetic walk (default 5000)")
    p.add_argument("--tol", type=float, default=1e-6, help="function/gradient/parameter tolerance")
    p.add_argument("--max-iterations", type=int, default=1000)


def _run(args: argparse.Namespace, firmware: Firmware, seeds: list[int], out: Path) -> list[str]:
    del firmware  # no replay
    result = benchmark(n=args.n, seed=seeds[0], tol=args.tol, max_iterations=args.max_iterations)
    text = json.dumps(result, indent=2)
    print(text)
    out.mkdir(parents=True, exist_ok=True)
    (out / "native_solver.json").write_text(text + "\n")
    print(f"wrote {out / 'native_solver.json'}")
    return []


BENCH = Bench(
    "native-solver",
    "the Ceres coordinate solver against its scipy twin on a synthetic walk (times, costs, agreement)",
    _run,
    seeds="0",
    add_arguments=_add_arguments,
    needs_firmware=False,
    in_make_bench=True,
)
