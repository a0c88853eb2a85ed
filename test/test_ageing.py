"""Mounts that age (`track`): the calibration re-fitted window by window flags a machine whose
mounts lose 30 % of their stiffness part-way through a record, in the first window after, and
not before."""

from __future__ import annotations

import re
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import yaml
from io_helpers import (
    AGEING_PUMP,
    ROOT,
    ageing_messages,
    pump_scene_file,
    read_raw,
    statuses_named,
)
from scipy.signal import butter, sosfiltfilt

from mount_twin import load_scene_file
from mount_twin.analysis import calibration as cal_mod
from mount_twin.analysis.ageing import WindowFit, track, window_table
from mount_twin.analysis.ageing_live import CUT_BY_JUMP, DROPPED, NAME, WindowJob, run_job
from mount_twin.cli import main
from mount_twin.engine.batch import LEVEL_NAMES
from mount_twin.engine.body_counts import RESETS
from mount_twin.errors import SceneError
from mount_twin.io.messages import IMU
from mount_twin.io.output_bag import OutputBag
from mount_twin.io.signals import Signal, ship_motion
from mount_twin.replay import replay
from mount_twin.scene.description import Scene
from mount_twin.scene.loader import scene_from_dict
from mount_twin.scene.yaml_reading import read_scene_yaml
from mount_twin.stream import TwinStream

RATE, TOTAL, CHANGE = 200.0, 92.5, 45.0


@pytest.fixture(scope="module")
def ageing_pair(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Signal, Signal]:
    """The pump (its body IMU on the frame) under ship motion with machinery vibration; at 40 s
    every mount loses 30 % of its stiffness. Both records carry 0.01 m/s² of noise. Also
    written as recorder CSVs and a scene file, for the command."""
    data = read_scene_yaml(ROOT / "config/pump_8_mounts.scene.yaml")
    data["input"]["gyro_filter"] = "none"
    data["body_sensor"] = {"position": [0.8, 0.3, 1.0]}
    d = tmp_path_factory.mktemp("ageing")
    (d / "pump.scene.yaml").write_text(yaml.safe_dump(data), encoding="utf-8")
    scene = load_scene_file(d / "pump.scene.yaml")
    sea = ship_motion(rate_hz=RATE, total=TOTAL)
    sos = butter(4, [1.0, 40.0], btype="band", fs=RATE, output="sos")
    vib = sosfiltfilt(sos, np.random.default_rng(5).normal(0, 1, sea.accel.shape), axis=0)
    foundation = Signal(sea.t, sea.accel + 0.3 * vib / vib.std(axis=0), sea.gyro)
    t, intact = cal_mod.predict(scene, foundation)
    _, aged = cal_mod.predict(cal_mod.calibrated_scene(scene, {"stiffness": 0.7}), foundation)
    rng = np.random.default_rng(1)
    f = np.where((t >= CHANGE)[:, None], aged, intact) + rng.normal(0, 0.01, intact.shape)
    body = Signal(t, f, np.zeros_like(f))
    noisy = Signal(sea.t, foundation.accel + rng.normal(0, 0.01, sea.accel.shape), sea.gyro)
    for name, rec in (("foundation", noisy), ("body", body)):
        rows = np.column_stack([rec.t, rec.accel, rec.gyro])
        head = "t,ax,ay,az,wx,wy,wz"
        np.savetxt(d / f"{name}.csv", rows, delimiter=",", header=head, comments="")
    return d, noisy, body


def test_mounts_losing_30_percent_are_flagged_within_a_minute_and_not_before(
    ageing_pair: tuple[Path, Signal, Signal], capsys: pytest.CaptureFixture[str]
) -> None:
    """Windows of 30 s: the one before the change is OK, the first wholly after it is an
    ERROR naming the stiffness at 0.70 (within 2 %), and the command exits 4. (The issue asks
    for one mount of several; the fit has one scale for all mounts: see the module.)"""
    d, _, _ = ageing_pair
    files = ["--foundation", str(d / "foundation.csv"), "--body", str(d / "body.csv")]
    assert main(["track", str(d / "pump.scene.yaml"), "--window", "30", *files]) == 4
    rows = [ln.split() for ln in capsys.readouterr().out.splitlines()[1:]]
    spans = [tuple(float(v) for v in r[0].split("–")) for r in rows]
    levels = [r[1] for r in rows]
    assert spans[0] == (2.0, 32.0) and levels[0] == "OK"
    first = next(i for i, level in enumerate(levels) if level != "OK")
    assert spans[first][1] - CHANGE <= 60.0
    after = next(i for i, (start, _) in enumerate(spans) if start >= CHANGE)
    assert levels[after] == "ERROR" and rows[after][2:4] == ["stiffness", rows[after][3]]
    assert float(rows[after][3].lstrip("×").rstrip(",")) == pytest.approx(0.7, rel=0.02)


