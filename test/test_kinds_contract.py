"""The mount-kind contract: every kind code runs that kind's own law in every compiled dispatcher,
and a code without a branch can never run another kind's law (it fails loudly instead).

The dispatchers (`kinds.kind_load`, `kind_monitor`, `kind_update`, the core's, in
src/core/kinds/dispatch.hpp) are `if code == ...` chains over the C++ ports of the kinds' Python
laws; before the contract was checked, a kind registered in KINDS without its branches ran the
shear key's law, silently.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path
from types import ModuleType

import numpy as np
import pytest
from kinds_helpers import kind_mount, law_of

from mount_twin import kinds
from mount_twin.integrate import stepper
from mount_twin.integrate.methods import NOT_FINITE, STATUS_TEXT, SUCCESS
from mount_twin.kinds import (
    CODES,
    KINDS,
    N_EVENTS,
    N_PAR,
    KindContractError,
    check_dispatch,
    check_modules,
    dispatch_results,
    elastomer,
    kind_load,
    kind_monitor,
    kind_update,
    probe_input,
    shear_key,
)
from mount_twin.model.assemble import assemble, gravity_input, initial_state
from mount_twin.physics.dynamics import OK, body_motion, mount_monitors, rhs
from mount_twin.scene.loader import load_scene_file

GENSET = Path(__file__).resolve().parent.parent / "config" / "genset_bolted_keyed.scene.yaml"
UNKNOWN = len(KINDS)
"""A code no kind has."""

REALISTIC = {
    "elastomer": kind_mount(
        "elastomer",
        stiffness_linear=[2.0e5, 2.0e5, 0.0],
        stiffness_cubic=[1.0e9, 0.0, 0.0],
        force_table={
            "z": {
                "deflection": [-0.01, -0.004, 0.0, 0.004, 0.01],
                "force": [-9e3, -1.5e3, 0.0, 1.2e3, 5e3],
            }
        },
        damping=[300.0, 300.0, 500.0],
        rotational_stiffness=[1.0e3, 1.0e3, 2.0e3],
        rotational_damping=[1.0, 1.0, 2.0],
        rated_deflection=[4e-3, 4e-3, 6e-3],
        hysteresis={"ratio": 0.7, "beta": 2.0e5, "gamma": 1.0e5, "n": 1.5, "axes": ["x", "z"]},
        snubber={"gap": 3e-3, "stiffness": 1.0e8, "exponent": 1.5, "damping": 0.2},
    ),
    "bolted_joint": kind_mount(
        "bolted_joint",
        bolt_stiffness=7.0e8,
        clamp_stiffness=3.5e9,
        preload=1.0e5,
        yield_force=1.57e5,
        ultimate_force=1.96e5,
        axial_damping=2.0e3,
        shear_damping=1.0e3,
    ),
    "shear_key": kind_mount(
        "shear_key",
        stiffness=[1.0e9, 0.0, 5.0e8],
        damping=[1.0e4, 0.0, 1.0e4],
        clearance=2.0e-4,
        allowable_force=2.0e5,
        engagement_height=5.0e-3,
    ),
}
"""One mount of every kind with every feature on, read and packed by the package."""


def realistic_inputs(name: str, rng: np.random.Generator) -> list[dict[str, np.ndarray]]:
    """Sample inputs for the kind's real parameter row: deflections from rest to well past its
    limits (contact, opening, yield, snubbing), rates, and internal states at and off rest."""
    law = law_of(REALISTIC[name])
    p = np.zeros(N_PAR)
    p[: law.p.shape[0]] = law.p
    inputs = []
    for scale in (0.0, 1e-5, 1e-4, 5e-4, 2e-3, 8e-3):
        for states in ("rest", "random"):
            y = np.zeros(16)
            if states == "random":
                y[3 : 3 + law.n_state] = rng.uniform(-1e-4, 1e-4, law.n_state)
            inputs.append(
                {
                    "p": p,
                    "y": y,
                    "y0": y * 0.5,
                    "d": rng.uniform(-scale, scale, 3),
                    "v": rng.uniform(-0.1, 0.1, 3),
                    "phi": rng.uniform(-1e-3, 1e-3, 3),
                    "w": rng.uniform(-1e-2, 1e-2, 3),
                    "dydt": np.full(16, 0.25),
                    "f": np.full(3, 0.25),
                    "c": np.full(3, 0.25),
                    "g": np.full(N_EVENTS, 0.25),
                }
            )
            d = inputs[-1]["d"]  # the twin beside the companion, as `carry` sees it
            inputs[-1]["dt"] = d + rng.uniform(-0.1, 0.1, 3) * np.abs(d)
            inputs[-1]["yt"] = y + rng.uniform(-1e-6, 1e-6, 16) * (y != 0.0)
    return inputs


@pytest.mark.parametrize("name", list(KINDS))
def test_every_code_runs_its_own_law_in_every_dispatcher(name: str) -> None:
    """kind_load, kind_monitor, kind_update and kind_carry with the kind's code give exactly what
    the kind module's own load, monitor, update and carry give, on its real parameters over its
    whole range."""
    rng = np.random.default_rng(7)
    code, module = CODES[name], KINDS[name]
    for x in realistic_inputs(name, rng):
        for dispatcher, (got, own) in dispatch_results(code, module, x).items():
            assert np.all(np.isfinite(own)), (dispatcher, own)
            np.testing.assert_array_equal(got, own, err_msg=f"{dispatcher} for {name}")


@pytest.mark.parametrize("name", list(KINDS))
def test_a_kind_the_companion_does_not_carry_writes_nothing_in_its_carry(name: str) -> None:
    """The companion skips the carry of a kind whose `kind_carries` is false (and the mount's
    motion it would read): on the kind's realistic inputs its carry, dispatched and its own,
    leaves the state as it is. A kind that does carry (a bolted joint) moves it on some."""
    rng = np.random.default_rng(13)
    code, module = CODES[name], KINDS[name]
    moved = False
    for x in realistic_inputs(name, rng):
        got, own = dispatch_results(code, module, x)["kind_carry"]
        np.testing.assert_array_equal(got, own, err_msg=name)
        moved = moved or not np.array_equal(got, x["y"])
    assert moved == kinds.kind_carries(code), name


@pytest.mark.parametrize("name", list(KINDS))
def test_every_kinds_settle_keeps_its_force_and_settles_once(name: str) -> None:
    """A start's `settle` changes no force or couple of the kind's own load (the start's
    equilibrium holds after it), and what it leaves it leaves as it is (an admissible state
    needs no settling), over the realistic inputs: at rest, faces far past their friction
    bound and open joints among them."""
    rng = np.random.default_rng(11)
    module = KINDS[name]
    for x in realistic_inputs(name, rng):
        forces = []
        for settles in (0, 1, 2):
            y = x["y"].copy()
            for _ in range(settles):
                module.settle(x["p"], y, 3, x["d"])
            if settles == 1:
                once = y.copy()
            f, c, dydt = np.zeros(3), np.zeros(3), np.zeros(16)
            module.load(x["p"], y, 3, x["d"], x["v"], x["phi"], x["w"], dydt, f, c)
            forces.append(np.concatenate([f, c]))
        np.testing.assert_allclose(forces[1], forces[0], rtol=1e-9, atol=1e-9, err_msg=name)
        np.testing.assert_allclose(y, once, rtol=4.0 * np.finfo(float).eps, err_msg=name)


def test_theprobe_input_tells_every_law_apart() -> None:
    """On the load-time probe's sample input, no two kinds' laws agree: a branch that runs
    another kind's law cannot pass the probe."""
    x = probe_input(N_PAR, N_EVENTS, 0)
    for dispatcher in ("kind_load", "kind_monitor"):
        own = {n: dispatch_results(c, KINDS[n], x)[dispatcher][1] for n, c in CODES.items()}
        for a in KINDS:
            for b in KINDS:
                assert a == b or not np.allclose(own[a], own[b]), (dispatcher, a, b)


