"""CPU time per message of the live node's small wake-ups, in process, without DDS.

    python3 bench/bench_wakeup.py [--scene config/pump_8_mounts.scene.yaml] [--rate 1000]
        [--per 1] [--seconds 3] [--repeats 5] [--body] [--against /path/to/another/tree]

What the node does with each wake-up's messages, `--per` at a time: `TwinStream.process` of
the raw Imu messages (decode, engine, encode) and `messages_of` of its outputs, the bytes it
would publish. The input is `--seconds` of Imu at `--rate` Hz, a small vibration about
rest (x: 0.3 m/s² at 3 Hz, z: 9.80665 + 0.5 m/s² at 7 Hz, Ω_x: 0.01 rad/s at 2 Hz), its
first half second left out of the figure (the twin's start, the gyro filter's design). With
`--body`, a body IMU's stream alongside, as a scene with a `body_sensor` has the node take it:
after each wake-up of the deck's, one of as many body messages (`TwinStream.process_body`),
stamped half a sample after the deck's and reading the same motion, in the body sensor's
frame_id; the scene must have a body_sensor (default: the bundled one that has,
`BODY_SCENE`), and the figure is per deck message, its body message's work included.
Printed per repeat: process CPU time (µs) per message, each repeat in a process of its own.
With `--against`, that tree (its package imported through PYTHONPATH) and this one
alternately, then the medians and their ratio: a before/after of one run on a shared machine.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parents[1]
SCENE = HERE / "config/pump_8_mounts.scene.yaml"
"""The scene without --scene."""
BODY_SCENE = HERE / "test/data/shake_table_1story/block.scene.yaml"
"""The scene with --body and without --scene: the bundled one with a body_sensor (the shake
table's block, one DOF)."""
WARM_S = 0.5
"""Input (s) pushed before the clock starts."""


def per_message_us(scene_path: str, rate_hz: float, seconds: float, per: int, body: bool) -> float:
    """CPU time (µs) per message of `per`-message wake-ups, after WARM_S of input; with `body`,
    each followed by a wake-up of as many body IMU messages (µs per deck message, its body
    message's included). SystemExit where `body` and the scene has no body_sensor."""
    import numpy as np

    from mount_twin.io.output_encoding import imu_messages, messages_of
    from mount_twin.scene.loader import load_scene_file
    from mount_twin.stream import TwinStream

    scene = load_scene_file(scene_path)
    if body and scene.body_sensor is None:
        sys.exit(f"{scene_path}: no body_sensor, which --body needs")
    n = int(rate_hz * seconds)
    t = np.arange(n) / rate_hz
    stamps = 1_700_000_000_000_000_000 + np.round(t * 1e9).astype(np.int64)
    accel, gyro = np.zeros((n, 3)), np.zeros((n, 3))
    accel[:, 0] = 0.3 * np.sin(2 * np.pi * 3.0 * t)
    accel[:, 2] = 9.80665 + 0.5 * np.sin(2 * np.pi * 7.0 * t)
    gyro[:, 0] = 0.01 * np.sin(2 * np.pi * 2.0 * t)
    frame_id = scene.input.frame_id or "deck_imu"
    raws = [raw for _, raw in imu_messages(stamps, accel, gyro, frame_id)]
    body_raws: list[bytes] = []
    if body and scene.body_sensor is not None:
        # half a sample after each deck sample, the same motion: its values do not change
        # the work a message costs (the comparison is computed whatever it finds)
        half = round(0.5e9 / rate_hz)
        body_frame = scene.body_sensor.frame_id or "body_imu"
        body_raws = [raw for _, raw in imu_messages(stamps + half, accel, gyro, body_frame)]
    stream = TwinStream(scene)

    def wake_up(i: int) -> None:
        messages_of(stream.process(raws[i : i + per]))
        if body_raws:
            stream.process_body(body_raws[i : i + per])

    warm = int(rate_hz * WARM_S) // per * per
    for i in range(0, warm, per):
        wake_up(i)
    cpu0 = time.process_time()
    for i in range(warm, n, per):
        wake_up(i)
    return (time.process_time() - cpu0) / (n - warm) * 1e6


def _repeat(tree: Path, args: argparse.Namespace) -> float:
    """One figure of `tree`'s package, in a process of its own (its error ends this one)."""
    command = [sys.executable, __file__, "--one", args.scene, str(args.rate)]
    command += [str(args.seconds), str(args.per), str(int(args.body))]
    env = {**os.environ, "PYTHONPATH": str(tree)}
    done = subprocess.run(command, env=env, capture_output=True, text=True, check=False)
    if done.returncode:
        sys.exit(f"{tree}: {done.stderr.strip() or f'exit status {done.returncode}'}")
    return float(done.stdout.split()[-1])


def main() -> None:
    """Print each repeat's figure (and with --against, the medians and their ratio)."""
    if len(sys.argv) == 7 and sys.argv[1] == "--one":
        scene, rate, seconds, per, body = sys.argv[2:]
        figure = per_message_us(scene, float(rate), float(seconds), int(per), body == "1")
        print(f"{figure:.2f}")
        return
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", help=f"default {SCENE.name}; with --body {BODY_SCENE.name}")
    parser.add_argument("--rate", type=float, default=1000.0, help="input rate, Hz")
    parser.add_argument("--per", type=int, default=1, help="messages a wake-up")
    parser.add_argument("--seconds", type=float, default=3.0, help="input, s")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument(
        "--body", action="store_true", help="a body IMU stream alongside (the scene's body_sensor)"
    )
    parser.add_argument("--against", type=Path, help="another tree, run alternately")
    args = parser.parse_args()
    if args.seconds <= WARM_S or args.per < 1:
        parser.error(f"--seconds must exceed {WARM_S} and --per be at least 1")
    args.scene = args.scene or str(BODY_SCENE if args.body else SCENE)
    trees = {"this": HERE} if args.against is None else {"against": args.against, "this": HERE}
    got: dict[str, list[float]] = {name: [] for name in trees}
    what = "a deck message and its body message" if args.body else "a message"
    print(f"{Path(args.scene).name}, {args.rate:g} Hz, {args.per} a wake-up: CPU µs {what}")
    for _ in range(args.repeats):
        for name, tree in trees.items():
            got[name].append(_repeat(tree, args))
            print(f"  {name:<8} {got[name][-1]:8.1f}", flush=True)
    medians = {name: statistics.median(values) for name, values in got.items()}
    print("medians: " + ", ".join(f"{name} {m:.1f}" for name, m in medians.items()))
    if args.against is not None:
        print(f"this / against: {medians['this'] / medians['against']:.3f}")


if __name__ == "__main__":
    main()
