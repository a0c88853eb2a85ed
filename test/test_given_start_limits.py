"""Force limits judged at a given start, at its pose and velocity.

With `initial_state.mode: given` the twin starts at the pose and velocity the scene gives, not
at the weight's equilibrium. A key's allowable force and a bolt's yield and ultimate force were
judged at load at an equilibrium start only: a pose given past them loaded without a word and
every report was ERROR from the first one. They are now judged at the given state, by the
mounts' own laws, with the figure the first report's utilisation divides.

Truths written here, independently of the package (SI units):
- a vertical shear key of stiffness k_key and clearance c, at a pose that moves it down by
  z_key: force k_key·(z_key − c) (0 within the clearance);
- a bolted joint (VDI 2230 joint diagram, kinds/bolted_joint.py) whose foot is lifted u from
  its preloaded rest: bolt force F_S = F_V + k_S·u, the joint closed (clamp force
  F_V − k_P·u > 0) while u < F_V/k_P, the bolt alone past it.
"""

from __future__ import annotations

import numpy as np
import pytest
import yaml
from hung_helpers import BOLT, CG_Z, CORNERS, K_P, K_S, MASS, K, hung_scene
from kinds_helpers import kind_mount
from physics_helpers import G, base_scene, mount

from mount_twin.engine.batch import ERROR, SampleBatch
from mount_twin.engine.engine import TwinEngine
from mount_twin.model.assemble import assemble
from mount_twin.scene.loader import scene_from_dict

AT_GIVEN = "at the given start (initial_state.pose and velocity, not the weight's equilibrium)"
BOLT_FORCE = "the bolt force F_S (its preload and its share of the load)"
PAST_1 = "its utilisation is past 1 from the first report (ERROR)"
K_KEY, CLEARANCE, ALLOWABLE = 1.0e9, 2.0e-4, 5.0e4  # N/m, m, N: the keyed scene's key
F_V = 5000.0  # N: the hung scene's bolt preload
INERTIA = [30.0, 40.0, 50.0, 0.0, 0.0, 0.0]  # kg·m²


def given_start(z: float, z_rate: float = 0.0) -> dict:
    """`initial_state` of a given start with the CG at z (m, F) moving at z_rate (m/s, F)."""
    return {
        "mode": "given",
        "pose": [0.0, 0.0, z, 0.0, 0.0, 0.0],
        "velocity": [0.0, 0.0, z_rate, 0.0, 0.0, 0.0],
    }


def keyed(z: float, rated_load: float = 0.0) -> dict:
    """MASS on four vertical springs K at the corners (rated `rated_load` N along z, 0:
    unrated) and this file's key under the CG, given the pose z (m)."""
    springs = [
        {
            **mount(f"s{i}", [x, y, 0.0], [1.0e5, 1.0e5, K, 0.0, 0.0, 0.0]),
            "rated_load": [0.0, 0.0, rated_load],
        }
        for i, (x, y) in enumerate(CORNERS)
    ]
    key = kind_mount(
        "shear_key",
        "key",
        stiffness=[0.0, 0.0, K_KEY],
        clearance=CLEARANCE,
        allowable_force=ALLOWABLE,
    )
    return base_scene(MASS, [0.0, 0.0, CG_Z], INERTIA, [*springs, key], initial=given_start(z))


def hung_given(
    lift: float,
    yield_force: float,
    ultimate_force: float,
    allowable: float = 0.0,
    rated_load: float = 0.0,
) -> dict:
    """test/hung_helpers.py's scene (its bolt's local z down, its key fitted and allowed
    `allowable` N, 0: not monitored, its springs rated `rated_load` N along z, 0: unrated),
    given the pose that lifts the bolt's foot by `lift` (m): the body `lift` down."""
    key = {"allowable_force": allowable}
    data = hung_scene(F_V, yield_force, ultimate_force, key, rated_load)
    data["initial_state"] = given_start(-lift)
    return data


def limited(scene) -> dict[str, str]:
    """The scene's force-limit warnings: {key path: message}."""
    ends = (".allowable_force", ".yield_force", ".ultimate_force")
    return {w.path: w.message for w in scene.warnings if w.path.endswith(ends)}


def rated(scene) -> dict[str, str]:
    """The scene's rating warnings: {key path: message}."""
    return {w.path: w.message for w in scene.warnings if ".rated_" in w.path}


def first_report(model):
    """The engine on a deck at rest under gravity for one sample (the start alone: a stiff key
    soon moves the body off its given pose): (engine, its first report's mount statuses by
    mount name)."""
    engine = TwinEngine(model)
    start = SampleBatch(np.array([1.0]), np.array([[0.0, 0.0, G]]), np.zeros((1, 3)), ["imu"])
    out = engine.run(start)
    prefix = "mount_twin: mount "
    statuses = {
        s.name.removeprefix(prefix): s for s in out.health[0].statuses if s.name.startswith(prefix)
    }
    return engine, statuses