def test_check_dispatch_passes_for_the_registered_kinds() -> None:
    """The load-time probe accepts the package's own kinds (it runs in `assemble`)."""
    check_dispatch(KINDS, samples=3)


def test_an_unknown_code_writes_nan_not_the_shear_keys_answer() -> None:
    """Each dispatcher's final else fails loudly: NaN force, couple, event functions,
    utilisation and state, where the shear key's law (the old fallback) gives numbers."""
    key = law_of(REALISTIC["shear_key"])
    p = np.zeros(N_PAR)
    p[: key.p.shape[0]] = key.p
    d, v, z3 = np.array([5e-4, 0.0, 1e-3]), np.array([0.01, 0.0, 0.0]), np.zeros(3)
    y = np.zeros(4)
    f_key, c_key, f, c = np.zeros(3), np.zeros(3), np.zeros(3), np.zeros(3)
    shear_key.load(p, y, -1, d, v, z3, z3, y.copy(), f_key, c_key)
    kind_load(UNKNOWN, p, y, -1, d, v, z3, z3, y.copy(), f, c)
    assert np.all(np.isfinite(f_key)) and f_key[0] < 0.0
    assert np.all(np.isnan(f)) and np.all(np.isnan(c))

    g_key, g = np.zeros(N_EVENTS), np.zeros(N_EVENTS)
    util_key = shear_key.monitor(p, y, y, -1, d, v, g_key)
    util = kind_monitor(UNKNOWN, p, y, y, -1, d, v, g)
    assert math.isfinite(util_key) and np.all(np.isfinite(g_key))
    assert math.isnan(util) and np.all(np.isnan(g))

    y_upd = np.zeros(4)
    kind_update(UNKNOWN, p, y_upd, -1, d)
    assert np.isnan(y_upd).any()


