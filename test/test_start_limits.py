"""A key's allowable force and a bolt's yield and ultimate force, judged at load at the start.

A shear key's `allowable_force` and a bolted joint's `yield_force` and `ultimate_force` were
never checked at load: a machine whose weight on its mounts (its bolts preloaded) already put a
key past its allowable force or a bolt past its yield read ERROR from the first report without
a word. The loader now leaves them to the start the assembly solves (`model.ratings`), which
warns with the force the utilisation divides (key: its force, bolt: F_S) and the ratio, the
first report's utilisation.

Truths written here, independently of the package: MASS hangs from one bolted joint above its
CG (local z down, along the bolt: the weight pulls the foot off its face) and rests on four
vertical springs k at the corners and a vertical key k_key under the CG (clearance c), all
symmetric about the CG, so the body sinks straight down by s with the joint closed (the bolt
and the clamped parts in parallel, k_S + k_P):
    4·k·s + k_key·(s − c) + (k_S + k_P)·s = m·g,
the key's force k_key·(s − c) and the bolt's F_S = F_V + k_S·s.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
import yaml
from hung_helpers import BOLT, K_KEY, K_P, K_S, MASS, K, hung_scene
from physics_helpers import G

from mount_twin.engine.batch import ERROR, SampleBatch
from mount_twin.engine.engine import TwinEngine
from mount_twin.model.assemble import assemble
from mount_twin.scene.checks import rated_at_start
from mount_twin.scene.loader import load_scene_file, scene_from_dict
from mount_twin.scene.params import as_params, effective_parameters

F_V = 5000.0  # N: the hanger's bolt's preload
AT_START = "at the start (the weight's equilibrium on the mounts' own force laws)"


def sag(clearance: float) -> float:
    """s (m, down) where the springs, the key past its clearance and the closed joint carry
    the weight."""
    s = (MASS * G + K_KEY * clearance) / (4.0 * K + K_KEY + K_S + K_P)
    assert clearance < s < F_V / K_P  # the key bears, the joint stays closed
    return s


def key_force(clearance: float) -> float:
    return K_KEY * (sag(clearance) - clearance)


def bolt_force(clearance: float) -> float:
    return F_V + K_S * sag(clearance)


def hung(
    allowable: float,
    yield_force: float,
    ultimate_force: float,
    clearance: float = 0.0,
    rated_load: float = 0.0,
) -> dict:
    """The scene of this file's truths; springs rated `rated_load` (N) along z, 0: unrated."""
    key = {"clearance": clearance, "allowable_force": allowable}
    return hung_scene(F_V, yield_force, ultimate_force, key, rated_load)


def limited(scene) -> dict[str, str]:
    """The scene's force-limit warnings: {key path: message}."""
    ends = (".allowable_force", ".yield_force", ".ultimate_force")
    return {w.path: w.message for w in scene.warnings if w.path.endswith(ends)}


def first_report(model, n: int = 5):
    """The engine on a deck at rest under gravity: (engine, its first health report's mount
    statuses by mount name)."""
    t = 1.0 + np.arange(n) * 1e-3
    f = np.zeros((n, 3))
    f[:, 2] = G
    engine = TwinEngine(model)
    out = engine.run(SampleBatch(t, f, np.zeros((n, 3)), ["imu"] * n))
    prefix = "mount_twin: mount "
    statuses = {
        s.name.removeprefix(prefix): s for s in out.health[0].statuses if s.name.startswith(prefix)
    }
    return engine, statuses


@pytest.mark.parametrize("clearance", [0.0, 2.0e-4], ids=["fitted", "clearance"])
def test_a_key_and_a_bolt_past_their_limits_at_the_start_are_warned_of_with_its_utilisation(
    clearance,
):
    """Allowed 90 % of the key's start force, the bolt yielding at 97 % of its start force:
    one warning each, at the start's figures, naming the limit's key; the first report's
    utilisation of each is the warned ratio, at ERROR."""
    force_key, force_bolt = key_force(clearance), bolt_force(clearance)
    allowable, yield_force = 0.9 * force_key, 0.97 * force_bolt
    scene = scene_from_dict(hung(allowable, yield_force, 2.0 * F_V, clearance), "<hung>")
    assert limited(scene) == {}  # the loader leaves them to the start
    model = assemble(scene)
    # the start is this file's equilibrium, to 1e-9 (the figures the warnings take)
    assert model.nominal_state[2] == pytest.approx(-sag(clearance), rel=1e-9)
    assert np.abs(model.nominal_state[[0, 1, 3, 4, 5]]).max() < 1e-12
    warned = limited(model.scene)
    assert set(warned) == {"mounts[4].allowable_force", "mounts[5].yield_force"}
    key_ratio, bolt_ratio = force_key / allowable, force_bolt / yield_force
    key_said = warned["mounts[4].allowable_force"]
    assert key_said.startswith(f"the key's force {AT_START}, {force_key:.4g} N, is ")
    assert f"is {key_ratio:.3g} times its allowable force {allowable:.4g} N: " in key_said
    assert "its utilisation is past 1 from the first report (ERROR)" in key_said
    bolt_said = warned["mounts[5].yield_force"]
    assert bolt_said.startswith(
        f"the bolt force F_S (its preload and its share of the load) {AT_START}"
    )
    assert f", {force_bolt:.4g} N, is {bolt_ratio:.3g} times its yield force" in bolt_said
    assert "the bolt taken as elastic there (its plastic elongation starts at 0" in bolt_said
    assert "its utilisation is past 1 from the first report (ERROR)" in bolt_said
    assert assemble(model.scene).scene.warnings == model.scene.warnings  # said once

    engine, statuses = first_report(model)
    for name, ratio in (("key", key_ratio), ("bolt", bolt_ratio)):
        assert engine.utilisation_max[name] == pytest.approx(ratio, rel=1e-9)
        assert statuses[name].level == ERROR
        assert float(statuses[name].values["utilisation_max"]) == pytest.approx(ratio, rel=1e-5)
    assert f"is {engine.utilisation_max['key']:.3g} times" in key_said
    assert f"is {engine.utilisation_max['bolt']:.3g} times" in bolt_said


