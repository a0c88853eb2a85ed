"""`integration.method: auto`: the method a scene takes, chosen at each start (the first and
every restart) and looked at again after mount events.

The rule is `integrate.methods.choose`: ρ·Δt, the spectral radius of the Jacobian (rad/s) times
the sample interval (s), against what an explicit method can step, and whether some mount's law
has pieces or the non-linear mounts are stiff (`Model.linear_stiffness`). At a start ρ is the
larger of the Jacobian's at the start state under the start sample's specific force and the
rate of the mounts' nominal tangents (`scene.statics`: a shear key, and a frictionless bolted
joint's shank, counts as bearing, however wide its clearance), so a light body beside a stiff
key starts on the method the key needs when it closes, not on the one its open clearance allows
(5 kg beside a 1e9 N/m key at 1 kHz: 9.8e-4 of the largest force by ros34pw2 from the start,
2.3e-2 by Dormand–Prince until the key had closed), and a start resting on a pressed snubber (a
heel, a restart under a sustained load) on the method the snubber needs: its contact logs no
event there, having touched before the first interval. ρ is taken again at the state of a
sample that logged an event that may stiffen the scene beyond that (a snubber touching: its
Hertzian contact has no tangent until it is pressed), at most once per REEXAMINE_S of record
time after a look or a start. The compiled loop ends a run at such a sample
(`engine.kernel.AT_EVENT`), so a live node pushing one sample at a time and a replay pushing
thousands make the same choices at the same samples.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from mount_twin.engine.batch import MountEvent
from mount_twin.errors import ModelError
from mount_twin.integrate.methods import choose
from mount_twin.model.assemble import Model
from mount_twin.model.stiffness import spectral_radius

REEXAMINE_S = 0.01
"""Record time (s) after a look at the scene before a mount event prompts the next: a joint
slipping in stick–slip logs events at the sample rate, and each look costs an eigenproblem."""


TANGENT_MARGIN = 1.05
"""The status names the keys when the tangents' rate is this much above the Jacobian's (on
linear mounts the two differ by the weight's geometric stiffness, a few 1e-3)."""


@dataclass(frozen=True)
class Choice:
    """A method for the scene (a name of `integrate.methods.METHODS`) and why, as the
    integration status says it."""

    method: str
    why: str

    @property
    def status(self) -> str:
        """e.g. `exprb32 (auto: ρ·Δt = 31.6)`."""
        return f"{self.method} (auto: {self.why})"


def at_start(
    model: Model, y: np.ndarray, specific_force: np.ndarray, interval_s: float, *, restart: bool
) -> Choice:
    """The choice at a start's first sample interval (s), from ρ at the start state y under the
    start sample's specific force (m/s², F) and the rate of the nominal tangents (rad/s,
    `Model.tangent_rate`): the larger of the two; `restart`: a restart's (the status says so).
    Where ρ cannot be taken at y (the α/γ/δ chart's edge), at the nominal start."""
    rho = radius(model, y, specific_force)
    if rho is None:
        gravity_up = np.array([0.0, 0.0, model.scene.input.g])
        rho = spectral_radius(model, model.nominal_state, gravity_up)
    rho_tangent = model.tangent_rate
    rho_dt = max(rho, rho_tangent) * interval_s
    bearing = rho_tangent > TANGENT_MARGIN * rho
    notes = [n for n, holds in (("keys bearing", bearing), ("at a restart", restart)) if holds]
    why = ", ".join([f"ρ·Δt = {rho_dt:.3g}", *notes])
    return Choice(choose(rho_dt, smooth=model.linear_stiffness), why)


def after_event(
    model: Model, y: np.ndarray, specific_force: np.ndarray, interval_s: float, event: MountEvent
) -> Choice | None:
    """The choice at state y under the sample's specific force (m/s², F) after `event`; None
    where ρ cannot be taken (the state at the α/γ/δ chart's edge): the method stays."""
    rho = radius(model, y, specific_force)
    if rho is None:
        return None
    rho_dt = rho * interval_s
    method = choose(rho_dt, smooth=model.linear_stiffness)
    return Choice(method, f"ρ·Δt = {rho_dt:.3g} after {event.event} of {event.mount}")


def radius(model: Model, y: np.ndarray, specific_force: np.ndarray) -> float | None:
    """ρ (rad/s, `model.stiffness.spectral_radius`) at state y under the specific force
    (m/s², F); None where it cannot be taken (y at the α/γ/δ chart's edge, or not finite)."""
    try:
        rho = spectral_radius(model, y, specific_force)
    except ModelError:
        return None
    return rho if math.isfinite(rho) else None
