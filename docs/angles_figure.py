"""Draw docs/angles.png: the attitude angles α, γ, δ the twin publishes (physics notes §2).

    python3 docs/angles_figure.py

γ is the elevation of body x above the horizontal plane of F, α that of body y, δ the heading
of body x's projection on that plane; R = Rz(δ)·Ry(−γ)·Rx(β), sin β = sin α / cos γ.
"""

from __future__ import annotations

import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from mount_twin.physics.rotations import rpy_matrix

ALPHA, GAMMA, DELTA = math.radians(20.0), math.radians(25.0), math.radians(35.0)


def chart_matrix(alpha: float, gamma: float, delta: float) -> np.ndarray:
    """R of (α, γ, δ): yaw δ, pitch −γ, roll atan2(sin α, cos θ)."""
    cos_theta = math.sqrt(math.cos(gamma) ** 2 - math.sin(alpha) ** 2)
    return rpy_matrix(math.atan2(math.sin(alpha), cos_theta), -gamma, delta)


def main() -> None:
    rot = chart_matrix(ALPHA, GAMMA, DELTA)
    assert abs(math.asin(rot[2, 0]) - GAMMA) < 1e-12 and abs(math.asin(rot[2, 1]) - ALPHA) < 1e-12
    fig = plt.figure(figsize=(7.5, 6.5))
    ax = fig.add_subplot(projection="3d")
    origin = np.zeros(3)
    for k, (name, colour) in enumerate(zip("xyz", ("red", "green", "blue"), strict=True)):
        axis = np.eye(3)[k]
        ax.plot(*zip(origin, 1.2 * axis, strict=True), color=colour, alpha=0.35, linewidth=1)
        ax.text(*(1.25 * axis), f"{name} of F", color=colour, alpha=0.6)
        body = rot[:, k]
        ax.plot(*zip(origin, body, strict=True), color=colour, linewidth=3)
        ax.text(*(1.05 * body), f"{name} of body", color=colour)
    # Elevations: body x and y against their projections on F's horizontal plane.
    for k, label, angle in ((0, "γ", GAMMA), (1, "α", ALPHA)):
        body = rot[:, k]
        flat = np.array([body[0], body[1], 0.0])
        ax.plot(*zip(body, flat, strict=True), color="gray", linestyle=":")
        ax.plot(*zip(origin, flat, strict=True), color="gray", linestyle="--")
        arc = (
            np.array(
                [
                    math.cos(s) * flat / np.linalg.norm(flat) + math.sin(s) * np.eye(3)[2]
                    for s in np.linspace(0, angle, 20)
                ]
            )
            * 0.55
        )
        ax.plot(*arc.T, color="black")
        ax.text(*(arc[len(arc) // 2] * 1.08), f"{label} = {math.degrees(angle):.0f}°", fontsize=12)
    heading = np.array([[math.cos(s), math.sin(s), 0.0] for s in np.linspace(0, DELTA, 20)]) * 0.4
    ax.plot(*heading.T, color="black")
    ax.text(*(heading[len(heading) // 2] * 1.15), f"δ = {math.degrees(DELTA):.0f}°", fontsize=12)
    ax.set_box_aspect((1, 1, 1))
    for setter in (ax.set_xlim, ax.set_ylim, ax.set_zlim):
        setter(-0.4, 1.2)
    ax.view_init(elev=18, azim=-60)
    ax.set_title(
        "γ: body x above F's horizontal plane (+: x up)   α: body y above it (+: y up)\n"
        "δ: heading of body x's projection (from x of F, +: toward y of F)",
        fontsize=9,
    )
    out = Path(__file__).with_name("angles.png")
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    print(out)


if __name__ == "__main__":
    main()
