"""Rated travel and load of linear mounts: utilisation against closed forms, and the mount
status OK → WARN → ERROR like the other kinds."""

from __future__ import annotations

import math

import numpy as np
import pytest
from io_helpers import batch
from physics_helpers import base_scene, mount

from mount_twin.engine.batch import ERROR, OK, WARN
from mount_twin.engine.engine import TwinEngine
from mount_twin.model.assemble import assemble
from mount_twin.replay_summary import ReplaySummary
from mount_twin.scene.loader import scene_from_dict

G = 9.80665
MASS, K, KH = 800.0, 2.0e6, 1.0e6  # kg, N/m vertical, N/m horizontal (per mount)


def _engine(
    rated_travel: list[float], rated_load: list[float], tilted: bool = False
) -> TwinEngine:
    """800 kg on four equal mounts at the corners of a 1 m × 0.6 m rectangle about the CG; the
    first mount rated. Tilted: the mounts lean in a V seen along y, each pitched 30° toward the
    centre plane x = 0 (mirror images, so a vertical load moves the body straight down)."""

    def rpy(x: float) -> tuple[float, float, float]:
        return (0.0, -math.copysign(math.radians(30.0), x) if tilted else 0.0, 0.0)

    corners = [(0.5, 0.3), (-0.5, 0.3), (-0.5, -0.3), (0.5, -0.3)]
    mounts = [
        mount(f"m{i}", (x, y, 0.0), (KH, KH, K, 0.0, 0.0, 0.0), rpy_=rpy(x))
        for i, (x, y) in enumerate(corners)
    ]
    mounts[0]["rated_travel"] = rated_travel
    mounts[0]["rated_load"] = rated_load
    data = base_scene(MASS, [0.0, 0.0, 0.2], [100.0, 150.0, 200.0, 0.0, 0.0, 0.0], mounts)
    data["input"]["frame_id"] = "deck_imu"
    return TwinEngine(assemble(scene_from_dict(data, "<ratings test>")))


def _run(engine: TwinEngine, accel: np.ndarray | None = None, n: int = 200):
    out = engine.run(batch(1.0 + np.arange(n) * 1e-3, accel))
    report = out.health[-1]
    (status,) = [s for s in report.statuses if s.name == "mount_twin: mount m0"]
    return out, status


def test_static_sag_and_load_give_the_closed_form_utilisation() -> None:
    """At rest the four equal vertical mounts share the weight: sag mg/(4k), load mg/4."""
    sag, load = MASS * G / (4 * K), MASS * G / 4
    engine = _engine([0.0, 0.0, 2.0 * sag], [0.0, 0.0, 0.0])
    _, status = _run(engine)
    assert engine.utilisation_max["m0"] == pytest.approx(0.5, rel=1e-9)
    assert status.level == OK
    engine = _engine([0.0, 0.0, 0.0], [0.0, 0.0, load / 0.25])
    _run(engine)
    assert engine.utilisation_max["m0"] == pytest.approx(0.25, rel=1e-9)
    assert "m1" not in engine.utilisation_max  # unrated mounts have no utilisation


@pytest.mark.parametrize("n", [1, 2])
def test_a_record_of_one_sample_is_judged_at_its_start(n: int) -> None:
    """A start is published: its closed-form load and sag count. With one sample (nothing
    integrated) the utilisation read 0 and the mount status "ok", which a sweep then ranked
    as its best case."""
    sag, load = MASS * G / (4 * K), MASS * G / 4
    for travel, rated, expected in (
        ([0.0, 0.0, 2.0 * sag], [0.0, 0.0, 0.0], 0.5),
        ([0.0, 0.0, 0.0], [0.0, 0.0, 0.8 * load], 1.25),
    ):
        engine = _engine(travel, rated)
        _, status = _run(engine, n=n)
        assert engine.utilisation_max["m0"] == pytest.approx(expected, rel=1e-9)
        assert status.values["utilisation_max"] == f"{expected:.4g}"
        assert status.level == (OK if expected < 1.0 else ERROR)


