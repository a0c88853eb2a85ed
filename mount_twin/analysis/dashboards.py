"""Ready dashboards for a scene's outputs: a PlotJuggler layout (XML) and a Foxglove layout
(JSON), each plotting the CG position, the attitude angles and every mount's force components
(with a body IMU, its predicted specific force and the residual too) from the node's topics
(live) or an output bag (the same topics). The topics are the node's private (`~/`) names,
resolved as rcl does for the node's namespace and name (`-r __ns:=/pump1 -r __node:=twin`:
/pump1/twin/pose); by default the node's own name, no namespace, as `ros2 run`, the bundled
launch file and `mount-twin replay` have it.

Series are named the way each tool names message fields: PlotJuggler `/topic/field/sub`,
Foxglove message paths `/topic.field.sub` (plotted against the header stamp). Each plot's title
carries its unit; Foxglove also labels each series with it (PlotJuggler names a curve by its
series only). No two curves of a panel share a colour (`PALETTE`).
"""

from __future__ import annotations

import json
from xml.etree import ElementTree as ET

from mount_twin.io.messages import NODE_NAME, resolve
from mount_twin.io.output_topics import (
    ANGLES_OUTPUT,
    BODY_PREDICTED_TOPIC,
    BODY_RESIDUAL_TOPIC,
    POSE_OUTPUT,
    WRENCHES_OUTPUT,
    Output,
)
from mount_twin.scene.description import Scene

PALETTE = (
    *("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd"),
    *("#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"),
    *("#aec7e8", "#ffbb78", "#98df8a", "#ff9896", "#c5b0d5"),
    *("#c49c94", "#f7b6d2", "#c7c7c7", "#dbdb8d", "#9edae5"),
)
"""matplotlib's tab20: its ten strong colours (tab10's, in order), then their light companions.
A panel's curves take one each, in order, and a panel holds at most this many curves (more
mounts go into further force panels): a curve's colour is all PlotJuggler styles it by (line
style and width are the plot's), and Foxglove has no dash pattern either, so a repeated colour
would draw two curves alike."""


Series = list[tuple[str, tuple[str, ...], str]]
"""A plot's series: (topic, field path, label with its unit)."""


def panels(
    scene: Scene, namespace: str = "/", node_name: str = NODE_NAME
) -> list[tuple[str, Series]]:
    """(panel title, [(topic, field path, series label)]) of each plot of what the scene
    publishes: pose, angles, force x, y, z (each over as few panels as hold at most
    len(PALETTE) mounts, in even shares, each titled with its first and last mount where there
    are several), and with a body_sensor the body IMU's predicted and residual specific
    force; titles and labels end with the unit; topics those of the node `node_name` in
    `namespace`. ValueError where it publishes none of them."""
    published = scene.outputs
    pose = resolve(POSE_OUTPUT.topic, node_name, namespace)
    angles = resolve(ANGLES_OUTPUT.topic, node_name, namespace)
    out: list[tuple[str, Series]] = []
    if published.pose:
        series = [(pose, _path(POSE_OUTPUT, k), f"{a} [m]") for k, a in enumerate("xyz")]
        out.append(("CG position in F [m]", series))
    if published.angles:
        series = [(angles, _path(ANGLES_OUTPUT, k), f"{a} [rad]") for k, a in enumerate("αγδ")]
        out.append(("α (x), γ (y), δ (z) [rad]", series))
    if published.wrenches:
        streams = zip(WRENCHES_OUTPUT.streams(scene), scene.mounts, strict=True)
        topics = [(resolve(st.topic, node_name, namespace), m.name) for st, m in streams]
        shares = -(-len(topics) // len(PALETTE))
        size = -(-len(topics) // shares)
        groups = [topics[i : i + size] for i in range(0, len(topics), size)]
        for k, axis in enumerate("xyz"):
            force = _path(WRENCHES_OUTPUT, k)
            for group in groups:
                which = f", {group[0][1]} … {group[-1][1]}" if shares > 1 else ""
                series = [(t, force, f"{name} [N]") for t, name in group]
                out.append((f"mount force along mount {axis}{which} [N]", series))
    if scene.body_sensor is not None:  # the body IMU against the twin (its axes)
        for topic, what in (
            (BODY_PREDICTED_TOPIC, "predicted"),
            (BODY_RESIDUAL_TOPIC, "residual"),
        ):
            resolved = resolve(topic, node_name, namespace)
            series = [(resolved, ("linear_acceleration", a), f"{a} [m/s²]") for a in "xyz"]
            out.append((f"body IMU specific force, {what} [m/s²]", series))
    if not out:
        msg = (
            f"{scene.source}: outputs.pose, outputs.angles and outputs.wrenches are off and "
            "there is no body_sensor: nothing to plot"
        )
        raise ValueError(msg)
    return out


def _path(output: Output, column: int) -> tuple[str, ...]:
    """The message field path of one of an output's columns (the output registry's)."""
    return tuple(output.fields[column].split("."))


def plotjuggler_layout(scene: Scene, namespace: str = "/", node_name: str = NODE_NAME) -> str:
    """A PlotJuggler layout: one tab, the panels stacked (`panels`: of the node `node_name` in
    `namespace`)."""
    root = ET.Element("root")
    tabs = ET.SubElement(root, "tabbed_widget", {"parent": "main_window", "name": "Main Window"})
    tab = ET.SubElement(tabs, "Tab", {"tab_name": scene.name, "containers": "1"})
    container = ET.SubElement(tab, "Container")
    items = panels(scene, namespace, node_name)
    share = ";".join([f"{1 / len(items):.6f}"] * len(items))
    split = ET.SubElement(
        container, "DockSplitter", {"orientation": "-", "sizes": share, "count": str(len(items))}
    )
    for title, series in items:
        area = ET.SubElement(split, "DockArea", {"name": title})
        plot = ET.SubElement(
            area,
            "plot",
            {"mode": "TimeSeries", "style": "Lines", "flip_x": "false", "flip_y": "false"},
        )
        ET.SubElement(plot, "limitY")
        for k, (topic, field, _label) in enumerate(series):
            name = "/".join([topic, *field])
            ET.SubElement(plot, "curve", {"name": name, "color": PALETTE[k]})
    ET.indent(root)
    return (
        "<?xml version='1.0' encoding='UTF-8'?>\n" + ET.tostring(root, encoding="unicode") + "\n"
    )


def foxglove_layout(scene: Scene, namespace: str = "/", node_name: str = NODE_NAME) -> str:
    """A Foxglove layout: the panels in one column (`panels`: of the node `node_name` in
    `namespace`)."""
    config: dict[str, object] = {}
    ids = []
    for k, (title, series) in enumerate(panels(scene, namespace, node_name)):
        panel = f"Plot!mt{k}"
        ids.append(panel)
        config[panel] = {
            "foxglovePanelTitle": title,  # the key Foxglove titles a panel from
            "title": title,  # where older Foxglove Studio releases read it
            "paths": [
                {
                    "value": f"{topic}.{'.'.join(field)}",
                    "enabled": True,
                    "timestampMethod": "headerStamp",
                    "label": label,
                    "color": PALETTE[k],
                }
                for k, (topic, field, label) in enumerate(series)
            ],
            "showLegend": True,
            "isSynced": True,
        }
    layout: object = ids[-1]
    for panel in reversed(ids[:-1]):
        layout = {"first": panel, "second": layout, "direction": "column"}
    return (
        json.dumps(
            {"configById": config, "globalVariables": {}, "userNodes": {}, "layout": layout},
            indent=2,
        )
        + "\n"
    )
