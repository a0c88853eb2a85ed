"""Modal analysis against an independently assembled eigenproblem, textbook closed forms, and
its own sums; the command on the bundled scenes."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from io_helpers import CONFIG
from physics_helpers import base_scene, mount, mount_frames
from scipy.linalg import eigh

from mount_twin.analysis.modes import modes
from mount_twin.cli import main
from mount_twin.scene.loader import scene_from_dict

INERTIA = [180.0, 260.0, 300.0, 12.0, -20.0, 6.0]
LAYOUT = [
    mount("a", (0.7, 0.45, -0.3), (4e5, 5e5, 1.3e6, 300, 200, 100), rpy_=(0.3, 0.0, 0.2)),
    mount("b", (0.6, -0.5, -0.35), (6e5, 3e5, 1.1e6, 0, 0, 0), rpy_=(-0.4, 0.1, 0.0)),
    mount("c", (-0.8, 0.4, -0.25), (5e5, 5e5, 0.9e6, 0, 0, 0), rpy_=(0.0, -0.3, 0.5)),
    mount("d", (-0.7, -0.45, -0.3), (3e5, 6e5, 1.4e6, 0, 0, 0)),
]


def _skew(p: np.ndarray) -> np.ndarray:
    return np.array([[0, -p[2], p[1]], [p[2], 0, -p[0]], [-p[1], p[0], 0]])


def test_frequencies_without_preload_equal_an_independent_6x6_eigenproblem() -> None:
    """K about the CG from each mount's K_t, K_r at its lever arm p (force −K_t·d at
    d = t + φ × p, moment p × f − K_r·φ), M = diag(m, I): K·φ = ω²·M·φ."""
    data = base_scene(900.0, [0.05, 0.02, 0.0], INERTIA, LAYOUT)
    k = np.zeros((6, 6))
    for fr in mount_frames(data):
        p, kt = fr["p"], fr["kt"]
        k[:3, :3] += kt
        k[:3, 3:] += -kt @ _skew(p)
        k[3:, :3] += _skew(p) @ kt
        k[3:, 3:] += -_skew(p) @ kt @ _skew(p) + fr["kr"]
    ixx, iyy, izz, ixy, ixz, iyz = INERTIA
    m = np.zeros((6, 6))
    m[:3, :3] = 900.0 * np.eye(3)
    m[3:, 3:] = [[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]]
    want = np.sqrt(eigh(k, m, eigvals_only=True)) / (2 * math.pi)
    got = [md.frequency_hz for md in modes(scene_from_dict(data, "indep"), geometric=False).modes]
    np.testing.assert_allclose(got, want, rtol=1e-6)


def test_bounce_pitch_of_a_two_spring_body_is_the_textbook_closed_form() -> None:
    """Thomson & Dahleh, Theory of Vibration, the automobile in bounce and pitch: mass m, pitch
    inertia J, springs k1 at a ahead of the CG and k2 at b behind it:
    m·J·ω⁴ − (m(k1a² + k2b²) + J(k1 + k2))·ω² + (k1 + k2)(k1a² + k2b²) − (k1a − k2b)² = 0."""
    m_, j, k1, k2, a, b = 1460.0, 2460.0, 3.5e4, 3.8e4, 1.0, 1.5
    springs = [
        mount("front", (a, 0.0, 0.0), (0, 0, k1, 0, 0, 0)),
        mount("rear", (-b, 0.0, 0.0), (0, 0, k2, 0, 0, 0)),
    ]
    data = base_scene(
        m_, [0.0, 0.0, 0.0], [500.0, j, 2000.0, 0, 0, 0], springs, dofs=["z", "gamma"]
    )
    p2 = m_ * (k1 * a * a + k2 * b * b) + j * (k1 + k2)
    p0 = (k1 + k2) * (k1 * a * a + k2 * b * b) - (k1 * a - k2 * b) ** 2
    w2 = np.roots([m_ * j, -p2, p0])
    want = np.sort(np.sqrt(w2.real)) / (2 * math.pi)
    got = [md.frequency_hz for md in modes(scene_from_dict(data, "car"), geometric=False).modes]
    np.testing.assert_allclose(got, want, rtol=1e-6)


def test_mass_on_two_inclined_springs_is_the_verification_case() -> None:
    """A mass on two axial springs at ±θ from vertical in the y–z plane (an FE code's
    verification case): K_yy = 2k·sin²θ, K_zz = 2k·cos²θ, so f_y = √(2k sin²θ/m)/2π and
    f_z = √(2k cos²θ/m)/2π."""
    m_, k, th = 10.0, 1.0e5, math.radians(30.0)
    springs = [
        mount(n, (0.0, 0.0, 0.0), (0, 0, k, 0, 0, 0), rpy_=(s * th, 0, 0))
        for n, s in (("l", 1), ("r", -1))
    ]
    data = base_scene(m_, [0.0, 0.0, 0.0], [1.0, 1.0, 1.0, 0, 0, 0], springs, dofs=["y", "z"])
    got = [md.frequency_hz for md in modes(scene_from_dict(data, "v"), geometric=False).modes]
    want = sorted(
        math.sqrt(2 * k * c / m_) / (2 * math.pi) for c in (math.sin(th) ** 2, math.cos(th) ** 2)
    )
    np.testing.assert_allclose(got, want, rtol=1e-6)


def test_energy_fractions_and_effective_masses_sum_as_they_must() -> None:
    data = base_scene(900.0, [0.05, 0.02, 0.0], INERTIA, LAYOUT)
    result = modes(scene_from_dict(data, "sums"))
    for md in result.modes:
        assert sum(md.energy_fraction.values()) == pytest.approx(1.0, abs=1e-9)
    for axis in "xyz":
        assert sum(md.effective_mass_kg[axis] for md in result.modes) == pytest.approx(
            900.0, rel=1e-9
        )
    # About the axes of F through the CG they add up to the body's inertia about those axes at
    # the equilibrium pose (M's rotation block, pitch sign turned), which is I turned by the
    # equilibrium's small tilt.
    s = np.diag([1.0, -1.0, 1.0])
    about_f = s @ result.mass_matrix[3:, 3:] @ s
    for j, axis in enumerate("xyz"):
        total = sum(md.effective_inertia_kg_m2[axis] for md in result.modes)
        assert total == pytest.approx(about_f[j, j], rel=1e-9)
        assert total == pytest.approx(INERTIA[j], rel=1e-4)


def test_the_command_on_the_bundled_scenes(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["modes", str(CONFIG / "pump_8_mounts.scene.yaml")]) == 0
    out = capsys.readouterr().out
    assert "elastic centre" in out and "static mount loads" in out
    assert main(["modes", str(CONFIG / "genset_bolted_keyed.scene.yaml"), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    freqs = [md["frequency_hz"] for md in doc["modes"]]
    assert len(freqs) == 6 and freqs == sorted(freqs) and freqs[0] > 50.0  # bolted: stiff
    total = sum(m["force_n"][2] for m in doc["mounts"])
    assert total == pytest.approx(3000.0 * 9.80665, rel=1e-6)  # the mounts carry the weight
