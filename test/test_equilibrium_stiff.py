"""Static equilibrium holds at any stiffness: stiff, light scenes load (an absolute residual
threshold refused them), the equilibrium matches the closed form, a body heeled onto a snubber
up to 2.5e6 times stiffer than its mounts starts resting on it, as one heeled from within a
key's clearance onto the key does, and a DOF no mount holds is still refused."""

from __future__ import annotations

import math

import numpy as np
import pytest
from kinds_helpers import kind_mount
from physics_helpers import base_scene, mount

from mount_twin.engine.restart import start_state
from mount_twin.errors import ModelError
from mount_twin.model.assemble import Model, assemble, initial_state
from mount_twin.physics.dynamics import evaluate
from mount_twin.scene.loader import scene_from_dict

CORNERS = [(0.4, 0.3), (-0.4, 0.3), (-0.4, -0.3), (0.4, -0.3)]
G = 9.80665
SNUB_MASS, SNUB_K, SNUB_KZ, SNUB_K1, SNUB_GAP = 5.0, 1e3, 1e4, 1.0, 1e-3
"""`_snubbed`: kg; N/m of each corner mount laterally and vertically, and of the snubbed
mount's elastomer along each axis; m of its snubber's gap."""


def _model(mass: float, k: float, stiffness_axes: tuple[float, float, float] = (1, 1, 1)):
    """`mass` on four equal isotropic (or as given) mounts in the plane of the CG."""
    kx, ky, kz = (k * a for a in stiffness_axes)
    mounts = [
        mount(f"m{i}", (x, y, 0.5), (kx, ky, kz, 0, 0, 0)) for i, (x, y) in enumerate(CORNERS)
    ]
    data = base_scene(mass, [0.0, 0.0, 0.5], [mass * 0.1] * 3 + [0.0] * 3, mounts)
    return assemble(scene_from_dict(data, "<equilibrium test>"))


@pytest.mark.parametrize(("mass", "k"), [(1.0, 1e10), (10.0, 1e11), (10.0, 1e9), (1e4, 1e5)])
@pytest.mark.parametrize(
    ("magnitude", "tilt"), [(m, t) for m in (8.0, 9.80665, 11.5) for t in (0.0, 0.2, -0.35)]
)
def test_the_equilibrium_of_stiff_light_scenes_is_found_and_is_the_closed_form(
    mass: float, k: float, magnitude: float, tilt: float
) -> None:
    """Isotropic mounts in the CG's plane, symmetric: the body translates by m·f/(4k) against
    the specific force f (the mounts push it back toward f), without rotating."""
    f = magnitude * np.array([0.0, math.sin(tilt), math.cos(tilt)])
    y = initial_state(_model(mass, k), f)
    np.testing.assert_allclose(y[:3], -mass * f / (4.0 * k), rtol=1e-6, atol=1e-300)
    assert np.abs(y[3:6]).max() <= 1e-12


def test_a_dof_no_mount_holds_is_still_refused_at_load() -> None:
    """Mounts stiff along z only: nothing holds x, and assembly (which solves the nominal
    start state) refuses the scene by naming it."""
    with pytest.raises(ModelError, match="DOF x is not held by any mount"):
        _model(10.0, 1e9, (0.0, 0.0, 1.0))


def test_a_start_on_a_turning_deck_rests_relative_to_it() -> None:
    """A deck turning steadily at 1.4 rad/s about z (a turntable; sensor on the axis reads g):
    started at the equilibrium that includes the centrifugal load, the pump stays put relative
    to the deck; the equilibrium without it differs by far more than the motion that follows."""
    from io_helpers import batch, default_model, engine_for

    omega = np.array([0.0, 0.0, 1.4])
    n = 1000
    gyro = np.tile(omega, (n, 1))
    engine = engine_for()
    out = engine.push(batch(1.0 + np.arange(n) * 1e-3, gyro=gyro))
    drift = np.abs(out.pose[:, :3] - out.pose[0, :3]).max()
    g_up = np.array([0.0, 0.0, 9.80665])
    shift = np.abs(
        initial_state(default_model(), g_up, omega)[:3] - initial_state(default_model(), g_up)[:3]
    ).max()
    assert shift > 1e-6  # m: the centrifugal load moves the equilibrium
    assert drift < 1e-4 * shift


