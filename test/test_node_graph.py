"""What the running node shows on the ROS graph is what docs/node.md's topic table says: the
topics it publishes and subscribes to, their types, reliability and durability, and the
defaults the table gives. Truth is the graph (`get_publishers_info_by_topic`,
`get_subscriptions_info_by_topic` of a peer node), held to the table parsed from the page.
"""

from __future__ import annotations

import os
import re
from pathlib import Path
from typing import Any

import pytest
import yaml

if os.environ.get("CI"):
    import rclpy  # noqa: F401  (CI installs it: a node test that skips there is a failure)
else:
    pytest.importorskip("rclpy")

from io_helpers import ROOT, params_yaml
from ros_harness import NodeProcess, Peer, fresh_domain, wait_for

NODE = "mount_twin"
MOUNTS = params_yaml()["mount_names"]
GRAPH_ONLY = {"/rosout", "/parameter_events"}
"""What every rclpy node publishes."""
LATCHED = {"/tf_static", f"/{NODE}/scene"}
"""The outputs published once, transient local (the mount frames, the scene)."""


def _table() -> list[tuple[str, list[str], list[str]]]:
    """docs/node.md's topic table: (direction, the topic cell's code spans, the types)."""
    text = (ROOT / "docs" / "node.md").read_text(encoding="utf-8")
    rows = []
    for line in text.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) >= 4 and cells[0] in ("in", "out"):
            types = [t.replace("/", "/msg/") for t in re.findall(r"\w+/\w+", cells[2])]
            rows.append((cells[0], re.findall(r"`([^`]+)`", cells[1]), types))
    return rows


def _documented_outputs() -> dict[str, str]:
    """Resolved topic → type of every output row (the body IMU's aside: no body_sensor here),
    `~` the node's name and `<name>` each mount of config/params.yaml."""
    out = {}
    for _, spans, (msgtype,) in (r for r in _table() if r[0] == "out"):
        for span in spans:
            if "body_imu" in span:
                continue
            topic = span.replace("~", f"/{NODE}", 1)
            for mount in MOUNTS if "<name>" in topic else [None]:
                out[topic.replace("<name>", mount) if mount else topic] = msgtype
    return out


def _graph(params: Path) -> tuple[dict[str, Any], dict[str, Any]]:
    """Start the node on `params`; (topic → publisher info, topic → subscription info) of the
    node as a peer sees them on the graph; the node stopped, exit 0."""
    domain = fresh_domain()
    peer = Peer(domain)
    node = NodeProcess(domain, ["--params-file", str(params)])
    try:

        def pubs() -> dict[str, Any]:
            return {
                name: info
                for name, _ in peer.node.get_topic_names_and_types()
                for info in peer.node.get_publishers_info_by_topic(name)
                if info.node_name == NODE
            }

        assert wait_for(lambda: "/tf_static" in pubs() or not node.alive, 120.0), node.failed()
        wait_for(lambda: False, 1.0)  # the rest of the node's endpoints
        published = pubs()
        subscribed = {
            name: info
            for name, _ in peer.node.get_topic_names_and_types()
            for info in peer.node.get_subscriptions_info_by_topic(name)
            if info.node_name == NODE
        }
    finally:
        code = node.stop()
        peer.close()
    assert code == 0, node.stderr
    return published, subscribed


def test_the_graph_is_what_the_topic_table_says(tmp_path: Path) -> None:
    """config/params.yaml without `input.topic`: the node subscribes to the table's default
    for it (the page gave the bundled params' /deck/imu as the default, which is /imu/data) and
    publishes exactly the table's outputs, reliable, /tf_static and ~/scene alone transient
    local."""
    from rclpy.qos import DurabilityPolicy, ReliabilityPolicy

    tree = yaml.safe_load((ROOT / "config" / "params.yaml").read_text(encoding="utf-8"))
    del tree["/**"]["ros__parameters"]["input"]["topic"]
    params = tmp_path / "params.yaml"
    params.write_text(yaml.safe_dump(tree), encoding="utf-8")
    published, subscribed = _graph(params)

    (inputs,) = [r for r in _table() if r[0] == "in" and r[1][0] == "input.topic"]
    _, (_, default, *_), input_types = inputs  # `input.topic` (`default`; ...)
    assert set(subscribed) == {default}, (default, sorted(subscribed))
    assert subscribed[default].topic_type in input_types
    assert subscribed[default].qos_profile.reliability == ReliabilityPolicy.BEST_EFFORT

    documented = _documented_outputs()
    assert set(published) - GRAPH_ONLY == set(documented)
    for topic, msgtype in documented.items():
        qos = published[topic].qos_profile
        assert published[topic].topic_type == msgtype, topic
        assert qos.reliability == ReliabilityPolicy.RELIABLE, topic
        latched = DurabilityPolicy.TRANSIENT_LOCAL if topic in LATCHED else None
        assert qos.durability == (latched or DurabilityPolicy.VOLATILE), topic


def test_the_parameter_table_gives_each_node_options_default_and_declared_range() -> None:
    """docs/node.md's table of the node's own parameters named defaults but no ranges, which
    the node declares and refuses values past (`ros2 param describe` shows them)."""
    from mount_twin.ros.parameters import _OPTIONS, NodeOptions

    text = (ROOT / "docs" / "node.md").read_text(encoding="utf-8")
    rows = {}
    for line in text.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) == 4 and cells[0].strip("`") in _OPTIONS:
            rows[cells[0].strip("`")] = cells[1:3]
    assert sorted(rows) == sorted(_OPTIONS)
    for name, descriptor in _OPTIONS.items():
        default, shown = rows[name]
        assert default == f"`{getattr(NodeOptions(), name)}`", name
        (bounds,) = descriptor.floating_point_range or descriptor.integer_range
        ends = [  # as the pages write numbers: 1 000 000, 3600, 0
            f"{int(v):,}".replace(",", " ") if v >= 10_000 else f"{v:g}"
            for v in (bounds.from_value, bounds.to_value)
        ]
        assert shown.startswith(f"{ends[0]}–{ends[1]} "), (name, shown, ends)
