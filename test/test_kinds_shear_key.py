"""Shear key: a stop with clearance on its stiff axes, nothing on its free ones.

Truths: along a stiff axis F = −k⟨|d| − clearance⟩·sign d − c·ḋ while in contact (0 inside the
clearance), F = 0 along free axes, never a couple; the contact and overload event functions; and a
body sliding freely in the clearance that bounces off the key: free flight at constant speed,
then half a sine of angular frequency √(k/m) pressing (v₀/ω) into the key, back out at −v₀.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from kinds_helpers import kind_mount, law_of
from physics_helpers import base_scene, build, mount

from mount_twin.engine.batch import SampleBatch
from mount_twin.engine.engine import TwinEngine

CASES = {
    "x_only": [1e8, 0.0, 0.0],
    "y_only": [0.0, 2e8, 0.0],
    "x_and_y": [1e8, 2e8, 0.0],
    "z_only": [0.0, 0.0, 5e8],
}


def key(stiffness, clearance=0.0, damping=(0.0, 0.0, 0.0), allowable=0.0, height=0.0):
    return law_of(
        kind_mount(
            "shear_key",
            "k1",
            stiffness=list(stiffness),
            damping=list(damping),
            clearance=clearance,
            allowable_force=allowable,
            engagement_height=height,
        )
    )


def stop_force(d: np.ndarray, v: np.ndarray, k, c, clearance: float) -> np.ndarray:
    """Per axis in contact: the push k⟨|d| − clearance⟩ + c·ḋ·sign d, never negative (a key
    face does not pull), against sign d; else, and along free axes (k = 0), 0."""
    k, c = np.asarray(k), np.asarray(c)
    pen = np.abs(d) - clearance
    contact = (k > 0.0) & (pen > 0.0)
    push = np.maximum(k * np.maximum(pen, 0.0) + c * v * np.sign(d), 0.0)
    return np.where(contact, -np.sign(d) * push, 0.0)


@pytest.mark.parametrize("clearance", [0.0, 5e-4])
@pytest.mark.parametrize("case", list(CASES))
def test_key_pushes_back_only_along_stiff_axes_and_only_past_the_clearance(case, clearance):
    k, c = CASES[case], [3e3, 4e3, 5e3]
    law = key(k, clearance, damping=c)
    assert law.n_state == 0
    rng = np.random.default_rng(3)
    for _ in range(300):
        d, v = rng.uniform(-2e-3, 2e-3, 3), rng.uniform(-0.2, 0.2, 3)
        phi, w = rng.uniform(-0.1, 0.1, 3), rng.uniform(-1.0, 1.0, 3)
        f, couple, _ = law.load(d, v, phi=phi, w=w)
        ref = stop_force(d, v, k, c, clearance)
        np.testing.assert_allclose(f, ref, rtol=1e-14, atol=1e-12)
        assert np.all(f * np.sign(d) <= 0.0), "a key face pushes the body back, never pulls"
        assert np.all(f[np.asarray(k) == 0.0] == 0.0)
        assert np.all(couple == 0.0)
    # exactly at the clearance, and a hair inside it, no force at all
    for j in np.flatnonzero(np.asarray(k) > 0.0):
        for edge in (clearance, clearance * (1 - 1e-12)):
            for side in (1.0, -1.0):
                f = law.load(np.eye(3)[j] * side * edge, np.eye(3)[j] * 0.1)[0]
                assert np.all(f == 0.0)


@pytest.mark.parametrize("clearance", [0.0, 5e-4])
def test_key_contact_and_overload_events_and_utilisation(clearance):
    k, allowable = [1e8, 2e8, 0.0], 5e4
    law = key(k, clearance, allowable=allowable)
    for d in np.array([[3e-4, 0.0, 0.0], [0.0, -6e-4, 0.0], [4e-4, 7e-4, 0.1], [0.0, 0.0, 0.5]]):
        util, g = law.monitor(d)
        pen = np.abs(d[:2]) - clearance
        force = np.max(np.asarray(k[:2]) * np.maximum(pen, 0.0))
        assert g[0] == (pytest.approx(np.max(pen), abs=1e-18) if clearance > 0.0 else -1.0)
        assert util == pytest.approx(force / allowable, rel=1e-14, abs=1e-18)
        assert g[1] == pytest.approx(force / allowable - 1.0, rel=1e-14)
    # the overload event crosses zero exactly at the allowable force
    at = clearance + allowable / k[1]
    assert law.monitor([0.0, at, 0.0])[1][1] == pytest.approx(0.0, abs=1e-12)
    assert (
        law.monitor([0.0, at * (1 - 1e-9), 0.0])[1][1]
        < 0.0
        < law.monitor([0.0, at * (1 + 1e-9), 0.0])[1][1]
    )
    # without an allowable force nothing is monitored
    util, g = key(k, clearance).monitor([0.0, 0.01, 0.0])
    assert util == 0.0
    assert g[1] == -1.0


# ------------------------------------------------------------------------ whole body: the bounce
MASS, K_KEY, CLEARANCE, SPEED = 50.0, 5e6, 5e-4, 0.05  # kg, N/m, m, m/s
OMEGA = math.sqrt(K_KEY / MASS)


def bounce(t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Position, velocity and key force (on the body) of a body leaving the centre at
    SPEED between two stops CLEARANCE away, each a spring K_KEY: flights of 2c/v (first c/v)
    and contacts of π/ω, alternating sides."""
    flight, contact = 2.0 * CLEARANCE / SPEED, math.pi / OMEGA
    x, v, force = np.zeros_like(t), np.zeros_like(t), np.zeros_like(t)
    for i, ti in enumerate(t):
        s = ti + 0.5 * flight  # time since leaving the far stop, in a period of two half-periods
        half, tau = divmod(s, flight + contact)
        side = 1.0 if int(half) % 2 == 0 else -1.0
        if tau < flight:
            x[i], v[i] = side * (SPEED * tau - CLEARANCE), side * SPEED
        else:
            pen = SPEED / OMEGA * math.sin(OMEGA * (tau - flight))
            x[i] = side * (CLEARANCE + pen)
            v[i] = side * SPEED * math.cos(OMEGA * (tau - flight))
            force[i] = -side * K_KEY * pen
    return x, v, force


