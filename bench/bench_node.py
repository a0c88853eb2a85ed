"""The live node over real DDS: which Imu rates it answers in full, and its latency.

    python3 bench/bench_node.py [--seconds 4] [--rates 1000 2000 5000 10000] [--modes ...]

For each mode (per message: `batch_period_s 0.0`; batched: `0.005`; each also with
`outputs.decimation 10`) and rate, the node (default scene, 8 mounts, 6 DOF) runs in its own
process, a second process publishes sensor_msgs/Imu at rest, each stamped with the wall-clock
time it is due and sent at that time (late if the sender falls behind), and this one takes
every /mount_twin/pose. Printed per run: the rate actually sent,
the share of inputs the node accepted (its final /diagnostics), the latency from input stamp to
the pose's arrival here (p50, p99, max) of the poses that came while the node ran (the gyro
filter's delay holds the last samples' outputs until the node shuts down: those are counted
apart, "at stop"), the worst input status level, the losses the node itself reported (from
stamp gaps and from the middleware), and the node's CPU time (user + system, from
/proc/PID/stat) per second of wall time while the input was sent: the share of a core it takes.
"""

from __future__ import annotations

import argparse
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import yaml

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "test"))
from ros_harness import PARAMS_FILE, NodeProcess, Peer, fresh_domain, wait_for

from mount_twin.engine.delay_line import delay_samples
from mount_twin.io.messages import DIAGNOSTICS, IMU, TYPESTORE
from mount_twin.io.output_encoding import imu_messages
from mount_twin.scene import scene_from_params
from mount_twin.scene.params import flatten

POSE = "/mount_twin/pose"
INPUT = scene_from_params(
    dict(flatten(yaml.safe_load(PARAMS_FILE.read_text())["/**"]["ros__parameters"])),
    str(PARAMS_FILE),
).input
"""The input spec of the bundled params file, the node's scene here."""


def publish(domain: int, rate_hz: float, seconds: float) -> None:
    """The input side, in a process of its own: Imu at rest at `rate_hz`, each stamped with the
    wall-clock time it is due and sent then; prints the rate achieved."""
    peer = Peer(domain, "bench_publisher")
    pub = peer.publisher(IMU, "/deck/imu")
    while pub.get_subscription_count() == 0:
        time.sleep(0.01)
    time.sleep(0.5)  # the node's reader matches this writer a moment after
    n = int(rate_hz * seconds)
    period_ns = round(1e9 / rate_hz)
    t0_ns = time.time_ns() + 100_000_000
    due = t0_ns + np.arange(n, dtype=np.int64) * period_ns
    accel = np.tile([0.0, 0.0, 9.80665], (n, 1))
    raws = [raw for _, raw in imu_messages(due, accel, np.zeros((n, 3)), "deck_imu")]
    for stamp, raw in zip(due.tolist(), raws, strict=True):
        while time.time_ns() < stamp:
            pass
        pub.publish(raw)
    print(n / ((time.time_ns() - t0_ns) * 1e-9), flush=True)
    time.sleep(0.5)
    peer.close()


