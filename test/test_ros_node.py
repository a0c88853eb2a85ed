"""The node, run for real: Jazzy rclpy, Fast DDS, the node in its own process.

In CI (CI set) rclpy must be importable: `.ci/run` installs it, and a missing one fails the
collection instead of skipping. Elsewhere the module skips without rclpy. Likewise tf2_msgs
(`.ci/run` builds it with `mount-twin build-tf2-msgs`): in CI a missing one fails the tests of
/tf and /tf_static; elsewhere they skip, and the comparison with the replay leaves /tf out.
"""

from __future__ import annotations

import json
import math
import os
import signal
import subprocess
import sys
import time
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

if os.environ.get("CI"):
    import rclpy  # noqa: F401  (CI installs it: a node test that skips there is a failure)
else:
    pytest.importorskip("rclpy")

from io_helpers import PARAMS_FILE, ROOT, read_raw, unprovided_imu
from ros_harness import (
    LOSSLESS,
    InProcessNode,
    NodeProcess,
    Peer,
    fresh_domain,
    publish_paced,
    stop_and_take,
    wait_for,
    wait_for_node,
)
from test_start_loaded import C_SOFT, RATED, rated_scene, start_sag

from mount_twin.engine.batch import ERROR, OK
from mount_twin.engine.delay_line import delay_samples
from mount_twin.io.input_bag import InputBag
from mount_twin.io.input_decoding import stamp_ns
from mount_twin.io.messages import (
    ACCEL,
    DIAGNOSTICS,
    IMU,
    NODE_NAME,
    POSE,
    TF,
    TF_STATIC_TOPIC,
    TF_TOPIC,
    TYPESTORE,
    resolve,
)
from mount_twin.io.output_bag import OutputBag
from mount_twin.io.output_encoding import imu_messages, static_transforms
from mount_twin.io.output_topics import output_types
from mount_twin.io.scene_record import STRING
from mount_twin.replay import replay
from mount_twin.scene import load_scene_file, scene_from_params
from mount_twin.scene.description import InputSpec
from mount_twin.scene.params import flatten

BAGS = ROOT / "bags"
GENSET = ROOT / "config" / "genset_bolted_keyed.scene.yaml"

GYRO_DELAY = delay_samples(InputSpec(), 1000.0)
"""The shipped default's delay at 1 kHz (38 samples)."""
STAMP0 = 1_700_000_000_000_000_000
SCENE = resolve("~/scene", NODE_NAME)
WALL_FIGURES = {"real_time_factor"}
"""Diagnostic values that measure wall time: they differ between any two runs."""


def tf_available() -> bool:
    """Whether tf2_msgs is importable here (it is not on the package registry: `mount-twin
    build-tf2-msgs` builds it). In CI, where `.ci/run` has built it, its absence fails the
    test that asks."""
    try:
        import tf2_msgs.msg  # noqa: F401
    except ImportError as err:
        if os.environ.get("CI"):
            pytest.fail(f"tf2_msgs is not importable in CI ({err}): .ci/run builds it")
        return False
    return True


def bag_inputs(bag: Path, n: int) -> list[bytes]:
    """The first `n` raw input messages of a bundled bag."""
    with InputBag(bag, "/deck/imu", IMU) as b:
        raws = [bytes(r) for chunk in b.chunks(1000) for r in chunk]
    return raws[:n]


def replayed(scene: Any, raws: list[bytes], tmp: Path) -> dict[str, list[bytes]]:
    """`mount-twin replay` of these input messages: topic → raw messages in order."""
    stamps = [TYPESTORE.deserialize_cdr(r, IMU).header.stamp for r in raws[:1]]
    assert stamps
    with OutputBag(tmp / "in", {"/deck/imu": IMU}) as out:
        out.write(
            [("/deck/imu", stamp_ns(TYPESTORE.deserialize_cdr(r, IMU).header), r) for r in raws]
        )
    replay(scene, tmp / "in", tmp / "out", progress=False)
    return {t: [raw for _, raw in msgs] for t, msgs in read_raw(tmp / "out").items()}


def diagnostics(raws: list[bytes]) -> list[tuple[int, list[tuple[str, int, str, dict]]]]:
    """(stamp ns, [(name, level, message, values without wall-time figures)]) per array."""
    out = []
    for raw in raws:
        msg = TYPESTORE.deserialize_cdr(raw, DIAGNOSTICS)
        stamp = msg.header.stamp.sec * 10**9 + msg.header.stamp.nanosec
        statuses = [
            (
                s.name,
                int(s.level),
                s.message,
                {kv.key: kv.value for kv in s.values if kv.key not in WALL_FIGURES},
            )
            for s in msg.status
        ]
        out.append((stamp, statuses))
    return out


def live_topics(scene: Any, node_name: str = NODE_NAME, namespace: str = "/") -> dict[str, str]:
    """Resolved output topic → type that the node publishes here."""
    types = {resolve(t, node_name, namespace): m for t, m in output_types(scene).items()}
    if not tf_available():
        types.pop("/tf", None)
    return types


def run_live(
    scene: Any,
    ros_args: list[str],
    raws: list[bytes],
    rate_hz: float,
    *,
    expect_outputs: int,
) -> tuple[Peer, NodeProcess, int]:
    """Start the node (input reliable: `LOSSLESS`), publish `raws` at `rate_hz`, wait for
    `expect_outputs` pose messages, SIGINT it and take until the last, partial diagnostics
    period (stamped with the last input's stamp) has come; return the peer (with everything
    recorded), the process and its exit code."""
    domain = fresh_domain()
    peer = Peer(domain)
    topics = live_topics(scene)
    peer.record(topics)
    node = NodeProcess(domain, [*ros_args, *LOSSLESS])
    pub = peer.publisher(IMU, "/deck/imu")
    pose = resolve("~/pose", NODE_NAME)
    last = _stamp(raws[-1])
    try:
        assert wait_for_node(pub, node), node.failed()
        assert wait_for(lambda: all(peer.connected(t) for t in topics), 10.0)
        # the node's side of the match too (the scene, published once, recorded by it)
        assert peer.matched_by(SCENE, 30.0), node.failed()
        publish_paced(pub, raws, rate_hz, peer)
        rate = 1e9 / (_stamp(raws[1]) - _stamp(raws[0]))
        before = expect_outputs - delay_samples(scene.input, rate)  # the rest come at shutdown
        peer.take_until(lambda: len(peer.got[pose]) >= before, 120.0)
        code = stop_and_take(
            node, peer, lambda: last in [d[0] for d in diagnostics(peer.got["/diagnostics"])]
        )
    except BaseException:
        node.stop(signal.SIGKILL)
        peer.close()
        raise
    return peer, node, code


CASES = [
    pytest.param("ship_motion_1khz", PARAMS_FILE, [], 2000, 0.0, id="ship-per_message"),
    pytest.param("ship_motion_1khz", PARAMS_FILE, [], 2000, 0.005, id="ship-batched"),
    pytest.param("genset_shock_10khz", None, [], 2500, 0.0, id="genset-per_message"),
    pytest.param("genset_shock_10khz", None, [], 2500, 0.005, id="genset-batched"),
]


