"""Error against run time of the default scene's stepper, in one run.

    python3 bench/work_precision.py

For a 10 s ship-motion segment and a 150 m/s² half-sine deck shock (both 1 kHz input), the
twin runs at several tolerances; each run's largest CG position (m), attitude (rad) and relative
mount-force error is taken against the same twin at rtol 1e-12, atol 1e-15, and its cost in µs
per input sample is measured alongside. The reference is the twin's own formulation: the physics
tests hold that against independent solutions.
"""

from __future__ import annotations

import dataclasses
import time

import numpy as np

from mount_twin.commands.common import DEFAULT_SCENE, share_dir
from mount_twin.engine.batch import OutputBatch, SampleBatch
from mount_twin.engine.engine import TwinEngine
from mount_twin.io.signals import Signal, half_sine_shock, ship_motion
from mount_twin.model.assemble import assemble
from mount_twin.scene.description import Scene
from mount_twin.scene.loader import load_scene_file

TOLERANCES = ((1e-4, 1e-7), (1e-6, 1e-9), (1e-8, 1e-11))


def run(scene: Scene, rtol: float, atol: float, sig: Signal) -> tuple[OutputBatch, float]:
    """Outputs and wall time per input sample (s) of one run."""
    integ = dataclasses.replace(scene.integration, rtol=rtol, atol=atol, max_substeps=100_000)
    engine = TwinEngine(assemble(dataclasses.replace(scene, integration=integ)))
    frames = [scene.input.frame_id] * len(sig.t)
    t0 = time.perf_counter()
    out = engine.push(SampleBatch(sig.t, sig.accel, sig.gyro, frames))
    return out, (time.perf_counter() - t0) / len(sig.t)


def main() -> None:
    """Print one line per signal and tolerance."""
    scene = load_scene_file(share_dir() / "config" / DEFAULT_SCENE)
    signals = {
        "ship motion 10 s": ship_motion(rate_hz=1000.0, total=10.0),
        "deck shock 1 s": half_sine_shock(
            peak=150.0, duration=0.011, rate_hz=1000.0, pre=0.1, total=1.0
        ),
    }
    print(f"{scene.name}: {scene.integration.method}, error against rtol 1e-12")
    for name, sig in signals.items():
        ref, _ = run(scene, 1e-12, 1e-15, sig)
        for rtol, atol in TOLERANCES:
            out, cost = run(scene, rtol, atol, sig)
            pos = np.abs(out.position - ref.position).max()
            ang = np.abs(out.angles - ref.angles).max()
            force = np.abs(out.wrenches - ref.wrenches).max() / np.abs(ref.wrenches).max()
            print(
                f"  {name:17} rtol {rtol:.0e}: CG {pos:.1e} m, attitude {ang:.1e} rad, "
                f"mount force {force:.1e} (relative), {cost * 1e6:5.1f} µs/sample"
            )


if __name__ == "__main__":
    main()
