"""Parity of the live body IMU check with another tree of the package: the same deck and body
streams fed to both, whole runs in several batchings, every published message compared byte for
byte, and the body check's reports and counts.

    git worktree add --detach /tmp/main_ref main
    cp mount_twin/_core_ext*.so /tmp/main_ref/mount_twin/   # its compiled core, if the same
    python3 bench/body_parity.py --reference /tmp/main_ref

Three scenes with a body sensor: the bundled shake-table block (`block.scene.yaml`), the pump
with a body sensor as the tests build it, and that pump's sensor tilted on the body and 1.3 ms
late (`lag_s`). Their streams, 3 s of deck and body Imu at 1 kHz, as `bench_wakeup.py`'s plus
motion on every axis: a 0.3 s gap in the deck, 120 body messages of another frame_id, ten not
finite, three stamped back, and both streams jumping back 1.2 s at their end (a bag played with
--loop); or, `apart`, the deck going on past the body's jump (counted jumped_back_apart). Fed a
wake-up of the deck's then the body's up to `lead` messages ahead of it (behind, if negative),
so many messages a call each: (1, 1, 0), (1, 1, 5), (16, 16, 0), (7, 3, -20), (64, 100, 50),
(2, 1, 1). A /diagnostics message is compared with its real_time_factor (wall-clock time) set
to "-", its every other byte as published. Each tree runs in a process of its own, its package
first on PYTHONPATH. Prints one line a run and tree; exit 0 when every run agrees, 1 otherwise.
"""

from __future__ import annotations

import argparse
import dataclasses
import hashlib
import json
import os
import pickle
import subprocess
import sys
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parents[1]
SCENES = ("block", "pump", "pump_tilted")
FEEDINGS = ((1, 1, 0), (1, 1, 5), (16, 16, 0), (7, 3, -20), (64, 100, 50), (2, 1, 1))
"""(deck messages a call, body messages a call, body messages ahead of the deck)."""
NS0 = 1_700_000_000_000_000_000


def _scene(name: str) -> Any:
    """The scene `name` (of SCENES) in the package imported, windows of 0.5 s of body stamps,
    frame_id body_imu."""
    from mount_twin.scene.description import BodySensor
    from mount_twin.scene.loader import load_scene_file

    if name == "block":
        scene = load_scene_file(HERE / "test/data/shake_table_1story/block.scene.yaml")
        sensor = scene.body_sensor
        assert sensor is not None
    else:
        scene = load_scene_file(HERE / "config/pump_8_mounts.scene.yaml")
        sensor = BodySensor(position=(0.8, 0.3, 1.0))
        if name == "pump_tilted":
            sensor = dataclasses.replace(sensor, orientation_rpy=(0.1, -0.2, 0.3), lag_s=0.0013)
    sensor = dataclasses.replace(sensor, window_s=0.5, frame_id="body_imu")
    return dataclasses.replace(scene, body_sensor=sensor)


def _streams(scene: Any, seconds: float, loop: bool) -> tuple[list[bytes], list[bytes]]:
    """(deck messages, body messages): module docstring."""
    import numpy as np

    from mount_twin.io.output_encoding import imu_messages

    n = int(1000 * seconds)
    t = np.arange(n) / 1000.0
    ns = NS0 + np.round(t * 1e9).astype(np.int64)
    accel = np.stack(
        [
            0.3 * np.sin(6 * np.pi * t),
            0.2 * np.sin(10 * np.pi * t),
            9.80665 + 0.5 * np.sin(14 * np.pi * t),
        ]
    ).T
    gyro = np.stack(
        [0.01 * np.sin(4 * np.pi * t), 0.02 * np.sin(8 * np.pi * t), 0.005 * np.cos(2 * np.pi * t)]
    ).T
    quiet = (t >= 1.5) & (t < 1.8)
    deck_frame = scene.input.frame_id or "deck_imu"
    deck_all = imu_messages(ns, accel, gyro, deck_frame)
    deck = [r for (_, r), q in zip(deck_all, quiet, strict=True) if not q]
    body_accel = accel + 0.01 * np.cos(t)[:, None]
    body_ns = ns + 500_000
    body = [r for _, r in imu_messages(body_ns, body_accel, gyro, "body_imu")]
    other = [r for _, r in imu_messages(body_ns, body_accel, gyro, "other")]
    body[200:320] = other[200:320]
    body_accel[900:905] = np.nan
    body_accel[905:910, 1] = np.inf
    bad = [r for _, r in imu_messages(body_ns, body_accel, gyro, "body_imu")]
    body[900:910] = bad[900:910]
    body[1200:1203] = body[1100:1103]
    if loop:
        deck, body = deck + deck[:1200], body + body[:1200]
    return deck, body


