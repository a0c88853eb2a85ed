"""Real-time factors of the engine alone on the bundled scenes and their bags, in one run.

    python3 bench/bench_engine.py [--repeats 7]

For the pump under ship motion (1 kHz, 10 s) and the bolted, keyed genset under its shock
(10 kHz, 0.25 s): the bag's samples decoded once, then pushed in one batch into fresh engines
of the scene as it is configured (gyro filter, `auto`, rtol 1e-6), without and with the live
error estimate, and without it with `gyro_filter: none` (the cost of the shipped gyro filter);
the best of `--repeats` runs (push and flush; the start's equilibrium included). Side by
side with another tree: run it with that tree first on PYTHONPATH, alternating.
"""

from __future__ import annotations

import argparse
import dataclasses
import time

from mount_twin.commands.common import share_dir
from mount_twin.engine.engine import TwinEngine
from mount_twin.io.input_samples import read_samples
from mount_twin.model.assemble import assemble
from mount_twin.scene.loader import load_scene_file

CASES = (
    ("pump_8_mounts.scene.yaml", "ship_motion_1khz"),
    ("genset_bolted_keyed.scene.yaml", "genset_shock_10khz"),
)


def real_time_factor(scene, samples, repeats: int) -> float:
    """Record seconds per wall second of the best push of `samples` into a fresh engine."""
    model = assemble(scene)
    span = float(samples.stamps[-1] - samples.stamps[0])
    best = float("inf")
    for _ in range(repeats):
        engine = TwinEngine(model)
        t0 = time.perf_counter()
        engine.run(samples)  # push and flush: with the gyro delay, every sample answered
        best = min(best, time.perf_counter() - t0)
    return span / best


def main() -> None:
    """Print one line per scene: × real time without and with the estimate."""
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
            rtf = real_time_factor(variant, samples, args.repeats)
            figures.append(f"{rtf:6.1f}x real time {label}")
        print(f"{scene.name:22s} ({bag}): " + ", ".join(figures), flush=True)


if __name__ == "__main__":
    main()