def test_an_unknown_code_fails_the_step_with_a_status() -> None:
    """In the compiled model, a mount whose code has no branch makes the stepper fail with
    NOT_FINITE (reported by the engine with its text), instead of integrating the shear key."""
    model = assemble(load_scene_file(GENSET))
    g = np.array([0.0, 0.0, model.scene.input.g])
    y0 = initial_state(model, g)
    u = gravity_input(0.0, g)
    kinds_row = model.arrays.nl.kind
    key_row = int(np.flatnonzero(kinds_row == CODES["shear_key"])[0])

    def step() -> int:
        st = stepper.new_stepper("dopri54", model.n_state, 1e-6, 1e-9, 1000)
        y = y0.copy()
        return int(
            stepper.advance(
                st.method,
                y,
                0.0,
                1e-4,
                st.settings,
                model.arrays,
                model.new_scratch(),
                u,
                st.work2d,
                st.work1d,
                st.result,
            )
        )

    assert step() == SUCCESS
    kinds_row[key_row] = UNKNOWN
    try:
        assert step() == NOT_FINITE
        assert "non-finite" in STATUS_TEXT[NOT_FINITE]
        # the monitors too: NaN utilisation and events, and the state poisoned for the next step
        nl, s = model.arrays.nl, model.new_scratch()
        y = y0.copy()
        model_g = np.zeros((nl.kind.shape[0], N_EVENTS))
        util = np.zeros(nl.kind.shape[0])
        body_motion(y, model.arrays, s)
        mount_monitors(y, y0, nl, s, model_g, util)
        assert math.isnan(util[key_row]) and np.all(np.isnan(model_g[key_row]))
        assert np.isnan(y).any()
    finally:
        kinds_row[key_row] = CODES["shear_key"]


# A kind registered without dispatcher branches ------------------------------------------------


def _stop_load(p, y, o, d, v, phi, w, dydt, f, c) -> None:
    for j in range(3):
        f[j] = -p[0] * d[j] - 1.0
        c[j] = 0.0


def _stop_monitor(p, y, y0, o, d, v, g) -> float:
    g[0] = abs(d[0]) - p[1]
    return abs(d[0]) / p[1]


def _stop_update(p, y, o, d) -> bool:
    return False