def _masked(message: Any) -> Any:
    """The message (topic, stamp ns, CDR bytes), a /diagnostics one with its real_time_factor
    set to "-"."""
    from mount_twin.io.messages import DIAGNOSTICS, TYPESTORE

    topic, stamp, raw = message
    if not topic.endswith("diagnostics"):
        return message
    msg: Any = TYPESTORE.deserialize_cdr(raw, DIAGNOSTICS)
    for status in msg.status:
        for kv in status.values:
            if kv.key == "real_time_factor":
                kv.value = "-"
    return topic, stamp, bytes(TYPESTORE.serialize_cdr(msg, DIAGNOSTICS))


def one_tree(name: str) -> list[dict[str, Any]]:
    """Every run of scene `name` in the package imported: its feeding, its messages' count and
    digest, its body reports' digest and its non-zero counts."""
    from mount_twin.stream import TwinStream

    scene, found = _scene(name), []
    for apart in (False, True):
        deck, body = _streams(scene, 3.0, loop=True)
        if apart:
            deck, _ = _streams(scene, 4.2, loop=False)
        for per_deck, per_body, lead in FEEDINGS:
            stream, out = TwinStream(scene), []
            i = j = 0
            while i < len(deck) or j < len(body):
                if i < len(deck):
                    out += stream.process(deck[i : i + per_deck])
                    i += per_deck
                while j < len(body) and (j < i + lead or i >= len(deck)):
                    out += stream.process_body(body[j : j + per_body])
                    j += per_body
            out += stream.finish()
            messages = [_masked(m) for m in out]
            reports = [repr(r) for r in stream.take_body_reports()]
            assert stream.body is not None
            found.append(
                {
                    "scene": name,
                    "apart": apart,
                    "feeding": [per_deck, per_body, lead],
                    "messages": len(messages),
                    "digest": hashlib.sha256(pickle.dumps(messages)).hexdigest()[:16],
                    "reports": hashlib.sha256(pickle.dumps(reports)).hexdigest()[:16],
                    "counts": {k: v for k, v in stream.body.counts.items() if v},
                }
            )
    return found


def _run(tree: Path, name: str) -> list[dict[str, Any]]:
    """`one_tree` in a process of its own, `tree`'s package first on PYTHONPATH."""
    env = {**os.environ, "PYTHONPATH": str(tree)}
    command = [sys.executable, __file__, "--one", name, str(tree)]
    done = subprocess.run(command, env=env, capture_output=True, text=True, check=False)
    if done.returncode:
        sys.exit(f"{tree}: {done.stderr.strip() or f'exit status {done.returncode}'}")
    result: list[dict[str, Any]] = json.loads(done.stdout)
    return result


def main() -> int:
    """Compare this tree with --reference; 0 when every run agrees."""
    if len(sys.argv) == 4 and sys.argv[1] == "--one":
        import mount_twin

        assert mount_twin.__file__ is not None
        assert mount_twin.__file__.startswith(sys.argv[3]), mount_twin.__file__
        print(json.dumps(one_tree(sys.argv[2])))
        return 0
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--reference", type=Path, required=True, help="another tree")
    parser.add_argument("--scenes", nargs="+", choices=SCENES, default=list(SCENES))
    args = parser.parse_args()
    differ = 0
    for name in args.scenes:
        ours, theirs = _run(HERE, name), _run(args.reference.resolve(), name)
        for a, b in zip(ours, theirs, strict=True):
            same = a == b
            differ += not same
            feeding = "apart " * a["apart"] + " ".join(map(str, a["feeding"]))
            print(
                f"{'same ' if same else 'DIFFER'} {name:<12} {feeding:<18} {a['messages']} "
                f"messages {a['digest']} reports {a['reports']}"
                + ("" if same else f"\n  reference: {b}\n  this:      {a}")
            )
    print(f"{differ} of {len(args.scenes) * 2 * len(FEEDINGS)} runs differ")
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main())
