"""`mount-twin show`: the layout picture is written, and its scale follows the scene (a scene
written in millimetres draws a layout a thousand times too large)."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from io_helpers import CONFIG, default_scene

from mount_twin.analysis.layout_view import layout_size, sensors
from mount_twin.cli import main
from mount_twin.physics.rotations import rpy_matrix
from mount_twin.scene.description import BodySensor


def test_the_command_writes_the_picture(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    png = tmp_path / "pump.png"
    assert main(["show", str(CONFIG / "pump_8_mounts.scene.yaml"), "-o", str(png)]) == 0
    assert f"layout: {png}" in capsys.readouterr().out
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 50_000


def test_the_layout_scale_is_the_scene_extent() -> None:
    scene = default_scene()
    assert layout_size(scene) == pytest.approx(1.8)  # mounts from x = −0.9 to 0.9 m
    in_mm = dataclasses.replace(
        scene,
        mounts=tuple(
            dataclasses.replace(m, position=tuple(1000.0 * v for v in m.position))
            for m in scene.mounts
        ),
    )
    assert layout_size(in_mm) == pytest.approx(1800.0)


def test_the_body_imu_is_drawn_where_the_scene_puts_it() -> None:
    """It was not drawn: a body IMU given in mm, or on the wrong side, did not show."""
    scene = default_scene()
    assert [label for label, _, _ in sensors(scene)] == ["foundation IMU"]
    far = BodySensor(position=(0.8, 0.3, 3.0), orientation_rpy=(0.0, 0.0, 1.5))
    with_body = dataclasses.replace(scene, body_sensor=far)
    assert sensors(with_body)[1] == ("body IMU", far.position, far.orientation_rpy)
    assert layout_size(with_body) == pytest.approx(3.0)  # z from 0 (origin) to 3 m


def test_the_pump_end_mounts_lean_outward_and_their_lines_cross_below() -> None:
    """What the picture shows and the scene comment says: fl (y = +0.4 m, roll −30°) has its
    z axis along (0, sin 30°, cos 30°); the lines of action of fl and fr cross on the centre
    line 0.4/tan 30° = 0.69 m below the mount plane."""
    mounts = {m.name: m for m in default_scene().mounts}
    fl, fr = mounts["fl"], mounts["fr"]
    z_fl = rpy_matrix(*fl.orientation_rpy)[:, 2]
    np.testing.assert_allclose(z_fl, [0.0, 0.5, np.sqrt(3) / 2], atol=1e-4)
    z_fr = rpy_matrix(*fr.orientation_rpy)[:, 2]
    # p_fl + s·z_fl = p_fr + t·z_fr, in the y–z plane
    a = np.column_stack([z_fl[1:], -z_fr[1:]])
    s, _ = np.linalg.solve(a, np.array(fr.position[1:]) - np.array(fl.position[1:]))
    crossing = np.array(fl.position) + s * z_fl
    assert crossing[1] == pytest.approx(0.0, abs=1e-9)
    assert crossing[2] == pytest.approx(-0.4 / np.tan(np.radians(30.0)), rel=1e-4)


def test_every_mount_kind_has_its_own_colour() -> None:
    """A new kind registered in mount_twin.kinds is drawn in a colour of its own, not in the
    grey kept for what no scene can hold."""
    from mount_twin.analysis.layout_view import KIND_COLOURS
    from mount_twin.kinds import KINDS

    assert set(KIND_COLOURS) == {"linear", *KINDS}
    assert len(set(KIND_COLOURS.values())) == len(KIND_COLOURS)


def test_a_shear_keys_line_of_action_is_along_its_stiff_axis_not_z() -> None:
    """The genset's keys bear along x (key_x, stiffness [1e9, 0, 0]) and y (key_y, [0, 1e9,
    0]) of F and leave z free, yet each was drawn with a vertical dashed line of action, as if
    it carried the weight. The dashed lines through a key now run along its stiff axes; a
    foot's (its bolt) stays vertical."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from mount_twin.analysis.layout_view import _draw_scene, _Views
    from mount_twin.scene import load_scene_file

    scene = load_scene_file(CONFIG / "genset_bolted_keyed.scene.yaml")
    fig = plt.figure()
    views = _Views(
        fig.add_subplot(1, 3, 1, projection="3d"), [fig.add_subplot(1, 3, k) for k in (2, 3)]
    )
    _draw_scene(views, scene)

    def dashed_through(ax: object, u: float, v: float) -> list[tuple[float, float]]:
        """Directions (du, dv) of the dashed lines through (u, v) in a 2-D view."""
        out = []
        for line in ax.get_lines():  # type: ignore[attr-defined]
            (u0, u1), (v0, v1) = line.get_xdata(), line.get_ydata()
            if (
                line.get_linestyle() == "--"
                and np.isclose((u0 + u1) / 2, u)
                and np.isclose((v0 + v1) / 2, v)
            ):
                d = np.array([u1 - u0, v1 - v0])
                if np.linalg.norm(d) > 0.0:  # (a line across the view is a point in it)
                    out.append(tuple(np.round(d / np.linalg.norm(d), 9) + 0.0))
        return out

    side, end = views.flat  # x–z and y–z of F
    assert dashed_through(side, -1.3, 0.0) == [(1.0, 0.0)]  # key_x at x = −1.3: along x
    assert dashed_through(end, 0.0, 0.0) == [(1.0, 0.0)]  # key_y, on the centre line: along y
    assert dashed_through(side, 1.1, 0.0) == [(0.0, 1.0)] * 2  # foot_fl, foot_fr: the bolts
    plt.close(fig)