@pytest.mark.parametrize(("bag", "params", "extra", "n", "batch_period_s"), CASES)
def test_live_node_over_dds_equals_the_replay_of_the_same_messages(
    tmp_path: Path, bag: str, params: Path | None, extra: list[str], n: int, batch_period_s: float
) -> None:
    """Every pose, angle, wrench (and /tf where tf2_msgs exists) message is byte-equal to the
    replay's, and so is the scene on ~/scene (the same file, or parameter set, and nothing
    over it); diagnostics are equal in stamp, level, message and every value except the
    real-time factor (wall time). The last one is the partial period published on SIGINT."""
    if params is None:
        scene = load_scene_file(GENSET)
        args = ["-p", f"scene_file:={GENSET}"]
    else:
        scene = scene_from_params(dict(flatten(_params())), str(params))
        args = ["--params-file", str(params)]
    # A publisher starved for one diagnostics period of the node's clock (a loaded machine)
    # makes the node report the stall, a live-only report with its own test: held off here.
    args += ["-p", f"batch_period_s:={batch_period_s}", "-p", "stall_period_s:=3600.0", *extra]
    raws = bag_inputs(BAGS / bag, n)
    want = replayed(scene, raws, tmp_path)
    peer, node, code = run_live(scene, args, raws, 1000.0, expect_outputs=n)
    peer.close()
    assert code == 0, node.stderr
    assert "Traceback" not in node.stderr and "Warning" not in node.stderr, node.stderr
    for topic in live_topics(scene):
        got = peer.got[topic]
        if topic == "/diagnostics":  # less the reports of the node's clock before input came
            span = (_stamp(raws[0]), _stamp(raws[-1]))
            live = [d for d in diagnostics(got) if span[0] <= d[0] <= span[1]]
            assert live == diagnostics(want[topic]), node.stderr
            continue
        assert len(got) == len(want[topic]) == n, topic
        assert got == want[topic], f"{topic}: live bytes differ from the replay's"
    assert len(want[SCENE]) == 1 and _records(peer.got[SCENE]) == _records(want[SCENE])
    # the live error estimate travels on /diagnostics (equal to the replay's, compared above)
    integration = [
        values
        for _, statuses in diagnostics(peer.got["/diagnostics"])
        for name, _, _, values in statuses
        if name == "mount_twin: integration"
    ]
    assert integration and all(0.0 <= float(v["est_force_error_rel"]) < 0.01 for v in integration)


def _records(raws: list[bytes]) -> list[dict[str, Any]]:
    """The JSON objects of ~/scene messages."""
    return [json.loads(TYPESTORE.deserialize_cdr(raw, STRING).data) for raw in raws]


def _stamp(raw: bytes) -> int:
    stamp = TYPESTORE.deserialize_cdr(raw, IMU).header.stamp
    return stamp.sec * 1_000_000_000 + stamp.nanosec


def _params() -> dict[str, Any]:
    import yaml

    return yaml.safe_load(PARAMS_FILE.read_text(encoding="utf-8"))["/**"]["ros__parameters"]


def _imu(stamps_ns: np.ndarray, accel: np.ndarray, frame: str = "deck_imu") -> list[bytes]:
    return [raw for _, raw in imu_messages(stamps_ns, accel, np.zeros_like(accel), frame)]


def _at_rest(n: int, t0_ns: int = STAMP0, dt_ns: int = 1_000_000) -> tuple[np.ndarray, np.ndarray]:
    stamps = t0_ns + np.arange(n, dtype=np.int64) * dt_ns
    return stamps, np.tile([0.0, 0.0, 9.80665], (n, 1))


def _statuses(peer: Peer) -> list[dict[str, tuple[int, str, dict]]]:
    return [
        {name: (level, msg, values) for name, level, msg, values in statuses}
        for _, statuses in diagnostics(peer.got["/diagnostics"])
    ]


def test_bad_input_is_counted_and_the_node_keeps_running(tmp_path: Path) -> None:
    """Garbage bytes, a publisher of the wrong type, NaN, stamps at 0 and going back, a wrong
    frame: each counted under its reason on /diagnostics; nothing non-finite published; no
    stray warning; SIGTERM still publishes the last period and exits 0."""
    domain = fresh_domain()
    peer = Peer(domain)
    peer.record({"/diagnostics": DIAGNOSTICS, "/mount_twin/pose": "geometry_msgs/msg/PoseStamped"})
    node = NodeProcess(domain, ["--params-file", str(PARAMS_FILE), *LOSSLESS])
    pub = peer.publisher(IMU, "/deck/imu")
    other = Peer(domain, "wrong_type_peer")  # one participant cannot mix types on a topic
    other.publisher(ACCEL, "/deck/imu")
    try:
        assert wait_for_node(pub, node), node.failed()
        stamps, accel = _at_rest(400)
        good = _imu(stamps, accel)
        nan = accel.copy()
        nan[100:110, 2] = math.nan
        bad = _imu(stamps, nan)
        sequence = [
            *good[:50],
            b"\x00\x01\x00\x00garbage",  # undecodable
            *bad[100:110],  # 10 non-finite
            _imu(np.array([0], dtype=np.int64), accel[:1])[0],  # unset stamp
            good[20],  # stamp went back (by 30 ms)
            *_imu(stamps[50:55], accel[50:55], frame="other_imu"),  # 5 wrong frame
            *good[55:400],
        ]
        publish_paced(pub, sequence, 1000.0, peer)
        peer.take_until(lambda: len(peer.got["/mount_twin/pose"]) >= 395 - GYRO_DELAY, 120.0)
        assert node.alive, node.stop()
        final = _stamp(good[-1])
        code = stop_and_take(
            node,
            peer,
            lambda: final in [d[0] for d in diagnostics(peer.got["/diagnostics"])],
            signal.SIGTERM,
        )
    finally:
        node.stop(signal.SIGKILL)
        peer.close()
        other.close()
    assert code == 0, node.stderr
    assert "Traceback" not in node.stderr and "Warning" not in node.stderr, node.stderr
    poses = [
        TYPESTORE.deserialize_cdr(r, "geometry_msgs/msg/PoseStamped")
        for r in peer.got["/mount_twin/pose"]
    ]
    assert len(poses) == 395  # 50 + 345 good samples answered, nothing else
    assert all(math.isfinite(p.pose.position.z) for p in poses)
    final = _statuses(peer)[-1]["mount_twin: input"][2]
    assert final["received"] == str(len(sequence))
    assert final["accepted"] == "395"
    assert final["rejected_undecodable"] == "1"
    assert final["rejected_non_finite"] == "10"
    assert final["rejected_zero_stamp"] == "1"
    assert final["rejected_stamp_went_back"] == "1"
    assert final["rejected_wrong_frame"] == "5"
    assert final["restarts"] == "0"


