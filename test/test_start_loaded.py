"""A new machine on hysteretic (Bouc–Wen) mounts starts as one set down slowly on them.

At rest every Bouc–Wen state z is an equilibrium of its own, so the start must say where z
lies: each axis loaded monotonically from (x, z) = (0, 0) sits on its virgin curve
dz/dx = A − (β + γ)·|z|ⁿ. Truths written here, independently of the package:
- the curve's closed forms (n = 1: z = z_u·(1 − e^(−(β+γ)x)); n = 2: z = z_u·tanh(√(A(β+γ))·x))
  and, for other n, solve_ivp of dz/dx at rtol 1e-13;
- the equilibrium of a 6-DOF body on four inclined, off-centre mounts solved here by scipy's
  least squares on this file's own statics (the mounts' local deflections from the pose through
  the chart of physics notes §2, the force law k₁x + k₃x³ and (1 − a)·k₀·z, moments about the CG);
- the rating warnings' figures: the one-DOF start's sag from the n = 1 closed form (brentq on
  the weight carried), and a linear spring's load k·|Z| beside it.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import yaml
from kinds_helpers import kind_mount
from physics_helpers import G, base_scene, build, chart_to_matrix_ref, mount, rpy
from scipy.integrate import solve_ivp
from scipy.optimize import brentq, least_squares

from mount_twin.engine.batch import SampleBatch
from mount_twin.engine.engine import TwinEngine
from mount_twin.model.assemble import assemble
from mount_twin.model.loading import virgin_z
from mount_twin.scene.loader import scene_from_dict
from mount_twin.scene.params import as_params, effective_parameters

MASS, CG_Z = 100.0, 0.3  # kg, m
K0 = 1.0e5  # N/m
RATIO = 0.3


def curve_ivp(x: float, a: float, c: float, n: float) -> float:
    """z after monotone loading to x (m), integrating dz/dx = A − c·|z|ⁿ."""
    if x == 0.0:
        return 0.0
    sol = solve_ivp(
        lambda _s, z: [a - c * abs(z[0]) ** n],
        (0.0, abs(x)),
        [0.0],
        method="DOP853",
        rtol=1e-13,
        atol=1e-16 * a * abs(x),  # z ≈ A·x where x is small: relative to it
    )
    return math.copysign(float(sol.y[0, -1]), x)


def curve_closed(x: float, a: float, c: float, n: int) -> float:
    z_u = (a / c) ** (1.0 / n)
    if n == 1:
        return math.copysign(z_u * -math.expm1(-c * abs(x)), x)
    return z_u * math.tanh(math.sqrt(a * c) * x)


@pytest.mark.parametrize(
    ("a", "c", "n"),
    [
        (1.0, 200.0, 1.0),
        (1.0, 4.0e4, 2.0),
        (0.8, 3.0e3, 1.5),
        (1.3, 50.0, 3.0),
        (1.0, 1.0e6, 10.0),  # a sharp knee
        (1.0, 1.0e-3, 1.0),  # z_u = 1000 m: linear wherever a mount deflects
    ],
)
def test_virgin_curve_matches_its_closed_form_and_an_integration_of_its_slope(a, c, n):
    z_u = (a / c) ** (1.0 / n)
    xs = np.array([0.0, 1e-9, 1e-6, 1e-4, 1e-3, 5e-3, 0.02, 0.1, 1.0]) * z_u / a * 50.0
    xs = np.concatenate([xs, [1e-12, 1e-6, 1e-3]])  # mounts' deflections, m, whatever z_u
    xs = np.concatenate([xs, -xs[1:]])
    got = virgin_z(np.full(xs.shape, a), np.full(xs.shape, c), np.full(xs.shape, n), xs)
    for x, z in zip(xs, got, strict=True):
        truth = curve_closed(x, a, c, int(n)) if n in (1.0, 2.0) else curve_ivp(x, a, c, n)
        assert z == pytest.approx(truth, rel=1e-11, abs=0.0), x  # relative to z, not z_u
        assert abs(z) <= z_u  # never past its asymptote


def start_sag(c: float, n: int, k_linear: float = 0.0) -> float:
    """Z (m, < 0) of MASS at rest on one vertical mount of this file (A = 1, β + γ = c),
    beside a linear spring k_linear (N/m), the z state on its loading curve."""

    def weight_carried(x: float) -> float:
        spring = (k_linear + RATIO * K0) * x
        return spring + (1.0 - RATIO) * K0 * curve_closed(x, 1.0, c, n) + MASS * G

    return brentq(weight_carried, -0.1, 0.0, xtol=1e-17, rtol=1e-15)


def hysteretic(name: str, position, rpy_=(0.0, 0.0, 0.0), k3: float = 0.0, bw=None) -> dict:
    bw = bw or {"A": 1.0, "beta": 120.0, "gamma": 80.0, "n": 1.0}
    return kind_mount(
        "elastomer",
        name,
        position=position,
        rpy=rpy_,
        stiffness_linear=[K0, K0, K0],
        stiffness_cubic=[k3, k3, k3],
        damping=[300.0, 300.0, 300.0],
        hysteresis={"ratio": RATIO, **bw, "axes": ["x", "y", "z"]},
    )


def still(model, n: int = 200, rate: float = 1000.0):
    """A run of the twin on a deck at rest under gravity; returns (engine, outputs)."""
    t = np.arange(n) / rate
    f = np.zeros((n, 3))
    f[:, 2] = G
    engine = TwinEngine(model)
    return engine, engine.run(SampleBatch(t, f, np.zeros((n, 3)), ["imu"] * n))


@pytest.mark.parametrize("n", [1, 2])
def test_one_dof_start_rests_where_the_loading_curve_carries_the_weight(n):
    """100 kg on k₀ = 1e5 N/m, a = 0.3: the start sags as the tangent k₀ predicts near rest
    (9.81 mm with z linear), not the 32.7 mm of the elastic share alone."""
    bw = {
        1: {"A": 1.0, "beta": 60.0, "gamma": 40.0, "n": 1.0},
        2: {"A": 1.0, "beta": 2e3, "gamma": 1e3, "n": 2.0},
    }[n]
    c = bw["beta"] + bw["gamma"]
    model = build(
        base_scene(
            MASS,
            [0.0, 0.0, CG_Z],
            [5.0, 6.0, 7.0, 0, 0, 0],
            [hysteretic("r", [0, 0, 0], bw=bw)],
            ["z"],
        )
    )

    x0 = start_sag(c, n)
    engine, out = still(model)
    assert out.pose[0, 2] - CG_Z == pytest.approx(x0, rel=1e-10)
    z_state = dict(zip(model.state_names, engine.state, strict=True))["r.z_z"]
    assert z_state == pytest.approx(curve_closed(x0, 1.0, c, n), rel=1e-10)
    # at rest it stays there, its state with it
    assert np.ptp(out.pose[:, 2]) <= 1e-12 * abs(x0)
    # softened by the curve, but far from the elastic share alone carrying it (32.7 mm)
    assert MASS * G / K0 < -x0 < 0.5 * MASS * G / (RATIO * K0)
    # the published force carries the weight
    assert out.wrenches[-1, 0, 2] == pytest.approx(MASS * G, rel=1e-9)


MOUNTS = (  # name, position (m, F), orientation rpy (rad)
    ("fl", (0.4, 0.3, 0.0), (-0.35, 0.0, 0.0)),
    ("fr", (0.4, -0.3, 0.0), (0.35, 0.0, 0.0)),
    ("rl", (-0.5, 0.25, 0.05), (-0.2, 0.1, 0.3)),
    ("rr", (-0.5, -0.25, 0.0), (0.2, 0.0, -0.1)),
)
CG6 = np.array([0.07, -0.03, 0.35])
K3 = 4.0e8
BW6 = {"A": 1.0, "beta": 150.0, "gamma": 50.0, "n": 1.0}


def reference_equilibrium() -> tuple[np.ndarray, np.ndarray]:
    """Pose (X, Y, Z, α, γ, δ) and each mount's local deflections (4, 3) at rest under gravity,
    the hysteretic states on their loading curves: this file's own statics."""
    c = BW6["beta"] + BW6["gamma"]
    arms = [np.array(p) - CG6 for _, p, _ in MOUNTS]
    axes = [rpy(*r) for _, _, r in MOUNTS]

    def deflections(q: np.ndarray) -> list[np.ndarray]:
        rot = chart_to_matrix_ref(*q[3:])
        return [ax.T @ (q[:3] + (rot - np.eye(3)) @ p) for p, ax in zip(arms, axes, strict=True)]

    def residual(q: np.ndarray) -> np.ndarray:
        rot = chart_to_matrix_ref(*q[3:])
        force, moment = np.array([0.0, 0.0, -MASS * G]), np.zeros(3)
        for p, ax, d in zip(arms, axes, deflections(q), strict=True):
            z = np.array([curve_closed(x, BW6["A"], c, 1) for x in d])
            local = -(RATIO * (K0 * d + K3 * d**3) + (1.0 - RATIO) * K0 * z)
            f = ax @ local
            force += f
            moment += np.cross(rot @ p, f)
        return np.concatenate([force / (MASS * G), moment / (MASS * G)])

    sol = least_squares(residual, np.zeros(6), xtol=1e-15, ftol=1e-15, gtol=1e-15)
    assert np.max(np.abs(sol.fun)) < 1e-13
    return sol.x, np.array(deflections(sol.x))


