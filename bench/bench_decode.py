"""Where decoding Imu messages one by one stops paying against decoding them in bulk.

    python3 bench/bench_decode.py [--sizes 1 2 4 8 ...] [--repeats 7] [--number 2000]
                                  [--two-sensors]

`decode_inputs` of n raw sensor_msgs/Imu messages (bytes, as the live node receives them; one
frame_id, its layout already known) two ways: one by one against the layout of the frame_id
last seen (`FixedLayout.unpack_one`, the path taken up to `ONE_BY_ONE_MAX` messages) and in
bulk (rosbags for the first message, one numpy pass for the rest). Printed per n: the best of
`--repeats` timings of `--number` calls each (process CPU time, the two ways alternately), µs
a call, and their ratio; then the largest n up to which one by one is the faster at every n
measured, the crossover `ONE_BY_ONE_MAX` is set from. With `--two-sensors`, each timed call is
a pair, as a scene with a body IMU makes them: n messages of the deck's frame_id, then n of the
body's (both layouts known: `RECENT_FRAMES`).
"""

from __future__ import annotations

import argparse
import time
import timeit

import numpy as np

from mount_twin.io import input_decoding
from mount_twin.io.input_decoding import decode_inputs
from mount_twin.io.messages import IMU
from mount_twin.io.output_encoding import imu_messages

SIZES = (1, 2, 4, 8, 12, 16, 20, 24, 32, 48, 64)


def raw_imu(n: int, frame: str = "deck_imu") -> list[bytes]:
    """n Imu messages of `frame`, 1 kHz stamps, a small vibration."""
    t = np.arange(n) / 1000.0
    stamps = 1_700_000_000_000_000_000 + np.round(t * 1e9).astype(np.int64)
    accel = np.column_stack([0.3 * np.sin(18.8 * t), np.zeros(n), 9.80665 + 0.1 * t])
    gyro = np.column_stack([0.01 * np.sin(12.6 * t), np.zeros(n), np.zeros(n)])
    return [raw for _, raw in imu_messages(stamps, accel, gyro, frame)]


def per_call_us(calls: list[list[bytes]], repeats: int, number: int) -> tuple[float, float]:
    """Best CPU time (µs) of `decode_inputs` of each of `calls` in turn one by one, and in
    bulk."""
    limit = input_decoding.ONE_BY_ONE_MAX
    timer = timeit.Timer(
        lambda: [decode_inputs(raws, IMU) for raws in calls], timer=time.process_time
    )
    best = [float("inf"), float("inf")]
    try:
        for _ in range(repeats):
            for way, most in enumerate((len(calls[0]), 0)):
                input_decoding.ONE_BY_ONE_MAX = most
                best[way] = min(best[way], timer.timeit(number) / number * 1e6)
    finally:
        input_decoding.ONE_BY_ONE_MAX = limit
    return best[0], best[1]


def main() -> None:
    """Print both paths' times per n and the crossover."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=list(SIZES))
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--number", type=int, default=2000)
    parser.add_argument(
        "--two-sensors", action="store_true", help="time a deck call and a body call a pair"
    )
    args = parser.parse_args()
    frames = ("deck_imu", "body_imu") if args.two_sensors else ("deck_imu",)
    for frame in frames:  # the layouts known, as after a node's first messages
        decode_inputs(raw_imu(2, frame), IMU)
    print(f"ONE_BY_ONE_MAX now {input_decoding.ONE_BY_ONE_MAX}")
    print("     n  one by one µs   bulk µs   one/bulk")
    faster, ahead = 0, True
    for n in sorted(args.sizes):
        one, bulk = per_call_us([raw_imu(n, f) for f in frames], args.repeats, args.number)
        print(f"{n:6d} {one:14.1f} {bulk:9.1f} {one / bulk:10.2f}", flush=True)
        ahead = ahead and one < bulk
        faster = n if ahead else faster
    print(f"one by one is the faster at every n measured up to {faster}")


if __name__ == "__main__":
    main()