def test_a_reading_its_imu_marks_not_provided_is_rejected_live_as_in_the_replay(
    tmp_path: Path,
) -> None:
    """An Imu whose linear_acceleration_covariance[0] or angular_velocity_covariance[0] is -1
    says it has no such reading (REP-145: disregard it): such a sample is counted
    (rejected_no_acceleration, rejected_no_angular_velocity) and skipped, never answered, and
    the live node publishes what the replay of the same messages writes. Taken, the zeros of a
    missing accelerometer drove the twin as a free fall and a 5 rad/s placeholder rate as a
    spinning deck, reported ok."""
    scene = scene_from_params(dict(flatten(_params())), str(PARAMS_FILE))
    stamps, accel = _at_rest(1500)
    good = _imu(stamps, accel)
    raws = [
        *good[:500],
        *unprovided_imu(good[500:530], "linear_acceleration"),
        *good[530:900],
        *unprovided_imu(good[900:940], "angular_velocity"),
        *good[940:],
    ]
    want = replayed(scene, raws, tmp_path)
    args = ["--params-file", str(PARAMS_FILE), "-p", "stall_period_s:=3600.0"]
    peer, node, code = run_live(scene, args, raws, 1000.0, expect_outputs=1500 - 70)
    peer.close()
    assert code == 0, node.stderr
    pose = resolve("~/pose", NODE_NAME)
    assert len(peer.got[pose]) == len(want[pose]) == 1500 - 70
    assert peer.got[pose] == want[pose]
    assert diagnostics(peer.got["/diagnostics"]) == diagnostics(want["/diagnostics"])
    _, _, final = _statuses(peer)[-1]["mount_twin: input"]
    assert (final["rejected_no_acceleration"], final["rejected_no_angular_velocity"]) == (
        "30",
        "40",
    )
    assert (final["received"], final["accepted"]) == ("1500", "1430")
    assert final["lost_estimated"] == "0"  # received and skipped: their stamps leave no hole
    mounts = [s for name, s in _statuses(peer)[-1].items() if name.startswith("mount_twin: mount")]
    assert len(mounts) == 8 and all(lv == OK for lv, _, _ in mounts), mounts


def test_diagnostics_go_out_every_clock_period_without_input() -> None:
    """No input: ERROR 'no input' every period; then only wrong-frame input: ERROR naming the
    frames; a publisher of another type on the input topic is named under mount_twin: ros."""
    domain = fresh_domain()
    peer = Peer(domain)
    peer.record({"/diagnostics": DIAGNOSTICS})
    other = Peer(domain, "wrong_type_peer")  # one participant cannot mix types on a topic
    node = NodeProcess(
        domain, ["--params-file", str(PARAMS_FILE), "-p", "outputs.diagnostics_period_s:=0.5"]
    )
    try:
        assert peer.take_until(lambda: len(peer.got["/diagnostics"]) >= 3, 60.0)
        stalled = [s["mount_twin: input"] for s in _statuses(peer) if "mount_twin: input" in s]
        assert stalled and all(level == ERROR for level, _, _ in stalled)
        assert all("no input received" in msg for _, msg, _ in stalled)
        pub = peer.publisher(IMU, "/deck/imu")
        other.publisher(ACCEL, "/deck/imu")
        stamps, accel = _at_rest(1500)
        peer.got["/diagnostics"].clear()
        publish_paced(pub, _imu(stamps, accel, frame="imu_link"), 1000.0, peer)
        peer.take_until(lambda: False, 1.5)
    finally:
        code = node.stop()
        peer.close()
        other.close()
    assert code == 0, node.stderr
    statuses = _statuses(peer)
    inputs = [s["mount_twin: input"] for s in statuses if "mount_twin: input" in s]
    assert inputs and all(level == ERROR for level, _, _ in inputs)
    assert any("'deck_imu'" in msg and "'imu_link'" in msg for _, msg, _ in inputs), inputs
    ros = [s["mount_twin: ros"] for s in statuses if "mount_twin: ros" in s]
    assert ros and ros[-1][0] == ERROR and ACCEL in ros[-1][1], ros


@pytest.mark.parametrize(
    ("stall_period_s", "sig"),
    [("0.5", signal.SIGINT), ("3600.0", signal.SIGTERM)],
    ids=["after_stall_reports", "before_any_stall_report"],
)
def test_a_node_stopped_without_input_says_so_in_its_last_report(
    stall_period_s: str, sig: int
) -> None:
    """A node that never received an input message (here: listening on a topic nobody
    publishes, a sensor on /deck/imu beside it) publishes, at its SIGINT or SIGTERM, a last
    report: the input ERROR, naming the topic and type it listened on, received 0, after the
    stall reports (never stamped before them) or alone where it was stopped before the first;
    exit 0. It published nothing at shutdown: a monitor kept the last stall report, or, for a
    node stopped within its first stall period, nothing at all, never learning why."""
    domain = fresh_domain()
    peer = Peer(domain)
    peer.record({"/diagnostics": DIAGNOSTICS})
    sensor = peer.publisher(IMU, "/deck/imu")  # not the topic the node listens on
    args = ["--params-file", str(PARAMS_FILE), "-p", "input.topic:=/deck/imu_raw"]
    node = NodeProcess(domain, [*args, "-p", f"stall_period_s:={stall_period_s}"])
    try:
        if stall_period_s == "0.5":  # the reports prove the diagnostics reach the peer
            assert peer.take_until(lambda: len(peer.got["/diagnostics"]) >= 2, 60.0), node.stop()
        else:  # discovered both ways (the node waits for a matched subscriber's ack)
            assert wait_for(lambda: peer.connected("/diagnostics"), 60.0), node.failed()
            peer.take_until(lambda: False, 1.0)
            assert peer.got["/diagnostics"] == []  # no stall period has passed
        for raw in _imu(*_at_rest(10)):
            sensor.publish(raw)
        stalls = len(peer.got["/diagnostics"])
        code = stop_and_take(node, peer, lambda: len(peer.got["/diagnostics"]) > stalls, sig)
    finally:
        node.stop(signal.SIGKILL)
        peer.close()
    assert code == 0, node.stderr
    assert "Traceback" not in node.stderr, node.stderr
    reports = diagnostics(peer.got["/diagnostics"])
    assert len(reports) >= stalls + 1, node.stderr
    *before, (stamp, statuses) = reports
    assert all(s <= stamp for s, _ in before)  # /diagnostics never goes back
    by_name = {name: (level, msg, values) for name, level, msg, values in statuses}
    level, msg, values = by_name["mount_twin: input"]
    assert level == ERROR, msg
    assert msg.startswith(f"no input received on /deck/imu_raw ({IMU}) over the node's life"), msg
    assert (values["received"], values["accepted"], values["topic"]) == ("0", "0", "/deck/imu_raw")
    # the statuses of every report: the input's, integration, attitude, one per mount
    stall_names = [[n for n, *_ in st] for _, st in before]
    assert all(names == [n for n, *_ in statuses] for names in stall_names)
    assert len(statuses) == 3 + 8
    # nothing integrated: no status reads "ok" as a twin at rest (the input's ERROR says why)
    said = "no input sample was accepted"
    for _, report in [*before, (stamp, statuses)]:
        for name, level, msg, _ in report[1:]:
            verb = "not run" if name == "mount_twin: integration" else "not computed"
            assert (level, msg) == (OK, f"{verb}: {said}"), name
    if before:  # the stall reports, unchanged: ERROR, "no input received for 500 ms"
        stalled = [{n: (lv, m) for n, lv, m, _ in st}["mount_twin: input"] for _, st in before]
        assert all(s == (ERROR, "no input received for 500 ms") for s in stalled), stalled


