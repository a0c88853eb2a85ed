"""Mistaken and hostile scene files: each refused at load naming file, line or key path, and a
fuzz over mutated scenes that finds no other exception than SceneError."""

from __future__ import annotations

import contextlib
import copy
import math
from pathlib import Path
from typing import Any

import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from io_helpers import CONFIG
from physics_helpers import base_scene, mount

from mount_twin.errors import ModelError, SceneError
from mount_twin.model.assemble import assemble, initial_state
from mount_twin.scene.loader import load_scene_file, read_scene_yaml, scene_from_dict

PUMP = CONFIG / "pump_8_mounts.scene.yaml"


def _file(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "s.scene.yaml"
    path.write_text(text, encoding="utf-8")
    return path


def _pump_text() -> str:
    return PUMP.read_text(encoding="utf-8")


def test_a_key_given_twice_is_an_error_naming_the_lines(tmp_path: Path) -> None:
    text = (
        _pump_text()
        + "mounts:\n  - {name: x, position: [0, 0, 0], stiffness: [1, 1, 1, 0, 0, 0]}\n"
    )
    with pytest.raises(
        SceneError, match=r"s\.scene\.yaml: <file>: line \d+: key 'mounts' given twice"
    ):
        load_scene_file(_file(tmp_path, text))


def test_exponents_without_a_dot_are_numbers(tmp_path: Path) -> None:
    text = _pump_text().replace(
        "stiffness: [5.0e+5, 5.0e+5, 1.2e+6,", "stiffness: [5e5, 5e5, 12E5,"
    )
    scene = load_scene_file(_file(tmp_path, text))
    assert scene.mounts[0].stiffness[:3] == (5e5, 5e5, 1.2e6)  # type: ignore[union-attr]


@pytest.mark.parametrize(
    ("text", "says"),
    [
        ("a: &x [1, 2]\nb: *x\n", r"line 2: aliases \(\*x\) are not accepted"),
        ("k: " + "[" * 80 + "]" * 80 + "\n", "nested deeper than 50"),
    ],
)
def test_aliases_and_deep_nesting_are_refused(tmp_path: Path, text: str, says: str) -> None:
    with pytest.raises(SceneError, match=says):
        read_scene_yaml(_file(tmp_path, text))


def _pump() -> dict[str, Any]:
    return yaml.safe_load(_pump_text())


@pytest.mark.parametrize(
    ("change", "key", "says"),
    [
        (lambda d: d["body"].update(cg=[1e300, 0, 0.5]), "body.cg[0]", r"beyond 1e\+15"),
        (
            lambda d: d["outputs"].update(decimation=2**63),
            "outputs.decimation",
            r"must be in \[1, 1000000000\]",
        ),
        (
            lambda d: (
                d["mounts"][0].update(position=[900.0, 400.0, 0.0])
                or d["mounts"][1].update(position=[900.0, -4000.0, 0.0])
            ),
            "mounts[1].position",
            "millimetres",
        ),
        (
            lambda d: d["mounts"][0].update(orientation_rpy=[-30.0, 0.0, 0.0]),
            "mounts[0].orientation_rpy",
            "radians, not degrees",
        ),
        (
            lambda d: d["input"].update(sensor_rpy=[0.0, 90.0, 0.0]),
            "input.sensor_rpy",
            "radians, not degrees",
        ),
        (lambda d: d["input"].update(topic="/deck imu"), "input.topic", "not a ROS topic name"),
        (lambda d: d["input"].update(topic="/2deck/imu"), "input.topic", "not a ROS topic name"),
        (lambda d: d["frames"].update(body="pump frame"), "frames.body", "not a tf2 frame id"),
        (lambda d: d["mounts"][0].update(name="x²"), "mounts[0].name", "ROS name token"),
        (lambda d: d.update(mounts=d["mounts"] * 130), "mounts", "at most 1000"),
    ],
)
def test_implausible_values_are_refused_with_their_key_path(change, key: str, says: str) -> None:
    data = _pump()
    change(data)
    with pytest.raises(SceneError, match=says) as err:
        scene_from_dict(data, "pump")
    assert f"pump: {key}: " in str(err.value)


def test_a_free_dof_no_mount_holds_is_refused_naming_it() -> None:
    """Mounts stiff along z only (no shear, no rotational stiffness): nothing holds yaw δ, nor
    x and y — the body would drift under any lateral input (0.51 m in 2 s, as reported)."""
    mounts = [
        mount(f"m{i}", (x, y, 0.0), (0.0, 0.0, 1e6, 0.0, 0.0, 0.0))
        for i, (x, y) in enumerate([(0.5, 0.4), (-0.5, 0.4), (-0.5, -0.4), (0.5, -0.4)])
    ]
    data = base_scene(500.0, [0.0, 0.0, 0.3], [50.0, 60.0, 70.0, 0, 0, 0], mounts)
    model = assemble(scene_from_dict(data, "z only"))
    with pytest.raises(ModelError, match=r"z only: DOF (x|y|delta) is not held by any mount"):
        initial_state(model, [0.0, 0.0, 9.80665])
    data["dofs"] = ["z", "alpha", "gamma"]  # the same mounts, only the held DOFs free
    reduced = assemble(scene_from_dict(data, "z only, reduced"))
    assert math.isfinite(initial_state(reduced, [0.0, 0.0, 9.80665])[0])


# ------------------------------------------------------------------------------------ fuzzing
def _mutations() -> st.SearchStrategy[list[tuple[int, Any]]]:
    weird = st.one_of(
        st.none(),
        st.booleans(),
        st.integers(min_value=-(2**70), max_value=2**70),
        st.floats(allow_nan=True, allow_infinity=True),
        st.text(max_size=8),
        st.lists(st.floats(allow_nan=True), max_size=7),
        st.dictionaries(st.text(max_size=4), st.integers(), max_size=2),
    )
    return st.lists(st.tuples(st.integers(0, 10_000), weird), min_size=1, max_size=4)


def _leaves(node: Any, path: tuple = ()) -> list[tuple]:
    if isinstance(node, dict):
        return [p for k, v in node.items() for p in [(*path, k), *_leaves(v, (*path, k))]]
    if isinstance(node, list):
        return [p for i, v in enumerate(node) for p in [(*path, i), *_leaves(v, (*path, i))]]
    return []


@settings(
    max_examples=300, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow]
)
@given(_mutations())
def test_a_mutated_scene_is_a_scene_or_a_scene_error_never_another_exception(changes) -> None:
    for name in ("pump_8_mounts", "genset_bolted_keyed"):
        data = read_scene_yaml(CONFIG / f"{name}.scene.yaml")
        paths = _leaves(data)
        for pick, value in changes:
            target = data
            path = paths[pick % len(paths)]
            try:  # an earlier change may have replaced a container on the way
                for k in path[:-1]:
                    target = target[k]
                target[path[-1]] = copy.deepcopy(value)
            except (KeyError, IndexError, TypeError):
                continue
        with contextlib.suppress(SceneError):
            scene_from_dict(data, name)
