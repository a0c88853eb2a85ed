"""The start gravity from one sample against the mean over a window, on real records at rest.

A start takes the mean specific force of its first samples as gravity
(`initial_state.gravity_window_s`, `gravity_samples`). For each real record's quiet stretch
(the shared recordings, `../shared/data/real`, see its README) the truth is the mean over the
whole stretch; for every start position in it, the start's error is the angle (rad) between
the mean of the samples a window of T takes from there and that truth (the start attitude's
error: the start equilibrium leans by it, and every mount takes m·g·sin(angle) of the weight
sideways until the start transient decays), and | |mean| − |truth| | (m/s²). Printed: rms,
95th percentile and largest over the start positions, per record and window; and how far from
the mean, and how often past the start check's 0.1 g ("not at rest"), the farthest sample (the
check before) and the farthest mean of one of REST_BLOCKS parts (the check now) lie.

Then the bundled pump on the whole water-entry record (rest, release, 47 g entry; sensor
turned so gravity on +x is +z of F): its mount forces, started from one sample and from the
default 50 ms, against the same twin started under the mean of the whole 0.28 s at rest.

    python3 bench/start_gravity.py [--data ../shared/data/real]
"""

from __future__ import annotations

import argparse
import dataclasses
import math
from pathlib import Path

import numpy as np

from mount_twin.commands.common import share_dir
from mount_twin.engine.batch import SampleBatch
from mount_twin.engine.engine import TwinEngine
from mount_twin.engine.starts import REST_BLOCKS
from mount_twin.io.input_samples import read_samples
from mount_twin.io.xsens_csv import read_xsens_csv
from mount_twin.model.assemble import assemble
from mount_twin.scene.description import STANDARD_GRAVITY, InputSpec
from mount_twin.scene.loader import load_scene_file

WINDOWS_S = (0.0, 0.005, 0.01, 0.02, 0.05, 0.1, 0.2)
"""Window lengths T, s (0: the start sample alone)."""
XSENS = ("sine_2hz_trial1_ground", "sine_2hz_trial1_top", "el_centro_trial1_ground")
"""Shake-table files at rest for their first 3 s (0.5 s blocks under 0.02 m/s² std)."""


def water_entry(data: Path) -> tuple[np.ndarray, np.ndarray]:
    """The sphere at rest before its release (0-0.28 s), 20 kHz: stamps s, f m/s² (sensor)."""
    d = np.loadtxt(data / "water_entry_rest_to_impact_20khz.csv", delimiter=",", skiprows=1)
    rest = d[:, 0] < 0.28
    return d[rest, 0], d[rest, 1:4]


def xsens(data: Path, name: str) -> tuple[np.ndarray, np.ndarray]:
    """A shake-table sensor's first 3 s, 120 Hz (the table still): stamps s, f m/s²."""
    signal = read_xsens_csv(data / "shake_table_1story" / f"{name}.csv").signal
    t = signal.t - signal.t[0]
    still = t < 3.0
    return t[still], signal.accel[still]


def vehicle(data: Path) -> tuple[np.ndarray, np.ndarray]:
    """The ground vehicle's IMU, 30 Hz, over 8 s it stands nearly still (from 236 s)."""
    batch = read_samples(data / "vehicle_imu_30hz_mcap", InputSpec(topic="/imu/data"))
    t = batch.stamps - batch.stamps[0]
    still = (t >= 236.0) & (t < 244.0)
    return t[still], batch.accel[still]


