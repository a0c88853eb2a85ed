"""The bundled PlotJuggler and Foxglove layouts plot fields that exist in the node's output
messages, on the node's topics, for every mount; regenerating them gives the files in config/."""

from __future__ import annotations

import dataclasses
import json
import re
from pathlib import Path
from xml.etree import ElementTree as ET

import pytest
import yaml
from io_helpers import CONFIG, ROOT
from matplotlib import colormaps
from matplotlib.colors import to_hex

from mount_twin.analysis.dashboards import foxglove_layout, plotjuggler_layout
from mount_twin.cli import main
from mount_twin.io.messages import IMU, NODE_NAME, TYPESTORE, resolve
from mount_twin.io.output_topics import output_streams, output_types
from mount_twin.scene.description import BodySensor, Scene
from mount_twin.scene.loader import load_scene_file

SCENES = ("pump_8_mounts", "genset_bolted_keyed")


def _field_exists(msgtype: str, path: list[str]) -> bool:
    """Whether `path` names a numeric field of `msgtype`, through rosbags' type definitions."""
    for name in path:
        fields = dict(TYPESTORE.get_msgdef(msgtype).fields)
        if name not in fields:
            return False
        kind = fields[name]
        msgtype = kind[1] if kind[0].name == "NAME" else ""
    return msgtype == ""  # ended on a base type


def _series(scene_name: str) -> list[tuple[str, list[str]]]:
    """(topic, field path) of every curve of the bundled PlotJuggler and Foxglove layouts."""
    scene = load_scene_file(CONFIG / f"{scene_name}.scene.yaml")
    topics = {resolve(s.topic, NODE_NAME) for s in output_streams(scene)}
    root = ET.fromstring((CONFIG / f"{scene_name}.plotjuggler.xml").read_text(encoding="utf-8"))
    out = []
    for curve in root.iter("curve"):
        name = curve.get("name", "")
        topic = next(t for t in sorted(topics, key=len, reverse=True) if name.startswith(t + "/"))
        out.append((topic, name[len(topic) + 1 :].split("/")))
    fox = json.loads((CONFIG / f"{scene_name}.foxglove.json").read_text(encoding="utf-8"))
    for panel in fox["configById"].values():
        for p in panel["paths"]:
            topic, _, rest = p["value"].partition(".")
            out.append((topic, rest.split(".")))
    return out


@pytest.mark.parametrize("scene_name", SCENES)
def test_every_curve_is_a_field_of_an_output_topic(scene_name: str) -> None:
    scene = load_scene_file(CONFIG / f"{scene_name}.scene.yaml")
    types = {resolve(s.topic, NODE_NAME): s.msgtype for s in output_streams(scene)}
    series = _series(scene_name)
    assert len(series) == 2 * (3 + 3 + 3 * len(scene.mounts))
    for topic, path in series:
        assert topic in types, topic
        assert _field_exists(types[topic], path), (topic, path)
    wrench_topics = {t for t, _ in series if t.endswith("/wrench")}
    assert wrench_topics == {resolve(f"~/mounts/{m.name}/wrench", NODE_NAME) for m in scene.mounts}


@pytest.mark.parametrize("scene_name", SCENES)
def test_the_bundled_layouts_are_what_the_command_writes(scene_name: str) -> None:
    scene = load_scene_file(CONFIG / f"{scene_name}.scene.yaml")
    assert (CONFIG / f"{scene_name}.plotjuggler.xml").read_text(encoding="utf-8") == (
        plotjuggler_layout(scene)
    )
    assert (CONFIG / f"{scene_name}.foxglove.json").read_text(encoding="utf-8") == (
        foxglove_layout(scene)
    )


@pytest.mark.parametrize("off", ["pose", "angles", "wrenches"])
def test_an_output_the_scene_turns_off_is_not_plotted(off: str) -> None:
    """Its panels were laid out on topics the node never publishes."""
    pump = load_scene_file(CONFIG / "pump_8_mounts.scene.yaml")
    scene = dataclasses.replace(pump, outputs=dataclasses.replace(pump.outputs, **{off: False}))
    published = {resolve(s.topic, NODE_NAME) for s in output_streams(scene)}
    curves = {c.get("name", "") for c in ET.fromstring(plotjuggler_layout(scene)).iter("curve")}
    paths = {
        p["value"]
        for panel in json.loads(foxglove_layout(scene))["configById"].values()
        for p in panel["paths"]
    }
    assert len(curves) == len(paths) == {"pose": 27, "angles": 27, "wrenches": 6}[off]
    assert all(any(c.startswith(f"{t}/") for t in published) for c in curves)
    assert {p.split(".")[0] for p in paths} <= published