def test_the_commands_default_bands_are_the_ageing_modules() -> None:
    from mount_twin.analysis.ageing import Band
    from mount_twin.commands.track import BANDS
    from mount_twin.scene.description import Ageing

    assert Band() == Band(BANDS["warn"], BANDS["error"]) == Band(Ageing().warn, Ageing().error)


def test_groups_of_mounts_are_tracked_apart(
    ageing_pair: tuple[Path, Signal, Signal], capsys: pytest.CaptureFixture[str]
) -> None:
    """`--fit` with a stiffness scale per group (the front pair, the other six): in the first
    window wholly after the change both read 0.70 (within 2 %), and the window is an ERROR."""
    d, _, _ = ageing_pair
    files = ["--foundation", str(d / "foundation.csv"), "--body", str(d / "body.csv")]
    groups = ["stiffness:fl+fr", "stiffness:ml1+mr1+ml2+mr2+rl+rr"]
    assert main(["track", str(d / "pump.scene.yaml"), *files, "--fit", *groups]) == 4
    rows = capsys.readouterr().out.splitlines()[1:]
    after = next(r for r in rows if float(r.split()[0].split("–")[0]) >= CHANGE)
    assert after.split()[1] == "ERROR"
    for group in groups:
        value = float(after.split(f"{group} ×")[1].split()[0])
        assert value == pytest.approx(0.7, rel=0.02), group


@pytest.mark.parametrize(
    ("options", "says"),
    [
        # 92.5 s of records: no 100 s window after the lead (an empty table, exit 0, before)
        (["--window", "100"], "the records hold 90.5 s after the 2 s lead: less than one window"),
        (["--window", "0"], "window 0 s: give more than 4 s"),  # 0 read as not given, before
        (["--warn", "1.2", "0.8"], "warn band [1.2, 0.8]: expected 0 ≤ low < high"),
        (["--warn", "0.9", "1.1", "--error", "0.95", "1.05"], "must hold the warn band"),
        # printed as "lag ×-0.001 ± 0.00032" and "stiffness:: 0.9307 ×", never judged
        (["--fit", "lag"], "--fit lag: track re-fits mount scales: stiffness, damping"),
        (["--fit", "stiffness:"], "stiffness:: a group names its mounts"),
    ],
)
def test_a_window_or_band_no_judgement_can_take_is_refused(
    ageing_pair: tuple[Path, Signal, Signal],
    options: list[str],
    says: str,
    capsys: pytest.CaptureFixture[str],
) -> None:
    d, _, _ = ageing_pair
    files = ["--foundation", str(d / "foundation.csv"), "--body", str(d / "body.csv")]
    assert main(["track", str(d / "pump.scene.yaml"), *files, *options]) == 2
    assert says in capsys.readouterr().err


def test_records_that_do_not_overlap_are_refused_for_it(
    ageing_pair: tuple[Path, Signal, Signal],
) -> None:
    """A body record from another day was told "less than one window of 30 s (give a shorter
    one)"."""
    d, foundation, body = ageing_pair
    later = Signal(body.t + 1000.0, body.accel, body.gyro)
    scene = load_scene_file(d / "pump.scene.yaml")
    with pytest.raises(ValueError, match="the records do not overlap on one clock: the found"):
        track(scene, foundation, later)


@pytest.mark.parametrize(
    ("bands", "says"),
    [
        ({"warn": [0.9, 1.1], "error": [0.95, 1.05]}, "ageing.error: [0.95, 1.05] must hold"),
        ({"warn": [1.2, 0.8]}, "ageing.warn: [1.2, 0.8]: expected low < high"),
    ],
)
def test_a_scenes_ageing_bands_are_refused_at_load_naming_the_key(
    bands: dict[str, list[float]], says: str
) -> None:
    """The same rule as the command's (`ageing_bands_problem`), with the key path."""
    data = read_scene_yaml(ROOT / "config/pump_8_mounts.scene.yaml")
    data["body_sensor"] = {"position": [0.8, 0.3, 1.0]}
    data["ageing"] = bands
    with pytest.raises(SceneError, match=re.escape(says)):
        scene_from_dict(data, "pump")