def _snubbed(stiffness: float, cg_height: float, axes: tuple[str, ...] = ("x",)) -> Model:
    """SNUB_MASS on four corner mounts soft laterally (SNUB_K; SNUB_KZ vertically) in the plane
    z = 0, beside an elastomer mount at the origin (SNUB_K1 per axis) with a linear snubber
    SNUB_GAP off along `axes` of `stiffness` (N/m); the CG `cg_height` (m) above that plane."""
    soft = [
        mount(f"m{i}", (x, y, 0.0), (SNUB_K, SNUB_K, SNUB_KZ, 0, 0, 0))
        for i, (x, y) in enumerate(CORNERS)
    ]
    snubbed = kind_mount(
        "elastomer",
        "snubbed",
        stiffness_linear=[SNUB_K1] * 3,
        damping=[0.0] * 3,
        snubber={"gap": SNUB_GAP, "stiffness": stiffness, "exponent": 1.0, "axes": list(axes)},
    )
    data = base_scene(SNUB_MASS, [0.0, 0.0, cg_height], [0.1] * 3 + [0.0] * 3, [*soft, snubbed])
    return assemble(scene_from_dict(data, "<snubber equilibrium test>"))


def _forces(model: Model, y: np.ndarray) -> np.ndarray:
    """(n_mounts, 6): each mount's force (N) and couple (N·m) on the body at y, in its axes."""
    wrenches = np.empty((model.n_mounts, 6))
    evaluate(y, model.arrays, model.new_scratch(), np.empty(10), wrenches)
    return wrenches


def _heel(lateral: float) -> np.ndarray:
    """Specific force (m/s², F) of magnitude G heeled `lateral` m/s² along x."""
    return np.array([lateral, 0.0, math.sqrt(G**2 - lateral**2)])


STIFF_SNUBBERS = [1e6, 1e7, 1e8, 1e9, 1e10]
"""N/m: 250 to 2.5e6 times the four corner mounts' lateral stiffness."""


@pytest.mark.parametrize("stiffness", STIFF_SNUBBERS)
@pytest.mark.parametrize("lateral", [1.0, 5.0])
def test_a_heel_onto_a_stiff_snubber_rests_on_it_at_the_closed_form(
    stiffness: float, lateral: float
) -> None:
    """Mounts and snubber in the CG's plane, symmetric: the heel translates the body along −x
    without turning it. The corners and the elastomer (K = 4·SNUB_K + SNUB_K1) take the
    lateral load m·f_x up to the gap, the snubber the rest: by hand, |x| = (m·f_x + k_s·g) /
    (K + k_s) where m·f_x > K·g (5 N and 25 N against 4.001 N: 1 N and 21 N bear on the snubber,
    pressing it 1e-6–1e-10 m at 1e6–1e10 N/m, under the Jacobian's difference step); z =
    −m·f_z/(4·SNUB_KZ + SNUB_K1). The mounts' forces sum to m·f, to the rounding of a force k_s·x.
    Before, Newton's halvings crept along the snubber's edge and least squares stalled on it:
    no equilibrium found (1e9 and 1e10 N/m at 1 m/s²)."""
    model = _snubbed(stiffness, 0.0)
    f = _heel(lateral)
    y = initial_state(model, f)
    soft = 4.0 * SNUB_K + SNUB_K1
    x = -(SNUB_MASS * f[0] + stiffness * SNUB_GAP) / (soft + stiffness)
    assert SNUB_MASS * f[0] > soft * SNUB_GAP  # the snubber bears at the closed form
    np.testing.assert_allclose(y[0], x, rtol=1e-12)
    np.testing.assert_allclose(y[2], -SNUB_MASS * f[2] / (4.0 * SNUB_KZ + SNUB_K1), rtol=1e-12)
    assert abs(y[1]) <= 1e-15 and np.abs(y[3:6]).max() <= 1e-12
    wrenches = _forces(model, y)
    floor = 64.0 * np.finfo(float).eps * 1.0 * stiffness  # N: k_s times a position's rounding
    np.testing.assert_allclose(wrenches[:, :3].sum(axis=0), SNUB_MASS * f, rtol=0, atol=floor)


