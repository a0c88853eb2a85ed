"""Ratings and force limits judged at a given start, at its pose and velocity.

With `initial_state.mode: given` the twin starts at the pose and velocity the scene gives, not
at the weight's equilibrium. A key's allowable force and a bolt's yield and ultimate force were
judged at load at an equilibrium start only: a pose given past them loaded without a word and
every report was ERROR from the first one. The ratings were judged by the tangent statics
under the weight, a state the twin does not start in: a pose given past a rating passed
unwarned, and one given at the reference (the mounts unstressed) was warned of a load it does
not start under. Both are now judged at the given state, by the mounts' own laws, with the
figure the first report's utilisation divides.

Truths written here, independently of the package (SI units):
- a vertical shear key of stiffness k_key and clearance c, at a pose that moves it down by
  z_key: force k_key·(z_key − c) (0 within the clearance);
- a bolted joint (VDI 2230 joint diagram, kinds/bolted_joint.py) whose foot is lifted u from
  its preloaded rest: bolt force F_S = F_V + k_S·u, the joint closed (clamp force
  F_V − k_P·u > 0) while u < F_V/k_P, the bolt alone past it;
- a linear Kelvin–Voigt mount deflected d at the rate v along z: force k·d + c·v.
"""

from __future__ import annotations

import numpy as np
import pytest
import yaml
from hung_helpers import BOLT, CG_Z, CORNERS, K_P, K_S, MASS, K, hung_scene
from hung_helpers import K_KEY as K_KEY_HUNG
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
C = 2000.0  # N·s/m: the linear springs' damping along z
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


def test_a_given_start_within_its_limits_and_ratings_is_not_warned_of_whatever_the_weight():
    """The hung scene given 0.3 mm down: its fitted key bears K_KEY·0.3 mm = 240 N (allowed
    10 % more), its bolt F_S = F_V + k_S·0.3 mm = 5300 N (yielding 3 % above it), its springs
    K·0.3 mm = 60 N each, rated 100 N: within all, nothing is said and the first report is not
    an ERROR. The tangent statics under the weight load each spring with
    m·g·K/(4K + K_KEY + k_S + k_P) = 140 N (the closed joint's k_S + k_P), past its rating:
    the loader warned of that, a state the twin does not start in. This file's key given
    0.24 mm down (4e4 N, 0.8 of its allowable) is not warned of either."""
    lift = 3.0e-4
    key_force, bolt_force, spring_load = K_KEY_HUNG * lift, F_V + K_S * lift, K * lift
    assert spring_load < 100.0 < MASS * G * K / (4.0 * K + K_KEY_HUNG + K_S + K_P)
    data = hung_given(lift, 1.03 * bolt_force, 1.2 * bolt_force, 1.1 * key_force, 100.0)
    model = assemble(scene_from_dict(data, "<hung>"))
    assert model.scene.warnings == ()
    engine, statuses = first_report(model)
    assert engine.utilisation_max["key"] == pytest.approx(1.0 / 1.1, rel=1e-9)
    assert engine.utilisation_max["bolt"] == pytest.approx(1.0 / 1.03, rel=1e-9)
    assert engine.utilisation_max["s0"] == pytest.approx(spring_load / 100.0, rel=1e-9)
    assert all(status.level != ERROR for status in statuses.values())

    z_key = 2.4e-4
    model = assemble(scene_from_dict(keyed(-z_key), "<keyed>"))
    assert model.scene.warnings == ()
    engine, statuses = first_report(model)
    force = K_KEY * (z_key - CLEARANCE)
    assert engine.utilisation_max["key"] == pytest.approx(force / ALLOWABLE, rel=1e-9)
    assert statuses["key"].level != ERROR


def four_springs(rated_load: float, initial: dict) -> dict:
    """MASS on four vertical linear springs K with damping C along z at the corners, each rated
    `rated_load` (N) along z: no non-linear mount."""
    springs = [
        {
            **mount(f"s{i}", [x, y, 0.0], [1.0e5, 1.0e5, K, 0, 0, 0], [0, 0, C, 0, 0, 0]),
            "rated_load": [0.0, 0.0, rated_load],
        }
        for i, (x, y) in enumerate(CORNERS)
    ]
    return base_scene(MASS, [0.0, 0.0, CG_Z], INERTIA, springs, initial=initial)


def test_linear_mounts_given_far_from_the_weight_s_equilibrium_are_judged_at_the_given_state():
    """Four linear springs (no non-linear mount: the tangent statics are exact under the
    weight) given 2 mm below the weight's 4.9 mm sag, moving down at 0.1 m/s: each carries
    K·(sag + 2 mm) + C·0.1 m/s = 1581 N, 1.25 times a rated load of 1265 N that the weight's
    981 N is within (the loader said nothing). One warning, with the given state's load (not
    "static": the damping's share counts), the first report's utilisation."""
    sag = MASS * G / (4.0 * K)
    depth, rate = sag + 2.0e-3, 0.1
    load = K * depth + C * rate
    rating = load / 1.25
    assert rating > MASS * G / 4.0
    model = assemble(scene_from_dict(four_springs(rating, given_start(-depth, -rate)), "<lin>"))
    (path, said), *others = rated(model.scene).items()
    assert others == []
    assert path in {f"mounts[{i}].rated_load" for i in range(4)}
    assert said.startswith(f"the load {AT_GIVEN}, {load:.4g} N along local z, is 1.25 times")
    assert "(and 3 more mounts)" in said
    engine, statuses = first_report(model)
    for i in range(4):
        assert engine.utilisation_max[f"s{i}"] == pytest.approx(1.25, rel=1e-9)
        assert statuses[f"s{i}"].level == ERROR


def test_linear_mounts_given_at_the_reference_are_not_judged_under_a_weight_they_start_without():
    """The same springs rated 800 N, below the weight's 981 N share, given at the reference
    pose at rest: they start unstressed (the first report's utilisation 0), so nothing is said
    at load; the loader's statics under the weight warned of them."""
    assert MASS * G / 4.0 > 800.0
    model = assemble(scene_from_dict(four_springs(800.0, given_start(0.0)), "<lin>"))
    assert rated(model.scene) == {}
    engine, statuses = first_report(model)
    assert engine.utilisation_max["s0"] == 0.0
    assert statuses["s0"].level != ERROR