def _node_parameters(
    args: list[str], set_mass: bool = False
) -> tuple[list[str], list, list, list]:
    """Start the node with `args`; through its parameter services (what `ros2 param` uses):
    its parameter names, values, descriptors, and the results of setting body.mass (if
    `set_mass`); the node stopped, exit 0."""
    from rclpy.parameter import Parameter
    from rclpy.parameter_client import AsyncParameterClient

    domain = fresh_domain()
    peer = Peer(domain)
    node = NodeProcess(domain, args)
    refused: list[Any] = []
    try:
        client = AsyncParameterClient(peer.node, "/mount_twin")
        assert client.wait_for_services(60.0), node.stop()
        names = peer.call(client.list_parameters).result.names
        values = peer.call(lambda: client.get_parameters(names)).values
        described = peer.call(lambda: client.describe_parameters(names)).descriptors
        if set_mass:
            mass = [Parameter("body.mass", value=1.0)]
            refused = peer.call(lambda: client.set_parameters(mass)).results
    finally:
        code = node.stop()
        peer.close()
    assert code == 0, node.stderr
    return names, values, described, refused


def _dumped(names: list[str], values: list[Any]) -> str:
    """The params file `ros2 param dump /mount_twin` writes (ros2param: names split at dots
    into nested mappings, PyYAML's block style; a string list's `y` comes out bare)."""
    from rclpy.parameter import parameter_value_to_python

    tree: dict[str, Any] = {}
    for name, value in zip(names, values, strict=True):
        *parents, leaf = name.split(".")
        node = tree
        for part in parents:
            node = node.setdefault(part, {})
        node[leaf] = parameter_value_to_python(value)
    return yaml.dump({"/mount_twin": {"ros__parameters": tree}}, default_flow_style=False)


def test_parameters_are_all_set_described_and_read_only(tmp_path: Path) -> None:
    """What `ros2 param dump/describe/set` see, through the parameter services; a dump
    reloads as a params file into the same parameters."""
    args = ["--params-file", str(PARAMS_FILE), "-p", "body.mass:=1300"]
    names, values, described, refused = _node_parameters(args, set_mass=True)
    dump = tmp_path / "dump.yaml"
    dump.write_text(_dumped(names, values), encoding="utf-8")
    assert "dofs: x y z alpha gamma delta" in dump.read_text()
    again = _node_parameters(["--params-file", str(dump)])
    assert dict(zip(again[0], again[1], strict=True)) == dict(zip(names, values, strict=True))
    unset = [n for n, v in zip(names, values, strict=True) if v.type == 0]
    assert not unset, f"parameters without a value: {unset}"
    by_name = dict(zip(names, values, strict=True))
    assert by_name["body.mass"].double_value == 1300.0  # an integer taken as the double
    assert by_name["outputs.decimation"].integer_value == 1  # a default, visible
    assert by_name["mounts.fl.kind"].string_value == "linear"
    scene_params = [
        d for d in described if d.name not in ("use_sim_time", "start_type_description_service")
    ]
    assert all(d.description and d.read_only for d in scene_params), [
        d.name for d in scene_params if not (d.description and d.read_only)
    ]
    assert not refused[0].successful and "read-only" in refused[0].reason
    # every number declares the loader's range (ros2 param describe shows it)
    numeric = {n for n, v in by_name.items() if v.type in (2, 3)}  # INTEGER, DOUBLE
    ranges = {d.name: d.floating_point_range or d.integer_range for d in described}
    assert len(numeric) >= 20 and [n for n in numeric if not ranges[n]] == []
    (rtol,) = ranges["integration.rtol"]
    assert (rtol.from_value, rtol.to_value) == (1e-13, 0.1)


@pytest.mark.parametrize(
    ("args", "names"),
    [
        (["-p", "outputs.decimaton:=2"], "outputs.decimaton: unknown key"),
        (  # the list names the node's own options too, not only the scene's
            ["-p", "batch_perod_s:=0.01"],
            "batch_perod_s: unknown parameter (known: ageing, batch_period_s, body,",
        ),
        ([], "mount_names: required parameter is missing"),
        (["-p", "scene_file:=/nonexistent.yaml"], "/nonexistent.yaml: cannot read"),
        (["-p", "input.topic:=/deck//imu"], "input.topic: '/deck//imu' is not a ROS topic name"),
        (["-p", "batch_period_s:=-1.0"], "batch_period_s: must be in [0.0, 1.0]"),
        (["-p", "input_queue_depth:=10.5"], "input_queue_depth: expected an integer, got 10.5"),
        (
            ["-p", f"scene_file:={GENSET}", "-p", "body.mass:=heavy"],
            "body.mass: expected a number, got 'heavy'",
        ),
        (["-p", "body.mass:=heavy"], "body.mass: expected a number, got 'heavy'"),
        (
            ["-p", "qos_overrides./deck/imu.subscription.reliability:=sometimes"],
            "qos_overrides./deck/imu.subscription.reliability: expected 'best_effort' or",
        ),
        (
            ["-p", "qos_overrides./deck/imu.subscription.depth:=5"],
            "qos_overrides./deck/imu.subscription.depth: no such QoS override",
        ),
        # what rcl refuses itself: it logged "[ERROR] [rcl]: Failed to parse global
        # arguments" first, and its message ended in C source positions
        (
            ["--params-file", "/nonexistent.yaml"],
            "/nonexistent.yaml: cannot read: No such file or directory",
        ),
        (
            ["--params-file", str(GENSET)],  # a scene file where a params file goes
            f"--params-file {GENSET}: not a valid params file: Cannot have a value before "
            "ros__parameters at line 5",
        ),
        (
            ["-p", "body.mass:=[1"],
            "-p body.mass:=[1: not a valid parameter override rule: Error parsing an event",
        ),
        (["-r", "/deck/imu:=//x"], "-r /deck/imu:=//x: not a valid remap rule"),
        # rclpy's own parameters, of another type: a traceback from Node.__init__, exit 1
        (["-p", "use_sim_time:=maybe"], "use_sim_time: expected true or false, got 'maybe'"),
        (
            ["-p", "start_type_description_service:=1"],
            "start_type_description_service: expected true or false, got 1",
        ),
    ],
    ids=[
        "unknown_key",
        "unknown_option",
        "no_parameters",
        "bad_scene_file",
        "bad_topic",
        "out_of_range",
        "option_not_an_integer",
        "bad_type",
        "bad_type_over_params_file",
        "bad_qos_override",
        "unknown_qos_override",
        "missing_params_file",
        "scene_file_as_params_file",
        "bad_override_rule",
        "bad_remap_rule",
        "bad_use_sim_time",
        "bad_type_description_switch",
    ],
)
def test_configuration_errors_end_the_node_with_one_line_naming_the_parameter(
    args: list[str], names: str
) -> None:
    with_file = ["--params-file", str(PARAMS_FILE)] if args and "scene_file" not in args[1] else []
    node = NodeProcess(fresh_domain(), [*with_file, *args])
    code = node.wait(60.0)
    assert code == 2, node.stderr
    (line,) = node.stderr.splitlines()  # nothing but the node's line: no rcl log, no traceback
    assert line.startswith("mount_twin_node: ") and names in line, node.stderr
    assert ", at /" not in line  # rcl's C source positions


