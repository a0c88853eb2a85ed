"""Real-time factors of the engine alone on the bundled scenes and their bags, in one run.

    python3 bench/bench_engine.py [--repeats 7]

For the pump under ship motion (1 kHz, 5 s) and the bolted, keyed genset under its shock
(10 kHz, 0.25 s): the bag's samples decoded once, then pushed in one batch into fresh engines
of the scene as it is configured (gyro filter, `auto`, rtol 1e-6), without and with the live
error estimate, and without it with `gyro_filter: none` (the cost of the shipped gyro filter);
the best of `--repeats` runs (push and flush; the start's equilibrium included), and how
that run's wall time splits between the compiled core's loop (`kernel.run_samples`: the
twin's steps, its outputs and the estimate) and the rest (Python: the start, intake, gyro
filter, delay line, reports). Side by side with another tree: run it with that tree first on
PYTHONPATH, alternating.
"""

from __future__ import annotations

import argparse
import dataclasses
import time
from collections.abc import Callable

from mount_twin.commands.common import share_dir
from mount_twin.engine import driver
from mount_twin.engine.engine import TwinEngine
from mount_twin.io.input_samples import read_samples
from mount_twin.model.assemble import assemble
from mount_twin.scene.loader import load_scene_file

CASES = (
    ("pump_8_mounts.scene.yaml", "ship_motion_1khz"),
    ("genset_bolted_keyed.scene.yaml", "genset_shock_10khz"),
)


def _timed(loop: Callable, spent: list[float]) -> Callable:
    """`loop` adding its wall time (s) to spent[0]: the bench's instrument on the core's loop."""

    def timed(*args):
        t0 = time.perf_counter()
        try:
            return loop(*args)
        finally:
            spent[0] += time.perf_counter() - t0

    return timed


def real_time_factor(scene, samples, repeats: int) -> tuple[float, float, float]:
    """Record seconds per wall second of the best push of `samples` into a fresh engine, and
    that push's wall time (s) in the core's loop and outside it."""
    model = assemble(scene)
    span = float(samples.stamps[-1] - samples.stamps[0])
    best, core = float("inf"), 0.0
    spent = [0.0]
    loop = driver.run_samples
    driver.run_samples = _timed(loop, spent)
    try:
        for _ in range(repeats):
            engine = TwinEngine(model)
            spent[0] = 0.0
            t0 = time.perf_counter()
            engine.run(samples)  # push and flush: with the gyro delay, every sample answered
            wall = time.perf_counter() - t0
            if wall < best:
                best, core = wall, spent[0]
    finally:
        driver.run_samples = loop
    return span / best, core, best - core


def main() -> None:
    """Print per scene: × real time without and with the estimate, and the time split."""
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--repeats", type=int, default=7, help="pushes per figure (best)")
    args = parser.parse_args()
    root = share_dir()
    for scene_file, bag in CASES:
        scene = load_scene_file(root / "config" / scene_file)
        samples = read_samples(root / "bags" / bag, scene.input)
        figures = []
        raw = dataclasses.replace(scene.input, gyro_filter="none")
        for label, estimate, spec in (
            ("without the estimate", False, scene.input),
            ("with it", True, scene.input),
            ("without, gyro_filter none", False, raw),
        ):
            integ = dataclasses.replace(scene.integration, error_estimate=estimate)
            variant = dataclasses.replace(scene, integration=integ, input=spec)
            rtf, core, rest = real_time_factor(variant, samples, args.repeats)
            figures.append(
                f"{rtf:6.1f}x real time {label} "
                f"(core {1e3 * core:.1f} ms, rest {1e3 * rest:.1f} ms)"
            )
        print(f"{scene.name} ({bag}):\n  " + "\n  ".join(figures), flush=True)


if __name__ == "__main__":
    main()