def test_a_window_in_which_every_scale_is_refused_is_not_judged_ok(
    ageing_pair: tuple[Path, Signal, Signal],
) -> None:
    """The body IMU dies at 32 s (it reads its last sample from then on): the window before is
    OK; the one after had its scales "fitted" to a sensor reading nothing, an ERROR (and, had
    they been refused, read OK). Every scale is refused, and the window is a WARN (as one the
    live tracker cannot fit), saying it is not judged."""
    d, foundation, body = ageing_pair
    dead = body.t >= 32.0
    accel = np.where(dead[:, None], body.accel[np.argmax(dead)], body.accel)
    died = Signal(body.t, accel, body.gyro)
    keep = foundation.t < 63.0  # two windows: 2–32 s, 32–62 s
    short = Signal(foundation.t[keep], foundation.accel[keep], foundation.gyro[keep])
    fits = track(load_scene_file(d / "pump.scene.yaml"), short, died, 30.0)
    assert [(f.start_s, f.level) for f in fits] == [(2.0, "OK"), (32.0, "WARN")]
    assert not fits[1].values and set(fits[1].refused) == {"stiffness", "damping"}
    assert "not judged" in fits[1].why


def _cut(record: Signal, end_s: float) -> Signal:
    """`record`'s samples stamped up to `end_s`."""
    keep = record.t <= end_s
    return Signal(record.t[keep], record.accel[keep], record.gyro[keep])


@pytest.mark.parametrize(
    ("end_s", "says"),
    [
        # 5 s overlap: 3 s after the lead, and a window is longer than 4 s: none can fit
        (
            5.0,
            "3 s after the 2 s lead, and a window is longer than 4 s: track needs records "
            "overlapping by more than 6 s",
        ),
        # 20 s: 18 s after the lead, one 30 s window does not fit, a shorter one does
        (
            20.0,
            "18 s after the 2 s lead: less than one window of 30 s (give one of more than "
            "4 s and at most 18 s)",
        ),
    ],
)
def test_records_too_short_for_a_window_are_told_what_would_fit(
    ageing_pair: tuple[Path, Signal, Signal], end_s: float, says: str
) -> None:
    """Records shorter than the lead were told "give a shorter one" (window), where no window
    (more than 4 s) could fit."""
    d, foundation, body = ageing_pair
    scene = load_scene_file(d / "pump.scene.yaml")
    with pytest.raises(ValueError, match=f"^the records hold {re.escape(says)}$"):
        track(scene, _cut(foundation, end_s), body, 30.0)