def test_six_dof_start_on_inclined_mounts_is_the_equilibrium_with_every_axis_on_its_curve():
    mounts = [hysteretic(name, p, r, k3=K3, bw=BW6) for name, p, r in MOUNTS]
    model = build(base_scene(MASS, list(CG6), [8.0, 10.0, 12.0, 0.3, 0.0, 0.0], mounts))
    engine, out = still(model, n=100)
    q_ref, d_ref = reference_equilibrium()
    sag = abs(q_ref[2])
    assert sag > 2e-3
    assert np.allclose(out.pose[0, :3] - CG6, q_ref[:3], rtol=0, atol=1e-10 * sag)
    assert np.allclose(out.pose[0, 7:10], q_ref[3:], rtol=0, atol=1e-10)
    c = BW6["beta"] + BW6["gamma"]
    z_ref = np.array([[curve_closed(x, BW6["A"], c, 1) for x in d] for d in d_ref])
    states = dict(zip(model.state_names, engine.state, strict=True))
    z_twin = np.array([[states[f"{name}.z_{a}"] for a in "xyz"] for name, _, _ in MOUNTS])
    assert np.allclose(z_twin, z_ref, rtol=0, atol=1e-9 * np.abs(z_ref).max())
    # every axis of every mount is loaded (the curve is exercised off its linear start)
    assert np.abs(d_ref).min() > 1e-5
    # and the body stays at rest there
    assert np.ptp(out.pose[:, :3], axis=0).max() <= 1e-11 * sag