def test_the_node_logs_at_start_the_ratings_its_start_passes(tmp_path: Path) -> None:
    """A scene's warnings are logged at start; on hysteretic mounts, with the ratings judged
    at the start the node solves (`model.ratings`), which the loader leaves to it: the mount
    named by its parameter, the start's sag in closed form (`test_start_loaded`)."""
    path = tmp_path / "rated.scene.yaml"
    path.write_text(yaml.safe_dump(rated_scene(RATED)), encoding="utf-8")
    domain = fresh_domain()
    peer = Peer(domain)
    peer.record({"/diagnostics": DIAGNOSTICS})
    node = NodeProcess(domain, ["-p", f"scene_file:={path}", "-p", "stall_period_s:=0.5"])
    try:  # a stall report: the node has started
        assert peer.take_until(lambda: len(peer.got["/diagnostics"]) >= 1, 60.0), node.stop()
    finally:
        code = node.stop()
        peer.close()
    assert code == 0, node.stderr
    sag = -start_sag(C_SOFT, 1)
    (line,) = [ln for ln in node.stderr.splitlines() if "rated_deflection" in ln]
    assert "[WARN]" in line
    assert f"{path}: mounts.r.rated_deflection: the static deflection at the start" in line
    assert f"{sag:.4g} m along local z, is {sag / RATED:.3g} times the rated 0.012 m" in line


def test_a_params_file_key_given_twice_ends_the_node_naming_the_file_and_lines(
    tmp_path: Path,
) -> None:
    """rcl keeps the last of `mass: -1.0` and `mass: 1200.0`, and the node ran; a scene file
    refuses a key given twice, and a params file is read by the same rules now."""
    text = PARAMS_FILE.read_text(encoding="utf-8")
    params = tmp_path / "p.yaml"
    params.write_text(text.replace("mass: ", "mass: -1.0\n      mass: ", 1), encoding="utf-8")
    node = NodeProcess(fresh_domain(), ["--params-file", str(params)])
    code = node.wait(60.0)
    assert code == 2, node.stderr
    (line,) = node.stderr.splitlines()
    assert f"{params}: line " in line, node.stderr
    assert "key 'mass' given twice in one mapping" in line


def test_the_command_line_outranks_a_params_file_section_for_the_node(tmp_path: Path) -> None:
    """rcl reads params files after every -p: the node takes back the -p values that a file's
    section for it (its name, its full name, or /**) also sets, and only those."""
    from mount_twin.ros.parameters import shadowed_command_line

    params = tmp_path / "p.yaml"
    params.write_text(
        "/**:\n  ros__parameters:\n    body: {mass: 1200.0, cg: [0.0, 0.0, 0.4]}\n    name: a\n"
        "/ship/twin:\n  ros__parameters:\n    outputs: {decimation: 4}\n"
        "other_node:\n  ros__parameters:\n    input: {g: 9.0}\n"
    )
    args = [
        "mount_twin_node",
        "--ros-args",
        "-p", "body.mass:=heavy",
        "--params-file", str(params),
        "-p", "twin:outputs.decimation:=2",
        "-p", "body.cg:=[0.05, 0.0, 5e-1]",  # rcl reads 5e-1 as a double: so must the node
        "-p", "input.g:=9.5",  # only another node's section sets it: rcl keeps this -p
        "-p", "other_node:name:=b",  # for another node
        "--",
        "-p", "name:=c",  # not a ROS argument
    ]  # fmt: skip
    got = shadowed_command_line(args, {"twin", "ship/twin"})
    assert got == {"body.mass": "heavy", "outputs.decimation": 2, "body.cg": [0.05, 0.0, 0.5]}


def test_a_renamed_namespaced_node_takes_the_bundled_params_file() -> None:
    domain = fresh_domain()
    peer = Peer(domain)
    topic = resolve("~/pose", "twin2", "/ship")
    peer.record({topic: "geometry_msgs/msg/PoseStamped"})
    node = NodeProcess(
        domain, ["--params-file", str(PARAMS_FILE), "-r", "__node:=twin2", "-r", "__ns:=/ship"]
    )
    try:
        pub = peer.publisher(IMU, "/deck/imu")
        assert wait_for_node(pub, node), node.failed()
        assert wait_for(lambda: peer.connected(topic), 10.0)
        assert peer.matched_by(resolve("~/scene", "twin2", "/ship"), 30.0), node.failed()
        publish_paced(pub, _imu(*_at_rest(100)), 1000.0, peer)
        # the last GYRO_DELAY samples are answered as the node shuts down
        assert peer.take_until(lambda: len(peer.got[topic]) >= 100 - GYRO_DELAY, 10.0)
    finally:
        code = node.stop()
        peer.close()
    assert code == 0, node.stderr
    assert "8 mounts" in node.stderr


def test_sim_time_without_clock_is_reported_and_with_clock_is_followed() -> None:
    """use_sim_time: no /clock → ERROR under mount_twin: ros (batched input still processed
    on the steady clock); with /clock the stalled-input reports follow sim time."""
    from rosgraph_msgs.msg import Clock

    domain = fresh_domain()
    peer = Peer(domain)
    peer.record({"/diagnostics": DIAGNOSTICS, "/mount_twin/pose": "geometry_msgs/msg/PoseStamped"})
    node = NodeProcess(
        domain,
        [
            "--params-file",
            str(PARAMS_FILE),
            "-p",
            "use_sim_time:=true",
            "-p",
            "batch_period_s:=0.005",
            "-p",
            "outputs.diagnostics_period_s:=0.5",
        ],
    )
    try:
        pub = peer.publisher(IMU, "/deck/imu")
        assert wait_for_node(pub, node), node.failed()
        publish_paced(pub, _imu(*_at_rest(200)), 1000.0, peer)
        assert peer.take_until(lambda: len(peer.got["/mount_twin/pose"]) >= 200 - GYRO_DELAY, 10.0)
        assert peer.take_until(
            lambda: sum("mount_twin: ros" in s for s in _statuses(peer)) >= 3, 15.0
        ), "no reports of the missing /clock"
        clock = peer.node.create_publisher(Clock, "/clock", 10)
        sim0 = 5_000_000_000
        peer.got["/diagnostics"].clear()
        for k in range(40):  # 2 s of sim time in 0.4 s of wall time
            msg = Clock()
            msg.clock.sec, msg.clock.nanosec = divmod(sim0 + k * 50_000_000, 1_000_000_000)
            clock.publish(msg)
            peer.take_until(lambda: False, 0.01)
        peer.take_until(lambda: any("mount_twin: ros" in st for st in _statuses(peer)), 5.0)
    finally:
        code = node.stop()
        peer.close()
    assert code == 0, node.stderr
    # reported every second, its text counting the seconds; logged once (it was every second)
    assert node.stderr.count("use_sim_time is true and no /clock has come") == 1, node.stderr
    ros = [s["mount_twin: ros"] for s in _statuses(peer) if "mount_twin: ros" in s]
    stamps = [
        stamp
        for stamp, statuses in diagnostics(peer.got["/diagnostics"])
        if any(name == "mount_twin: input" for name, *_ in statuses)
    ]
    assert stamps and all(sim0 <= s <= sim0 + 2_000_000_000 for s in stamps), stamps
    assert ros[-1][0] == OK, ros  # the clock came: the problem clears