def test_a_scene_that_publishes_nothing_to_plot_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    data = yaml.safe_load((CONFIG / "pump_8_mounts.scene.yaml").read_text(encoding="utf-8"))
    data["outputs"] = {**data["outputs"], "pose": False, "angles": False, "wrenches": False}
    scene = tmp_path / "tf_only.scene.yaml"
    scene.write_text(yaml.safe_dump(data), encoding="utf-8")
    args = ["dashboard", str(scene), "--plotjuggler", str(tmp_path / "l.xml")]
    assert main(args) == 2
    said = capsys.readouterr().err
    assert "wrenches are off and there is no body_sensor: nothing to plot" in said
    assert not (tmp_path / "l.xml").exists()


def test_a_body_imu_adds_its_prediction_and_residual_on_their_topics() -> None:
    """With a body_sensor, both layouts plot the body IMU's predicted and residual specific
    force, fields of the node's sensor_msgs/Imu outputs."""
    pump = load_scene_file(CONFIG / "pump_8_mounts.scene.yaml")
    scene = dataclasses.replace(pump, body_sensor=BodySensor(position=(0.8, 0.3, 1.0)))
    types = {resolve(t, NODE_NAME): m for t, m in output_types(scene).items()}
    root = ET.fromstring(plotjuggler_layout(scene))
    names = [c.get("name", "") for c in root.iter("curve")]
    paths = [
        p["value"]
        for panel in json.loads(foxglove_layout(scene))["configById"].values()
        for p in panel["paths"]
    ]
    for topic in ("/mount_twin/body_imu/predicted", "/mount_twin/body_imu/residual"):
        assert types[topic] == IMU
        for a in "xyz":
            assert f"{topic}/linear_acceleration/{a}" in names
            assert f"{topic}.linear_acceleration.{a}" in paths
            assert _field_exists(IMU, ["linear_acceleration", a])
    assert len(names) == len(paths) == 2 * 3 + 3 * len(scene.mounts) + 2 * 3


