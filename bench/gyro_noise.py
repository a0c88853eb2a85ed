"""False alarms from gyro noise, and the gyro filter's effect on shock peaks, on a real record.

The record: `../shared/data/real/water_entry_rest_to_impact_20khz.csv` (an instrumented sphere
at rest for ~0.3 s with gravity on +x of the sensor, then free fall and a 47 g water entry with
tumbling), fed as the foundation motion of the bundled scenes. Per `input.gyro_filter` policy:
the bolted genset's mount events in the rest phase (each a false alarm; its bolts break in the
impact, after which its peaks are chaotic), and the peak mount force of the pump on elastomer
mounts (which stays elastic) over the whole record, against the unfiltered run.

    python3 bench/gyro_noise.py
"""

from __future__ import annotations

import dataclasses
import math
import sys
from pathlib import Path

import numpy as np

from mount_twin.commands.common import share_dir
from mount_twin.engine.batch import SampleBatch
from mount_twin.engine.engine import TwinEngine
from mount_twin.model.assemble import assemble
from mount_twin.scene.loader import load_scene_file

RECORD = (
    Path(__file__).resolve().parents[2] / "shared/data/real/water_entry_rest_to_impact_20khz.csv"
)
REST_END_S = 0.28
"""The record is at rest before this, s (its provenance says 'about 0-0.3 s at rest')."""
POLICIES = (("none", 50.0), ("lowpass", 200.0), ("lowpass", 50.0), ("ignore", 50.0))


def run(scene_file: str, policy: str, cutoff_hz: float, data: np.ndarray) -> tuple[int, float]:
    """(mount events in the rest phase, peak |mount force| N) of a run."""
    scene = load_scene_file(share_dir() / "config" / scene_file)
    scene = dataclasses.replace(
        scene,
        input=dataclasses.replace(
            scene.input,
            frame_id="",
            sensor_rpy=(0.0, -math.pi / 2, 0.0),  # sensor +x (up at rest) onto +z of F
            gyro_filter=policy,
            gyro_cutoff_hz=cutoff_hz,
        ),
    )
    engine = TwinEngine(assemble(scene))
    n = data.shape[0]
    out = engine.push(SampleBatch(data[:, 0] + 1.0, data[:, 1:4], data[:, 4:7], [""] * n))
    rest = sum(1 for e in engine.events if e.stamp < 1.0 + REST_END_S)
    peak = float(np.linalg.norm(out.wrenches[:, :, :3], axis=2).max())
    return rest, peak


def main() -> int:
    if not RECORD.exists():
        print(f"{RECORD} not found (the shared real recordings)", file=sys.stderr)
        return 1
    data = np.loadtxt(RECORD, delimiter=",", skiprows=1)
    print(f"{RECORD.name}: {data.shape[0]} samples, rest phase 0–{REST_END_S} s")
    print(
        f"{'gyro_filter':<12} {'cutoff Hz':>9} {'genset events at rest':>22} "
        f"{'pump peak |F| N':>16} {'vs none':>8}"
    )
    base = math.nan
    for policy, cutoff in POLICIES:
        rest, _ = run("genset_bolted_keyed.scene.yaml", policy, cutoff, data)
        _, peak = run("pump_8_mounts.scene.yaml", policy, cutoff, data)
        base = peak if policy == "none" else base
        cut = f"{cutoff:g}" if policy == "lowpass" else "-"
        print(f"{policy:<12} {cut:>9} {rest:>22} {peak:>16.5g} {peak / base:>8.4f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
