"""The shipped gyro conditioning (`input.gyro_filter`, default `linear_phase`) against raw.

1. Noise-free rotating decks (`analysis/deck_motion.py`: rolling 1, 5, 20 Hz, a ship's deck)
   under the bundled pump, sensor off its CG: the largest mount-force error relative to the
   largest mount force, and the attitude error, of each policy against the raw-gyro twin
   (`gyro_filter: none`) at the same stamps.
2. Gyro noise at rest under the bundled genset (bolted joints that slip): its mount events
   (each a false alarm) on the real record's rest phase
   (`../shared/data/real/water_entry_rest_to_impact_20khz.csv`, gravity on +x of the sensor) and
   on a synthetic 20 kHz record with 0.02 rad/s white gyro noise.
3. The latency of `linear_phase` at 1, 10 and 20 kHz, and the pump's peak mount force over the
   whole real record (47 g water entry with tumbling) against the raw gyro.

    python3 bench/gyro_noise.py
"""

from __future__ import annotations

import dataclasses
import math
import sys
from pathlib import Path

import numpy as np

from mount_twin.analysis.deck_motion import SHIP, DeckMotion, deck_samples, rolling
from mount_twin.commands.common import share_dir
from mount_twin.engine.batch import OutputBatch, SampleBatch
from mount_twin.engine.engine import TwinEngine
from mount_twin.model.assemble import assemble
from mount_twin.scene.description import Scene
from mount_twin.scene.loader import load_scene_file

RECORD = (
    Path(__file__).resolve().parents[2] / "shared/data/real/water_entry_rest_to_impact_20khz.csv"
)
REST_END_S = 0.28
"""The record is at rest before this, s (its provenance says 'about 0-0.3 s at rest')."""
POLICIES = ("linear_phase", "ignore")
DECKS: tuple[tuple[str, DeckMotion, float], ...] = (
    ("roll 1 Hz 0.05 rad", rolling(0.05, 1.0), 6.0),
    ("roll 5 Hz 0.02 rad", rolling(0.02, 5.0), 4.0),
    ("roll 20 Hz 0.005 rad", rolling(0.005, 20.0), 3.0),
    ("ship deck, 6 DOF", SHIP, 20.0),
)
"""(name, motion, duration s)."""
SENSOR_OFF_CG = (0.6, -0.35, -0.25)
"""Where the pump's sensor is put, m in F: off the CG, so rotation reaches it as lever arm."""


def scene(file: str, **fields: object) -> Scene:
    """A bundled scene with input fields replaced (any frame_id accepted)."""
    loaded = load_scene_file(share_dir() / "config" / file)
    spec = dataclasses.replace(loaded.input, frame_id="", **fields)  # type: ignore[arg-type]
    return dataclasses.replace(loaded, input=spec)


def run(sc: Scene, samples: SampleBatch) -> tuple[OutputBatch, TwinEngine]:
    """Every output of the twin over `samples` (`TwinEngine.run`), and the engine."""
    engine = TwinEngine(assemble(sc))
    return engine.run(samples), engine


def errors(out: OutputBatch, ref: OutputBatch) -> tuple[float, float]:
    """(max mount-force error / max |mount force|, max attitude error rad) at the same stamps."""
    assert np.array_equal(out.stamps, ref.stamps), "runs answer different samples"
    force, force_ref = out.wrenches[:, :, :3], ref.wrenches[:, :, :3]
    return (
        float(np.abs(force - force_ref).max() / np.abs(force_ref).max()),
        float(np.abs(out.angles - ref.angles).max()),
    )


def rest_events(sc: Scene, samples: SampleBatch, rest_end_s: float) -> int:
    """Mount events before `rest_end_s` (s, a stamp)."""
    _, engine = run(sc, samples)
    return sum(1 for e in engine.events if e.stamp < rest_end_s)


def main() -> int:
    print("1. noise-free rotating decks, 1 kHz, pump with its sensor off the CG, vs gyro raw")
    print(f"{'deck':<22} {'gyro_filter':<13} {'force err':>10} {'attitude rad':>13}")
    for name, motion, duration in DECKS:
        samples = deck_samples(motion, 1000.0, duration)
        ref, _ = run(
            scene("pump_8_mounts.scene.yaml", sensor_position=SENSOR_OFF_CG, gyro_filter="none"),
            samples,
        )
        for policy in POLICIES:
            out, _ = run(
                scene(
                    "pump_8_mounts.scene.yaml", sensor_position=SENSOR_OFF_CG, gyro_filter=policy
                ),
                samples,
            )
            force, attitude = errors(out, ref)
            print(f"{name:<22} {policy:<13} {force:>10.2g} {attitude:>13.2g}")

    print("\n2. gyro noise at rest: genset mount events (false alarms)")
    rng = np.random.default_rng(7)
    n = 10_000
    t = 1.0 + np.arange(n) / 20_000.0
    accel = np.tile([0.0, 0.0, 9.80665], (n, 1))
    noise = SampleBatch(t, accel, 0.02 * rng.standard_normal((n, 3)), [""] * n)
    cases = [("synthetic 20 kHz, 0.02 rad/s", noise, {}, 2.0)]
    if RECORD.exists():
        data = np.loadtxt(RECORD, delimiter=",", skiprows=1)
        real = SampleBatch(data[:, 0] + 1.0, data[:, 1:4], data[:, 4:7], [""] * data.shape[0])
        turned = {"sensor_rpy": (0.0, -math.pi / 2, 0.0)}  # sensor +x (up at rest) onto +z
        cases.append(("real rest 0-0.28 s", real, turned, 1.0 + REST_END_S))
    else:
        print(f"   ({RECORD} not found: the real record is skipped)")
    print(f"{'record':<30} " + " ".join(f"{p:>13}" for p in ("none", *POLICIES)))
    for name, samples, fields, end in cases:
        counts = [
            rest_events(
                scene("genset_bolted_keyed.scene.yaml", gyro_filter=p, **fields), samples, end
            )
            for p in ("none", *POLICIES)
        ]
        print(f"{name:<30} " + " ".join(f"{c:>13}" for c in counts))

    print("\n3. latency of linear_phase")
    for rate in (1000.0, 10_000.0, 20_000.0):
        _, engine = run(
            scene("pump_8_mounts.scene.yaml"), deck_samples(rolling(0.0, 1.0), rate, 0.5)
        )
        print(f"   {rate:>7g} Hz: {engine.latency} samples = {engine.latency / rate * 1e3:.2f} ms")
    if RECORD.exists():
        turned = {"sensor_rpy": (0.0, -math.pi / 2, 0.0)}
        peaks = {
            p: float(
                np.linalg.norm(
                    run(scene("pump_8_mounts.scene.yaml", gyro_filter=p, **turned), real)[
                        0
                    ].wrenches[:, :, :3],
                    axis=2,
                ).max()
            )
            for p in ("none", *POLICIES)
        }
        print(
            "   pump peak |F| over the real water entry: "
            + ", ".join(
                f"{p} {v:.5g} N ({v / peaks['none'] - 1.0:+.2%})" for p, v in peaks.items()
            )
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