@pytest.mark.parametrize("clearance", [0.0, 2.0e-4], ids=["fitted", "clearance"])
def test_a_start_within_its_limits_is_not_warned_of(clearance):
    """The key allowed 10 % more than its start force, the bolt yielding 3 % above its start
    force: nothing said, though the start is solved for them, and the first report is not
    an ERROR."""
    force_key, force_bolt = key_force(clearance), bolt_force(clearance)
    data = hung(1.1 * force_key, 1.03 * force_bolt, 1.2 * force_bolt, clearance)
    model = assemble(scene_from_dict(data, "<hung>"))
    assert model.scene.warnings == ()
    engine, statuses = first_report(model)
    assert engine.utilisation_max["key"] == pytest.approx(1.0 / 1.1, rel=1e-9)
    assert engine.utilisation_max["bolt"] == pytest.approx(1.0 / 1.03, rel=1e-9)
    assert statuses["key"].level != ERROR
    assert statuses["bolt"].level != ERROR


def test_a_bolt_past_its_ultimate_force_at_the_start_is_warned_that_it_breaks(tmp_path, capsys):
    """F_u at 98 % of the start's bolt force (F_y at 90 %): past its yield and its ultimate
    force, each warned of once (the ultimate against F_u), on the command line's stderr too;
    the bolt is broken from the first report on."""
    from mount_twin.cli import main

    force_bolt = bolt_force(0.0)
    yield_force, ultimate = 0.9 * force_bolt, 0.98 * force_bolt
    data = hung(2.0 * key_force(0.0), yield_force, ultimate)
    model = assemble(scene_from_dict(data, "<hung>"))
    warned = limited(model.scene)
    assert set(warned) == {"mounts[5].yield_force", "mounts[5].ultimate_force"}
    said = warned["mounts[5].ultimate_force"]
    ratio = force_bolt / ultimate
    assert f", {force_bolt:.4g} N, is {ratio:.3g} times its ultimate force {ultimate:.4g} N" in (
        said
    )
    assert "it breaks at the start (bolt_fractured)" in said
    _, statuses = first_report(model)
    assert statuses["bolt"].level == ERROR
    assert "bolt_fractured" in statuses["bolt"].values["now"].split(", ")

    path = tmp_path / "hung.scene.yaml"
    path.write_text(yaml.safe_dump(data))
    assert main(["info", str(path)]) == 0
    err = capsys.readouterr().err.splitlines()
    (line,) = [s for s in err if ".ultimate_force:" in s]
    assert line == f"mount-twin: warning: {path}: mounts[5].ultimate_force: {said}"
    assert len([s for s in err if ".yield_force:" in s]) == 1


def test_a_parameter_set_names_the_limit_by_its_parameter():
    """A parameter set's mounts are mounts.<name>: the key's warning is
    mounts.key.allowable_force."""
    data = hung(0.5 * key_force(0.0), 2.0 * F_V, 3.0 * F_V)
    scene = effective_parameters(as_params(data), "params").scene
    (path,) = limited(assemble(scene).scene)
    assert path == "mounts.key.allowable_force"


def test_a_rated_spring_beside_a_fitted_key_keeps_the_loader_s_warning():
    """Springs rated below their load beside a fitted key (its law is its tangent) are judged
    as before, by the loader's statics ("under the weight"), once: the start is solved for the
    key's limit, and adds no second rating warning. (A bolt makes a scene non-linear at rest,
    its ratings judged at the start: it is taken out.)"""
    data = hung(MASS * G, 2.0 * F_V, 3.0 * F_V, rated_load=100.0)  # the key within
    del data["mounts"][BOLT]
    scene = scene_from_dict(data, "<keyed>")
    rated = [w for w in scene.warnings if w.path.endswith(".rated_load")]
    (warning,) = rated
    assert "static load under the weight" in warning.message
    model = assemble(scene)
    assert [w for w in model.scene.warnings if w.path.endswith(".rated_load")] == rated
    assert limited(model.scene) == {}


def test_the_bundled_genset_starts_within_its_limits():
    """Six bolts at F_S ≈ 0.63·F_y, keys unloaded at rest: its start is solved for them, and
    nothing is said."""
    scene = load_scene_file(Path(__file__).parents[1] / "config/genset_bolted_keyed.scene.yaml")
    assert rated_at_start(scene)
    assert assemble(scene).scene.warnings == ()


def test_a_force_a_hair_past_its_limit_never_reads_as_1_times_it():
    """The key's force at the start 1e-6 of itself past its allowable force: "is 1 times its
    allowable force", a force at its limit, not past it. Past by 1e-6 of F, it is past by
    F·1e-6 N (to the start's 1e-9)."""
    force_key = key_force(0.0)
    allowable = force_key * (1.0 - 1e-6)
    model = assemble(scene_from_dict(hung(allowable, 2.0 * F_V, 3.0 * F_V), "<hung>"))
    said = limited(model.scene)["mounts[4].allowable_force"]
    excess = re.search(r", is (\S+) N past its allowable force ", said)
    assert excess is not None, said
    assert float(excess.group(1)) == pytest.approx(force_key * 1e-6, rel=0.01)
    assert f"its allowable force {allowable:.4g} N: " in said
