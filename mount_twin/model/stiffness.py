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
from mount_twin.physics.jacobian import central_columns


def jacobian(model: Model, y: np.ndarray, u: np.ndarray, columns: int | None = None) -> np.ndarray:
    """∂(dy/dt)/∂y (n × n) of the whole state at y under the input vector u; with `columns`,
    only the derivatives by the first that many states (n × columns); central differences
    (`physics.jacobian`). Raises ModelError where y is at the α/γ/δ chart's edge."""
    n = model.n_state
    jac = np.empty((n, n if columns is None else columns))
    plus, minus = np.empty(n), np.empty(n)
    probe = np.array(y, dtype=float)
    if not central_columns(probe, 0.0, model.arrays, model.new_scratch(), u, plus, minus, jac):
        msg = f"{model.scene.source}: the state is at the α/γ/δ chart's edge"
        raise ModelError(msg)
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