@pytest.mark.parametrize("scene_file", ["pump_8_mounts", "genset_bolted_keyed"])
def test_every_label_is_readable(scene_file: str, monkeypatch: pytest.MonkeyPatch) -> None:
    """The pump's side view wrote "F (deck), foundation IMU" across the labels of ml1 and mr1
    0.3 m on, and the 3-D view its F and IMU labels over each other; then the pump's end view
    drew that label's leader over "fl, ml1, ml2, rl", and the genset's side view ran "F (deck),
    foot_ml, foot_mr, foundation IMU" out past the axes' right edge. In every view, as saved,
    each label's box lies inside its axes and meets no other label, no other label's leader
    and no marker (a disc of the marker's size) but its own point's."""
    matplotlib = pytest.importorskip("matplotlib")
    matplotlib.use("Agg")
    from matplotlib.path import Path as MplPath
    from matplotlib.text import Text
    from matplotlib.transforms import Bbox

    from mount_twin import figure_files
    from mount_twin.analysis.layout_view import draw_layout
    from mount_twin.scene import load_scene_file

    saved: list = []

    def keep(fig: Any, png: Any) -> Any:  # as save_png lays the figure out, without the file
        fig.tight_layout()
        fig.canvas.draw()
        saved.append(fig)
        return png

    monkeypatch.setattr(figure_files, "save_png", keep)
    draw_layout(load_scene_file(CONFIG / f"{scene_file}.scene.yaml"), "unused.png")
    (fig,) = saved
    renderer = fig.canvas.get_renderer()
    page = fig.bbox
    for ax in fig.axes:
        view, frame = ax.get_title(), ax.get_window_extent(renderer)
        labels = [t for t in ax.texts if t.get_text().strip()]
        assert len(labels) >= 4, view
        boxes = [Text.get_window_extent(t, renderer) for t in labels]  # the text alone
        leaders = [  # as drawn, in pixels
            t.arrow_patch.get_transform().transform_path(t.arrow_patch.get_path()) for t in labels
        ]
        markers = [  # (centre, radius) in pixels, of every scatter marker as drawn
            (centre, np.sqrt(size) / 2.0 * renderer.points_to_pixels(1.0))
            for c in ax.collections
            for centre, size in zip(
                c.get_offset_transform().transform(c.get_offsets()),
                np.broadcast_to(c.get_sizes(), len(c.get_offsets())),
                strict=True,
            )
        ]
        for label, box in zip(labels, boxes, strict=True):
            name = f"{view}: {label.get_text()!r}"
            assert page.x0 <= box.x0 and box.x1 <= page.x1, f"{name} leaves the figure"
            assert frame.x0 <= box.x0 and box.x1 <= frame.x1, f"{name} leaves the axes"
            assert frame.y0 <= box.y0 and box.y1 <= frame.y1, f"{name} leaves the axes"
            own = ax.transData.transform(label.xy)  # its point's pixels
            for other, other_box, leader in zip(labels, boxes, leaders, strict=True):
                if other is label:
                    continue
                assert not box.overlaps(other_box), f"{name} meets {other.get_text()!r}"
                assert not MplPath(leader.vertices).intersects_bbox(box), (
                    f"{name} is crossed by the leader of {other.get_text()!r}"
                )
            for centre, radius in markers:
                if np.hypot(*(centre - own)) < 1.0:
                    continue  # its own point's marker, which its leader starts at
                disc = Bbox.from_extents(*(centre - radius), *(centre + radius))
                assert not box.overlaps(disc), f"{name} covers the marker at {centre}"
