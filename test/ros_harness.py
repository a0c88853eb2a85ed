"""The real node over real DDS, for tests and the node benchmark.

Each run gets a DDS domain of its own (`ROS_DOMAIN_ID`) on localhost only, the node runs as its
own process (`python -m mount_twin.ros.start`, what the console script runs), and the test side
is one rclpy node in a context of its own that publishes raw input and takes raw outputs from
its subscriptions without an executor (`take_waiting`), so the recorder keeps up with a node
publishing a dozen topics at kHz rates.
"""

from __future__ import annotations

import atexit
import itertools
import os
import signal
import subprocess
import sys
import time
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

import rclpy
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

from mount_twin.io.scene_record import STRING
from mount_twin.ros.outputs import message_class
from mount_twin.ros.rclpy_private import take_waiting

ROOT = Path(__file__).resolve().parents[1]
PARAMS_FILE = ROOT / "config" / "params.yaml"
_domains = itertools.count()
_RUNNING: list[NodeProcess] = []


@atexit.register
def _kill_leftovers() -> None:
    """No node outlives the test session, whatever failed."""
    for node in _RUNNING:
        if node.alive:
            node.proc.kill()


def fresh_domain() -> int:
    """A DDS domain id for one run: differs between runs of this process, between the
    workers of one pytest-xdist run (each has its own share of the ids 1…100) and, very
    likely, between processes (parallel CI jobs on one machine)."""
    worker = os.environ.get("PYTEST_XDIST_WORKER", "")  # gw0, gw1, ...
    workers = int(os.environ.get("PYTEST_XDIST_WORKER_COUNT", "1"))
    share = 100 // workers
    first = 1 + share * int(worker[2:]) if worker.startswith("gw") else 1
    return first + (os.getpid() * 7 + next(_domains)) % share


def ros_env(domain: int) -> dict[str, str]:
    """The environment of a node process in `domain`, on this machine only."""
    return {
        **os.environ,
        "ROS_DOMAIN_ID": str(domain),
        "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST",
        "ROS_PYTHON_CHECK_FIELDS": "1",
    }


class NodeProcess:
    """`mount_twin_node --ros-args ARGS` in its own process (`group`: leading a process group
    of its own, which `os.killpg` signals whole, as a terminal's Ctrl-C or systemd's stop
    does the node and the processes it started)."""

    def __init__(self, domain: int, ros_args: Iterable[str], group: bool = False) -> None:
        self.proc = subprocess.Popen(
            [sys.executable, "-m", "mount_twin.ros.start", "--ros-args", *ros_args],
            env=ros_env(domain),
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            cwd=ROOT,
            process_group=0 if group else None,
        )
        self.stdout = self.stderr = ""
        _RUNNING.append(self)

    @property
    def alive(self) -> bool:
        """True while the process runs."""
        return self.proc.poll() is None

    def failed(self) -> str:
        """Stop the node (SIGINT) and say how it ended: for an assertion's message."""
        return f"node exit {self.stop()}: {self.stderr}"

    def stop(self, sig: int = signal.SIGINT, timeout: float = 30.0) -> int:
        """Send `sig`, wait for the exit, keep its output; return the exit code."""
        if self.alive:
            self.proc.send_signal(sig)
        return self.wait(timeout)

    def wait(self, timeout: float = 60.0) -> int:
        """Wait for the process to end; kill it past `timeout` (s) and raise. The exit code."""
        try:
            self.stdout, self.stderr = self.proc.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.stdout, self.stderr = self.proc.communicate()
            raise
        return self.proc.returncode


class InProcessNode:
    """The node in this process, in DDS domain `domain`, `ros_args` after its --ros-args: its
    own context and a single-threaded executor, for a test that reaches into it (counts,
    publishers, timers) or drives its shutdown; `close` destroys them."""

    def __init__(self, domain: int, ros_args: list[str]) -> None:
        from mount_twin.ros.node import MountTwinNode

        self.context = Context()
        args = ["mount_twin_node", "--ros-args", *ros_args]
        rclpy.init(args=args, context=self.context, domain_id=domain)
        self.node = MountTwinNode(args, context=self.context)
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)

    def close(self) -> None:
        """Shut the executor down, destroy the node and its context."""
        self.executor.shutdown()
        self.node.destroy_node()
        rclpy.try_shutdown(context=self.context)