def run(rate_hz: float, seconds: float, options: list[str]) -> dict[str, float]:
    """One run with the node's `options` (-p name:=value ...); the figures printed for it."""
    domain = fresh_domain()
    peer = Peer(domain, "bench_recorder")
    peer.record({POSE: "geometry_msgs/msg/PoseStamped", "/diagnostics": DIAGNOSTICS})
    node = NodeProcess(domain, ["--params-file", str(PARAMS_FILE), *options])
    # the recorder must have matched the node's publishers before the first output: a reliable,
    # volatile subscriber that matches late misses what came before and gets the next late
    if not wait_for(lambda: peer.connected(POSE) or not node.alive, 120.0):
        node.stop()
        raise RuntimeError(f"the node did not start: {node.stderr}")
    time.sleep(0.5)
    cpu0, wall0 = _cpu_s(node.proc.pid), time.monotonic()
    publisher = subprocess.Popen(
        [sys.executable, __file__, "--publish", str(domain), str(rate_hz), str(seconds)],
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        peer.take_until(lambda: publisher.poll() is not None or not node.alive, seconds + 120.0)
        cpu_share = (_cpu_s(node.proc.pid) - cpu0) / (time.monotonic() - wall0)
        n = int(rate_hz * seconds)
        decimation = int(options[-1].split(":=")[1]) if "decimation" in options[-1] else 1
        held = delay_samples(INPUT, rate_hz)  # answered at shutdown
        peer.take_until(lambda: len(peer.got[POSE]) >= (n - held) // decimation, 3.0)
        stopped = time.time()  # the clock of peer.arrival
        node.stop(signal.SIGINT)
        peer.take_until(lambda: False, 0.5)
    finally:
        node.stop(signal.SIGKILL)
        publisher.kill()
        peer.close()
    published_hz = float(publisher.communicate()[0].split()[-1])
    stamps = np.array([_stamp_s(r, "geometry_msgs/msg/PoseStamped") for r in peer.got[POSE]])
    arrival = np.array(peer.arrival[POSE])
    latency = (arrival - stamps)[arrival < stopped]
    lost = {"accepted": 0, "lost_estimated": 0, "lost_middleware": 0}
    level, worst = 0, "ok"
    for raw in peer.got["/diagnostics"]:
        msg = TYPESTORE.deserialize_cdr(raw, DIAGNOSTICS)
        for status in msg.status:
            if status.name == "mount_twin: input":
                values = {kv.key: kv.value for kv in status.values}
                lost = {k: int(values.get(k, 0)) for k in lost}
                # the clock's reports before the first sample and after the last one
                quiet = status.message.startswith("no input received") or status.message.endswith(
                    "before it in this period)"
                )
                if not quiet and int(status.level) > level:
                    level, worst = int(status.level), status.message

    return {
        "published_hz": published_hz,
        "answered": lost["accepted"] / n,
        "p50_ms": 1e3 * float(np.percentile(latency, 50)) if len(latency) else np.nan,
        "p99_ms": 1e3 * float(np.percentile(latency, 99)) if len(latency) else np.nan,
        "max_ms": 1e3 * float(latency.max()) if len(latency) else np.nan,
        "at_stop": int((arrival >= stopped).sum()),
        "missing": n - lost["accepted"],
        "level": ("OK", "WARN", "ERROR")[level],
        "worst": worst,
        "cpu": cpu_share,
        **lost,
    }


def _cpu_s(pid: int) -> float:
    """User + system CPU time (s) of process `pid` so far (Linux: /proc/PID/stat)."""
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def _stamp_s(raw: bytes, msgtype: str) -> float:
    stamp = TYPESTORE.deserialize_cdr(raw, msgtype).header.stamp
    return stamp.sec + stamp.nanosec * 1e-9


MODES = {
    "per_message": ["-p", "batch_period_s:=0.0"],
    "batched": ["-p", "batch_period_s:=0.005"],
    "per_msg/dec10": ["-p", "batch_period_s:=0.0", "-p", "outputs.decimation:=10"],
    "batched/dec10": ["-p", "batch_period_s:=0.005", "-p", "outputs.decimation:=10"],
}


def main() -> None:
    """Run every mode and rate; print one line each and the highest rate answered in full."""
    if len(sys.argv) == 5 and sys.argv[1] == "--publish":
        publish(int(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4]))
        return
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=4.0)
    parser.add_argument("--rates", type=float, nargs="+", default=[1000, 2000, 5000, 10000])
    parser.add_argument("--modes", nargs="+", default=list(MODES), choices=list(MODES))
    args = parser.parse_args()
    print(
        f"{'mode':<14} {'rate Hz':>8} {'sent Hz':>8} {'answered':>9} {'missing':>8} "
        f"{'p50 ms':>7} {'p99 ms':>7} {'max ms':>7} {'at stop':>7} {'CPU':>5}  input status, "
        "node-reported lost "
        "(stamps, DDS)"
    )
    for mode in args.modes:
        full = 0.0
        for rate in args.rates:
            r = run(rate, args.seconds, MODES[mode])
            if r["missing"] == 0:
                full = rate
            print(
                f"{mode:<14} {rate:8.0f} {r['published_hz']:8.0f} {r['answered']:9.2%} "
                f"{r['missing']:8d} {r['p50_ms']:7.2f} {r['p99_ms']:7.2f} {r['max_ms']:7.2f} "
                f"{r['at_stop']:7d} {r['cpu']:5.0%}  "
                f"{r['level']}, {r['lost_estimated']}, {r['lost_middleware']}"
                + ("" if r["level"] == "OK" else f" ({r['worst']})"),
                flush=True,
            )
        print(f"{mode}: highest rate answered in full: {full:.0f} Hz", flush=True)


if __name__ == "__main__":
    main()