def test_sim_time_switched_on_at_run_time_counts_the_missing_clock_from_the_switch() -> None:
    """`ros2 param set /mount_twin use_sim_time true` on a node running for seconds: the
    "no /clock for N s" report counted N from the node's start (and came at once, its grace
    spent long before), not from the switch. It comes after the grace of two watch periods
    (2 s) from the switch, N at most the seconds since it."""
    import re

    from rclpy.parameter import Parameter
    from rclpy.parameter_client import AsyncParameterClient

    domain = fresh_domain()
    peer = Peer(domain)
    peer.record({"/diagnostics": DIAGNOSTICS})
    node = NodeProcess(domain, ["--params-file", str(PARAMS_FILE)])
    said: list[tuple[float, str]] = []  # (test's monotonic s at receipt, the ros status' text)

    def clock_said() -> bool:
        for status in _statuses(peer)[len(said) :]:
            said.append((time.monotonic(), status.get("mount_twin: ros", (0, ""))[1]))
        return any("no /clock has come" in text for _, text in said)

    try:
        client = AsyncParameterClient(peer.node, "/mount_twin")
        assert client.wait_for_services(60.0), node.failed()
        peer.take_until(lambda: False, 6.0)  # the node runs 6 s on wall time
        assert not clock_said()
        asked = time.monotonic()  # the node switches after this
        use_sim_time = [Parameter("use_sim_time", value=True)]
        result = peer.call(lambda: client.set_parameters(use_sim_time))
        assert all(r.successful for r in result.results), result
        assert peer.take_until(clock_said, 20.0), "no report of the missing /clock"
    finally:
        code = node.stop()
        peer.close()
    assert code == 0, node.stderr
    at, text = next((t, x) for t, x in said if "no /clock has come" in x)
    found = re.search(r"no /clock has come for (\d+) s", text)
    assert found, text
    waited = int(found.group(1))
    # the grace is 2 s (two watch periods) after the switch, which came after it was asked
    # for; the report before its receipt (its seconds rounded: ≤ 0.5 s more)
    assert 2 <= waited <= at - asked + 0.5, (waited, at - asked, text)


def test_tf_static_is_latched_for_a_late_subscriber_and_tf_carries_the_pose() -> None:
    """/tf_static reaches a subscriber that joins seconds after the node published it (reliable,
    transient local: tf2_ros' static listener), once, with one transform per mount: byte-equal
    to `static_transforms` at the node's stamp (frames.foundation → each mount frame at its
    position and axes); a volatile subscriber joining then gets nothing. /tf: one transform per
    pose, frames.foundation → frames.body, with the pose's stamp, position and orientation."""
    if not tf_available():
        pytest.skip("tf2_msgs is not importable: `mount-twin build-tf2-msgs` builds it")
    scene = scene_from_params(dict(flatten(_params())), str(PARAMS_FILE))
    pose = resolve("~/pose", NODE_NAME)
    domain = fresh_domain()
    peer, late, volatile = (Peer(domain, f"{n}_peer") for n in ("tf", "late", "volatile"))
    peer.record({TF_TOPIC: TF, pose: POSE})
    node = NodeProcess(domain, ["--params-file", str(PARAMS_FILE), *LOSSLESS])
    pub = peer.publisher(IMU, "/deck/imu")
    try:
        assert wait_for_node(pub, node), node.stop()
        assert wait_for(lambda: peer.connected(TF_TOPIC) and peer.connected(pose), 10.0)
        assert peer.matched_by(SCENE, 30.0), node.stop()
        stamps, accel = _at_rest(300)
        publish_paced(pub, _imu(stamps, accel), 1000.0, peer)
        # the last GYRO_DELAY samples are answered as the node shuts down
        answered = lambda: min(len(peer.got[t]) for t in (TF_TOPIC, pose))  # noqa: E731
        assert peer.take_until(lambda: answered() >= 300 - GYRO_DELAY, 60.0)
        late.record({TF_STATIC_TOPIC: TF}, latched=True)  # the node published it at its start
        volatile.record({TF_STATIC_TOPIC: TF})
        assert late.take_until(lambda: len(late.got[TF_STATIC_TOPIC]) >= 1, 10.0)
        assert wait_for(lambda: volatile.connected(TF_STATIC_TOPIC), 10.0)  # matched under load
        late.take_until(lambda: False, 0.5)
        volatile.take()
        code = stop_and_take(node, peer, lambda: answered() >= 300)
    finally:
        node.stop(signal.SIGKILL)
        for p in (peer, late, volatile):
            p.close()
    assert code == 0, node.stderr
    assert "tf2_msgs" not in node.stderr, node.stderr  # no "not importable": it published TF
    assert len(late.got[TF_STATIC_TOPIC]) == 1 and volatile.got[TF_STATIC_TOPIC] == []
    raw = late.got[TF_STATIC_TOPIC][0]
    static = TYPESTORE.deserialize_cdr(raw, TF).transforms
    assert [(t.header.frame_id, t.child_frame_id) for t in static] == [
        (scene.frames.foundation, scene.frames.mount_frame(m.name)) for m in scene.mounts
    ]
    stamp = static[0].header.stamp
    assert raw == static_transforms(scene, stamp.sec * 10**9 + stamp.nanosec)[2]
    tfs = [TYPESTORE.deserialize_cdr(r, TF).transforms for r in peer.got[TF_TOPIC]]
    poses = [TYPESTORE.deserialize_cdr(r, POSE) for r in peer.got[pose]]
    assert len(tfs) == len(poses) == 300
    frames = (scene.frames.foundation, scene.frames.body)
    for (tf,), p in zip(tfs, poses, strict=True):
        assert (tf.header.frame_id, tf.child_frame_id) == frames == (p.header.frame_id, frames[1])
        assert tf.header.stamp == p.header.stamp
        t, q = tf.transform.translation, tf.transform.rotation
        x, o = p.pose.position, p.pose.orientation
        assert (t.x, t.y, t.z, q.x, q.y, q.z, q.w) == (x.x, x.y, x.z, o.x, o.y, o.z, o.w)