def fake_kind(name: str = "end_stop") -> ModuleType:
    """A complete kind module whose code the compiled dispatchers do not know."""
    module = ModuleType(f"fake_kinds.{name}")
    module.KIND = name
    module.EVENTS = ("stop_contact",)
    module.EVENT_ERROR = (False,)
    module.EVENT_STIFFENS = (True,)
    module.EVENT_SWITCHES = (False,)
    module.EVENT_COMPANION = ("carried",)
    module.ROTATIONAL = False
    module.RESTUCK = ()
    module.PARAMETERS = {}
    module.N_PAR = 2
    module.CONTACT_STIFFNESS = (0,)
    module.read = lambda r, name, position, rpy: None
    module.pack = lambda m: np.array([1.0e6, 1e-3])
    module.state_names = lambda m: ()
    module.load, module.monitor, module.update = _stop_load, _stop_monitor, _stop_update
    module.settle = lambda p, y, o, d: None
    module.carry = lambda p, y, y0, yt, o, d, dt: None
    module.nominal_tangent = lambda m: ((1.0e6,) * 3 + (0.0,) * 3, ("stiffness",) * 6)
    module.piecewise = lambda m: True
    module.kinked = lambda m: False
    return module


def test_a_kind_without_dispatcher_branches_is_refused() -> None:
    """Registered after the others (code 3) but never dispatched: the probe names it."""
    registry = {**KINDS, "end_stop": fake_kind()}
    with pytest.raises(
        KindContractError, match=r"kind_load with the code of kind 'end_stop' \(3\)"
    ):
        check_dispatch(registry)


def test_a_kind_without_branches_fails_at_assemble(monkeypatch: pytest.MonkeyPatch) -> None:
    """Added to KINDS and CODES (as a new kind module would be), any model with non-linear mounts
    is refused at load, before a kernel runs."""
    monkeypatch.setitem(kinds.KINDS, "end_stop", fake_kind())
    monkeypatch.setitem(kinds.CODES, "end_stop", 3)
    with pytest.raises(KindContractError, match="end_stop"):
        assemble(load_scene_file(GENSET))


def test_crossed_branches_are_refused() -> None:
    """Codes that do not match the dispatchers' branches (a kind moved in KINDS without its
    branch) are refused: the probe compares laws, not names."""
    crossed = dict(reversed(KINDS.items()))
    with pytest.raises(KindContractError, match="does not run"):
        check_dispatch(crossed)


@pytest.mark.parametrize("name", ["update", "settle", "carry", "nominal_tangent", "piecewise"])
def test_a_module_lacking_part_of_the_contract_is_refused(name: str) -> None:
    """check_modules (run at import) names what a kind module lacks, and a KIND mismatch: a
    kind without its own nominal tangent cannot be taken for another (statics asks each)."""
    module = fake_kind()
    delattr(module, name)
    with pytest.raises(KindContractError, match=f"lacks {name}"):
        check_modules({"end_stop": module})
    with pytest.raises(KindContractError, match="whose KIND is"):
        check_modules({"other_name": fake_kind()})


@pytest.mark.parametrize(
    "table", ["EVENT_ERROR", "EVENT_STIFFENS", "EVENT_SWITCHES", "EVENT_COMPANION"]
)
def test_an_event_table_of_another_length_than_the_events_is_refused(table: str) -> None:
    """Each event has its level and whether it may stiffen the scene (`auto` looks again)."""
    module = fake_kind()
    setattr(module, table, (False, True))
    with pytest.raises(KindContractError, match=f"{table} and EVENTS differ in length"):
        check_modules({"end_stop": module})


def test_a_companion_treatment_the_core_does_not_know_is_refused() -> None:
    """EVENT_COMPANION names how the error estimate's companion takes an interval that starts
    with each event holding; its index in COMPANION_TREATMENTS is the code the core reads, so a
    misspelt one (or a flag, as the table was) cannot reach it as some other treatment."""
    for wrong in ("integrate", True):
        module = fake_kind()
        module.EVENT_COMPANION = (wrong,)
        with pytest.raises(KindContractError, match=r"EVENT_COMPANION holds .* not one of"):
            check_modules({"end_stop": module})