def test_travel_along_inclined_mount_axes() -> None:
    """Mounts in a V: the body sinks by s, so mount m0 (at x > 0, pitched −30°: its z axis is
    (−sin 30°, 0, cos 30°) in F, its x axis (cos 30°, 0, sin 30°)) moves −s·cos 30° along its z
    and −s·sin 30° along its x. Vertical stiffness of each mount: K cos²30° + KH sin²30°, so
    s = mg / (4 (K cos²30° + KH sin²30°))."""
    c, s_ = math.cos(math.radians(30.0)), math.sin(math.radians(30.0))
    sag = MASS * G / (4 * (K * c * c + KH * s_ * s_))
    engine = _engine([sag * s_ / 0.8, 0.0, 0.0], [0.0, 0.0, 0.0], tilted=True)
    _run(engine)
    assert engine.utilisation_max["m0"] == pytest.approx(0.8, rel=1e-6)
    engine = _engine([0.0, 0.0, sag * c / 0.3], [0.0, 0.0, 0.0], tilted=True)
    _run(engine)
    assert engine.utilisation_max["m0"] == pytest.approx(0.3, rel=1e-6)


def test_a_shock_past_the_rating_is_an_error_and_near_it_a_warning() -> None:
    sag = MASS * G / (4 * K)
    shock = np.tile([0.0, 0.0, G], (200, 1))
    shock[20:40, 2] += 30.0 * np.sin(np.linspace(0.0, math.pi, 20))  # ~3 g half-sine, 20 ms
    _, status = _run(_engine([0.0, 0.0, 1.5 * sag], [0.0, 0.0, 0.0]), shock)
    assert status.level == ERROR
    assert float(status.values["utilisation_max"]) > 1.0
    # Rated so that the peak sits within the 10 % alarm margin below 1.
    probe = _engine([0.0, 0.0, 1.0], [0.0, 0.0, 0.0])
    _run(probe, shock)
    peak = probe.utilisation_max["m0"]  # the peak travel, m
    _, status = _run(_engine([0.0, 0.0, peak / 0.95], [0.0, 0.0, 0.0]), shock)
    assert status.level == WARN
    assert float(status.values["utilisation_max"]) == pytest.approx(0.95, rel=1e-6)


def test_a_utilisation_just_under_1_does_not_read_as_1() -> None:
    """At rest at 0.9998 of its rated load the mount is at WARN (past 1 − alarm_margin, below
    1): its status said "utilisation 1", the limit whose reaching is an ERROR, beside mounts
    at ERROR saying "utilisation 1.1". The number said is the one judged: below 1."""
    load = MASS * G / 4
    engine = _engine([0.0, 0.0, 0.0], [0.0, 0.0, load / 0.9998])
    _, status = _run(engine)
    assert engine.utilisation_max["m0"] == pytest.approx(0.9998, rel=1e-9)
    assert status.level == WARN
    said = float(status.message.removeprefix("utilisation "))
    assert said < 1.0
    assert said == pytest.approx(0.9998, abs=5e-5)


def _replayed_at_rest(engine: TwinEngine, tmp_path) -> ReplaySummary:
    """The replay summary of `engine`'s scene on 0.5 s of a deck at rest (a 1e-4 m/s² pulse)."""
    from mount_twin.cli import main
    from mount_twin.replay import replay

    bag = tmp_path / "still"
    quiet = ["--peak", "1e-4", "--pulse", "0.01", "--rate", "1000", "--duration", "0.5"]
    topic = ["--topic", engine.scene.input.topic]
    assert main(["generate", "half-sine", "-o", str(bag), *quiet, *topic]) == 0
    return replay(engine.scene, bag, tmp_path / "out", progress=False)