# ----------------------------------------------------------------- ratings judged at the start
BW_SOFT = {"A": 1.0, "beta": 120.0, "gamma": 80.0, "n": 1.0}  # β + γ = 200, as reported
C_SOFT = 200.0
RATED = 0.012  # m


def rated_scene(rated_z: float, hysteresis: bool = True, **sections) -> dict:
    """MASS on one vertical elastomer (this file's, BW_SOFT) rated `rated_z` (m) along its z,
    z the only free DOF; `sections` replace the scene's own."""
    rubber = hysteretic("r", [0.0, 0.0, 0.0], bw=BW_SOFT)
    rubber["rated_deflection"] = [0.0, 0.0, rated_z]
    if not hysteresis:
        del rubber["hysteresis"]
    data = base_scene(MASS, [0.0, 0.0, CG_Z], [5.0, 6.0, 7.0, 0, 0, 0], [rubber], ["z"])
    return {**data, **sections}


def rating_warnings(scene) -> list:
    return [w for w in scene.warnings if ".rated_" in w.path]


def test_a_start_past_its_rated_deflection_on_the_loading_curve_is_warned_of_at_load(
    tmp_path, capsys
):
    """As reported: the tangent at zero load (k₀ = 1e5 N/m) sags 9.81 mm, within the rated
    12 mm, and nothing was said at load; the start the twin uses, on the loading curve, sags
    21.2 mm (closed form), 1.77 times the rating, and every report then said ERROR. The
    warning gives the start's figures, by every path a scene's warnings take: the assembled
    model's scene, the command line's stderr at load, the node's stream."""
    from mount_twin.cli import main
    from mount_twin.stream import TwinStream

    x0 = start_sag(C_SOFT, 1)
    assert MASS * G / K0 < RATED < 1.5 * RATED < -x0
    said = f"{-x0:.4g} m along local z, is {-x0 / RATED:.3g} times the rated 0.012 m"
    scene = scene_from_dict(rated_scene(RATED), "<rated>")
    assert rating_warnings(scene) == []  # the loader leaves it to the start
    model = assemble(scene)
    (warning,) = rating_warnings(model.scene)
    assert warning.path == "mounts[0].rated_deflection"
    assert "static deflection at the start" in warning.message
    assert said in warning.message
    assert model.scene.warnings == (*scene.warnings, warning)
    # assembled again (the command line's scene, then the engine's), said once
    assert assemble(model.scene).scene.warnings == model.scene.warnings
    assert TwinStream(scene).scene.warnings == model.scene.warnings

    path = tmp_path / "rated.scene.yaml"
    path.write_text(yaml.safe_dump(rated_scene(RATED)))
    assert main(["info", str(path)]) == 0
    (line,) = [s for s in capsys.readouterr().err.splitlines() if "rated_deflection" in s]
    assert line.startswith(f"mount-twin: warning: {path}: mounts[0].rated_deflection: ")
    assert said in line


