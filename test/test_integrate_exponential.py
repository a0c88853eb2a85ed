"""The exponential method (exprb32) and its matrix functions, against independent truth.

- φ_1, φ_2, φ_3 of hJ against scipy's matrix exponential of the augmented block matrix
  [[A, I, 0, 0], [0, 0, I, 0], [0, 0, 0, I], [0, 0, 0, 0]], whose first block row is
  [e^A, φ_1(A), φ_2(A), φ_3(A)] (Higham, Functions of Matrices, §10.7.4), and against the
  closed form of an undamped oscillator badly scaled as a mechanical Jacobian is;
- one step of a stiff oscillator (hω = 19) under a ramp against its closed form: exact, where
  the L-stable Rosenbrock damps and the explicit method is unstable;
- third order on a non-linear problem (a torque-free tumbling body: Euler's equations and the
  chart's kinematics) against an independent quaternion integration.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from physics_helpers import (
    build,
    chart_to_matrix_ref,
    free_body,
    inertia_tensor,
    kinematic_matrix_ref,
    rotation_angle_between,
    torque_free_reference,
)
from scipy.linalg import expm
from scipy.spatial.transform import Rotation
from test_integrate_methods import oscillator

from mount_twin.integrate import exprb32, methods, stepper
from mount_twin.integrate.phi import Blocks, phi_functions

EXPRB32 = methods.METHODS["exprb32"].id


def phi_reference(a: np.ndarray) -> list[np.ndarray]:
    """[φ_1(a), φ_2(a), φ_3(a)] from scipy's expm of the augmented block matrix."""
    n = a.shape[0]
    eye, zero = np.eye(n), np.zeros((n, n))
    big = np.block(
        [[a, eye, zero, zero], [zero, zero, eye, zero], [zero, zero, zero, eye], [zero] * 4]
    )
    e = expm(big)
    return [e[:n, k * n : (k + 1) * n] for k in (1, 2, 3)]


def phi_compiled(jac: np.ndarray, h: float) -> tuple[bool, list[np.ndarray]]:
    """The compiled φ functions of h·jac, in a work array laid out as exprb32's."""
    n = jac.shape[0]
    k = np.zeros((exprb32.work_rows(n), n))
    blocks = Blocks(exprb32.J0, exprb32.J0 + n, exprb32.J0 + 4 * n, exprb32.SCALE)
    k[blocks.j : blocks.j + n] = jac
    ok = phi_functions(k, n, h, blocks)
    return ok, [k[blocks.p1 + i * n : blocks.p1 + (i + 1) * n] for i in range(3)]


@pytest.mark.parametrize("norm", [0.3, 3.0, 30.0, 300.0])
def test_phi_functions_match_the_augmented_exponential(norm: float) -> None:
    rng = np.random.default_rng(7)
    jac = rng.normal(size=(7, 7)) * norm / math.sqrt(7)
    ok, got = phi_compiled(jac, 1.0)
    assert ok
    for mine, ref in zip(got, phi_reference(jac), strict=True):
        np.testing.assert_allclose(mine, ref, rtol=0, atol=1e-12 * np.abs(ref).max())


def test_phi_functions_of_zero_are_the_reciprocal_factorials() -> None:
    ok, got = phi_compiled(np.zeros((4, 4)), 1e-3)
    assert ok
    for k, mine in enumerate(got, start=1):
        np.testing.assert_array_equal(mine, np.eye(4) / math.factorial(k))


@pytest.mark.parametrize("omega", [2.0 * math.pi * 0.5, 2.0 * math.pi * 3100.0, 2.0e5])
def test_phi_functions_of_a_badly_scaled_oscillator_match_its_closed_form(omega: float) -> None:
    """J = [[0, 1], [−ω², 0]] (x in m, v in m/s: entries 1 beside 4e10), h = 1 ms: e^(sJ) =
    [[cos, sin/ω], [−ω sin, cos]](ωs), and φ_k(hJ) = h^−k ∫₀^h e^((h−s)J) s^(k−1)/(k−1)! ds in
    closed form through the scalar φ_k of ±iωh."""
    h = 1e-3
    jac = np.array([[0.0, 1.0], [-(omega**2), 0.0]])
    ok, got = phi_compiled(jac, h)
    assert ok
    z = 1j * omega * h
    # eigenvectors (1, ±iω): φ_k(hJ) = V diag(φ_k(z), φ_k(−z)) V⁻¹, φ_k(z) by its definition
    vecs = np.array([[1.0, 1.0], [1j * omega, -1j * omega]])
    inv = np.linalg.inv(vecs)
    for k, mine in enumerate(got, start=1):
        lam = []
        for zz in (z, -z):
            head = sum(zz**j / math.factorial(j) for j in range(k))
            series = sum(zz**j / math.factorial(j + k) for j in range(30))
            lam.append(series if abs(zz) < 1.0 else (np.exp(zz) - head) / zz**k)
        want = (vecs @ np.diag(lam) @ inv).real
        scale = np.abs(want).max(axis=1, keepdims=True)  # row scales differ by ω
        np.testing.assert_allclose(mine / scale, want / scale, rtol=0, atol=1e-11)


