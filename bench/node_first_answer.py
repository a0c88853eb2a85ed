"""How soon a starting node answers: from `mount_twin_node`'s process start to its first
/mount_twin/pose, while an Imu stream at rest is already running (issue 21: ≤ 2 s).

    python3 bench/node_first_answer.py [--runs 5] [--rate 1000]

Each run starts the node (bundled params file, real DDS, its own domain) in a fresh process
while this process publishes sensor_msgs/Imu at `--rate`, each stamped with the wall-clock time
it is sent, and takes every pose. Printed per run: the seconds from the process's start to the
node's input subscription matching this publisher (imports, the scene, the equilibrium, DDS
discovery) and to the first pose (that plus the gyro filter's 38 ms and the first batch), and
the latency of that first pose from its input's stamp; then the median and the worst.
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "test"))
from ros_harness import LOSSLESS, PARAMS_FILE, NodeProcess, Peer, fresh_domain

from mount_twin.io.messages import IMU, TYPESTORE
from mount_twin.io.output_encoding import imu_messages

POSE = "/mount_twin/pose"
POSE_TYPE = "geometry_msgs/msg/PoseStamped"


def one_run(rate_hz: float, timeout_s: float) -> tuple[float, float, float]:
    """(s to the input match, s to the first pose, that pose's latency s) of one start."""
    domain = fresh_domain()
    peer = Peer(domain, "first_answer_peer")
    try:
        pub = peer.publisher(IMU, "/deck/imu")
        peer.record({POSE: POSE_TYPE})
        period = 1.0 / rate_hz
        start = time.monotonic()
        node = NodeProcess(domain, ["--params-file", str(PARAMS_FILE), *LOSSLESS])
        matched = first = latency = float("nan")
        next_due = start
        try:
            while time.monotonic() - start < timeout_s:
                now = time.monotonic()
                if now >= next_due:
                    stamp = np.array([time.time_ns()], dtype=np.int64)
                    accel = np.array([[0.0, 0.0, 9.80665]])
                    for _, raw in imu_messages(stamp, accel, np.zeros((1, 3)), "deck_imu"):
                        pub.publish(raw)
                    next_due += period
                if math.isnan(matched) and pub.get_subscription_count() > 0:
                    matched = time.monotonic() - start
                if peer.take():
                    first = time.monotonic() - start
                    msg = TYPESTORE.deserialize_cdr(peer.got[POSE][0], POSE_TYPE)
                    sent = msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9
                    latency = time.time() - sent
                    break
                if not node.alive:
                    sys.exit(f"the node exited: {node.failed()}")
        finally:
            node.stop()
    finally:
        peer.close()
    return matched, first, latency


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--rate", type=float, default=1000.0, help="Imu rate, Hz")
    parser.add_argument("--timeout", type=float, default=120.0, help="per run, s")
    args = parser.parse_args()
    print(f"{'run':>4} {'input matched s':>16} {'first pose s':>13} {'its latency ms':>15}")
    firsts = []
    for run in range(args.runs):
        matched, first, latency = one_run(args.rate, args.timeout)
        firsts.append(first)
        print(f"{run + 1:>4} {matched:>16.2f} {first:>13.2f} {latency * 1e3:>15.1f}", flush=True)
    print(f"first pose: median {statistics.median(firsts):.2f} s, worst {max(firsts):.2f} s")


if __name__ == "__main__":
    main()
