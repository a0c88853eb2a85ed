"""Real-time factors of the default scene (8 mounts, 6 DOF, 1 kHz input), measured in one run.

    python3 bench/bench_replay.py [--seconds 10]

1. engine alone: decode raw Imu bytes, integrate, compute outputs (no encoding, no bag I/O),
   with the live error estimate (the default) and without it;
2. end-to-end replay writing every output at the input rate, in CPU seconds against the bag
   writers' own floors: rosbags, and our writer, writing the same messages, already encoded, in
   the same order;
3. end-to-end replay at a 100 Hz output rate (decimation 10, peaks held).
"""

from __future__ import annotations

import argparse
import dataclasses
import tempfile
import time
from pathlib import Path

from rosbags.rosbag2 import Reader, StoragePlugin, Writer  # noqa: TID251 (the floor is rosbags)

from mount_twin.cli import main
from mount_twin.commands.common import DEFAULT_SCENE, share_dir
from mount_twin.engine.engine import TwinEngine
from mount_twin.io.input_bag import InputBag
from mount_twin.io.input_decoding import TimeBase, decode_inputs
from mount_twin.io.mcap_writer import McapBagWriter
from mount_twin.model.assemble import assemble
from mount_twin.replay import replay
from mount_twin.scene.loader import load_scene_file

CHUNK = 2000


def writer_floors(bag: Path, tmp: Path) -> tuple[float, float]:
    """CPU seconds rosbags, then our writer (`io.mcap_writer`, which the replay uses), take to
    write the messages of `bag` (read beforehand, encoded) into a new mcap bag, in the same
    order, with the same topics and types."""
    with Reader(bag) as r:
        msgs = list(r.messages())
    c0 = time.process_time()
    with Writer(tmp / "floor", version=9, storage_plugin=StoragePlugin.MCAP) as w:
        conns = {}
        for c in {c.topic: c for c, _, _ in msgs}.values():
            conns[c.topic] = w.add_connection(
                c.topic, c.msgtype, typestore=None, msgdef=c.msgdef.data, rihs01=c.digest
            )
        for c, t, raw in msgs:
            w.write(conns[c.topic], t, raw)
    theirs = time.process_time() - c0
    c0 = time.process_time()
    ours = McapBagWriter(tmp / "our_floor", {c.topic: c.msgtype for c, _, _ in msgs}, {})
    plain = [(c.topic, t, raw) for c, t, raw in msgs]
    for k in range(0, len(plain), CHUNK):
        ours.write(plain[k : k + CHUNK])
    ours.close()
    return theirs, time.process_time() - c0


def engine_alone(scene, bag: Path) -> float:
    """Real-time factor of decode + engine over the bag's messages held in memory."""
    with InputBag(bag, scene.input.topic, scene.input.msg_type) as b:
        chunks = list(b.chunks(CHUNK))
    engine = TwinEngine(assemble(scene))
    base = None
    t0 = time.perf_counter()
    first: float | None = None
    last = 0.0
    for raws in chunks:
        decoded = decode_inputs(raws, scene.input.msg_type)
        base = base or TimeBase.at(int(decoded.stamps_ns[0]))
        out = engine.push(decoded.batch(base))
        first = float(out.stamps[0]) if first is None else first  # 0.0 is a valid stamp
        last = float(out.stamps[-1])
    return (last - (first or 0.0)) / (time.perf_counter() - t0)


def main_bench() -> None:
    """Print the three real-time factors."""
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--seconds", type=float, default=10.0, help="input length, s")
    args = parser.parse_args()
    scene = load_scene_file(share_dir() / "config" / DEFAULT_SCENE)
    with tempfile.TemporaryDirectory() as tmp:
        bag = Path(tmp) / "in"
        main(
            [
                "generate",
                "ship-motion",
                "-o",
                str(bag),
                "--topic",
                scene.input.topic,
                "--frame-id",
                scene.input.frame_id,
                "--rate",
                "1000",
                "--duration",
                str(args.seconds),
            ]
        )
        rtf_engine = engine_alone(scene, bag)
        off = dataclasses.replace(scene.integration, error_estimate=False)
        rtf_no_estimate = engine_alone(dataclasses.replace(scene, integration=off), bag)
        c0 = time.process_time()
        every = replay(scene, bag, Path(tmp) / "out1", progress=False)
        every_cpu = time.process_time() - c0
        floor, our_floor = writer_floors(Path(tmp) / "out1", Path(tmp))
        slow = dataclasses.replace(
            scene, outputs=dataclasses.replace(scene.outputs, decimation=10)
        )
        at_100hz = replay(slow, bag, Path(tmp) / "out10", progress=False)
    print(
        f"default scene: {len(scene.mounts)} mounts, {len(scene.dofs)} DOF, 1 kHz input, "
        f"{args.seconds:g} s"
    )
    print(f"  engine alone (decode, integrate, outputs): {rtf_engine:7.1f} x real")
    print(f"  engine alone, error_estimate: false:       {rtf_no_estimate:7.1f} x real")
    print(
        f"  replay, every output at 1 kHz:             {every.real_time_factor:7.1f} x real"
        f"  ({every.written} messages)"
    )
    print(
        f"  that replay, CPU: {every_cpu:.2f} s; the writers' floors (writing the same messages "
        f"pre-encoded): rosbags {floor:.2f} s ({every_cpu / floor:.2f}x), ours "
        f"{our_floor:.2f} s ({every_cpu / our_floor:.2f}x)"
    )
    print(
        f"  replay, outputs at 100 Hz:                 {at_100hz.real_time_factor:7.1f} x real"
        f"  ({at_100hz.written} messages)"
    )


if __name__ == "__main__":
    main_bench()