def test_a_body_in_the_clearance_flies_freely_and_bounces_elastically_off_the_key():
    """Only 'y' free; the key's local x points along F's y (yaw 90°), so its wrench is along its
    own x; foundation at rest, gravity off (the frozen DOFs ignore it anyway)."""
    mount = kind_mount(
        "shear_key",
        "stop",
        rpy=(0.0, 0.0, math.pi / 2),
        stiffness=[K_KEY, 0.0, 0.0],
        clearance=CLEARANCE,
    )
    scene = base_scene(
        MASS,
        [0.0, 0.0, 0.2],
        [1.0, 1.0, 1.0, 0.0, 0.0, 0.0],
        [mount],
        ["y"],
        initial={"mode": "given", "velocity": [0.0, SPEED, 0.0, 0.0, 0.0, 0.0]},
    )
    t = np.arange(1501) / 10_000.0  # 150 ms: more than two bounces
    engine = TwinEngine(build(scene))
    out = engine.run(SampleBatch(t, np.zeros((t.size, 3)), np.zeros((t.size, 3)), [""] * t.size))
    x_ref, v_ref, force_ref = bounce(t)
    assert np.sum(np.diff(np.sign(x_ref)) != 0) >= 3, "the body should cross the clearance"
    scale = SPEED / OMEGA  # penetration amplitude
    assert np.max(np.abs(out.pose[:, 1] - x_ref)) <= 1e-6 * scale
    np.testing.assert_array_equal(out.pose[:, [0, 2]], np.tile([0.0, 0.2], (t.size, 1)))
    assert np.max(np.abs(out.wrenches[:, 0, 0] - force_ref)) <= 1e-6 * K_KEY * scale
    np.testing.assert_array_equal(out.wrenches[:, 0, 1:], 0.0)
    assert engine.state[1] == pytest.approx(v_ref[-1], abs=1e-6 * SPEED)


def test_a_foot_lifted_past_the_engagement_height_has_cleared_the_key() -> None:
    """A key is a block on the deck: the foot it holds sideways escapes once lifted over it."""
    law = key([1e9, 0.0, 0.0], clearance=1e-4, damping=(1e4, 0.0, 0.0), height=0.02)
    d_side, v = 5e-4, (0.3, 0.0, 0.0)
    held, _, _ = law.load([d_side, 0.0, 0.019], v)
    assert held[0] == pytest.approx(-(1e9 * (d_side - 1e-4) + 1e4 * 0.3), rel=1e-14)
    free, _, _ = law.load([d_side, 0.0, 0.021], v)
    assert np.all(free == 0.0)
    util, g = law.monitor([d_side, 0.0, 0.021])
    assert util == 0.0 and np.all(g < 0.0), "no contact and no overload once cleared"
    util_held, _ = law.monitor([d_side, 0.0, 0.019])
    assert util_held == 0.0  # no allowable given: not monitored


@pytest.mark.parametrize("tilt", [0.0, 0.05, -0.3, 1.0])
def test_a_dof_a_key_holds_within_its_clearance_starts_at_rest_where_it_bears(
    tilt: float,
) -> None:
    """x held only by a key with a clearance (a spring holds z): the loader takes the scene, and
    the start at equilibrium rests in the clearance on a level deck, or bears on the key on a
    deck tilted by `tilt` (rad about y): x = −sign·(c + m·g·sin θ/k), z = −m·g·cos θ/k_z. It was
    refused ("DOF x is not held by any mount"), its stiffness singular inside the clearance."""
    k_x, k_z, c = 1e7, 1e6, 5e-4
    spring = mount("spring", (0.0, 0.0, 0.0), (0.0, 0.0, k_z, 0.0, 0.0, 0.0))
    stop = kind_mount("shear_key", "stop", stiffness=[k_x, 0.0, 0.0], clearance=c)
    inertia = [5.0, 6.0, 7.0, 0.0, 0.0, 0.0]
    scene = base_scene(MASS, [0.0, 0.0, 0.3], inertia, [spring, stop], ["x", "z"])
    f = 9.80665 * np.array([math.sin(tilt), 0.0, math.cos(tilt)])
    t = np.arange(101) / 1000.0
    engine = TwinEngine(build(scene))
    out = engine.run(SampleBatch(t, np.tile(f, (t.size, 1)), np.zeros((t.size, 3)), [""] * 101))
    assert engine.counts["starts_at_nominal_gravity"] == 0
    x = -math.copysign(c + MASS * abs(f[0]) / k_x, f[0]) if tilt else 0.0
    expected = np.tile([x, 0.0, 0.3 - MASS * f[2] / k_z], (t.size, 1))
    np.testing.assert_allclose(out.pose[:, :3], expected, rtol=0, atol=1e-12)