def test_the_replay_summary_does_not_round_a_utilisation_under_1_up_to_1(tmp_path) -> None:
    """The replay's summary printed the same mount's peak utilisation as "1.000"."""
    load = MASS * G / 4
    summary = _replayed_at_rest(_engine([0.0, 0.0, 0.0], [0.0, 0.0, load / 0.9998]), tmp_path)
    assert summary.utilisation_max["m0"] == pytest.approx(0.9998, abs=2e-5)
    text = summary.text()
    peaks = text.split("peak utilisation")[1]
    (line,) = [s for s in peaks.splitlines() if s.strip().startswith("m0:")]
    said = float(line.split(":")[1])
    assert said < 1.0
    assert said == pytest.approx(0.9998, abs=5e-5)


@pytest.mark.parametrize(
    ("over", "says"),
    [
        (1.002, "is 1.002 times the rated"),  # 1 to 3 figures, 1.002 to 4
        (1.0 + 1e-6, "is {excess:.3g} N past the rated"),  # 1 to 4 figures: the excess, N
    ],
)
def test_a_load_a_hair_past_its_rating_never_reads_as_1_times_it(over: float, says: str) -> None:
    """Four equal mounts share the weight, mg/4 each; m0 rated `over` times less. The warning
    read "is 1 times the rated", a load at its rating, not past it."""
    load = MASS * G / 4
    rated = load / over
    mounts = [
        mount(f"m{i}", (x, y, 0.0), (KH, KH, K, 0.0, 0.0, 0.0))
        for i, (x, y) in enumerate([(0.5, 0.3), (-0.5, 0.3), (-0.5, -0.3), (0.5, -0.3)])
    ]
    mounts[0]["rated_load"] = [0.0, 0.0, rated]
    data = base_scene(MASS, [0.0, 0.0, 0.2], [100.0, 150.0, 200.0, 0.0, 0.0, 0.0], mounts)
    (warning,) = [w for w in scene_from_dict(data, "<hair>").warnings if "rated" in w.message]
    assert warning.path.endswith("mounts[0].rated_load")
    assert f"{load:.4g} N along local z, " in warning.message
    assert says.format(excess=load - rated) + f" {rated:.4g} N" in warning.message
    assert "is 1 times" not in warning.message


def test_the_replay_summary_says_what_a_linear_mounts_utilisation_divides(tmp_path) -> None:
    """A scene of linear mounts read `peak utilisation (bolt F/F_y, rubber deflection/rated,
    key F/allowable)`: none of its mounts' ratios. Here the load alone is rated, 0.8 at rest."""
    load = MASS * G / 4
    text = _replayed_at_rest(_engine([0.0, 0.0, 0.0], [0.0, 0.0, load / 0.8]), tmp_path).text()
    (head,) = [s for s in text.splitlines() if "peak utilisation" in s]
    assert "linear travel/rated_travel or F/rated_load" in head
    (line,) = [
        s for s in text.split("peak utilisation")[1].splitlines() if s.strip().startswith("m0:")
    ]
    assert float(line.split(":")[1]) == pytest.approx(0.8, abs=1e-3)


def test_the_summary_heads_the_peak_loads_over_their_columns(tmp_path) -> None:
    """`|F| [N]  |M| [N·m]` trailed the title line, over no column. At rest each of the four
    equal mounts about the CG carries a quarter of the weight and, with no rotational
    stiffness, no couple: the figures under each head."""
    text = _replayed_at_rest(_engine([0.0, 0.0, 0.0], [0.0, 0.0, 0.0]), tmp_path).text()
    lines = text.splitlines()
    at = next(i for i, s in enumerate(lines) if "peak mount loads" in s)
    head, rows = lines[at + 1], lines[at + 2 : at + 6]
    for name, column in (("|F| [N]", 0), ("|M| [N·m]", 1)):
        end = head.index(name) + len(name)
        for row in rows:
            figure = row[:end].split()[-1]
            assert row[:end].endswith(figure) and row.split()[1:][column] == figure
            assert float(figure) == pytest.approx((MASS * G / 4, 0.0)[column], abs=0.1)