def test_the_node_publishes_its_scene_latched_for_a_late_subscriber(tmp_path: Path) -> None:
    """A recording of the node's topics could be checked against a scene by its mount names,
    rtol and atol only. The node publishes its scene on ~/scene once at its start, latched:
    a subscriber joining seconds later (reliable, transient local) gets it, once; its digest
    is that of the scene file loaded here with the parameter given over it written into it
    (outputs.decimation 10), its value hashes to it, its file is the scene_file given and its
    overrides the parameter given; a volatile subscriber joining then gets nothing."""
    import hashlib

    from mount_twin.scene.description import scene_digest

    data = yaml.safe_load(GENSET.read_text(encoding="utf-8"))
    data["outputs"]["decimation"] = 10
    written = tmp_path / "decimated.scene.yaml"
    written.write_text(yaml.safe_dump(data), encoding="utf-8")
    domain = fresh_domain()
    waiting, late, volatile = (Peer(domain, f"{n}_peer") for n in ("waiting", "late", "volatile"))
    args = ["-p", f"scene_file:={GENSET}", "-p", "outputs.decimation:=10"]
    node = NodeProcess(domain, args)
    pub = waiting.publisher(IMU, "/deck/imu")
    try:
        assert wait_for_node(pub, node), node.stop()
        wait_for(lambda: False, 2.0)  # the node published its scene seconds ago
        late.record({SCENE: STRING}, latched=True)
        volatile.record({SCENE: STRING})
        assert late.take_until(lambda: len(late.got[SCENE]) >= 1, 10.0)
        assert wait_for(lambda: volatile.connected(SCENE), 10.0)
        late.take_until(lambda: False, 0.5)
        volatile.take()
        code = node.stop()
    finally:
        node.stop(signal.SIGKILL)
        for p in (waiting, late, volatile):
            p.close()
    assert code == 0, node.stderr
    assert len(late.got[SCENE]) == 1 and volatile.got[SCENE] == []
    record = json.loads(TYPESTORE.deserialize_cdr(late.got[SCENE][0], STRING).data)
    assert record["sha256"] == scene_digest(load_scene_file(written))
    assert record["sha256"] != scene_digest(load_scene_file(GENSET))
    text = json.dumps(record["value"], sort_keys=True, separators=(",", ":"))
    assert hashlib.sha256(text.encode()).hexdigest() == record["sha256"]
    assert record["file"] == str(GENSET) and record["overrides"] == {"outputs.decimation": 10}
    assert record["value"]["outputs"]["decimation"] == 10


