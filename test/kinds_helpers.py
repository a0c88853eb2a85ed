"""Shared drivers for the mount-kind tests (not a conftest: import explicitly).

A mount kind's law is a compiled function of local deflection, rate and internal states. These
helpers build one mount through the scene loader, call its law, monitor and update directly, and
drive its internal states along a prescribed deflection path, either node by node (quasi-static)
or with scipy's solve_ivp. They hold no physics of their own: the truths the tests compare with
(closed forms, separate integrations) are written in the test files.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from types import ModuleType
from typing import Any

import numpy as np
from physics_helpers import base_scene
from scipy.integrate import solve_ivp

from mount_twin.kinds import KINDS
from mount_twin.scene import scene_from_dict

Path = Callable[[float], tuple[np.ndarray, np.ndarray]]
"""t → (local deflection d (3,), rate v (3,)) of a prescribed motion."""


def kind_mount(
    kind: str,
    name: str = "m1",
    position: Sequence[float] = (0.0, 0.0, 0.0),
    rpy: Sequence[float] = (0.0, 0.0, 0.0),
    **keys: Any,
) -> dict[str, Any]:
    """One mount mapping of a non-linear kind, as a scene YAML file holds it."""
    return {
        "name": name,
        "kind": kind,
        "position": [float(v) for v in position],
        "orientation_rpy": [float(v) for v in rpy],
        **keys,
    }


def one_mount_scene(mount: dict[str, Any], dofs: Sequence[str] = ("z",)) -> dict[str, Any]:
    """A full scene mapping holding a single mount under a 100 kg body (for the law alone)."""
    return base_scene(100.0, [0.0, 0.0, 0.3], [2.0, 3.0, 4.0, 0.0, 0.0, 0.0], [mount], list(dofs))


@dataclass(frozen=True)
class Law:
    """One mount's compiled law with its parameter row; internal states start at offset 0."""

    module: ModuleType
    p: np.ndarray
    n_state: int

    def states(self, *values: float) -> np.ndarray:
        """An internal-state vector (zeros unless given; at least one entry for the calls)."""
        y = np.zeros(max(self.n_state, 1))
        y[: len(values)] = values
        return y

    def load(
        self,
        d: Sequence[float],
        v: Sequence[float] = (0.0, 0.0, 0.0),
        y: np.ndarray | None = None,
        phi: Sequence[float] = (0.0, 0.0, 0.0),
        w: Sequence[float] = (0.0, 0.0, 0.0),
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(force on the body, couple on the body, internal-state rates) in local axes."""
        y = self.states() if y is None else np.asarray(y, dtype=float)
        f, c = np.full(3, np.nan), np.full(3, np.nan)
        dydt = np.full(y.shape[0], np.nan)
        self.module.load(self.p, y, 0, _vec(d), _vec(v), _vec(phi), _vec(w), dydt, f, c)
        return f, c, dydt[: self.n_state]

    def monitor(
        self,
        d: Sequence[float],
        v: Sequence[float] = (0.0, 0.0, 0.0),
        y: np.ndarray | None = None,
        y0: np.ndarray | None = None,
    ) -> tuple[float, np.ndarray]:
        """(utilisation, event functions in the order of the module's EVENTS); y0: the
        previous sample's states, on which trial functions are judged (default: y, no trial
        state)."""
        y = self.states() if y is None else np.asarray(y, dtype=float)
        y0 = y if y0 is None else np.asarray(y0, dtype=float)
        g = np.full(len(self.module.EVENTS), np.nan)
        util = self.module.monitor(self.p, y, y0, 0, _vec(d), _vec(v), g)
        return float(util), g

    def update(self, y: np.ndarray, d: Sequence[float]) -> None:
        """The discrete switches between samples, in place on y."""
        self.module.update(self.p, y, 0, _vec(d))


def _vec(a: Sequence[float]) -> np.ndarray:
    return np.asarray(a, dtype=float).reshape(3)


def law_of(mount: dict[str, Any]) -> Law:
    """The law of a mount mapping, read and packed by the package's loader and the kind."""
    scene = scene_from_dict(one_mount_scene(mount), "test.yaml")
    built = scene.mounts[0]
    module = KINDS[built.kind]
    return Law(module, module.pack(built), len(module.state_names(built)))


def quasi_static(
    law: Law, path: np.ndarray, y0: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Drive a law's internal states along a piecewise-linear deflection path (N, 3) of nodes.

    Each segment is one unit of time: the states advance by the law's rate at the segment's
    midpoint deflection (exact for rate-independent laws whose flow is linear in the rate, as
    long as switches fall on nodes). At every node `update` runs, as the engine does between
    samples. Returns the force on the body (N, 3) at rest at each node and the states (N, n).
    """
    y = law.states() if y0 is None else np.array(y0, dtype=float)
    forces = np.zeros((path.shape[0], 3))
    states = np.zeros((path.shape[0], y.shape[0]))
    law.update(y, path[0])
    forces[0], states[0] = law.load(path[0], y=y)[0], y
    for k in range(1, path.shape[0]):
        step = path[k] - path[k - 1]
        rate = law.load(0.5 * (path[k] + path[k - 1]), step, y)[2]
        y[: law.n_state] += rate
        law.update(y, path[k])
        forces[k], states[k] = law.load(path[k], y=y)[0], y
    return forces, states


def nodes(*legs: np.ndarray) -> np.ndarray:
    """Concatenate path legs, dropping each leg's first node when it repeats the previous end."""
    out = [np.asarray(legs[0], dtype=float)]
    for raw in legs[1:]:
        part = np.asarray(raw, dtype=float)
        out.append(part[1:] if np.array_equal(part[0], out[-1][-1]) else part)
    return np.concatenate(out)


def leg(start: float, stop: float, n: int, *kinks: float) -> np.ndarray:
    """Monotone scalar leg from start to stop: n even steps plus the given kink points inside."""
    pts = np.concatenate([np.linspace(start, stop, n + 1), kinks])
    pts = np.unique(pts[(pts - start) * (pts - stop) <= 0.0])
    return pts if stop > start else pts[::-1]


def along(axis: int, values: np.ndarray) -> np.ndarray:
    """Deflection path (N, 3) with the given values along one local axis."""
    out = np.zeros((values.shape[0], 3))
    out[:, axis] = values
    return out


@dataclass(frozen=True)
class Driven:
    """A law driven along a path by solve_ivp: times, internal states (n, N) and the energy
    dissipated so far, −∫ f·ḋ dt (N,), f the force on the body."""

    t: np.ndarray
    states: np.ndarray
    dissipated: np.ndarray


def drive(
    law: Law,
    path: Path,
    t_span: tuple[float, float],
    y0: np.ndarray | None = None,
    t_eval: np.ndarray | None = None,
    rtol: float = 1e-11,
    atol: float = 1e-15,
) -> Driven:
    """Integrate a law's internal states with its own rates along a prescribed motion, together
    with the work the body does on the mount (dissipated + stored)."""
    y_law = law.states() if y0 is None else np.array(y0, dtype=float)
    n = law.n_state

    def rates(t: float, x: np.ndarray) -> np.ndarray:
        d, v = path(t)
        y_law[:n] = x[:n]
        f, _, dydt = law.load(d, v, y_law)
        return np.concatenate([dydt, [-float(f @ v)]])

    x0 = np.concatenate([y_law[:n], [0.0]])
    sol = solve_ivp(
        rates, t_span, x0, t_eval=t_eval, rtol=rtol, atol=atol, method="DOP853", dense_output=False
    )
    assert sol.success, sol.message
    return Driven(sol.t, sol.y[:n], sol.y[n])


def sine_path(amplitude: Sequence[float], omega: float, offset: Sequence[float] = (0, 0, 0)):
    """d(t) = offset + amplitude·sin(ωt) (per local axis) and its rate."""
    amp, off = _vec(amplitude), _vec(offset)

    def path(t: float) -> tuple[np.ndarray, np.ndarray]:
        return off + amp * np.sin(omega * t), amp * omega * np.cos(omega * t)

    return path
