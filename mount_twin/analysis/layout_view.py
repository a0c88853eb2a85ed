"""A picture of a scene's layout, to check it before anything runs.

Three views of the reference pose: 3-D, side (x–z of F) and end (y–z of F). Drawn: the axes of
the foundation frame F at its origin; the CG; each mount at its position, coloured by kind,
with its own axes (x red, y green, z blue, as RViz draws frames) and its line of action (dashed,
through the mount, both ways): its local z, or for a mount that takes no load along z (a shear
key) each local axis it is stiff along, so an inclined mount pointing the wrong way,
lines of action meeting below the mounts, or positions in millimetres show at a glance; the
IMUs (the foundation's, the body's) with their axes. matplotlib is imported here only (the
`plot` extra).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from mount_twin.physics.rotations import rpy_matrix
from mount_twin.scene.description import Mount, Scene, Vec3
from mount_twin.scene.statics import nominal_tangent

KIND_COLOURS = {
    "linear": "tab:blue",
    "elastomer": "tab:purple",
    "bolted_joint": "tab:orange",
    "shear_key": "tab:brown",
}
AXIS_COLOURS = ("red", "green", "blue")
SENSOR_COLOURS = ("teal", "magenta")
"""The foundation IMU's and the body IMU's markers."""
VIEWS = (("side view (x–z of F)", 0, 2), ("end view (y–z of F)", 1, 2))
"""2-D panels: title, horizontal and vertical axis of F."""


def sensors(scene: Scene) -> list[tuple[str, Vec3, Vec3]]:
    """(label, position m in F, axes' roll, pitch, yaw rad) of each IMU of the scene: the
    foundation's (the input) and the body's, if any (its axes relative to B, which is F's at
    the reference pose drawn)."""
    out = [("foundation IMU", scene.input.sensor_position, scene.input.sensor_rpy)]
    if (body := scene.body_sensor) is not None:
        out.append(("body IMU", body.position, body.orientation_rpy))
    return out


def layout_size(scene: Scene) -> float:
    """The layout's extent, m: the largest distance between the CG, the origin, the IMUs and
    the mounts (at least 0.1 m), the scale of the arrows and lines drawn."""
    points = np.array(
        [
            scene.body.cg,
            (0.0, 0.0, 0.0),
            *(position for _, position, _ in sensors(scene)),
            *(m.position for m in scene.mounts),
        ]
    )
    return max(float(np.ptp(points, axis=0).max()), 0.1)


def draw_layout(scene: Scene, png: str | Path) -> Path:
    """Write the three views of `scene` to `png`; returns its path."""
    from mount_twin.figure_files import pyplot, save_png

    plt = pyplot()

    fig = plt.figure(figsize=(15, 5.5))
    ax3 = fig.add_subplot(1, 3, 1, projection="3d")
    views = _Views(ax3, [fig.add_subplot(1, 3, 2 + k) for k in range(2)])
    _draw_scene(views, scene)
    kinds = sorted({m.kind for m in scene.mounts})
    _dress(views, kinds)
    fig.suptitle(
        f"{scene.name}: {scene.body.mass:g} kg, {len(scene.mounts)} mounts "
        f"({', '.join(kinds)}), "
        f"DOFs {', '.join(scene.dofs)} — {scene.source}",
        fontsize=10,
    )
    # The axes where save_png's layout draws them (the title too takes its room) and their tick
    # labels where drawing puts them: labels are placed apart on the page.
    fig.tight_layout()
    fig.canvas.draw()
    views.annotate(fig.canvas.get_renderer())
    return save_png(fig, png)


class _Views:
    """The 3-D axes and the 2-D axes of `VIEWS`, drawn into together (positions in m, F)."""

    def __init__(self, ax3: Any, flat: list[Any]) -> None:
        self.ax3 = ax3
        self.flat = flat
        self.labels: list[dict[tuple[float, float], list[str]]] = [{} for _ in VIEWS]
        """Per 2-D view: the labels of the points at each position (rounded to 1 µm)."""
        self.labels3: dict[tuple[float, float, float], list[str]] = {}
        """The 3-D view's, likewise."""

    def segment(self, a: np.ndarray, b: np.ndarray, **style: Any) -> None:
        """A line from `a` to `b` in every view."""
        self.ax3.plot(*zip(a, b, strict=True), **style)
        for ax, (_, i, j) in zip(self.flat, VIEWS, strict=True):
            ax.plot([a[i], b[i]], [a[j], b[j]], **style)

    def point(self, p: np.ndarray, label: str, **style: Any) -> None:
        """A marker at `p` in every view, labelled by `annotate`."""
        self.ax3.scatter(*p, **style)
        # Points that fall on one another in a view share one label.
        self.labels3.setdefault((round(p[0], 6), round(p[1], 6), round(p[2], 6)), []).append(label)
        for ax, (_, i, j), named in zip(self.flat, VIEWS, self.labels, strict=True):
            ax.scatter(p[i], p[j], **style)
            named.setdefault((round(p[i], 6), round(p[j], 6)), []).append(label)

    def frame(self, origin: np.ndarray, rot: np.ndarray, length: float, width: float) -> None:
        """The axes of a frame at `origin` rotated by `rot` into F, `length` m long."""
        for k in range(3):
            self.segment(
                origin, origin + length * rot[:, k], color=AXIS_COLOURS[k], linewidth=width
            )

    def annotate(self, renderer: Any) -> None:
        """Every view's point labels, one per position, each where it meets no other label, no
        leader, no labelled point and stays inside its axes (`_place_apart`); in 3-D at the
        points' projections onto the page, so call it once the views' limits and layout are
        final."""
        from mpl_toolkits.mplot3d import proj3d

        proj = self.ax3.get_proj()
        flat3 = {proj3d.proj_transform(*p, proj)[:2]: names for p, names in self.labels3.items()}
        for ax, named in ((self.ax3, flat3), *zip(self.flat, self.labels, strict=True)):
            labels = [
                ax.annotate(
                    label_text(names),
                    (u, v),
                    fontsize=7,
                    xytext=(0.0, 0.0),  # placed by _place_apart
                    textcoords="offset points",
                    arrowprops={"arrowstyle": "-", "color": "0.5", "lw": 0.5, "shrinkA": 0},
                    bbox={"boxstyle": "square,pad=0.1", "fc": "white", "ec": "none", "alpha": 0.7},
                )
                for (u, v), names in sorted(named.items())
            ]
            for label in labels:  # placed for this layout: the figure's saving keeps it
                label.set_in_layout(False)
            _place_apart(ax, labels, renderer)


LABEL_LINE = 24
"""A point label's longest line, characters: the names of the points at one place are wrapped
onto lines of at most this (a name longer than it has a line of its own)."""
LABEL_GAP = 5.0
"""The least space between two labels, or a label and a labelled point, points."""
LABEL_OFFSETS = (4.0, 10.0, 18.0, 30.0, 45.0, 65.0, 90.0, 120.0)
"""A point label's distances from its point tried in turn, points (1/72 in)."""
LABEL_SIDES = ((1, 1), (1, -1), (-1, 1), (-1, -1), (0, 1), (0, -1), (1, 0), (-1, 0))
"""The sides of its point a label is tried on at each distance, in turn: up right, down right,
up left, down left, above, below, right, left."""


def label_text(names: list[str]) -> str:
    """The label of the points named `names`: the names, comma separated, wrapped onto lines of
    at most LABEL_LINE characters, never within a name."""
    lines = [names[0]]
    for name in names[1:]:
        if len(lines[-1]) + len(name) + 2 > LABEL_LINE:
            lines[-1] += ","
            lines.append(name)
        else:
            lines[-1] += f", {name}"
    return "\n".join(lines)


def _place_apart(ax: Any, labels: list[Any], renderer: Any) -> None:
    """Place each of `labels` (annotations in offset points) in turn at the first of the
    LABEL_OFFSETS × LABEL_SIDES places where its box lies inside `ax`, meets no label placed
    before it, no labelled point (a LABEL_GAP square around it) and no leader of another label,
    and its own leader (the grey line back to its point) crosses no other label nor passes
    through another point; where none is free, at the place with the fewest such conflicts.
    Labels of points close on the page (the pump's F, its IMU and the mounts 0.3 m on; the
    genset's feet and keys) ran into one another, their leaders through other labels, or out
    of the axes."""
    from matplotlib.path import Path as MplPath
    from matplotlib.text import Text
    from matplotlib.transforms import Bbox

    scale = renderer.points_to_pixels(1.0)
    gap = LABEL_GAP * scale
    frame = ax.get_window_extent(renderer)
    points = [ax.transData.transform(label.xy) for label in labels]
    marks = [Bbox.from_extents(x - gap, y - gap, x + gap, y + gap) for x, y in points]
    # A leader may pass near another point, not through it (as if it led there).
    dots = [Bbox.from_extents(x, y, x, y).padded(gap / 2.0) for x, y in points]
    marks += [  # the axes' ticks and tick labels too: the 3-D view's lie within its axes
        box.padded(gap / 2.0)
        for axis in (ax.xaxis, ax.yaxis, getattr(ax, "zaxis", ax.xaxis))
        if (box := axis.get_tightbbox(renderer)) is not None
    ]
    boxes: list[Any] = []  # the labels placed so far, padded
    leaders: list[Any] = []  # and their leaders

    def conflicts(k: int, box: Any, leader: Any) -> int:
        inside = frame.x0 <= box.x0 and box.x1 <= frame.x1 and frame.y0 <= box.y0
        inside = inside and box.y1 <= frame.y1
        others = marks[:k] + marks[k + 1 :]  # its own point's square excepted
        return (
            (not inside)
            + sum(box.overlaps(b) for b in (*others, *boxes))
            + sum(line.intersects_bbox(box) for line in leaders)
            + sum(leader.intersects_bbox(b) for b in (*dots[:k], *dots[k + 1 :], *boxes))
        )

    for k, (label, (x, y)) in enumerate(zip(labels, points, strict=True)):
        best: tuple[int, Any, Any, tuple[float, float, str, str]] | None = None
        for offset in LABEL_OFFSETS:
            for sx, sy in LABEL_SIDES:
                place = (
                    sx * offset,
                    sy * offset,
                    ("center", "left", "right")[sx],
                    ("center", "bottom", "top")[sy],
                )
                _put(label, place)
                label.update_positions(renderer)  # where this place puts it
                box = Text.get_window_extent(label, renderer).padded(gap / 2.0)
                leader = MplPath([(x, y), ((box.x0 + box.x1) / 2, (box.y0 + box.y1) / 2)])
                n = conflicts(k, box, leader)
                if best is None or n < best[0]:
                    best = (n, box, leader, place)
                if n == 0:
                    break
            if best is not None and best[0] == 0:
                break
        assert best is not None  # LABEL_OFFSETS and LABEL_SIDES are not empty
        _, box, leader, place = best
        _put(label, place)
        boxes.append(box)
        leaders.append(leader)


def _put(label: Any, place: tuple[float, float, str, str]) -> None:
    """Move `label` (an annotation in offset points) to `place`: its offset from its point,
    points, and its horizontal and vertical alignment there."""
    label.xyann = place[:2]
    label.set_horizontalalignment(place[2])
    label.set_verticalalignment(place[3])


def _draw_scene(views: _Views, scene: Scene) -> None:
    """F's axes at its origin; each mount's line of action, axes and name; the IMUs with their
    axes and the CG (arrows and lines scaled to `layout_size`)."""
    size = layout_size(scene)
    arrow, reach = 0.12 * size, 0.9 * size
    views.frame(np.zeros(3), np.eye(3), 2.0 * arrow, 2.0)
    views.point(np.zeros(3), f"F ({scene.frames.foundation})", color="black", marker="+", s=60)
    for m in scene.mounts:
        p, rot = np.array(m.position), rpy_matrix(*m.orientation_rpy)
        colour = KIND_COLOURS.get(m.kind, "tab:gray")
        for k in acting_axes(m):
            views.segment(
                p - reach * rot[:, k],
                p + reach * rot[:, k],
                color=colour,
                linestyle="--",
                linewidth=0.8,
            )
        views.frame(p, rot, arrow, 1.2)
        views.point(p, m.name, color=colour, s=30)
    for (label, position, rpy), colour in zip(sensors(scene), SENSOR_COLOURS, strict=False):
        views.frame(np.array(position), rpy_matrix(*rpy), 0.7 * arrow, 1.0)
        views.point(np.array(position), label, color=colour, marker="^", s=40)
    cg = np.array(scene.body.cg)
    views.point(cg, f"CG ({scene.frames.body})", color="black", marker="o", s=70)


def acting_axes(mount: Mount) -> tuple[int, ...]:
    """The local axes (0 x, 1 y, 2 z) a mount's line of action is drawn along: z, unless its
    nominal stiffness along z is 0 (a shear key, free in z): then each axis it is stiff along."""
    k = nominal_tangent(mount).stiffness[:3]
    return (2,) if k[2] > 0.0 else tuple(j for j in range(3) if k[j] > 0.0)


def _dress(views: _Views, kinds: list[str]) -> None:
    """Axis labels, equal scales and titles of every view, and the legend of the mount
    `kinds`' colours."""
    import matplotlib.lines

    ax3 = views.ax3
    ax3.set_xlabel("x [m]")
    ax3.set_ylabel("y [m]")
    ax3.set_zlabel("z [m]")
    ax3.set_box_aspect((1.0, 1.0, 1.0))
    _equal_3d(ax3)
    ax3.set_title("3-D (F: x red, y green, z blue)", fontsize=9)
    for ax, (title, i, j) in zip(views.flat, VIEWS, strict=True):
        ax.set_title(f"{title}; dashed: each mount's line of action", fontsize=9)
        ax.set_xlabel(f"{'xyz'[i]} [m]")
        ax.set_ylabel(f"{'xyz'[j]} [m]")
        ax.set_aspect("equal", adjustable="datalim")
        ax.grid(True, alpha=0.3)
    views.flat[0].legend(
        handles=[
            matplotlib.lines.Line2D(
                [], [], color=KIND_COLOURS.get(k, "tab:gray"), marker="o", linestyle="--", label=k
            )
            for k in kinds
        ],
        fontsize=7,
        loc="lower right",
        title="mount kind",
        title_fontsize=7,
    )


def _equal_3d(ax: object) -> None:
    """Equal scales on a 3-D axes (matplotlib keeps them independent)."""
    limits = np.array([ax.get_xlim3d(), ax.get_ylim3d(), ax.get_zlim3d()])  # type: ignore[attr-defined]
    centre, half = limits.mean(axis=1), (limits[:, 1] - limits[:, 0]).max() / 2.0
    ax.set_xlim3d(centre[0] - half, centre[0] + half)  # type: ignore[attr-defined]
    ax.set_ylim3d(centre[1] - half, centre[1] + half)  # type: ignore[attr-defined]
    ax.set_zlim3d(centre[2] - half, centre[2] + half)  # type: ignore[attr-defined]