def test_a_key_given_past_its_allowable_force_is_warned_of_with_the_given_start_s_ratio(
    tmp_path, capsys
):
    """The body given 0.3 mm down pushes the key 0.1 mm past its 0.2 mm clearance:
    1e9 N/m · 0.1 mm = 1e5 N, twice its allowable 5e4 N. One warning, naming the key's
    allowable_force and saying the figures are the given start's; the first report's
    utilisation is that ratio, at ERROR; the command line says it at load."""
    from mount_twin.cli import main

    z_key = 3.0e-4
    force = K_KEY * (z_key - CLEARANCE)
    assert force == pytest.approx(1.0e5, rel=1e-12)
    data = keyed(-z_key)
    scene = scene_from_dict(data, "<keyed>")
    assert limited(scene) == {}  # the loader leaves it to the start
    model = assemble(scene)
    assert model.nominal_state[2] == -z_key  # the given pose, not solved
    warned = limited(model.scene)
    assert set(warned) == {"mounts[4].allowable_force"}
    said = warned["mounts[4].allowable_force"]
    assert said.startswith(f"the key's force {AT_GIVEN}, 1e+05 N, is 2 times its allowable force ")
    assert "5e+04 N: " in said
    assert PAST_1 in said
    assert "initial_state.pose or stiffness in the wrong units" in said
    assert assemble(model.scene).scene.warnings == model.scene.warnings  # said once

    engine, statuses = first_report(model)
    assert engine.utilisation_max["key"] == pytest.approx(force / ALLOWABLE, rel=1e-9)
    assert statuses["key"].level == ERROR

    path = tmp_path / "keyed.scene.yaml"
    path.write_text(yaml.safe_dump(data))
    assert main(["info", str(path)]) == 0
    err = capsys.readouterr().err.splitlines()
    assert f"mount-twin: warning: {path}: mounts[4].allowable_force: {said}" in err


@pytest.mark.parametrize("lift", [1.0e-3, 2.5e-3], ids=["joint_closed", "joint_open"])
def test_a_bolt_given_past_its_yield_is_warned_of_with_its_force_from_the_joint_diagram(lift):
    """The foot lifted 1 mm (the joint still closed: F_V/k_P = 1.67 mm) or 2.5 mm (open):
    F_S = F_V + k_S·u, 6000 N or 7500 N, 1.1 times a yield force of F_S/1.1. One warning at
    the bolt's yield_force, with the given start's F_S; the first report's utilisation is
    F_S/F_y, at ERROR."""
    bolt_force = F_V + K_S * lift
    assert (F_V - K_P * lift > 0.0) == (lift < F_V / K_P)  # the two regimes, as named
    yield_force = bolt_force / 1.1
    model = assemble(scene_from_dict(hung_given(lift, yield_force, 2.0 * bolt_force), "<hung>"))
    warned = limited(model.scene)
    assert set(warned) == {f"mounts[{BOLT}].yield_force"}
    said = warned[f"mounts[{BOLT}].yield_force"]
    assert said.startswith(f"{BOLT_FORCE} {AT_GIVEN}")
    assert f", {bolt_force:.4g} N, is 1.1 times its yield force {yield_force:.4g} N" in said
    assert "the bolt taken as elastic there (its plastic elongation starts at 0" in said
    assert PAST_1 in said

    engine, statuses = first_report(model)
    assert engine.utilisation_max["bolt"] == pytest.approx(1.1, rel=1e-9)
    assert statuses["bolt"].level == ERROR


def test_a_bolt_given_past_its_ultimate_force_is_warned_that_it_breaks_at_the_start():
    """Lifted 2 mm: F_S = 7000 N, past F_y = 6000 N and F_u = 6500 N: both warned of, the
    ultimate saying the bolt breaks at the start; the first report logs it breaking there."""
    lift = 2.0e-3
    bolt_force = F_V + K_S * lift
    yield_force, ultimate = 6000.0, 6500.0
    model = assemble(scene_from_dict(hung_given(lift, yield_force, ultimate), "<hung>"))
    warned = limited(model.scene)
    assert set(warned) == {f"mounts[{BOLT}].yield_force", f"mounts[{BOLT}].ultimate_force"}
    said = warned[f"mounts[{BOLT}].ultimate_force"]
    ratio = bolt_force / ultimate
    assert f"{AT_GIVEN}, 7000 N, is {ratio:.3g} times its ultimate force 6500 N" in said
    assert "it breaks at the start (bolt_fractured)" in said
    _, statuses = first_report(model)
    assert statuses["bolt"].level == ERROR
    assert statuses["bolt"].values["bolt_fractured.count"] == "1"
    assert statuses["bolt"].values["bolt_fractured.first_stamp_ns"] == "1000000000"
