"""The linearised model where it stands: its Jacobian and how stiff it is.

The Jacobian ∂f/∂y of the compiled right-hand side at a state and input, by central
differences, and the largest |λ| of its eigenvalues (rad/s): the fastest mode's rate.
`analysis.modes` builds its stiffness and damping from the Jacobian;
`integrate.methods.choose` compares ρ·Δt with an explicit method's stability.
"""

from __future__ import annotations

import numpy as np

from mount_twin.errors import ModelError
from mount_twin.model.assemble import Model, gravity_input
from mount_twin.physics.dynamics import OK, rhs

STEP = 1.0e-7
"""Central-difference step, relative to max(1, |y_i|)."""


def jacobian(model: Model, y: np.ndarray, u: np.ndarray, columns: int | None = None) -> np.ndarray:
    """∂(dy/dt)/∂y (n × n) of the whole state at y under the input vector u; with `columns`,
    only the derivatives by the first that many states (n × columns). Raises ModelError where
    y is at the α/γ/δ chart's edge."""
    n = model.n_state
    scratch = model.new_scratch()
    jac = np.empty((n, n if columns is None else columns))
    plus, minus = np.empty(n), np.empty(n)
    for k in range(jac.shape[1]):
        h = STEP * max(1.0, abs(y[k]))
        y_plus, y_minus = y.copy(), y.copy()
        y_plus[k] += h
        y_minus[k] -= h
        for probe, out in ((y_plus, plus), (y_minus, minus)):
            if rhs(0.0, probe, model.arrays, scratch, u, out) != OK:
                msg = f"{model.scene.source}: the state is at the α/γ/δ chart's edge"
                raise ModelError(msg)
        jac[:, k] = (plus - minus) / (y_plus[k] - y_minus[k])
    return jac


def spectral_radius(model: Model, y: np.ndarray, specific_force: np.ndarray) -> float:
    """Largest |λ| of the body's block of the Jacobian (its positions and rates; the mounts'
    internal states held) at y under a constant specific force (m/s², F), foundation at rest
    otherwise (rad/s): the rate of the body's fastest mode on its mounts there.

    The mounts' internal states are left out: their rates switch where the mounts do (a face
    between sticking and sliding, a bolt between elastic and flowing), and a difference taken
    across such a switch reads as a rate of 1e5–1e6 rad/s that no mode has; the mount forces,
    hence the body's block, are continuous there."""
    arrays = model.arrays
    body = 2 * (arrays.free_trans.shape[0] + arrays.free_rot.shape[0])
    jac = jacobian(model, y, gravity_input(0.0, specific_force), columns=body)
    return float(np.abs(np.linalg.eigvals(jac[:body, :body])).max())
