"""The start's equilibrium with bolted joints in bearing and shear keys pressed, under a heel.

A heel past the joints' friction bound slides their faces (μ·F_K, whatever the slide) until the
shanks bear on their holes past the clearance: between the stuck face and the bearing shank the
lateral stiffness is zero, a plateau of the residual that Newton's step cannot cross (singular,
or orders of magnitude too long). Truths: the closed form of a block on four symmetric joints
heeled along x (each joint's share by statics); the force and moment balance of the mounts
against m·f for a body pitched and turned by the heel; a key pressed within and past its
clearance beside a spring, by hand; a start with no bearing past the friction bound refused
with the mounts that slide named; and a body held across only past clearances (frictionless
joints, or keys), free within them and bearing past them by hand, heeled onto them at the
closed form. A start whose faces slid leaves each stick point on its friction bound
(`kinds.bolted_joint.settle`), a new machine's, a given one's and a restart's: admissible by
the joint diagram's μ·F_K, its wrenches those of the start solved, and a foot moved back
unloading its face by k_τ per metre at once, by hand.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from kinds_helpers import kind_mount
from physics_helpers import base_scene, mount

from mount_twin.engine.batch import SampleBatch
from mount_twin.engine.engine import TwinEngine
from mount_twin.engine.restart import start_state
from mount_twin.errors import ModelError, SceneError
from mount_twin.model.assemble import Model, assemble, initial_state
from mount_twin.physics.dynamics import body_motion, evaluate, mount_deflections
from mount_twin.physics.pose_row import ANGLES_COLS, POSITION_COLS
from mount_twin.scene.loader import scene_from_dict

G = 9.80665
EPS = float(np.finfo(float).eps)
MASS = 1000.0
"""kg, the block on the joints."""
CORNERS = [(0.4, 0.3), (-0.4, 0.3), (-0.4, -0.3), (0.4, -0.3)]
"""m, the joints in the plane z = 0 of F."""
K_S, K_P, F_V, MU, K_TAU, CLEAR = 7e8, 3.5e9, 1e3, 0.1, 1e9, 1e-3
"""Each joint's bolt and clamp stiffness (N/m), preload (N), friction, face stick stiffness
(N/m) and hole clearance (m): a light preload, so that a heel of 3–6 m/s² slides the faces."""


def _joints(bearing: float, preload: float = F_V, friction: float = MU) -> list[dict]:
    """Four bolted joints at CORNERS, bolts along z of F, shanks bearing at `bearing` N/m
    (preload N, friction as given)."""
    return [
        kind_mount(
            "bolted_joint",
            f"j{i}",
            (x, y, 0.0),
            bolt_stiffness=K_S,
            clamp_stiffness=K_P,
            preload=preload,
            yield_force=1.5e5,
            ultimate_force=2e5,
            friction=friction,
            shear_stiffness=K_TAU,
            hole_clearance=CLEAR,
            bearing_stiffness=bearing,
        )
        for i, (x, y) in enumerate(CORNERS)
    ]


def _block(
    bearing: float,
    cg: tuple[float, float, float] = (0.0, 0.0, 0.0),
    preload: float = F_V,
    friction: float = MU,
) -> Model:
    """MASS with its CG at `cg` (m, F) on `_joints(bearing, preload, friction)`."""
    joints = _joints(bearing, preload, friction)
    data = base_scene(MASS, list(cg), [100.0, 150.0, 200.0, 0.0, 0.0, 0.0], joints)
    return assemble(scene_from_dict(data, "<bearing equilibrium test>"))


def _heel(lateral: float, azimuth: float = 0.0) -> np.ndarray:
    """Specific force (m/s², F) of magnitude G heeled `lateral` m/s² toward `azimuth` rad."""
    horizontal = lateral * np.array([math.cos(azimuth), math.sin(azimuth)])
    return np.array([*horizontal, math.sqrt(G**2 - lateral**2)])


def _wrenches(model: Model, y: np.ndarray) -> np.ndarray:
    """(n_mounts, 6): each mount's force (N) and couple (N·m) on the body at y, in its axes
    (here F's)."""
    wrenches = np.empty((model.n_mounts, 6))
    evaluate(y, model.arrays, model.new_scratch(), np.empty(10), wrenches)
    return wrenches


def _moment(model: Model, y: np.ndarray, wrenches: np.ndarray) -> np.ndarray:
    """N·m about the CG, in F: the mounts' forces at their attachment points as the body is
    turned at y (arms R·a), and their couples."""
    s = model.new_scratch()
    body_motion(y, model.arrays, s)
    arms = np.array([mt.position for mt in model.scene.mounts]) - np.array(model.scene.body.cg)
    return np.cross(arms @ s.rot.T, wrenches[:, :3]).sum(axis=0) + wrenches[:, 3:].sum(axis=0)


def _bearing_floor(bearing: float) -> float:
    """N: the force the start may leave unbalanced, the equilibrium's accepted residual (1e-9
    of G over the mass) plus k_b times a position's rounding (64 ulp of 1 m)."""
    return 1e-9 * G * MASS + 64.0 * EPS * 4.0 * bearing


@pytest.mark.parametrize("bearing", [5e8, 1e10, 1e11, 1e12])
@pytest.mark.parametrize("lateral", [3.0, 6.0])
def test_a_heel_past_the_friction_bound_rests_on_the_shanks_at_the_closed_form(
    bearing: float, lateral: float
) -> None:
    """CG in the joints' plane, joints symmetric: the heel translates the block without turning
    it, each joint taking a quarter. Axially u = −m·f_z/(4(k_S + k_P)) (the joint closed), so
    F_K = F_V − k_P·u; across, the face slides at μ·F_K (295 N and 254 N) under m·f_x/4 (750
    N and 1500 N) and the shank bears the rest past the clearance: by hand X = −(c + (m·f_x/4
    − μ·F_K)/k_b), 0.5–2.5e-6 m past it at 5e8 N/m, 5e-10 at 1e12. Before, Newton's first step
    landed on the faces' plateau (friction at its bound, no lateral stiffness: a singular
    Jacobian) and least squares stalled there: no equilibrium found at any k_b."""
    model = _block(bearing)
    f = _heel(lateral)
    y = initial_state(model, f)
    u = -MASS * f[2] / (4.0 * (K_S + K_P))
    friction = MU * (F_V - K_P * u)
    assert MASS * f[0] / 4.0 > friction  # the faces slide: the shanks bear
    x = -(CLEAR + (MASS * f[0] / 4.0 - friction) / bearing)
    allowed = _bearing_floor(bearing) / (4.0 * bearing)  # m: the force floor over the stiffness
    np.testing.assert_allclose(y[0], x, rtol=0.0, atol=allowed)
    np.testing.assert_allclose(y[2], u, rtol=1e-9)
    assert abs(y[1]) <= 1e-15 and np.abs(y[3:6]).max() <= 1e-12
    wrenches = _wrenches(model, y)
    floor = _bearing_floor(bearing)
    np.testing.assert_allclose(wrenches[:, :3].sum(axis=0), MASS * f, rtol=0.0, atol=floor)


TURNING = [
    ((0.0, 0.0, 0.3), 3.0, math.pi / 4.0, F_V, MU, 5e8),  # pitched and rolled, the diagonal
    ((0.0, 0.0, 0.5), 6.0, 0.0, F_V, MU, 5e8),  # pitched onto the front joints
    ((0.1, 0.15, 0.4), 3.0, 0.6435, F_V, MU, 5e8),  # off centre: turned about z too
    ((-0.035, 0.127, 0.081), 4.84, 5.975, F_V, MU, 1e8),
    ((-0.1, 0.092, 0.354), 5.33, 6.104, F_V, 0.2, 5e8),
    ((0.049, 0.147, 0.147), 5.26, 0.276, 5e3, MU, 5e8),
    ((0.108, -0.13, 0.263), 3.91, 1.962, F_V, MU, 5e8),
    ((-0.067, -0.031, 0.141), 3.46, 5.752, F_V, MU, 1e8),
    ((0.046, -0.047, 0.499), 6.91, 4.307, 5e3, 0.2, 1e10),
    ((-0.184, 0.093, 0.307), 2.63, 4.519, F_V, MU, 1e10),
    ((0.184, -0.052, 0.276), 5.17, 5.33, 5e3, MU, 1e10),
    ((0.087, 0.058, 0.306), 2.83, 1.548, F_V, 0.2, 1e10),
    ((0.099, -0.165, 0.213), 4.29, 1.27, F_V, 0.2, 1e10),
    ((-0.131, 0.035, 0.479), 5.72, 6.161, 5e3, 0.2, 1e10),
    ((-0.151, -0.169, 0.267), 3.25, 5.072, F_V, MU, 1e10),
]
"""(CG m, heel m/s², its azimuth rad, preload N, friction, bearing stiffness N/m) of the
turning heels: three by design, five off-centre ones of 60 drawn at random (the start turned
the body by radians in the first two, and found none in the last three, before the limit on a
step's turn and the halving of the steps past a kink), and seven of `bench/start_heels.py`'s
120 at 1e10 N/m (seed 0: heels 4, 18, 23, 57, 66, 68 and 94), found only since the start's
continuation in the contact stiffnesses (`model.assemble.CONTINUATION`)."""


@pytest.mark.parametrize(("cg", "lateral", "azimuth", "preload", "friction", "bearing"), TURNING)
def test_a_heel_onto_bolts_in_bearing_turning_the_body_balances_its_weight(
    cg: tuple[float, float, float],
    lateral: float,
    azimuth: float,
    preload: float,
    friction: float,
    bearing: float,
) -> None:
    """The CG above the joints' plane and off centre: the heel pitches, rolls and turns the
    block, each joint bearing a share of its own (its clamp force, and so its friction bound,
    moved by the pitch). Every joint's face slides (its lateral force, friction and bearing,
    past μ·F_K with F_K from its own axial force: F_z = F_K − F_S = −(k_S + k_P)·u), the
    mounts' forces balance m·f and their moments about the CG vanish, to the equilibrium's
    residual, and the block rests turned by less than a hundredth of a radian (the shanks bear
    past 1 mm of clearance on arms of 0.5 m). Before, none was found; then, leaving the
    plateau, without a limit on the Newton step's turn some rested turned by radians (faces
    that slid hold yaw only by the friction's stiffness across its direction), and others
    found none (the steps past the bearing edges crossed other joints' edges as the body
    turned)."""
    model = _block(bearing, cg, preload, friction)
    f = _heel(lateral, azimuth)
    y = initial_state(model, f)
    assert np.abs(y[3:6]).max() < 0.01
    wrenches = _wrenches(model, y)
    u = -wrenches[:, 2] / (K_S + K_P)
    bound = friction * (preload - K_P * u)
    assert (np.hypot(wrenches[:, 0], wrenches[:, 1]) > bound).all()
    floor = _bearing_floor(bearing)
    np.testing.assert_allclose(wrenches[:, :3].sum(axis=0), MASS * f, rtol=0.0, atol=floor)
    np.testing.assert_allclose(_moment(model, y, wrenches), 0.0, rtol=0.0, atol=floor)


def test_a_restart_heeled_past_the_friction_bound_starts_on_the_shanks() -> None:
    """A (re)start under a 3 m/s² heel (CG 0.3 m up) is its equilibrium on the bearing shanks,
    with no fallback on nominal gravity (from which the body would slide onto them: a transient
    not in the physics); before, it fell back, with the note that none held."""
    model = _block(5e8, (0.0, 0.0, 0.3))
    f = _heel(3.0)
    start = start_state(model, model.nominal_state, _heel(0.0), f, np.zeros(3), None)
    assert start.note is None and start.state is not None
    wrenches = _wrenches(model, start.state)
    np.testing.assert_allclose(
        wrenches[:, :3].sum(axis=0), MASS * f, rtol=0.0, atol=_bearing_floor(5e8)
    )


def test_a_heel_past_the_friction_bound_without_bearing_names_the_sliding_joints() -> None:
    """Shanks that never bear (k_b = 0): past the friction bound nothing holds the heel, and
    the start is refused with the mounts that slide named (before: only the DOF, and "check
    that the mounts hold every free DOF"), which a (re)start's note on its fallback to nominal
    gravity repeats (before: none said why); within the bound the faces hold it, stuck: by hand
    X = −m·f_x/(4·k_τ) (CG in the joints' plane: no pitch)."""
    model = _block(0.0)
    with pytest.raises(ModelError, match=r"joint_slipped at j0, j1, j2, j3"):
        initial_state(model, _heel(3.0))
    start = start_state(model, model.nominal_state, _heel(0.0), _heel(3.0), np.zeros(3), None)
    assert start.note is not None and "joint_slipped at j0, j1, j2, j3" in start.note
    assert "started from rest under nominal gravity" in start.note
    f = _heel(0.5)
    y = initial_state(model, f)
    np.testing.assert_allclose(y[0], -MASS * f[0] / (4.0 * K_TAU), rtol=1e-6)


KEY_MASS, SPRING_K, KEY_CLEAR = 10.0, 1e5, 5e-4
"""`_keyed`: kg; N/m of the spring along x and z; m of the key's clearance along x."""


def _keyed(key: float) -> Model:
    """KEY_MASS on a spring (SPRING_K along x and z) beside a shear key along x, KEY_CLEAR
    off, of `key` N/m; x and z free."""
    spring = mount("spring", (0.0, 0.0, 0.0), (SPRING_K, 0.0, SPRING_K, 0.0, 0.0, 0.0))
    stop = kind_mount("shear_key", "key", stiffness=[key, 0.0, 0.0], clearance=KEY_CLEAR)
    data = base_scene(KEY_MASS, [0.0, 0.0, 0.0], [1.0, 1.0, 1.0, 0, 0, 0], [spring, stop])
    data["dofs"] = ["x", "z"]
    return assemble(scene_from_dict(data, "<key equilibrium test>"))


@pytest.mark.parametrize("key", [1e7, 1e9, 1e11])
@pytest.mark.parametrize("lateral", [2.0, 4.9, 5.1, 8.0])
def test_a_key_pressed_within_and_past_its_clearance_is_the_closed_form(
    key: float, lateral: float
) -> None:
    """The spring alone carries m·f_x while it moves the body less than the clearance (20 N
    and 49 N: 2e-4 m and 4.9e-4 m of 5e-4): X = −m·f_x/k; past it (51 N, 80 N) the key bears
    the rest, X = −(k_key·c + m·f_x)/(k + k_key), 1e-9–3e-5 m past the edge at 1e11–1e7 N/m.
    Held these before."""
    model = _keyed(key)
    f = _heel(lateral)
    y = initial_state(model, f)
    load = KEY_MASS * f[0]
    if load < SPRING_K * KEY_CLEAR:
        x = -load / SPRING_K
    else:
        x = -(key * KEY_CLEAR + load) / (SPRING_K + key)
    allowed = (1e-9 * G * KEY_MASS + 64.0 * EPS * key) / (SPRING_K + key)  # m
    np.testing.assert_allclose(y[0], x, rtol=0.0, atol=allowed + 4.0 * EPS * abs(x))
    np.testing.assert_allclose(y[1], -KEY_MASS * f[2] / SPRING_K, rtol=1e-12)


@pytest.mark.parametrize("key", [1e7, 1e9, 1e11])
def test_a_key_along_z_carries_the_weight_from_within_its_clearance(key: float) -> None:
    """KEY_MASS held along z by a key alone, KEY_CLEAR of clearance, z the one free DOF: the
    body sinks through the clearance onto it, by hand Z = −(c + m·g/k_key), 9.8e-6–9.8e-10 m
    past the edge. Before, none was found: at the guess nothing bears, J is 0, and the anchor
    springs leaving a plateau had no scale to take (now the mounts' nominal tangent's)."""
    stop = kind_mount("shear_key", "key", stiffness=[0.0, 0.0, key], clearance=KEY_CLEAR)
    data = base_scene(KEY_MASS, [0.0, 0.0, 0.0], [1.0, 1.0, 1.0, 0, 0, 0], [stop], ["z"])
    model = assemble(scene_from_dict(data, "<key along z test>"))
    f = _heel(0.0)
    y = initial_state(model, f)
    z = -(KEY_CLEAR + KEY_MASS * G / key)
    allowed = (1e-9 * G * KEY_MASS + 64.0 * EPS * key) / key  # m: the force floor over k_key
    np.testing.assert_allclose(y[0], z, rtol=0.0, atol=allowed + 4.0 * EPS * abs(z))


K_B = 5e8
"""N/m: the shank's bearing in its hole, and the key's stiffness, of `_in_clearances`."""


def _in_clearances(kind: str, bearing: float = K_B, cg_height: float = 0.0) -> Model:
    """MASS, CG `cg_height` m above the middle of CORNERS, held across only past a clearance
    CLEAR at each corner: by frictionless bolted joints (`_joints(bearing, friction=0)`), or by
    shear keys of `bearing` N/m along x and y beside linear springs of the joints' axial
    stiffness K_S + K_P along z. Loaded as a scene file is (a DOF nothing holds refused)."""
    if kind == "bolted_joint":
        mounts = _joints(bearing, friction=0.0)
    else:
        keys = [
            kind_mount("shear_key", f"k{i}", (x, y, 0.0), stiffness=[bearing, bearing, 0.0])
            | {"clearance": CLEAR}
            for i, (x, y) in enumerate(CORNERS)
        ]
        springs = [
            mount(f"s{i}", (x, y, 0.0), (0.0, 0.0, K_S + K_P, 0.0, 0.0, 0.0))
            for i, (x, y) in enumerate(CORNERS)
        ]
        mounts = keys + springs
    data = base_scene(MASS, [0.0, 0.0, cg_height], [100.0, 150.0, 200.0, 0.0, 0.0, 0.0], mounts)
    return assemble(scene_from_dict(data, "<clearance test>", refuse_unheld=True))


@pytest.mark.parametrize("kind", ["bolted_joint", "shear_key"])
def test_a_body_held_across_only_past_clearances_rests_free_within_them(kind: str) -> None:
    """A frictionless bolted face holds nothing across until its shank bears past the hole's
    clearance, as a key holds nothing within its clearance: x, y and yaw are held only there,
    and upright the body rests centred, free within the clearances (a neutral equilibrium),
    not adrift (it moves by the clearance at most). Both load, as a key always did; the bolts
    were refused ("no mount holds x, y, delta": their nominal tangent counted nothing across
    a clearance). By hand: z = −m·g/(4(k_S + k_P)) (the joint closed; the springs), no force
    across at the start nor anywhere within the clearances (here moved 0.3 mm along x and y
    and turned 0.5 mrad: corners 0.67 mm off at most), and 1.5 clearances along x each mount
    bears k_b·0.5·c back."""
    model = _in_clearances(kind, cg_height=0.3)
    f = _heel(0.0)
    y = initial_state(model, f)
    assert np.abs(y[[0, 1, 3, 4, 5]]).max() <= 1e-15
    np.testing.assert_allclose(y[2], -MASS * G / (4.0 * (K_S + K_P)), rtol=1e-9)
    wrenches = _wrenches(model, y)
    assert (wrenches[:, :2] == 0.0).all()
    floor = _bearing_floor(K_B)
    np.testing.assert_allclose(wrenches[:, :3].sum(axis=0), MASS * f, rtol=0.0, atol=floor)
    within = y.copy()
    within[[0, 1, 5]] = 0.3 * CLEAR, 0.3 * CLEAR, 5e-4
    wrenches = _wrenches(model, within)
    assert (wrenches[:, :2] == 0.0).all()
    assert _moment(model, within, wrenches)[2] == 0.0
    past = y.copy()
    past[0] = 1.5 * CLEAR
    bearing = _wrenches(model, past)[:, :2]
    bears = bearing[np.abs(bearing).sum(axis=1) > 0.0]
    np.testing.assert_allclose(bears, [[-K_B * 0.5 * CLEAR, 0.0]] * 4, rtol=1e-9, atol=0.0)


@pytest.mark.parametrize("kind", ["bolted_joint", "shear_key"])
@pytest.mark.parametrize("lateral", [0.5, 3.0])
def test_a_heel_onto_clearances_rests_on_their_bearing_at_the_closed_form(
    kind: str, lateral: float
) -> None:
    """Heeled along x with nothing across but the bearing past the clearances (CG in the
    mounts' plane: no pitch), each mount bears a quarter of m·f_x: by hand X = −(c +
    m·f_x/(4·k_b)), while y and yaw stay free within the clearances (with keys: no stiffness
    there at all, a neutral rest). Before, the bolts were refused at load, and the keys' start
    was not found (its Jacobian singular along y at the root itself: Newton gave up there, and
    least squares stalled in the clearance, 0.5 m/s² off)."""
    model = _in_clearances(kind)
    f = _heel(lateral)
    y = initial_state(model, f)
    x = -(CLEAR + MASS * f[0] / (4.0 * K_B))
    allowed = _bearing_floor(K_B) / (4.0 * K_B)  # m: the force floor over the stiffness
    np.testing.assert_allclose(y[0], x, rtol=0.0, atol=allowed)
    np.testing.assert_allclose(y[2], -MASS * f[2] / (4.0 * (K_S + K_P)), rtol=1e-9)
    assert abs(y[1]) <= 1e-15 and np.abs(y[3:6]).max() <= 1e-12
    wrenches = _wrenches(model, y)
    floor = _bearing_floor(K_B)
    np.testing.assert_allclose(wrenches[:, :3].sum(axis=0), MASS * f, rtol=0.0, atol=floor)


def test_a_block_on_frictionless_bolts_shaken_across_logs_no_slip() -> None:
    """Shaken along x (0.05 m/s² at 5 Hz, from rest after 0.2 s) the block on frictionless
    joints travels its clearance and bears on the shanks, which is what a frictionless face is
    for: no joint slipped, opened or anything else (before: four `joint_slipped` WARNs when
    the motion began, the slip function reading each foot's travel in a sample)."""
    model = _in_clearances("bolted_joint")
    n, rate = 1200, 1000.0
    stamps = 1.0 + np.arange(n) / rate
    f = np.tile(_heel(0.0), (n, 1))
    shake = stamps[200:] - stamps[200]
    f[200:, 0] += 0.05 * np.sin(2.0 * math.pi * 5.0 * shake)
    engine = TwinEngine(model)
    out = engine.run(SampleBatch(stamps, f, np.zeros((n, 3)), ["imu"] * n))
    travel = np.ptp(out.pose[:, POSITION_COLS][:, 0])
    assert travel > 0.5 * CLEAR, "the block moves across its clearance"
    assert engine.events == []


def test_frictionless_bolts_whose_shanks_never_bear_are_refused_at_load() -> None:
    """μ = 0 and k_b = 0: nothing holds the body across at any displacement, so a scene file
    is refused naming the DOFs (the body would drift), as before."""
    with pytest.raises(SceneError, match=r"mounts: no mount holds x, y, delta"):
        _in_clearances("bolted_joint", bearing=0.0)


@pytest.mark.parametrize("cg", [(0.0, 0.0, 0.3), (0.1, -0.05, 0.3)])
def test_a_block_on_keys_alone_heeled_from_within_their_clearances_balances_its_weight(
    cg: tuple[float, float, float],
) -> None:
    """MASS on four keys at CORNERS bearing K_B along x, y and z past CLEAR, nothing else:
    upright and centred it sinks by hand to Z = −(c + m·g/(4·k)); heeled 2 m/s² along x (CG
    0.3 m up, and off centre) the keys' forces balance m·f and their moments about the CG
    vanish, to the equilibrium's residual. Before, neither start was found (J 0 at the guess)."""
    keys = [
        kind_mount("shear_key", f"k{i}", (x, y, 0.0), stiffness=[K_B] * 3, clearance=CLEAR)
        for i, (x, y) in enumerate(CORNERS)
    ]
    data = base_scene(MASS, list(cg), [100.0, 150.0, 200.0, 0.0, 0.0, 0.0], keys)
    model = assemble(scene_from_dict(data, "<keys alone test>"))
    if cg[:2] == (0.0, 0.0):
        z = -(CLEAR + MASS * G / (4.0 * K_B))
        allowed = _bearing_floor(K_B) / (4.0 * K_B)
        np.testing.assert_allclose(model.nominal_state[2], z, rtol=0.0, atol=allowed)
    f = _heel(2.0)
    y = initial_state(model, f)
    wrenches = _wrenches(model, y)
    floor = _bearing_floor(K_B)
    np.testing.assert_allclose(wrenches[:, :3].sum(axis=0), MASS * f, rtol=0.0, atol=floor)
    np.testing.assert_allclose(_moment(model, y, wrenches), 0.0, rtol=0.0, atol=floor)


def _faces(model: Model, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(d, s): each joint's deflection (m, its axes) at y's pose, (n, 3), and its stick point
    (slip_x, slip_y) in y, (n, 2)."""
    d = np.empty((model.n_mounts, 3))
    assert mount_deflections(y, model.arrays, model.new_scratch(), d) > 0.0
    index = {name: i for i, name in enumerate(model.state_names)}
    s = [[y[index[f"{mt.name}.slip_{a}"]] for a in "xy"] for mt in model.scene.mounts]
    return d, np.array(s)


def _bound(d: np.ndarray, preload: float, friction: float) -> np.ndarray:
    """N: each joint's friction bound μ·F_K at deflections d (m), F_K = max(F_V − k_P·u, 0)
    (the joint diagram)."""
    return friction * np.maximum(preload - K_P * d[:, 2], 0.0)


def _unstuck(model: Model, y: np.ndarray) -> np.ndarray:
    """y with every stick point at zero: the state the start's equilibrium was solved in."""
    out = y.copy()
    for i, name in enumerate(model.state_names):
        if ".slip_" in name:
            out[i] = 0.0
    return out


SLID = [((0.0, 0.0, 0.0), 3.0, 0.0, F_V, MU, 1e12), *TURNING[:3], TURNING[4], TURNING[8]]
"""(as TURNING) heels whose faces all slide at the start: on the axis (CG in the joints'
plane), then pitched, rolled and turned."""


@pytest.mark.parametrize("heel", SLID)
def test_a_start_whose_faces_slid_leaves_each_stick_point_on_its_friction_bound(
    heel: tuple,
) -> None:
    """Admissible: every face's stick spring k_τ·|d − s| is on its bound μ·F_K (F_K from the
    joint's own axial deflection), not beyond it, and the mounts' wrenches are those of the
    start solved with the stick points at zero (to rounding: the radial return leaves the face
    force μ·F_K along e), balancing m·f with no moment about the CG. Before, the stick points
    stayed at zero: k_τ·|d|, the feet 1.0–1.003 mm across, was 538–9515 times the bound."""
    cg, lateral, azimuth, preload, friction, bearing = heel
    model, f = _block(bearing, cg, preload, friction), _heel(lateral, azimuth)
    y = initial_state(model, f)
    d, s = _faces(model, y)
    bound = _bound(d, preload, friction)
    spring = K_TAU * np.hypot(*(d[:, :2] - s).T)
    np.testing.assert_allclose(spring, bound, rtol=1e-9, atol=1e-9)
    wrenches = _wrenches(model, y)
    np.testing.assert_allclose(wrenches, _wrenches(model, _unstuck(model, y)), rtol=0, atol=1e-9)
    floor = _bearing_floor(bearing)
    np.testing.assert_allclose(wrenches[:, :3].sum(axis=0), MASS * f, rtol=0.0, atol=floor)
    np.testing.assert_allclose(_moment(model, y, wrenches), 0.0, rtol=0.0, atol=floor)


@pytest.mark.parametrize("lateral", [3.0, 6.0])
def test_a_face_that_slid_at_the_start_sticks_at_once_when_the_foot_moves_back(
    lateral: float,
) -> None:
    """The block heeled along x onto shanks of 1e12 N/m (1e-9 m past the clearance), moved
    back along +x by δ (a translation: each foot by δ' = δ in its axes, off its shank): the
    face sticks on reversal and unloads by k_τ per metre, μ·F_K − k_τ·δ' (295 − 100 N at 3
    m/s²); past 2·μ·F_K/k_τ (5.1–5.9e-7 m) it slides the other way, −μ·F_K. Before, the stick
    point at zero, |e| = 1 mm: the face stayed at +μ·F_K until the foot had come back 1 mm."""
    model = _block(1e12)
    y = initial_state(model, _heel(lateral))
    d, _ = _faces(model, y)
    bound = _bound(d, F_V, MU)
    for delta in (1e-7, 1e-6):
        back = y.copy()
        back[0] += delta
        moved, _ = _faces(model, back)
        assert (np.hypot(moved[:, 0], moved[:, 1]) < CLEAR).all()  # the shanks bear no more
        reversed_by = moved[:, 0] - d[:, 0]  # δ': δ to the rounding of the feet's positions
        np.testing.assert_allclose(reversed_by, delta, rtol=0.0, atol=1e-16)
        np.testing.assert_allclose(moved[:, 1:] - d[:, 1:], 0.0, rtol=0.0, atol=1e-16)
        face = np.where(reversed_by < 2.0 * bound / K_TAU, bound - K_TAU * reversed_by, -bound)
        wrenches = _wrenches(model, back)
        np.testing.assert_allclose(wrenches[:, 0], face, rtol=1e-9, atol=0.0)
        np.testing.assert_allclose(wrenches[:, 1], 0.0, rtol=0.0, atol=1e-9)


def _given(pose: list[float]) -> Model:
    """MASS on `_joints(0.0)` started at the given `pose` (X, Y, Z m, angles rad; at rest)."""
    initial = {"mode": "given", "pose": pose, "velocity": [0.0] * 6}
    data = base_scene(MASS, [0.0] * 3, [100.0, 150.0, 200.0, 0.0, 0.0, 0.0], _joints(0.0))
    data["initial_state"] = initial
    return assemble(scene_from_dict(data, "<given slid test>"))


@pytest.mark.parametrize("lift", [0.0, 1e-7])
def test_a_given_pose_past_the_friction_bound_starts_each_face_on_it(lift: float) -> None:
    """A given start translated by (−0.2, 0.1) mm across and `lift` up (each joint's d that
    translation; the joint closed, F_K = F_V − k_P·u = 1000 N and 650 N), the stick point by
    hand on the bound along d: s = d − (μ·F_K/k_τ)·d/|d|. Before, s = 0."""
    d = np.array([-2e-4, 1e-4, lift])
    model = _given([*d, 0.0, 0.0, 0.0])
    y = initial_state(model, _heel(0.0))
    _, s = _faces(model, y)
    across = d[:2] - MU * (F_V - K_P * lift) / K_TAU * d[:2] / np.hypot(*d[:2])
    np.testing.assert_allclose(s, [across] * 4, rtol=1e-12, atol=0.0)


def test_a_restart_of_a_damaged_machine_under_a_heel_settles_its_faces() -> None:
    """A restart keeps a stretched bolt (1 µm of plastic elongation at j0) and zeroes the stick
    points its run left (`RESTUCK`, here 0.5 mm), then starts in the equilibrium under the
    heel: there every face slid, and each is settled on its bound as a new machine's is."""
    model = _block(5e8, (0.0, 0.0, 0.3))
    nf = len(model.scene.dofs)
    internal = model.nominal_state[2 * nf :].copy()
    for i, name in enumerate(model.state_names[2 * nf :]):
        internal[i] = {"j0.plastic_elongation": 1e-6}.get(name, 5e-4 if ".slip_" in name else 0)
    f = _heel(3.0)
    start = start_state(model, model.nominal_state, _heel(0.0), f, np.zeros(3), internal)
    assert start.note is None and start.state is not None
    d, s = _faces(model, start.state)
    spring = K_TAU * np.hypot(*(d[:, :2] - s).T)
    np.testing.assert_allclose(spring, _bound(d, F_V, MU), rtol=1e-9, atol=1e-9)


@pytest.mark.parametrize("heel", SLID)
def test_a_start_whose_faces_slid_rests_without_slip_events(heel: tuple) -> None:
    """Held at the start's heel for 40 ms, the block stays where it started and logs no event:
    its faces, settled on their bounds, move only by the rounding of a body at rest (some 1e-15
    m a sample), which is no slip (`bolted_joint.SLIP_FLOOR`; without it these heels logged
    hundreds of `joint_slipped` events at rest)."""
    cg, lateral, azimuth, preload, friction, bearing = heel
    model, f = _block(bearing, cg, preload, friction), _heel(lateral, azimuth)
    n = 40
    stamps = 1.0 + 1e-3 * np.arange(n)
    engine = TwinEngine(model)
    out = engine.run(SampleBatch(stamps, np.tile(f, (n, 1)), np.zeros((n, 3)), ["imu"] * n))
    assert engine.events == []
    for cols in (POSITION_COLS, ANGLES_COLS):  # m, rad
        moved = out.pose[:, cols] - out.pose[:1, cols]
        np.testing.assert_allclose(moved, 0.0, rtol=0.0, atol=1e-12)
