"""Mounts that age, through the replay the node equals: no false alarm on an unchanged
machine, and a flag soon after a change.

The pump (its body IMU on the frame, 200 Hz, 0.01 m/s² of noise on both IMUs) under ship
motion with machinery vibration, replayed with an `ageing` section (windows of `--window` s)
and the body IMU comparison (windows of 10 s); prints every ageing window and the worst
body sensor window, and the CPU time. With `--change S` every mount loses 30 % of its
stiffness at S seconds (default: never).

    python3 bench/ageing_live.py [--minutes 10] [--window 60] [--change S]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import yaml

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "test"))

from io_helpers import SCENE_FILE, ageing_bag, read_raw, statuses_named

from mount_twin.analysis.ageing_live import NAME as AGEING
from mount_twin.engine.agreement import NAME as BODY
from mount_twin.engine.batch import LEVEL_NAMES
from mount_twin.replay import replay
from mount_twin.scene import load_scene_file


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--minutes", type=float, default=10.0)
    parser.add_argument("--window", type=float, default=60.0)
    parser.add_argument("--change", type=float, default=float("inf"))
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        data = yaml.safe_load(SCENE_FILE.read_text(encoding="utf-8"))
        data["input"]["gyro_filter"] = "none"
        data["body_sensor"] = {"topic": "/machine/imu", "position": [0.8, 0.3, 1.0]}
        data["ageing"] = {"window_s": args.window}
        (d / "pump.scene.yaml").write_text(yaml.safe_dump(data), encoding="utf-8")
        scene = load_scene_file(d / "pump.scene.yaml")
        total = args.minutes * 60.0 + 2.5
        ageing_bag(d / "in", scene, total, args.change, "/machine/imu")
        t0 = time.process_time()
        summary = replay(scene, d / "in", d / "out", progress=False)
        cpu = time.process_time() - t0
        raws = [raw for _, raw in read_raw(d / "out")["/diagnostics"]]
        for _, level, message, _ in statuses_named(raws, AGEING):
            print(f"{LEVEL_NAMES[level]:5} {message}")
        body = statuses_named(raws, BODY)
        worst = max(body, key=lambda s: s[1])
        print(f"body sensor: {len(body)} windows, worst {LEVEL_NAMES[worst[1]]}: {worst[2]}")
        levels = " ".join(LEVEL_NAMES[level][0] for _, level, _, _ in body)
        print(f"body sensor windows (O/W/E), one per 10 s (the default): {levels}")
        print(f"replay of {total:.1f} s: {cpu:.1f} s CPU, verdict {summary.verdict}")


if __name__ == "__main__":
    main()