def test_building_tf2_msgs_again_finds_the_build() -> None:
    """`mount-twin build-tf2-msgs` run again (.ci/run ran it before the tests) rebuilds
    nothing, needs no export, and the interpreter it checks with imports this tf2_msgs."""
    if not tf_available():
        pytest.skip("tf2_msgs is not importable: `mount-twin build-tf2-msgs` builds it")
    import tf2_msgs

    done = subprocess.run(
        [sys.executable, "-m", "mount_twin.cli", "build-tf2-msgs"],
        capture_output=True,
        text=True,
        cwd=ROOT,
        timeout=120,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    assert "tf2_msgs up to date in" in done.stdout and "export" not in done.stdout, done.stdout
    assert f"type support from {tf2_msgs.__file__}" in done.stdout, done.stdout


def test_a_slow_subscriber_loses_outputs_and_no_event_says_so() -> None:
    """What docs/node.md's `output_queue_depth` says a user must size for: a reliable keep-last
    subscriber that cannot take messages while a burst comes keeps its last `depth` of them,
    and it gets no lost-message event (Fast DDS; the publisher has none to offer) — so the
    node has nothing to count and the depths must be chosen."""
    from rclpy.event_handler import SubscriptionEventCallbacks
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy
    from std_msgs.msg import Int32

    peer = Peer(fresh_domain())
    lost: list[int] = []
    got: list[int] = []
    qos = QoSProfile(
        depth=10, reliability=ReliabilityPolicy.RELIABLE, history=HistoryPolicy.KEEP_LAST
    )
    executor = SingleThreadedExecutor(context=peer.context)
    executor.add_node(peer.node)

    def spin(seconds: float) -> None:
        deadline = time.monotonic() + seconds
        while time.monotonic() < deadline:
            executor.spin_once(timeout_sec=0.02)

    try:
        peer.node.create_subscription(
            Int32,
            "burst",
            lambda m: got.append(m.data),
            qos,
            event_callbacks=SubscriptionEventCallbacks(
                message_lost=lambda e: lost.append(e.total_count_change)
            ),
        )
        pub = peer.node.create_publisher(Int32, "burst", qos)
        assert wait_for(lambda: pub.get_subscription_count() == 1, 10.0)
        spin(0.5)  # the reader matches the writer too
        for i in range(1000):  # the subscriber's executor does not run meanwhile
            pub.publish(Int32(data=i))
        spin(1.0)
    finally:
        executor.remove_node(peer.node)
        peer.close()
    assert got == list(range(990, 1000)) and lost == []


def test_the_node_wakes_its_executor_only_for_work() -> None:
    """rclpy's executor builds its wait set anew at every wake-up (about a millisecond of CPU
    here): the outputs' publishers add no event handlers to it (rclpy's defaults, two a
    publisher, were 26 of the pump's 31 waitables), and the batch timer runs only while input
    comes (it woke an idle node every 5 ms: 35 % of a core). In this process, the node on an
    executor of its own context, a peer publishing."""
    domain = fresh_domain()
    args = ["--params-file", str(PARAMS_FILE), *LOSSLESS]
    args += ["-p", "batch_period_s:=0.005"]  # reliable input: none lost while discovery ends
    twin = InProcessNode(domain, args)
    node, executor = twin.node, twin.executor
    peer = Peer(domain)
    try:
        outputs = [*node._pubs.values(), node._scene_pub, getattr(node, "_static", None)]
        outputs = [p for p in outputs if p is not None]  # /tf_static: with tf2_msgs
        assert len(outputs) >= 12 and all(not p.event_handlers for p in outputs)  # 8 mounts
        timer = node._batch_timer
        assert timer is not None and timer.is_canceled()  # no input yet: not running
        pub = peer.publisher(IMU, "/deck/imu")
        assert wait_for(lambda: pub.get_subscription_count() > 0, 30.0)
        for raw in _imu(*_at_rest(50)):
            pub.publish(raw)
        counts = node.stream.engine.counts
        _spin_until_accepted(executor, counts, 50)
        for _ in range(10):  # input has stopped: the next period finds nothing and stops it
            executor.spin_once(timeout_sec=0.01)
        assert timer.is_canceled() and not node._pending
        for raw in _imu(*_at_rest(5, STAMP0 + 50_000_000)):  # input again: running again
            pub.publish(raw)
        deadline = time.monotonic() + 30.0
        while not node._pending and time.monotonic() < deadline:
            executor.spin_once(timeout_sec=0.01)
        assert node._pending and not timer.is_canceled()
    finally:
        peer.close()
        twin.close()


def _catches_sigterm(pid: int) -> bool:
    """Whether process `pid` has a handler for SIGTERM (Linux: SigCgt of /proc/PID/status;
    Python catches SIGINT from its start, SIGTERM only where a program asks)."""
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("SigCgt:"):
            return bool(int(line.split()[1], 16) >> (signal.SIGTERM - 1) & 1)
    return False


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_a_stop_while_the_node_starts_exits_0_without_a_traceback(sig: int) -> None:
    """SIGINT or SIGTERM while the process still imports rclpy, numpy and the core (about a
    second): exit 0, nothing on stderr. They ended it with a KeyboardInterrupt traceback (exit
    130) or without a word (143). The signal goes once the process catches SIGTERM (its entry
    point does so first thing) or 0.3 s after its start, whichever comes first."""
    node = NodeProcess(fresh_domain(), ["--params-file", str(PARAMS_FILE)])
    started = time.monotonic()
    while not _catches_sigterm(node.proc.pid) and time.monotonic() < started + 0.3:
        time.sleep(0.002)
    code = node.stop(sig)
    assert (code, node.stderr) == (0, "")


def test_a_diagnostics_period_longer_than_a_timer_can_wait_runs_the_node() -> None:
    """outputs.diagnostics_period_s of 1e12 s, which the scene takes (any finite period; a
    replay runs it): the node's stall check at that period never comes, and the node answers
    its input and exits 0. The stall timer's period overflowed rclpy's (int64 ns): the node
    ended at start with a TypeError traceback, exit 1."""
    domain = fresh_domain()
    peer = Peer(domain)
    peer.record({"/mount_twin/pose": POSE})
    period = ["-p", "outputs.diagnostics_period_s:=1.0e+12"]
    node = NodeProcess(domain, ["--params-file", str(PARAMS_FILE), *LOSSLESS, *period])
    pub = peer.publisher(IMU, "/deck/imu")
    try:
        assert wait_for_node(pub, node), node.failed()
        assert peer.matched_by(SCENE, 30.0), node.failed()
        publish_paced(pub, _imu(*_at_rest(100)), 1000.0, peer)
        peer.take_until(lambda: len(peer.got["/mount_twin/pose"]) >= 100 - GYRO_DELAY, 60.0)
        code = stop_and_take(node, peer, lambda: len(peer.got["/mount_twin/pose"]) >= 100)
    finally:
        node.stop(signal.SIGKILL)
        peer.close()
    assert code == 0, node.stderr
    assert "Traceback" not in node.stderr, node.stderr
    assert len(peer.got["/mount_twin/pose"]) == 100


SILENT_SUBSCRIBER = """
import sys, time
sys.path.insert(0, "test")
from ros_harness import Peer, wait_for
peer = Peer(int(sys.argv[1]), "silent_subscriber")
peer.record({"/diagnostics": "diagnostic_msgs/msg/DiagnosticArray"})
assert wait_for(lambda: peer.connected("/diagnostics"), 120.0)
print("connected", flush=True)
time.sleep(3600.0)
"""
"""A reliable subscriber of /diagnostics in a process of its own: stopped (SIGSTOP), it
acknowledges nothing, and the node's shutdown waits for it."""


@pytest.mark.parametrize(("again", "code"), [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_a_second_stop_ends_the_shutdown_at_once_saying_what_it_dropped(
    again: int, code: int
) -> None:
    """SIGINT, then, while the node waits for a subscriber that never acknowledges its last
    diagnostics, SIGINT again (Ctrl-C pressed twice) or SIGTERM: the node exits at once
    (here: within 5 s of the second signal; the wait lasts 10 s) with 128 + that signal,
    naming the topic whose last outputs it dropped. It ignored the second signal and waited
    the 10 s out, then exited 0."""
    domain = fresh_domain()
    node = NodeProcess(domain, ["--params-file", str(PARAMS_FILE)])
    silent = subprocess.Popen(
        [sys.executable, "-c", SILENT_SUBSCRIBER, str(domain)],
        env={**os.environ, "ROS_DOMAIN_ID": str(domain)},
        stdout=subprocess.PIPE,
        text=True,
        cwd=ROOT,
    )
    try:
        assert silent.stdout is not None and silent.stdout.readline() == "connected\n"
        time.sleep(1.0)  # the node's writer matches the reader too
        assert node.alive, node.failed()
        silent.send_signal(signal.SIGSTOP)
        node.proc.send_signal(signal.SIGINT)
        time.sleep(2.0)
        assert node.alive, node.failed()  # waiting for the acknowledgement
        sent = time.monotonic()
        assert node.stop(again) == code, node.stderr
        took = time.monotonic() - sent
    finally:
        node.stop(signal.SIGKILL)
        silent.kill()
        silent.communicate()
    assert took < 5.0, node.stderr
    said = "stopped again: the last outputs not acknowledged by every subscriber were dropped on "
    assert f"{said}/diagnostics (subscribers matched: 1)" in node.stderr, node.stderr
    assert "Traceback" not in node.stderr, node.stderr


def test_a_second_stop_leaves_the_backlog_unprocessed_and_the_last_report_counts_it() -> None:
    """The node's shutdown after a second stop (`StopRequests` taking SIGINT twice), in this
    process: of 200 samples processed and 3000 still waiting in the input's queue, the 3000
    are not processed; the last report still goes out, its period's 200 samples all answered
    (the gyro filter's delayed ones flushed), counting the 3000 `lost_unprocessed_at_stop`
    (ERROR: 94 % of the samples due). Before, the shutdown processed the whole backlog, however
    long it took."""
    from rclpy.duration import Duration

    from mount_twin.ros.start import StopRequests

    domain = fresh_domain()
    twin = InProcessNode(domain, ["--params-file", str(PARAMS_FILE), *LOSSLESS])
    node, executor = twin.node, twin.executor
    peer = Peer(domain)
    peer.record({"/diagnostics": DIAGNOSTICS, "/mount_twin/pose": POSE})
    stops = StopRequests()
    try:
        pub = peer.publisher(IMU, "/deck/imu")
        assert wait_for(lambda: pub.get_subscription_count() > 0, 30.0)
        # both recorded topics matched before the first sample, on both sides (a pose published
        # before the node's writer matched the peer's reader is not sent to it: the peer had 0
        # of 200 on a busy machine, and 38 once in CI, most likely the gyro delay's tail
        # flushed at the stop after a match on the peer's side only)
        recorded = ("/diagnostics", "/mount_twin/pose")
        assert wait_for(lambda: all(peer.connected(t) for t in recorded), 30.0)
        writers = [p for p in node._pubs.values() if p.topic_name in recorded]
        assert len(writers) == 2
        assert wait_for(lambda: all(w.get_subscription_count() > 0 for w in writers), 30.0)
        stamps, accel = _at_rest(3200)
        for raw in _imu(stamps[:200], accel[:200]):
            pub.publish(raw)
        counts = node.stream.engine.counts
        _spin_until_accepted(executor, counts, 200)
        for raw in _imu(stamps[200:], accel[200:]):
            pub.publish(raw)
        assert pub.wait_for_all_acked(Duration(seconds=30.0))  # all in the node's queue
        stops.take(signal.SIGINT)
        stops.take(signal.SIGINT)
        assert node.finish(stops)
        # a second stop does not wait for the outputs' acknowledgements (that is its point):
        # the test does, so that a busy machine's slow delivery is not read as a lost pose
        assert all(p.wait_for_all_acked(Duration(seconds=30.0)) for p in node._pubs.values())
        peer.take_until(lambda: len(peer.got["/diagnostics"]) >= 1, 30.0)
        peer.take_until(lambda: False, 0.5)
    finally:
        peer.close()
        twin.close()
    assert (counts["received"], counts["lost_unprocessed_at_stop"]) == (200, 3000)
    assert len(peer.got["/mount_twin/pose"]) == 200
    (_, statuses), *_ = diagnostics(peer.got["/diagnostics"][-1:])
    level, msg, values = {n: (lv, m, v) for n, lv, m, v in statuses}["mount_twin: input"]
    assert (values["received"], values["lost_unprocessed_at_stop"]) == ("200", "3000")
    assert level == ERROR and "reported lost_unprocessed_at_stop 3000" in msg, msg


def _spin_until_accepted(executor: Any, counts: Mapping[str, int], n: int) -> None:
    """Spin the node's executor (in this process) until its engine has accepted `n` input
    samples (30 s at most): they are all in the twin."""
    deadline = time.monotonic() + 30.0
    while counts["accepted"] < n and time.monotonic() < deadline:
        executor.spin_once(timeout_sec=0.01)
    assert counts["accepted"] == n