def angle(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Angle (rad) between each row of a and the vector b."""
    return np.arctan2(np.linalg.norm(np.cross(a, b), axis=1), a @ b)


def windows(
    t: np.ndarray, f: np.ndarray, window_s: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """For each start position k whose window fits in the record, over samples k to the last
    within window_s after t[k]: their mean, the largest distance of one of them from it (the
    start check before), and that of the mean of one of REST_BLOCKS parts of them (now)."""
    ends = np.searchsorted(t, t + window_s + 1e-9, side="right")
    fits = np.flatnonzero(ends < t.shape[0])
    means, spread, parts = np.empty((fits.shape[0], 3)), np.empty(fits.shape[0]), []
    for i, k in enumerate(fits):
        taken = f[k : ends[k]]
        means[i] = taken.mean(axis=0)
        spread[i] = np.linalg.norm(taken - means[i], axis=1).max()
        blocks = np.array_split(taken, min(REST_BLOCKS, taken.shape[0]))
        parts.append(max(np.linalg.norm(b.mean(axis=0) - means[i]) for b in blocks))
    return means, spread, np.array(parts)


def pump_forces(data: Path) -> None:
    """The pump's mount forces on the whole water-entry record by start window (see the
    module), against a start under the 0.28 s mean at rest."""
    d = np.loadtxt(data / "water_entry_rest_to_impact_20khz.csv", delimiter=",", skiprows=1)
    samples = SampleBatch(d[:, 0], d[:, 1:4], d[:, 4:7], [""] * d.shape[0])
    pump = load_scene_file(share_dir() / "config" / "pump_8_mounts.scene.yaml")
    spec = dataclasses.replace(pump.input, frame_id="", sensor_rpy=(0.0, -math.pi / 2, 0.0))
    forces = {}
    for window_s in (0.0, 0.05, 0.28):
        initial = dataclasses.replace(pump.initial, gravity_window_s=window_s)
        scene = dataclasses.replace(pump, input=spec, initial=initial)
        forces[window_s] = TwinEngine(assemble(scene)).run(samples).wrenches[:, :, :3]
    truth = forces.pop(0.28)
    share = pump.body.mass * STANDARD_GRAVITY / len(pump.mounts)
    peak = np.linalg.norm(truth, axis=2).max(axis=0)
    for window_s, f in forces.items():
        off = np.abs(f - truth).max()
        moved = np.abs(np.linalg.norm(f, axis=2).max(axis=0) / peak - 1.0).max()
        print(
            f"pump, start window {1e3 * window_s:g} ms: mount forces up to {off:.1f} N "
            f"({off / share:.1%} of a mount's share of the weight) off; peak forces moved "
            f"{moved:.2%} at most"
        )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    default = Path(__file__).resolve().parents[2] / "shared/data/real"
    parser.add_argument("--data", type=Path, default=default)
    data = parser.parse_args().data
    if not data.is_dir():  # the recordings are not in the repository
        parser.error(f"--data {data}: no such directory (the real recordings, see its README)")
    records = {"water entry, 20 kHz (0-0.28 s)": water_entry(data)}
    records |= {f"{n}, 120 Hz (0-3 s)": xsens(data, n) for n in XSENS}
    records["vehicle, 30 Hz (236-244 s)"] = vehicle(data)
    print(
        "record | T ms | samples | tilt rms | p95 | max rad | |f| err rms m/s² | "
        "spread max g, 'not at rest' | parts max g, 'not at rest'"
    )
    g = STANDARD_GRAVITY
    for name, (t, f) in records.items():
        truth = f.mean(axis=0)
        for window_s in WINDOWS_S:
            means, spread, parts = windows(t, f, window_s)
            e = angle(means, truth)
            mag = np.linalg.norm(means, axis=1) - np.linalg.norm(truth)
            n = np.searchsorted(t, t[0] + window_s + 1e-9, side="right")
            print(
                f"{name} | {1e3 * window_s:g} | {n} | {np.sqrt(np.mean(e**2)):.2e} | "
                f"{np.percentile(e, 95):.2e} | {e.max():.2e} | {np.sqrt(np.mean(mag**2)):.3f} | "
                f"{spread.max() / g:.3f}, {np.mean(spread > 0.1 * g):.0%} | "
                f"{parts.max() / g:.3f}, {np.mean(parts > 0.1 * g):.0%}"
            )
    pump_forces(data)


if __name__ == "__main__":
    main()
