"""Real-time factors of the engine alone on the bundled scenes and their bags, in one run.

    python3 bench/bench_engine.py [--repeats 7]

For the pump under ship motion (1 kHz, 5 s) and the bolted, keyed genset under its shock
(10 kHz, 0.25 s): the bag's samples decoded once, then pushed in one batch into fresh engines
of the scene as it is configured (gyro filter, `auto`, rtol 1e-6), without and with the live
error estimate, and without it with `gyro_filter: none` (the cost of the shipped gyro filter);
the best of `--repeats` runs (push and flush; the start's equilibrium included), and how
that run's wall time splits between the compiled core's loop (`kernel.run_samples`: the
twin's steps, its outputs and the estimate) and the rest (Python: the start, intake, gyro
filter, delay line, reports). The three settings take their runs in turn, one of each a
repeat, so that a machine whose speed drifts over the minutes of a bench (a shared host's)
moves all three alike, and their ratio, the estimate's cost as shipped, is printed. Side by
side with another tree: run it with that tree first on PYTHONPATH, alternating.
"""

from __future__ import annotations

import argparse
import dataclasses
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from mount_twin.commands.common import share_dir
from mount_twin.engine import driver
from mount_twin.engine.batch import SampleBatch
from mount_twin.engine.engine import TwinEngine
from mount_twin.io.input_samples import read_samples
from mount_twin.model.assemble import assemble
from mount_twin.scene.description import Scene
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


@dataclass
class Best:
    """The best (shortest) push of one setting so far: its wall time and the core's share (s)."""

    wall: float = float("inf")
    core: float = 0.0

    def offer(self, wall: float, core: float) -> None:
        """Keep a push's times (s) if it is the shortest yet."""
        if wall < self.wall:
            self.wall, self.core = wall, core


def best_pushes(scenes: Sequence[Scene], samples: SampleBatch, repeats: int) -> list[Best]:
    """The best push of `samples` into a fresh engine of each scene, the scenes taking their
    pushes in turn (`repeats` rounds, one push each a round)."""
    models = [assemble(scene) for scene in scenes]
    bests = [Best() for _ in models]
    spent = [0.0]
    loop = driver.run_samples
    driver.run_samples = _timed(loop, spent)
    try:
        for _ in range(repeats):
            for model, best in zip(models, bests, strict=True):
                engine = TwinEngine(model)
                spent[0] = 0.0
                t0 = time.perf_counter()
                engine.run(samples)  # push and flush: with the gyro delay, every sample answered
                best.offer(time.perf_counter() - t0, spent[0])
    finally:
        driver.run_samples = loop
    return bests


def main() -> None:
    """Print per scene: × real time without and with the estimate, the time split, and the
    estimate's cost (with over without)."""
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--repeats", type=int, default=7, help="pushes per figure (best)")
    args = parser.parse_args()
    root = share_dir()
    for scene_file, bag in CASES:
        scene = load_scene_file(root / "config" / scene_file)
        samples = read_samples(root / "bags" / bag, scene.input)
        span = float(samples.stamps[-1] - samples.stamps[0])
        raw = dataclasses.replace(scene.input, gyro_filter="none")
        settings = (
            ("without the estimate", False, scene.input),
            ("with it", True, scene.input),
            ("without, gyro_filter none", False, raw),
        )
        variants = [
            dataclasses.replace(
                scene,
                integration=dataclasses.replace(scene.integration, error_estimate=estimate),
                input=spec,
            )
            for _, estimate, spec in settings
        ]
        bests = best_pushes(variants, samples, args.repeats)
        figures = [
            f"{span / best.wall:6.1f}x real time {label} "
            f"(core {1e3 * best.core:.1f} ms, rest {1e3 * (best.wall - best.core):.1f} ms)"
            for (label, _, _), best in zip(settings, bests, strict=True)
        ]
        figures.append(f"the estimate's cost as shipped: {bests[1].wall / bests[0].wall:.2f}x")
        print(f"{scene.name} ({bag}):\n  " + "\n  ".join(figures), flush=True)


if __name__ == "__main__":
    main()