def test_a_contact_stiffness_outside_the_parameter_row_is_refused() -> None:
    """The start's equilibrium softens the columns a kind names in CONTACT_STIFFNESS; one past
    its N_PAR (here column 2 of a row of 2) would scale another kind's parameter or none."""
    module = fake_kind()
    module.CONTACT_STIFFNESS = (2,)
    with pytest.raises(KindContractError, match="CONTACT_STIFFNESS names a column outside"):
        check_modules({"end_stop": module})


def test_a_switch_that_stiffens_is_refused() -> None:
    """A start's switches (a bolt breaking under the start's load) are logged outside the
    compiled loop, which alone counts stiffening events and ends a run for `auto` to look
    again; a switch that stiffened would go unexamined at a start. No kind has one (the one
    switch, a bolt breaking, softens); a kind declaring one is refused, not run so."""
    module = fake_kind()
    module.EVENT_SWITCHES = (True,)
    with pytest.raises(KindContractError, match="'stop_contact' is a discrete switch that may"):
        check_modules({"end_stop": module})


def test_only_contact_events_may_stiffen_a_scene() -> None:
    """A key closing or a snubber touching adds stiffness; a joint yielding, opening, slipping
    or breaking, an overload or an over-travel (already in contact) adds none."""
    stiffening = {
        (name, event)
        for name, module in KINDS.items()
        for event, flag in zip(module.EVENTS, module.EVENT_STIFFENS, strict=True)
        if flag
    }
    assert stiffening == {("shear_key", "key_contact"), ("elastomer", "snubber_contact")}


def test_only_a_bolt_breaking_is_a_discrete_switch() -> None:
    """`update` switches a bolt to broken and nothing else: its event is the one a start that
    breaks it reports (`EVENT_SWITCHES`); the others holding at a start are states."""
    switches = {
        (name, event)
        for name, module in KINDS.items()
        for event, flag in zip(module.EVENTS, module.EVENT_SWITCHES, strict=True)
        if flag
    }
    assert switches == {("bolted_joint", "bolt_fractured")}


def test_a_kind_that_reads_the_rotation_must_declare_it(monkeypatch: pytest.MonkeyPatch) -> None:
    """A kind declared without a rotational law gets NaN for its local rotation and rate and
    no couple is taken from it: the elastomer (rotational stiffness) declared so is refused at
    load, not run without its couple; the bolted joint and the key pass with NaN there."""
    monkeypatch.setattr(elastomer, "ROTATIONAL", False)
    with pytest.raises(KindContractError, match="'elastomer' declares ROTATIONAL = False"):
        check_dispatch(dict(KINDS))
    monkeypatch.setattr(elastomer, "ROTATIONAL", True)
    check_dispatch(dict(KINDS))


def test_mounts_in_the_axes_of_f_skip_the_rotation_and_give_the_same_loads() -> None:
    """A non-linear mount whose axes are F's (the genset's feet and keys) is moved into and out
    of them by copying: the right-hand side is the general rotation's to the last bit, and a
    mount turned by its orientation_rpy still takes the rotation."""
    model = assemble(load_scene_file(GENSET))
    nl = model.arrays.nl
    assert nl.aligned.all()
    rotating = model.arrays._replace(nl=nl._replace(aligned=np.zeros_like(nl.aligned)))
    g = np.array([0.0, 0.0, model.scene.input.g])
    rng = np.random.default_rng(3)
    for _ in range(10):
        y = initial_state(model, g)
        y[:12] += rng.normal(0.0, [2e-4] * 6 + [0.05] * 6)
        u = gravity_input(0.0, g + rng.normal(0.0, 5.0, 3))
        fast, general = np.zeros(model.n_state), np.zeros(model.n_state)
        assert rhs(0.0, y, model.arrays, model.new_scratch(), u, fast) == OK
        assert rhs(0.0, y, rotating, model.new_scratch(), u, general) == OK
        np.testing.assert_array_equal(fast, general)
    turned = dataclasses.replace(
        model.scene,
        mounts=(
            dataclasses.replace(model.scene.mounts[0], orientation_rpy=(0.0, 0.0, 0.3)),
            *model.scene.mounts[1:],
        ),
    )
    assert list(assemble(turned).arrays.nl.aligned) == [False] + [True] * 7
