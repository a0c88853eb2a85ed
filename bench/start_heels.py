"""Starts under random off-centre heels onto bolted joints whose faces slide into bearing.

A block of 1000 kg on four bolted joints (bolts along z of F at (±0.4, ±0.3, 0) m; the
joints of `test/test_equilibrium_bearing.py`), its CG up to 0.5 m up and 0.2 m off centre,
heeled 2.5–7 m/s² toward a random azimuth, preload 1 or 5 kN, friction 0.1 or 0.2: past the
friction bound the faces slide at μ·F_K until the shanks bear past the 1 mm hole clearance.
The same seeded heels for each bearing stiffness (N/m). Printed per stiffness: the starts
found and not found (with the seeds of those not found), the worst imbalance of a found
start (|Σ mount forces − m·f| in N and |Σ moments about the CG| in N·m, from the mounts'
wrenches, not from the solver's residual), and the mean time of a start.

    python3 bench/start_heels.py [--heels 120] [--seed 0] [--bearing 1e8 5e8 2e9 1e10]
"""

from __future__ import annotations

import argparse
import math
import time
from dataclasses import dataclass

import numpy as np

from mount_twin.errors import ModelError
from mount_twin.model.assemble import Model, assemble, initial_state
from mount_twin.physics.dynamics import evaluate
from mount_twin.scene.loader import scene_from_dict

G = 9.80665
"""m/s²: the magnitude of every heeled specific force."""
MASS = 1000.0
"""kg."""
CORNERS = ((0.4, 0.3), (-0.4, 0.3), (-0.4, -0.3), (0.4, -0.3))
"""m: the joints in the plane z = 0 of F."""
JOINT = {
    "bolt_stiffness": 7e8,
    "clamp_stiffness": 3.5e9,
    "yield_force": 1.5e5,
    "ultimate_force": 2e5,
    "shear_stiffness": 1e9,
    "hole_clearance": 1e-3,
}
"""Each joint's parameters besides preload, friction and bearing stiffness (N/m, N, m)."""


@dataclass(frozen=True)
class Heel:
    """One random heel: CG (m, F), lateral specific force (m/s²) toward azimuth (rad, about
    z of F), preload (N), friction coefficient."""

    cg: tuple[float, float, float]
    lateral: float
    azimuth: float
    preload: float
    friction: float

    def specific_force(self) -> np.ndarray:
        """m/s², F: magnitude G, `lateral` of it horizontal toward `azimuth`."""
        c, s = math.cos(self.azimuth), math.sin(self.azimuth)
        return np.array([self.lateral * c, self.lateral * s, math.sqrt(G**2 - self.lateral**2)])


def heels(count: int, seed: int) -> list[Heel]:
    """`count` heels drawn from `seed`: CG x, y uniform in ±0.2 m, z in 0–0.5 m; lateral
    2.5–7 m/s²; azimuth 0–2π; preload 1 or 5 kN; friction 0.1 or 0.2."""
    rng = np.random.default_rng(seed)
    drawn = []
    for _ in range(count):
        cg = (rng.uniform(-0.2, 0.2), rng.uniform(-0.2, 0.2), rng.uniform(0.0, 0.5))
        lateral, azimuth = rng.uniform(2.5, 7.0), rng.uniform(0.0, 2.0 * math.pi)
        preload, friction = float(rng.choice([1e3, 5e3])), float(rng.choice([0.1, 0.2]))
        drawn.append(Heel(cg, lateral, azimuth, preload, friction))
    return drawn


def block(heel: Heel, bearing: float) -> Model:
    """MASS at the heel's CG on four bolted joints at CORNERS, shanks bearing at `bearing` N/m."""
    joints = [
        {
            "name": f"j{i}",
            "kind": "bolted_joint",
            "position": [x, y, 0.0],
            "orientation_rpy": [0.0, 0.0, 0.0],
            "preload": heel.preload,
            "friction": heel.friction,
            "bearing_stiffness": bearing,
            **JOINT,
        }
        for i, (x, y) in enumerate(CORNERS)
    ]
    data = {
        "name": "start_heels",
        "body": {"mass": MASS, "cg": list(heel.cg), "inertia": [100.0, 150.0, 200.0, 0, 0, 0]},
        "mounts": joints,
        "dofs": ["x", "y", "z", "alpha", "gamma", "delta"],
        "input": {"includes_gravity": True},
        "initial_state": {"mode": "equilibrium", "gravity": "first_sample"},
    }
    return assemble(scene_from_dict(data, "<start_heels>"))


def imbalance(model: Model, y: np.ndarray, specific_force: np.ndarray) -> tuple[float, float]:
    """(N, N·m): |Σ mount forces − m·f| and |Σ mount moments about the CG| at the state y,
    from each mount's wrench at its attachment point (arms turned by the body's attitude)."""
    wrenches, s = np.empty((model.n_mounts, 6)), model.new_scratch()
    evaluate(y, model.arrays, s, np.empty(10), wrenches)  # s: the body's motion at y
    arms = np.array([mt.position for mt in model.scene.mounts]) - np.array(model.scene.body.cg)
    moment = np.cross(arms @ s.rot.T, wrenches[:, :3]).sum(axis=0) + wrenches[:, 3:].sum(axis=0)
    force = wrenches[:, :3].sum(axis=0) - model.scene.body.mass * specific_force
    return float(np.linalg.norm(force)), float(np.linalg.norm(moment))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--heels", type=int, default=120, help="heels drawn (default 120)")
    parser.add_argument("--seed", type=int, default=0, help="the draw's seed (default 0)")
    parser.add_argument(
        "--bearing", type=float, nargs="+", default=[1e8, 5e8, 2e9, 1e10], help="N/m"
    )
    args = parser.parse_args()
    if args.heels < 1:
        parser.error(f"--heels {args.heels}: must be at least 1")
    drawn = heels(args.heels, args.seed)
    print("bearing N/m | found | not found (heel indices) | worst |ΣF − m·f| N | |ΣM| N·m | ms")
    for bearing in args.bearing:
        missed, worst_force, worst_moment, spent = [], 0.0, 0.0, 0.0
        for index, heel in enumerate(drawn):
            model = block(heel, bearing)
            f = heel.specific_force()
            began = time.perf_counter()
            try:
                y = initial_state(model, f)
            except ModelError:
                missed.append(index)
                continue
            finally:
                spent += time.perf_counter() - began
            force, moment = imbalance(model, y, f)
            worst_force, worst_moment = max(worst_force, force), max(worst_moment, moment)
        print(
            f"{bearing:.0e} | {len(drawn) - len(missed)} | {len(missed)} {missed} | "
            f"{worst_force:.2e} | {worst_moment:.2e} | {1e3 * spent / len(drawn):.1f}"
        )


if __name__ == "__main__":
    main()