def test_a_non_finite_jacobian_gives_no_phi_functions() -> None:
    jac = np.eye(3)
    jac[1, 2] = math.nan
    ok, _ = phi_compiled(jac, 1e-3)
    assert not ok


def _one_step(name: str, model, y0: np.ndarray, u: np.ndarray, span: float):
    """One interval of `name` with loose tolerances (one step), from y0: the state after it,
    and the stepper (its work arrays as the step left them)."""
    st = stepper.new_stepper(name, model.n_state, 1e-2, 1.0, 1)
    y = y0.copy()
    args = (y, 0.0, span, st.settings, model.arrays, model.new_scratch(), u)
    status = stepper.advance(methods.METHODS[name].id, *args, st.work2d, st.work1d, st.result)
    assert status == methods.SUCCESS and st.result[1] == 1
    return y, st


def test_one_step_is_exact_on_a_stiff_driven_oscillator() -> None:
    """A 3.1 kHz oscillator (ω·h = 19.5 over the 1 ms step) from rest under a ramping specific
    force: the exponential step lands on the closed form to the finite-difference Jacobian's
    accuracy (a forward difference over √ε·|z| of a spring term that carries ulp(z): J to
    ~1e-9, the velocity to 1e-7 of its amplitude); the L-stable Rosenbrock, in the same single
    step, is off by more than 1e-3 (it damps the mode), the explicit method is unstable."""
    omega = 2.0 * math.pi * 3100.0
    model, y_eq, u = oscillator(omega)
    u = u.copy()
    ramp = 500.0  # ḟ_z, m/s³
    u[6] = ramp
    span = 1e-3
    response = ramp / omega**2 * (span - math.sin(omega * span) / omega)
    exact_z = y_eq[0] - response
    exact_v = -ramp / omega**2 * (1.0 - math.cos(omega * span))
    got = {name: _one_step(name, model, y_eq, u, span)[0] for name in methods.METHODS}
    y = got["exprb32"]
    assert abs(y[0] - exact_z) < 1e-8 * response
    assert abs(y[1] - exact_v) < 1e-7 * 2.0 * ramp / omega**2  # of the velocity's amplitude
    assert abs(got["ros34pw2"][0] - exact_z) > 1e-3 * response
    assert abs(got["dopri54"][0] - exact_z) > response


def test_a_step_keeps_the_half_steps_phi_functions() -> None:
    """The φ functions of half the step that an interval's single step keeps (for the error
    estimate's check in two steps) are φ_k((h/2)·J) of the Jacobian it held: the same bits as
    computing them at h/2, and the augmented exponential's values."""
    model, y_eq, u = oscillator(2.0 * math.pi * 3100.0)
    n, span = model.n_state, 1e-3
    k = _one_step("exprb32", model, y_eq, u, span)[1].work2d
    assert k[exprb32.HALF, 0] == 0.5 * span
    jac = k[exprb32.J0 : exprb32.J0 + n].copy()
    first = exprb32.J0 + exprb32.HALF_P1 * n
    kept = [k[first + i * n : first + (i + 1) * n] for i in range(3)]
    ok, direct = phi_compiled(jac, 0.5 * span)
    assert ok
    for mine, theirs, ref in zip(kept, direct, phi_reference(0.5 * span * jac), strict=True):
        np.testing.assert_array_equal(mine, theirs)
        np.testing.assert_allclose(mine, ref, rtol=0, atol=1e-12 * np.abs(ref).max())


INERTIA6 = [2.0, 3.0, 4.0, 0.15, -0.1, 0.2]
OMEGA0 = np.array([0.9, -0.7, 2.5])  # rad/s in B: a non-linear tumble (test_physics_torque_free)


def _tumble_error(intervals: int, duration: float = 0.4) -> float:
    """Attitude error (rad) after `duration` s of the torque-free tumble in `intervals` equal
    intervals, one exprb32 step each with a fresh Jacobian, against the quaternion reference."""
    model = build(free_body(INERTIA6, OMEGA0))
    y = np.concatenate([np.zeros(9), np.linalg.solve(kinematic_matrix_ref(0.0, 0.0), OMEGA0)])
    st = stepper.new_stepper("exprb32", model.n_state, 1.0, 1.0, 1)
    s, u = model.new_scratch(), np.zeros(13)
    times = np.linspace(0.0, duration, intervals + 1)
    for t0, t1 in itertools.pairwise(times):
        st.reset()  # a Jacobian at every step: the method's own order
        status = stepper.advance(
            EXPRB32, y, t0, t1, st.settings, model.arrays, s, u, st.work2d, st.work1d, st.result
        )
        assert status == methods.SUCCESS and st.result[1] == 1
    ref = torque_free_reference(inertia_tensor(*INERTIA6), OMEGA0, times[[0, -1]])
    want = Rotation.from_quat(ref.y[:4, -1]).as_matrix()
    return rotation_angle_between(chart_to_matrix_ref(*y[3:6]), want)


def test_the_method_is_third_order_on_a_non_linear_tumble() -> None:
    errors = [_tumble_error(n) for n in (8, 16, 32, 64)]
    slopes = np.diff(np.log2(errors))
    assert np.all(np.abs(slopes + 3.0) < 0.35), (errors, slopes)