class Peer:
    """The test side: publishers of raw input, raw subscriptions recording every output."""

    def __init__(self, domain: int, name: str = "mount_twin_test_peer") -> None:
        self.context = Context()
        rclpy.init(context=self.context, domain_id=domain)
        self.node = rclpy.create_node(name, context=self.context)
        self._subs: dict[str, Any] = {}
        self.got: dict[str, list[bytes]] = {}
        self.arrival: dict[str, list[float]] = {}

    def close(self) -> None:
        """Destroy the node and its context."""
        self.node.destroy_node()
        rclpy.try_shutdown(context=self.context)

    def call(self, request: Callable[[], Any], attempts: int = 4, timeout: float = 10.0) -> Any:
        """The result of a service call: `request()` sends it and returns its future, and this
        peer spins until it completes, sending it again (up to `attempts` times, `timeout` s
        each) where no response came. A request sent as soon as `wait_for_services` saw the
        service can go unanswered: Fast DDS drops a response whose reader on the client's side
        is not matched yet (ros2/rmw_fastrtps#467), which a loaded machine makes likely (one
        run in the suite under Python 3.12, 2026-11-28); `ros2 param` would be asked again."""
        executor = SingleThreadedExecutor(context=self.context)
        executor.add_node(self.node)
        try:
            for _ in range(attempts):
                future = request()
                executor.spin_until_future_complete(future, timeout_sec=timeout)
                if future.done():
                    return future.result()
                future.cancel()
        finally:
            executor.remove_node(self.node)
        msg = f"no response to a service request in {attempts} attempts of {timeout} s"
        raise AssertionError(msg)

    def publisher(self, msgtype: str, topic: str, depth: int = 100_000) -> Any:
        """A publisher of `msgtype` (reliable, keeping `depth` messages: a node whose input is
        overridden to reliable gets every one; a best-effort input matches it too)."""
        return self.node.create_publisher(message_class(msgtype), topic, depth)

    def record(self, topics: dict[str, str], depth: int = 10_000, latched: bool = False) -> None:
        """Subscribe to `topics` (name → type), reliable, and keep what arrives; `latched`:
        transient local, as tf2_ros' static listener (gets what was published before)."""
        qos = QoSProfile(
            depth=depth,
            reliability=ReliabilityPolicy.RELIABLE,
            history=HistoryPolicy.KEEP_LAST,
            durability=DurabilityPolicy.TRANSIENT_LOCAL if latched else DurabilityPolicy.VOLATILE,
        )
        for topic, msgtype in topics.items():
            self._subs[topic] = self.node.create_subscription(
                message_class(msgtype), topic, lambda _m: None, qos, raw=True
            )
            self.got.setdefault(topic, [])
            self.arrival.setdefault(topic, [])

    def take(self) -> int:
        """Take every message waiting on the recorded topics; return how many."""
        n = 0
        for topic, sub in self._subs.items():
            raws = take_waiting(sub, 100_000)
            if raws:
                now = time.time()
                self.got[topic].extend(raws)
                self.arrival[topic].extend([now] * len(raws))
                n += len(raws)
        return n

    def take_until(self, done: Callable[[], bool], timeout: float) -> bool:
        """Take messages until `done()` or `timeout` (s); return done()."""
        deadline = time.monotonic() + timeout
        while not done() and time.monotonic() < deadline:
            if not self.take():
                time.sleep(0.002)
        self.take()
        return done()

    def connected(self, topic: str) -> bool:
        """True once the recorder's subscription to `topic` has a publisher."""
        return self._subs[topic].get_publisher_count() > 0

    def matched_by(self, scene_topic: str, timeout: float) -> bool:
        """Whether the node that publishes its latched scene on `scene_topic` has matched, on
        its side, every reader this peer made before this call (`connected` proves this side
        only, and a message published before the node's writer matched a reader is not sent to
        it): a latched reader made now, after them, gets the scene once the node's writer has
        matched it, and discovery announces this peer's readers reliably and in order."""
        self.record({scene_topic: STRING}, latched=True)
        return self.take_until(lambda: bool(self.got[scene_topic]), timeout)


LOSSLESS = [
    "-p",
    "qos_overrides./deck/imu.subscription.reliability:=reliable",
    "-p",
    "input_queue_depth:=100000",
    "-p",
    "output_queue_depth:=100000",
]
"""Node arguments for tests that compare every message: a reliable input (ROS 2's QoS
override) and histories no test run fills, so a loaded machine delays messages but never drops
them (a best-effort input under load lost 36 % of a 10 kHz stream)."""


def stop_and_take(
    node: NodeProcess, peer: Peer, done: Callable[[], bool], sig: int | None = signal.SIGINT
) -> int:
    """Signal the node (`sig`; None: the caller has), take its outputs while it shuts down
    (it waits for its reliable subscribers' acknowledgements before it exits), then until
    `done()` (e.g. the final diagnostics period has arrived) or 30 s; the node's exit code.
    A signal sent while the node shuts down is a second stop, which cuts the shutdown short."""
    if sig is not None and node.alive:
        node.proc.send_signal(sig)
    peer.take_until(lambda: not node.alive, 60.0)
    code = node.wait()
    peer.take_until(done, 30.0)
    return code


def wait_for(predicate: Callable[[], bool], timeout: float, step: float = 0.02) -> bool:
    """Poll `predicate` until it holds or `timeout` (s) passes; return it."""
    deadline = time.monotonic() + timeout
    while not predicate():
        if time.monotonic() > deadline:
            return False
        time.sleep(step)
    return True


def wait_for_node(pub: Any, node: NodeProcess, timeout: float = 300.0) -> bool:
    """Wait until the node's input subscription has matched `pub` (or the node died).

    The publisher sees the match when the node's reader is discovered; the reader matches the
    writer on its own discovery a moment later, and best-effort samples sent in between are
    dropped: hence the settling time. The timeout is generous: a node starting on a loaded
    machine (imports, kernels, DDS discovery) took over 60 s beside a parallel test run.
    """
    if not wait_for(lambda: pub.get_subscription_count() > 0 or not node.alive, timeout):
        return False
    time.sleep(0.5)
    return node.alive


def publish_paced(pub: Any, raws: list[bytes], rate_hz: float, peer: Peer) -> None:
    """Publish `raws` at `rate_hz` (wall clock), taking outputs in between."""
    t0 = time.perf_counter()
    for i, raw in enumerate(raws):
        pub.publish(raw)
        while time.perf_counter() < t0 + (i + 1) / rate_hz:
            if not peer.take():
                time.sleep(0.0002)