@pytest.mark.parametrize("stiffness", STIFF_SNUBBERS)
def test_a_restart_heeled_onto_a_stiff_snubber_starts_resting_on_it(stiffness: float) -> None:
    """CG 0.1 m above the mounts' plane (x and pitch coupled), heeled by 2 m/s²: 10 N
    laterally, of which the corners take 4 N to the gap. The (re)start under that specific
    force is its equilibrium, pressing the snubber, with no fallback on nominal gravity (from
    which the body would swing into the snubber: a transient not in the physics); before, at
    1e9 N/m and stiffer, none was found. The snubber bears most of the 6 N the corners leave
    at the gap, and the mounts' forces sum to m·f, to the rounding of a force k_s·x."""
    model = _snubbed(stiffness, 0.1)
    f = _heel(2.0)
    start = start_state(model, model.nominal_state, _heel(0.0), f, np.zeros(3), None)
    assert start.note is None and start.state is not None
    wrenches = _forces(model, start.state)
    snubber = wrenches[-1, 0]  # N, on the body along +x
    assert snubber > 0.5 * (SNUB_MASS * 2.0 - 4.0 * SNUB_K * SNUB_GAP)
    floor = 64.0 * np.finfo(float).eps * 1.0 * stiffness  # N: k_s times a position's rounding
    np.testing.assert_allclose(wrenches[:, :3].sum(axis=0), SNUB_MASS * f, rtol=0, atol=floor)


@pytest.mark.parametrize("stiffness", STIFF_SNUBBERS)
def test_a_heel_onto_a_snubber_along_x_and_y_at_once_starts_resting_on_both(
    stiffness: float,
) -> None:
    """Snubbed along x and y, the CG 0.3 m above the mounts (both coordinates coupled to the
    rotations), heeled by 8 m/s² along the diagonal: 28 N along each axis, of which the corners
    take 4 N to the gap. The start rests on the snubber along both axes (it bears most of the
    24 N the corners leave along each), and the mounts' forces sum to m·f, to the rounding of
    a force k_s·x. Before, at 1e10 N/m, the steps on from where the first one landed, both
    contacts within the Jacobian's difference step of their edges, crawled by a few % each, and
    no equilibrium was found."""
    model = _snubbed(stiffness, 0.3, ("x", "y"))
    lateral = 8.0 / math.sqrt(2.0)  # m/s² along x and along y
    f = np.array([lateral, lateral, math.sqrt(G**2 - 2.0 * lateral**2)])
    wrenches = _forces(model, initial_state(model, f))
    assert (wrenches[-1, :2] > 0.5 * (SNUB_MASS * lateral - 4.0 * SNUB_K * SNUB_GAP)).all()
    floor = 64.0 * np.finfo(float).eps * 1.0 * stiffness  # N: k_s times a position's rounding
    np.testing.assert_allclose(wrenches[:, :3].sum(axis=0), SNUB_MASS * f, rtol=0, atol=floor)


@pytest.mark.parametrize(("stiffness", "lateral"), [(1e7, 0.01), (1e9, 0.5), (1e10, 5.0)])
def test_a_heel_onto_a_key_from_within_its_clearance_rests_on_it_at_the_closed_form(
    stiffness: float, lateral: float
) -> None:
    """x held only by a shear key with a clearance (a spring holds z): the stiffness is singular
    at the guess, inside the clearance, and the start leaves it (`newton.anchored`). Heeled by
    `lateral` m/s², the key bears m·f_x (0.1–50 N) pressed 1e-8–5e-9 m at 1e7–1e10 N/m, under
    the Jacobian's difference step: by hand x = −(c + m·f_x/k), z = −m·f_z/k_z. Before, the
    anchored solves took no finer Jacobian, and no equilibrium was found."""
    mass, k_z, clearance = 10.0, 1e6, 5e-4
    spring = mount("spring", (0.0, 0.0, 0.0), (0.0, 0.0, k_z, 0.0, 0.0, 0.0))
    key = kind_mount("shear_key", "key", stiffness=[stiffness, 0.0, 0.0], clearance=clearance)
    data = base_scene(mass, [0.0, 0.0, 0.3], [5.0, 6.0, 7.0, 0, 0, 0], [spring, key], ["x", "z"])
    model = assemble(scene_from_dict(data, "<key equilibrium test>"))
    f = _heel(lateral)
    y = initial_state(model, f)
    tolerance = 1e-8 * mass / stiffness  # m: the residual allowed, 1e-9·G m/s², over k/m
    np.testing.assert_allclose(
        y[0], -(clearance + mass * f[0] / stiffness), rtol=0, atol=tolerance
    )
    np.testing.assert_allclose(y[1], -mass * f[2] / k_z, rtol=1e-12)