def test_both_layouts_into_one_file_are_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The PlotJuggler XML was overwritten by the Foxglove JSON, and 'layout: same' printed
    twice, exit 0."""
    same = str(tmp_path / "same.out")
    scene = str(CONFIG / "pump_8_mounts.scene.yaml")
    assert main(["dashboard", scene, "--plotjuggler", same, "--foxglove", same]) == 2
    assert "--plotjuggler and --foxglove name one file" in capsys.readouterr().err
    assert not Path(same).exists()


def _readme_units() -> dict[str, str]:
    """Topic as README.md's "What it publishes" table writes it (`~/pose`,
    `~/mounts/<name>/wrench`) → the unit its row names first, in parentheses ("the CG's
    position (m)", "specific force (m/s², rad/s, ...)")."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    table = text.split("## What it publishes", 1)[1].strip().split("\n\n", 1)[0]
    units = {}
    for row in table.splitlines()[2:]:
        topics, _, what = (c.strip() for c in row.strip().strip("|").split("|"))
        first = re.search(r"\(([^),]+)", what)
        for topic in re.findall(r"`([^`]+)`", topics):
            if first:
                units[topic] = first.group(1).strip()
    return units


def _as_readme_writes(topic: str) -> str:
    """A resolved output topic as the README's table names it."""
    private = "~" + topic.removeprefix(f"/{NODE_NAME}")
    return re.sub(r"^~/mounts/[^/]+/", "~/mounts/<name>/", private)


@pytest.mark.parametrize("body", [False, True], ids=["scene", "with_body_imu"])
@pytest.mark.parametrize("scene_name", SCENES)
def test_foxglove_shows_each_plot_and_series_with_its_unit(scene_name: str, body: bool) -> None:
    """Foxglove titles a panel from its config's `foxglovePanelTitle` and a series from its
    path's `label` (else the bare message path): the layout's `title` key, which it does not
    read, left every plot untitled and every series without its unit. The units are the
    README's, topic by topic."""
    scene = load_scene_file(CONFIG / f"{scene_name}.scene.yaml")
    if body:
        scene = dataclasses.replace(scene, body_sensor=BodySensor(position=(0.8, 0.3, 1.0)))
    units = _readme_units()
    for panel in json.loads(foxglove_layout(scene))["configById"].values():
        (unit,) = {units[_as_readme_writes(p["value"].partition(".")[0])] for p in panel["paths"]}
        assert panel.get("foxglovePanelTitle", "").endswith(f"[{unit}]"), panel
        for path in panel["paths"]:
            assert path.get("label", "").endswith(f"[{unit}]"), path
    for area in ET.fromstring(plotjuggler_layout(scene)).iter("DockArea"):
        curves = [c.get("name", "") for c in area.iter("curve")]
        topics = {next(t for t in units if _as_readme_writes(c).startswith(t)) for c in curves}
        (unit,) = {units[t] for t in topics}
        assert area.get("name", "").endswith(f"[{unit}]")


def _with_mounts(count: int) -> Scene:
    """The pump with `count` mounts: copies of its first, named m00, m01, ..."""
    pump = load_scene_file(CONFIG / "pump_8_mounts.scene.yaml")
    mounts = tuple(dataclasses.replace(pump.mounts[0], name=f"m{k:02d}") for k in range(count))
    return dataclasses.replace(pump, mounts=mounts)


FORCE = re.compile(r"/mounts/([^/]+)/wrench[/.]wrench[/.]force[/.]([xyz])$")
"""A mount force curve (PlotJuggler's `/` or Foxglove's `.` after the topic): mount, axis."""


@pytest.mark.parametrize("count", [8, 11, 20, 21, 41])
def test_no_two_curves_of_a_panel_look_alike(count: int) -> None:
    """Curves took 8 colours in turn: in a force panel of 11 mounts the 9th mount's curve was
    drawn as the 1st's; Foxglove's series named none, so it cycled its own 7 (in the bundled
    layouts mount 8 looked like mount 1). Each panel's curves now take colours of matplotlib's
    tab20, each a different one (a curve's colour is all PlotJuggler styles it by, and
    Foxglove has no dash pattern either): a force panel holds at most 20 mounts, more go into
    further panels, each mount's force plotted once per axis."""
    scene = _with_mounts(count)
    tab20 = {to_hex(c) for c in colormaps["tab20"].colors}
    root = ET.fromstring(plotjuggler_layout(scene))
    fox = json.loads(foxglove_layout(scene))["configById"].values()
    layouts = {
        "plotjuggler": [
            [(c.get("name", ""), c.get("color")) for c in area.iter("curve")]
            for area in root.iter("DockArea")
        ],
        "foxglove": [[(p["value"], p.get("color")) for p in panel["paths"]] for panel in fox],
    }
    for tool, panels in layouts.items():
        for curves in panels:
            colours = [colour for _, colour in curves]
            assert len(set(colours)) == len(colours), (tool, curves)
            assert set(colours) <= tab20, (tool, curves)
        names = [name for curves in panels for name, _ in curves]
        forces = [m.groups() for name in names if (m := FORCE.search(name))]
        for axis in "xyz":
            plotted = [mount for mount, a in forces if a == axis]
            assert plotted == [m.name for m in scene.mounts], (tool, axis)
        assert len(panels) == 2 + 3 * -(-count // 20), tool


def _layout_curves(xml: str, json_text: str) -> tuple[list[str], list[str]]:
    """The curves of a PlotJuggler layout and the series of a Foxglove one, in order."""
    fox = json.loads(json_text)["configById"].values()
    return (
        [c.get("name", "") for c in ET.fromstring(xml).iter("curve")],
        [p["value"] for panel in fox for p in panel["paths"]],
    )


def test_a_namespaced_renamed_node_is_plotted_on_its_topics(tmp_path: Path) -> None:
    """`ros2 run mount_twin mount_twin_node --ros-args -r __ns:=/pump1 -r __node:=twin`
    publishes `~/pose` on /pump1/twin/pose (rcl: a private name is the namespace, the node's
    name, then the rest); the layouts plotted /mount_twin/pose, and every panel stayed empty.
    `--namespace /pump1 --node-name twin`, as the remaps, plots the topics named here by
    hand."""
    pj, fox = tmp_path / "l.xml", tmp_path / "l.json"
    scene_file = CONFIG / "pump_8_mounts.scene.yaml"
    args = ["dashboard", str(scene_file), "--plotjuggler", str(pj), "--foxglove", str(fox)]
    assert main([*args, "--namespace", "/pump1", "--node-name", "twin"]) == 0
    mounts = [m.name for m in load_scene_file(scene_file).mounts]
    assert mounts[:2] == ["fl", "fr"]
    fields = [
        *(("/pump1/twin/pose", f"pose.position.{a}") for a in "xyz"),
        *(("/pump1/twin/angles", f"vector.{a}") for a in "xyz"),
        *((f"/pump1/twin/mounts/{m}/wrench", f"wrench.force.{a}") for a in "xyz" for m in mounts),
    ]
    curves, paths = _layout_curves(pj.read_text("utf-8"), fox.read_text("utf-8"))
    assert curves == [f"{t}/{f.replace('.', '/')}" for t, f in fields]
    assert paths == [f"{t}.{f}" for t, f in fields]


def test_a_body_imu_under_a_nested_namespace() -> None:
    """`-r __ns:=/plant/pump1 -r __node:=twin`: `~/body_imu/residual` is
    /plant/pump1/twin/body_imu/residual."""
    pump = load_scene_file(CONFIG / "pump_8_mounts.scene.yaml")
    scene = dataclasses.replace(pump, body_sensor=BodySensor(position=(0.8, 0.3, 1.0)))
    node = {"namespace": "/plant/pump1", "node_name": "twin"}
    curves, paths = _layout_curves(
        plotjuggler_layout(scene, **node), foxglove_layout(scene, **node)
    )
    for what in ("predicted", "residual"):
        topic = f"/plant/pump1/twin/body_imu/{what}"
        assert [c for c in curves if c.startswith(f"{topic}/")] == [
            f"{topic}/linear_acceleration/{a}" for a in "xyz"
        ]
        assert [p for p in paths if p.startswith(f"{topic}.")] == [
            f"{topic}.linear_acceleration.{a}" for a in "xyz"
        ]
    assert all(c.startswith("/plant/pump1/twin/") for c in curves + paths)


@pytest.mark.parametrize("scene_name", SCENES)
def test_the_default_node_name_and_namespace_write_the_bundled_layouts(
    scene_name: str, tmp_path: Path
) -> None:
    """`--namespace /` (no namespace, as `ros2 run` gives) and `--node-name mount_twin`, the
    defaults, are the layouts in config/."""
    pj, fox = tmp_path / "l.xml", tmp_path / "l.json"
    scene = str(CONFIG / f"{scene_name}.scene.yaml")
    node = ["--namespace", "/", "--node-name", "mount_twin"]
    assert main(["dashboard", scene, "--plotjuggler", str(pj), "--foxglove", str(fox), *node]) == 0
    assert pj.read_text("utf-8") == (CONFIG / f"{scene_name}.plotjuggler.xml").read_text("utf-8")
    assert fox.read_text("utf-8") == (CONFIG / f"{scene_name}.foxglove.json").read_text("utf-8")


@pytest.mark.parametrize(
    ("option", "value", "said"),
    [
        ("--namespace", "pump1", "absolute"),  # rcl: `__ns:=pump1` is no remap rule
        ("--namespace", "/pump1/", "ends with '/'"),
        ("--namespace", "/a//b", "empty token"),
        ("--namespace", "/1pump", "starts with a digit"),
        ("--namespace", "/a-b", "only ASCII letters"),
        ("--node-name", "1twin", "not a ROS node name"),
        ("--node-name", "a/b", "not a ROS node name"),
        ("--node-name", "~twin", "not a ROS node name"),
        ("--node-name", "", "not a ROS node name"),
    ],
)
def test_a_name_ros_refuses_is_refused_naming_the_option(
    option: str, value: str, said: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Each is a remap rcl refuses (`-r __ns:=pump1`, `-r __node:=1twin` end the node at
    its start): no layout for a node that cannot run."""
    args = ["dashboard", str(CONFIG / "pump_8_mounts.scene.yaml"), "--plotjuggler"]
    with pytest.raises(SystemExit, match="2"):
        main([*args, str(tmp_path / "l.xml"), f"{option}={value}"])
    err = capsys.readouterr().err
    assert f"argument {option}: {value!r}" in err
    assert said in err
    assert not (tmp_path / "l.xml").exists()