def test_a_linear_mount_beside_hysteretic_ones_is_judged_at_the_start_by_its_parameter_path():
    """A linear spring beside the hysteretic mount carries k·|Z| at the start (closed form),
    past a rated load the tangent statics keep it within; a parameter set names it by its
    parameter (mounts.<name>)."""
    k_lin = 5.0e4
    x0 = start_sag(C_SOFT, 1, k_linear=k_lin)
    tangent_load = k_lin * MASS * G / (k_lin + K0)
    rated_load = 1.2 * tangent_load
    assert k_lin * -x0 > 1.1 * rated_load
    data = rated_scene(0.0)
    spring = mount("lin", [0.0, 0.0, 0.0], [k_lin] * 3 + [0.0] * 3)
    data["mounts"].append({**spring, "rated_load": [0.0, 0.0, rated_load]})
    scene = effective_parameters(as_params(data), "params").scene
    assert rating_warnings(scene) == []
    (warning,) = rating_warnings(assemble(scene).scene)
    assert warning.path == "mounts.lin.rated_load"
    ratio = k_lin * -x0 / rated_load
    assert f"{k_lin * -x0:.4g} N along local z, is {ratio:.3g} times the rated" in warning.message


@pytest.mark.parametrize("hysteresis", [True, False])
def test_a_rating_is_warned_of_once_by_the_statics_that_give_the_start(hysteresis):
    """Rated 8 mm, past the tangent's 9.81 mm sag too: a hysteretic start at equilibrium is
    warned of once, with the loading curve's sag; a mount without hysteresis keeps the
    loader's tangent statics, and the assembly adds none."""
    rated = 0.008
    data = rated_scene(rated, hysteresis, initial_state={"mode": "equilibrium"})
    scene = scene_from_dict(data, "<rated>")
    model = assemble(scene)
    (warning,) = rating_warnings(model.scene)
    sag = -start_sag(C_SOFT, 1) if hysteresis else MASS * G / K0
    where = "at the start" if hysteresis else "under the weight"
    assert f"static deflection {where}" in warning.message
    assert f"{sag:.4g} m along local z, is {sag / rated:.3g} times" in warning.message
    assert rating_warnings(scene) == ([] if hysteresis else [warning])


def test_a_given_start_on_a_hysteretic_mount_is_judged_at_its_pose():
    """A given start is its pose, its Bouc–Wen state at 0: given at the reference (z = 0) the
    mount starts unstressed, and nothing is said of a rated 8 mm that the tangent's 9.81 mm sag
    under the weight passes; given at the loading curve's sag, its deflection there is warned
    of once, at the given start (no loading curve)."""
    rated = 0.008
    at_rest = {"mode": "given", "pose": [0.0] * 6, "velocity": [0.0] * 6}
    scene = scene_from_dict(rated_scene(rated, initial_state=at_rest), "<rated>")
    assert rating_warnings(assemble(scene).scene) == []
    sag = -start_sag(C_SOFT, 1)
    down = {**at_rest, "pose": [0.0, 0.0, -sag, 0.0, 0.0, 0.0]}
    model = assemble(scene_from_dict(rated_scene(rated, initial_state=down), "<rated>"))
    (warning,) = rating_warnings(model.scene)
    assert warning.message.startswith("the deflection at the given start (initial_state.pose")
    assert f"{sag:.4g} m along local z, is {sag / rated:.3g} times" in warning.message
    assert "loading curve" not in warning.message