def test_a_part_window_left_at_the_end_is_said(
    ageing_pair: tuple[Path, Signal, Signal],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """40 s of records, windows of 30 s after the 2 s lead: one window, 2–32 s, and the last
    8 s (32–40 s) in none, which went without a word."""
    d, foundation, _ = ageing_pair
    short = _cut(foundation, 40.0)
    rows = np.column_stack([short.t, short.accel, short.gyro])
    cut = tmp_path / "foundation_40s.csv"
    np.savetxt(cut, rows, delimiter=",", header="t,ax,ay,az,wx,wy,wz", comments="")
    files = ["--foundation", str(cut), "--body", str(d / "body.csv")]
    assert main(["track", str(d / "pump.scene.yaml"), "--window", "30", *files]) == 0
    said = capsys.readouterr()
    assert [ln.split()[0] for ln in said.out.splitlines()[1:]] == ["2.0–32.0"]
    assert said.err == (
        "mount-twin: warning: the last 8 s of the records, 32–40 s, are in no window: less "
        "than one of 30 s\n"
    )


def test_the_window_table_heading_stands_over_its_columns_and_refusals_read_plainly() -> None:
    """The heading was "window s" padded to 19 over spans right-aligned in 9 + 1 + 9, with
    no heading over why; a refusal read "damping refused (1σ is 80 % of its value (the
    record barely moves it))", parentheses nested."""
    why = "1σ is 80% of its value (the record barely moves it)"
    fits = [
        WindowFit(2.0, 32.0, {"stiffness": 1.0}, {"stiffness": 0.004}),
        WindowFit(1022.0, 1052.0, {}, {}, {"damping": why}, "WARN", "not judged"),
    ]
    head, ok, warn = window_table(fits)
    assert head.split() == ["window", "s", "level", "fit:", "scale", "×value", "±", "1σ", "why"]
    assert head.index("s ") + 1 == ok.index("32.0") + 4 == warn.index("1052.0") + 6
    assert head.index("level") == ok.index("OK") == warn.index("WARN")
    assert head.index("fit:") == ok.index("stiffness") == warn.index("-  ")
    assert head.index("why") == warn.index("not judged")
    assert warn.endswith(f"not judged; damping refused: {why}")


JUMP_AT, JUMP_BY = 34.0, 8.0
"""The loop test's record: its stamps go back by JUMP_BY s at JUMP_AT s of the record, where
its mounts lose 30 % of their stiffness."""


@pytest.fixture(scope="module")
def jumping(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, list[tuple[str, int, bytes]]]:
    """The pump (AGEING_PUMP: windows of 20 s) under 56.5 s of ship motion, deck and body IMU,
    both streams' stamps jumping back 8 s at 34 s, where every mount loses 30 % of its
    stiffness: stamps 0–34 s, then 26–48.5 s (from the first deck stamp)."""
    path = pump_scene_file(tmp_path_factory.mktemp("jump"), **AGEING_PUMP)
    messages = ageing_messages(
        load_scene_file(path), 56.5, JUMP_AT, "/machine/imu", (JUMP_AT, JUMP_BY)
    )
    return path, messages


def _jobs(scene: Scene, messages: list[tuple[str, int, bytes]], feed: str) -> list[WindowJob]:
    """The ageing jobs of a TwinStream fed `messages` (in their order) as `feed` says: 'replay'
    (deck chunks of 97, body chunks of 13 while the body is behind, as a replay feeds them),
    'body first' (every body message, then the deck in one), 'deck first' (the deck in one,
    then the body in chunks of 7), 'one by one' (each message as it comes, as live)."""
    deck = [raw for topic, _, raw in messages if topic == "/deck/imu"]
    body = [raw for topic, _, raw in messages if topic != "/deck/imu"]
    stream = TwinStream(scene)
    if feed == "replay":
        bodies = iter([body[i : i + 13] for i in range(0, len(body), 13)])
        for i in range(0, len(deck), 97):
            stream.process(deck[i : i + 97])
            while stream.body_behind and (chunk := next(bodies, None)) is not None:
                stream.process_body(chunk)
        for chunk in bodies:
            stream.process_body(chunk)
    elif feed == "body first":
        stream.process_body(body)
        stream.process(deck)
    elif feed == "deck first":
        stream.process(deck)
        for i in range(0, len(body), 7):
            stream.process_body(body[i : i + 7])
    else:
        for topic, _, raw in messages:
            if topic == "/deck/imu":
                stream.process([raw])
            else:
                stream.process_body([raw])
    stream.finish()
    return stream.take_ageing_jobs()


def _same(a: list[WindowJob], b: list[WindowJob]) -> bool:
    """Whether two lists of jobs cut the same windows of the same samples."""
    fields = [(j.span, j.stamp_ns, j.restarts, j.dropped, j.cut) for j in (*a, *b)]
    records = [np.hstack([r.t[:, None], r.accel, r.gyro]) for j in (*a, *b) for r in j.records]
    n = 2 * len(a)
    return (
        len(a) == len(b)
        and fields[: len(a)] == fields[len(a) :]
        and all(np.array_equal(x, y) for x, y in zip(records[:n], records[n:], strict=True))
    )


FEEDS = ("replay", "body first", "deck first", "one by one")


def test_the_live_tracker_restarts_where_both_streams_stamps_jump_back(
    jumping: tuple[Path, list[tuple[str, int, bytes]]],
) -> None:
    """Stamps 0–34 s, then 26–48.5 s (a recorder's clock set back 8 s, a bag played with
    --loop), the mounts at 0.7× stiffness from the jump on. The tracker took only stamps past
    34 s after the jump: it fitted 2–22 s and nothing more, silently. Now it restarts with the
    twin: 2–22 s, the window open at the jump (22–34 s, more than half a window) cut there,
    both at ×1.00, then 28–48 s (the new run's first body stamp plus the 2 s lead) at ×0.70
    (within 2 %), its values saying one jump back; the same windows of the same samples
    however the two streams come batched and interleaved."""
    path, messages = jumping
    scene = load_scene_file(path)
    jobs = {feed: _jobs(scene, messages, feed) for feed in FEEDS}
    assert [round(j.span[0], 6) for j in jobs["replay"]] == [2.0, 22.0, 28.0]
    assert [round(j.span[1], 2) for j in jobs["replay"]] == [22.0, 34.0, 48.0]
    for feed in FEEDS[1:]:
        assert _same(jobs[feed], jobs["replay"]), feed
    statuses = [run_job(job).statuses[0] for job in jobs["replay"]]
    assert [float(s.values["stiffness"]) for s in statuses] == [
        pytest.approx(1.0, abs=0.01),
        pytest.approx(1.0, abs=0.01),
        pytest.approx(0.7, rel=0.02),
    ]
    assert [s.values[RESETS] for s in statuses] == ["0", "0", "1"]
    assert [s.values[DROPPED] for s in statuses] == ["0", "0", "0"]
    assert [CUT_BY_JUMP in s.message for s in statuses] == [False, True, False]
    assert statuses[2].message.endswith(
        "; the stamps jumped back 1× before it, the tracker restarted"
    )
    assert [LEVEL_NAMES[s.level] for s in statuses] == ["OK", "OK", "ERROR"]


def test_a_window_open_at_a_jump_back_too_short_to_fit_is_dropped_and_said(
    jumping: tuple[Path, list[tuple[str, int, bytes]]],
) -> None:
    """Windows of 14 s on the same record: 2–16 and 16–30 s, then 30–34 s open at the jump
    (4 s, less than half a window) is dropped, and the next window, 28–42 s (after the
    jump, ×0.70 within 2 %), says so; the same in any batching."""
    path, messages = jumping
    scene = load_scene_file(path)
    scene = replace(scene, ageing=replace(scene.ageing, window_s=14.0))
    jobs = {feed: _jobs(scene, messages, feed) for feed in FEEDS}
    assert [tuple(round(x, 6) for x in j.span) for j in jobs["replay"]] == [
        (2.0, 16.0),
        (16.0, 30.0),
        (28.0, 42.0),
    ]
    assert [(j.restarts, j.dropped, j.cut) for j in jobs["replay"]] == [
        (0, 0, False),
        (0, 0, False),
        (1, 1, False),
    ]
    for feed in FEEDS[1:]:
        assert _same(jobs[feed], jobs["replay"]), feed
    status = run_job(jobs["replay"][2]).statuses[0]
    assert float(status.values["stiffness"]) == pytest.approx(0.7, rel=0.02)
    assert (status.values[RESETS], status.values[DROPPED]) == ("1", "1")
    assert (
        "; 1 window(s) open at a jump held less than half a window: not fitted" in status.message
    )


@pytest.mark.parametrize("first", ["/deck/imu", "/machine/imu"])
def test_where_only_one_streams_stamps_jump_back_the_window_is_cut_and_that_said(
    jumping: tuple[Path, list[tuple[str, int, bytes]]], first: str
) -> None:
    """One stream's stamps jump back at 34 s, the other's go on (a body IMU on another clock,
    a recorder restarted): its second run has no run of the other's to pair with. The window
    open at the jump, 22–34 s, is fitted once the other passes the jump's last stamp (its
    later samples belong to no run of the first's: not kept). The first stream's second run
    was then kept for good (memory growing, nothing said). Now, once the other's stamps pass
    the jump by more than input.back_jump_reset_s (1 s), a WARN says which stream jumped back
    and when, and no sample of a later run is kept (counted: the end of the stream's report,
    `test_the_samples_that_pair_with_none_are_counted_at_the_end`); the same in any batching."""
    path, messages = jumping
    scene = load_scene_file(path)
    mixed = _one_stream_jumping(messages, scene, first)
    jobs = {feed: _jobs(scene, mixed, feed) for feed in FEEDS}
    assert [(round(j.span[0], 6), round(j.span[1], 2), j.cut) for j in jobs["replay"]] == [
        (2.0, 22.0, False),
        (22.0, 34.0, True),
        (33.995, 34.0, False),  # the WARN (its end rounded), at the last stamp before the jump
        (56.495, 56.5, False),  # the end of the stream: the samples not paired
    ]
    for feed in FEEDS[1:]:
        assert _same(jobs[feed], jobs["replay"]), feed
        assert [j.apart for j in jobs[feed]] == [j.apart for j in jobs["replay"]], feed
    status = run_job(jobs["replay"][2]).statuses[0]
    assert LEVEL_NAMES[status.level] == "WARN"
    name = {"/deck/imu": "the deck's", "/machine/imu": "the body IMU's"}[first]
    assert f"stamps jumped back apart: {name} jumped back at 33.995 s" in status.message
    assert status.message.endswith("not tracked from there on")


def _one_stream_jumping(
    messages: list[tuple[str, int, bytes]], scene: Scene, first: str
) -> list[tuple[str, int, bytes]]:
    """56.5 s of both streams, `first`'s stamps jumping back 8 s at 34 s (those of
    `messages`), the other's going on."""
    steady = ageing_messages(scene, 56.5, JUMP_AT, "/machine/imu")
    jumped = iter(m for m in messages if m[0] == first)  # in the record's order
    return [next(jumped) if m[0] == first else m for m in steady]


@pytest.mark.parametrize("first", ["/deck/imu", "/machine/imu"])
def test_the_samples_that_pair_with_none_are_counted_at_the_end(
    jumping: tuple[Path, list[tuple[str, int, bytes]]], first: str, tmp_path: Path
) -> None:
    """One stream's stamps jump back at 34 s, the other's go on to 56.5 s: the jumping
    stream's samples after its jump pair with none of the other's (no second run comes), nor
    do the other's stamped after the jumping one's last before it. The tracker counted the
    first in a value no report carried, and the second nowhere: its fits stopped with no
    count saying what was left out. The end of the stream's report (WARN: the streams jumped
    back apart) counts both, per stream: by hand from the stamps fed, the same in any
    batching, and in a replay's summary."""
    path, messages = jumping
    scene = load_scene_file(path)
    mixed = _one_stream_jumping(messages, scene, first)
    stamps = {t: np.array([s for topic, s, _ in mixed if topic == t]) for t in TOPICS}
    jump = int(np.flatnonzero(np.diff(stamps[first]) < 0)[0])  # the last sample before it
    other = next(t for t in TOPICS if t != first)
    want = {
        first: stamps[first].shape[0] - jump - 1,
        other: int((stamps[other] > stamps[first][jump]).sum()),
    }
    assert want[first] == want[other] == 4500  # 22.5 s at 200 Hz each: a sanity check
    want_values = {
        "deck_samples_unpaired": want[TOPICS[0]],
        "body_samples_unpaired": want[TOPICS[1]],
    }
    for feed in FEEDS:
        end = _jobs(scene, mixed, feed)[-1]
        status = run_job(end).statuses[0]
        assert {k: int(status.values[k]) for k in want_values} == want_values, feed
        assert LEVEL_NAMES[status.level] == "WARN", feed
        deck, body = want[TOPICS[0]], want[TOPICS[1]]
        said = f"at the end of the stream: {deck} deck and {body} body IMU samples paired with no"
        assert status.message.startswith(said), status.message
        assert "stamps jumped back apart" in status.message
        assert end.stamp_ns == max(stamps[TOPICS[0]][-1], stamps[TOPICS[1]][-1])
    with OutputBag(tmp_path / "in", dict.fromkeys(TOPICS, IMU)) as bag:  # log times rise
        bag.write([(topic, 1 + i, raw) for i, (topic, _, raw) in enumerate(mixed)])
    summary = replay(scene, tmp_path / "in", tmp_path / "out", progress=False)
    assert summary.ageing_counts == {RESETS: 1, DROPPED: 0, **want_values}
    assert summary.to_dict()["ageing"] == {"counts": summary.ageing_counts}
    said = f"samples paired with none of the other stream's: deck {deck}, body IMU {body}"
    assert said in summary.text()
    raws = [raw for _, raw in read_raw(tmp_path / "out")["/diagnostics"]]
    _, level, message, values = statuses_named(raws, NAME)[-1]  # the end's, as the node's
    assert (LEVEL_NAMES[level], message) == ("WARN", status.message)
    assert {k: int(values[k]) for k in want_values} == want_values


TOPICS = ("/deck/imu", "/machine/imu")
