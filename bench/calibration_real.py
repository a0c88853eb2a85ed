"""The real shake-table pair: calibrate on one run, predict the others (issue 24's figure).

For each run, the block sensor's normalised RMS error of the notebook's scene and of the scene
calibrated on `--fit-on`, broadband and below 10 Hz, over all three axes and along the shaking
direction (the sensors' x). The repository holds 16 s excerpts of the two sine runs; the whole
records (El Centro too) are where the excerpt's README says they come from.

    python3 bench/calibration_real.py
    python3 bench/calibration_real.py --data ../shared/data/real/shake_table_1story --suffix ""
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

from mount_twin import load_scene_file
from mount_twin.analysis.calibration import calibrate, prediction_error
from mount_twin.io.xsens_csv import read_xsens_csv

ROOT = Path(__file__).resolve().parents[1]
RUNS = ("sine_2hz_trial1", "sine_2hz_trial2", "el_centro_trial1")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", type=Path, default=ROOT / "test/data/shake_table_1story")
    parser.add_argument("--suffix", default="_excerpt", help="file name suffix of the records")
    parser.add_argument("--fit-on", default=RUNS[0])
    args = parser.parse_args()
    scene = load_scene_file(ROOT / "test/data/shake_table_1story/block.scene.yaml")
    pairs = {}
    for run in RUNS:
        files = [args.data / f"{run}_{side}{args.suffix}.csv" for side in ("ground", "top")]
        if all(f.exists() for f in files):
            pairs[run] = tuple(read_xsens_csv(f).signal for f in files)
    t0 = time.process_time()
    cal = calibrate(scene, *pairs[args.fit_on])
    print(f"calibrated on {args.fit_on} in {time.process_time() - t0:.1f} s CPU:")
    for name, value in cal.values.items():
        shown = math.degrees(value) if name == "yaw" else value * 1e3 if name == "lag" else value
        unit = "°" if name == "yaw" else " ms" if name == "lag" else "×"
        print(f"  {name} {shown:.4g}{unit}", cal.refused.get(name, ""))
    print(f"{'run':<18} {'axes':<6} {'band':<8} {'before':>7} {'after':>7}")
    for run, pair in pairs.items():
        for axes, label in ((slice(None), "xyz"), (slice(0, 1), "x")):
            for below, band in ((None, "all"), (10.0, "<10 Hz")):
                before = prediction_error(scene, pair, axes, below)
                after = prediction_error(cal.scene, pair, axes, below)
                print(f"{run:<18} {label:<6} {band:<8} {before:7.3f} {after:7.3f}")


if __name__ == "__main__":
    main()
