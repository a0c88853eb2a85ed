"""The body IMU against the twin, live (`engine.body_check` through `TwinStream`): the stream's
prediction is the whole record's (`engine.sensor_reading`, checked against independent
kinematics in test_body_sensor.py) at every body sample, to the bit however the two streams
come batched or interleaved; the agreement windows pass an unchanged machine and flag a
softened one; the body recorder's lag is taken out; bad body messages are counted and
skipped."""

from __future__ import annotations

import dataclasses
import warnings
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np
import pytest
from io_helpers import (
    AGEING_PUMP,
    SCENE_FILE,
    ageing_bag,
    pump_scene_file,
    statuses_named,
    unprovided_imu,
)
from scipy.signal import butter, sosfiltfilt

from mount_twin import load_scene_file
from mount_twin.analysis.calibration_parameters import calibrated_scene
from mount_twin.analysis.response import followed
from mount_twin.engine import body_check, body_matching
from mount_twin.engine.agreement import NAME
from mount_twin.engine.batch import ERROR, OK, WARN, SampleBatch
from mount_twin.engine.reading_screen import rotated
from mount_twin.engine.sensor_reading import SensorGeometry, predicted_reading
from mount_twin.errors import SceneError
from mount_twin.io.input_decoding import TimeBase
from mount_twin.io.messages import DIAGNOSTICS, DIAGNOSTICS_TOPIC, IMU, TYPESTORE
from mount_twin.io.output_encoding import Encoded, imu_messages
from mount_twin.io.output_topics import BODY_PREDICTED_TOPIC, BODY_RESIDUAL_TOPIC
from mount_twin.io.signals import Signal, ship_motion
from mount_twin.scene.description import BodySensor, Scene
from mount_twin.scene.loader import scene_from_dict
from mount_twin.scene.yaml_reading import read_scene_yaml
from mount_twin.stream import TwinStream

RATE = 200.0
NS0 = 1_700_000_000_250_000_000
Messages = list[tuple[str, int, bytes]]


def _pump(**sensor: object) -> Scene:
    scene = load_scene_file(SCENE_FILE)
    body = BodySensor(position=(0.8, 0.3, 1.0), window_s=5.0, **sensor)  # type: ignore[arg-type]
    return dataclasses.replace(
        scene, body_sensor=body, input=dataclasses.replace(scene.input, gyro_filter="none")
    )


def _deck(total: float = 20.0) -> Signal:
    """Ship motion with the machinery's broadband vibration (1-40 Hz, 0.3 m/s² RMS)."""
    sea = ship_motion(rate_hz=RATE, total=total)
    sos = butter(4, [1.0, 40.0], btype="band", fs=RATE, output="sos")
    vib = sosfiltfilt(sos, np.random.default_rng(5).normal(0, 1, sea.accel.shape), axis=0)
    return Signal(sea.t, sea.accel + 0.3 * vib / vib.std(axis=0), sea.gyro)


def _stamps(deck: Signal) -> np.ndarray:
    return NS0 + np.round(deck.t * 1e9).astype(np.int64)


def _whole_record(
    scene: Scene, deck: Signal, ns: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """(row stamps s, (k, 6) prediction) of the scene's twin on the whole deck record at once
    (stamped `ns`, by default `_stamps`), its stamps on the stream's time base."""
    frames = [scene.input.frame_id] * deck.t.shape[0]
    t = TimeBase.at(NS0).seconds(_stamps(deck) if ns is None else ns)
    model, out = followed(scene, SampleBatch(t, deck.accel, deck.gyro, frames), "deck")
    rate = rotated(deck.gyro, model.sensor_rotation)
    assert scene.body_sensor is not None
    pose = (out.position, out.quaternion)
    f, w = predicted_reading(
        SensorGeometry.of(scene, scene.body_sensor), out.stamps, pose, out.wrenches, rate
    )
    return out.stamps, np.hstack([f, w])


def _body_raws(stamps_ns: np.ndarray, values: np.ndarray, frame: str = "") -> list[bytes]:
    return [r for _, r in imu_messages(stamps_ns, values[:, :3], values[:, 3:], frame)]


def _interleaved(
    scene: Scene,
    deck_raws: list[bytes],
    deck_ns: np.ndarray,
    body: tuple[list[bytes], np.ndarray],
    stream: TwinStream | None = None,
) -> Messages:
    """Message by message, each body sample once the deck sample at or after its stamp went
    (into `stream`, by default a new one)."""
    stream = TwinStream(scene) if stream is None else stream
    out, j = [], 0
    for raw, ns in zip(deck_raws, deck_ns.tolist(), strict=True):
        out += stream.process([raw])
        while j < len(body[0]) and body[1][j] <= ns:
            out += stream.process_body([body[0][j]])
            j += 1
    return out + stream.process_body(body[0][j:]) + stream.finish()


def _chunked(
    scene: Scene,
    deck_raws: list[bytes],
    body_raws: list[bytes],
    size: int,
    body_first: bool,
    stream: TwinStream | None = None,
) -> Messages:
    """In chunks of `size` of each stream, the body's chunk before or after the deck's (into
    `stream`, by default a new one)."""
    stream = TwinStream(scene) if stream is None else stream
    out: Messages = []
    for i in range(0, max(len(deck_raws), len(body_raws)), size):
        steps: list[Callable[[], Messages]] = [
            lambda i=i: stream.process(deck_raws[i : i + size]),
            lambda i=i: stream.process_body(body_raws[i : i + size]),
        ]
        for step in reversed(steps) if body_first else steps:
            out += step()
    return out + stream.finish()


def _imu_values(out: Messages, topic: str) -> tuple[np.ndarray, np.ndarray]:
    msgs = [TYPESTORE.deserialize_cdr(raw, IMU) for t, _, raw in out if t == topic]
    stamps = np.array([m.header.stamp.sec * 10**9 + m.header.stamp.nanosec for m in msgs])
    values = [
        [getattr(v, a) for v in (m.linear_acceleration, m.angular_velocity) for a in "xyz"]
        for m in msgs
    ]
    return stamps, np.array(values).reshape(-1, 6)


def _windows(out: Messages) -> list[tuple[int, str, dict[str, str]]]:
    """(level, message, values) of each body sensor status on /diagnostics."""
    found = []
    for topic, _, raw in out:
        if topic == DIAGNOSTICS_TOPIC:
            for s in TYPESTORE.deserialize_cdr(raw, DIAGNOSTICS).status:
                if s.name == NAME:
                    found.append((s.level, s.message, {kv.key: kv.value for kv in s.values}))
    return found


def _deck_raws(scene: Scene, deck: Signal) -> list[bytes]:
    return [r for _, r in imu_messages(_stamps(deck), deck.accel, deck.gyro, "deck_imu")]


def _deck_silent_between(
    t0: float, t1: float
) -> tuple[Scene, np.ndarray, np.ndarray, list[bytes], list[bytes], np.ndarray]:
    """The pump under 12 s of deck record at 200 Hz, the deck silent from t0 to t1 s (a gap):
    (scene, every sample's stamp ns, the silent ones, the deck's messages sent, the body
    IMU's messages at every stamp, the whole record's body readings)."""
    scene, deck = _pump(), _deck(12.0)
    _, whole = _whole_record(scene, deck)
    ns = _stamps(deck)
    silent = (deck.t >= t0) & (deck.t < t1)
    deck_raws = [r for r, s in zip(_deck_raws(scene, deck), silent, strict=True) if not s]
    return scene, ns, silent, deck_raws, _body_raws(ns, whole), whole


def test_the_live_prediction_is_the_whole_records_at_every_body_sample() -> None:
    """A body IMU sampled at the deck's stamps: each sample's prediction is, to the bit, the
    whole record's at that row (the first and last rows by one-sided differences), and its
    residual the sample minus it."""
    scene, deck = _pump(), _deck(6.0)
    _, whole = _whole_record(scene, deck)
    ns = _stamps(deck)
    measured = whole + np.random.default_rng(2).normal(0.0, 0.01, whole.shape)
    out = _interleaved(scene, _deck_raws(scene, deck), ns, (_body_raws(ns, measured), ns))
    got_ns, predicted = _imu_values(out, BODY_PREDICTED_TOPIC)
    _, residual = _imu_values(out, BODY_RESIDUAL_TOPIC)
    assert np.array_equal(got_ns, ns)
    assert np.array_equal(predicted, whole)
    assert np.array_equal(residual, measured - whole)


def test_batching_and_interleaving_do_not_change_a_bit() -> None:
    """Every body message (prediction, residual, window report) is the same bytes whether the
    two streams come message by message, or in chunks with the body's first or last."""
    scene, deck = _pump(), _deck(13.5)  # the last window, 3.5 s, is judged too
    t, whole = _whole_record(scene, deck)
    ns = _stamps(deck)[::2] + 1_234_567  # a slower body IMU, between the deck's samples
    measured = np.stack([np.interp(TimeBase.at(NS0).seconds(ns), t, v) for v in whole.T], 1)
    body = _body_raws(ns, measured)
    deck_raws = _deck_raws(scene, deck)
    runs = [
        _interleaved(scene, deck_raws, _stamps(deck), (body, ns)),
        _chunked(scene, deck_raws, body, 700, body_first=True),
        _chunked(scene, deck_raws, body, 333, body_first=False),
    ]
    kept = [[m for m in run if m[0] != DIAGNOSTICS_TOPIC or NAME.encode() in m[2]] for run in runs]
    body_msgs = [
        [m for m in k if m[0] in (BODY_PREDICTED_TOPIC, BODY_RESIDUAL_TOPIC)] for k in kept
    ]
    assert len(body_msgs[0]) == 2 * ns.shape[0]
    assert body_msgs[1] == body_msgs[0] and body_msgs[2] == body_msgs[0]
    reports = [sorted(m for m in k if m[0] == DIAGNOSTICS_TOPIC) for k in kept]
    assert len(reports[0]) == 3 and reports[1] == reports[0] and reports[2] == reports[0]


def _measured(machine: Scene, deck: Signal, lag_s: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """(stamps ns, (k, 6) readings) of a body IMU on `machine` recorded `lag_s` late, with a
    MEMS IMU's noise (0.01 m/s², 0.001 rad/s)."""
    t, truth = _whole_record(machine, deck)
    ns = _stamps(deck)[20:]
    motion_t = TimeBase.at(NS0).seconds(ns) - lag_s
    measured = np.stack([np.interp(motion_t, t, v) for v in truth.T], 1)
    rng = np.random.default_rng(3)
    measured += np.hstack(
        [rng.normal(0, 0.01, (ns.shape[0], 3)), rng.normal(0, 1e-3, (ns.shape[0], 3))]
    )
    return ns, measured


def _judged(scene: Scene, machine: Scene, deck: Signal, lag_s: float = 0.0) -> Messages:
    """The stream of `scene` compared with a body IMU on `machine` (the same twin with its
    changes) recorded `lag_s` late, with a MEMS IMU's noise (0.01 m/s², 0.001 rad/s)."""
    ns, measured = _measured(machine, deck, lag_s)
    return _chunked(scene, _deck_raws(scene, deck), _body_raws(ns, measured), 500, False)


def test_an_unchanged_machine_agrees_and_one_on_softened_mounts_is_an_error() -> None:
    """20 s of ship motion with machinery vibration, windows of 5 s: the machine the scene
    describes agrees in every window (worst NRMS in 0-10 Hz below 0.1); the same machine with
    every mount at 0.7× stiffness is an ERROR in every window, and with one mount of the eight
    at 0.7× at least a WARN in every window."""
    scene, deck = _pump(), _deck()
    same = _windows(_judged(scene, scene, deck))
    softened = _windows(_judged(scene, calibrated_scene(scene, {"stiffness": 0.7}), deck))
    assert len(same) == len(softened) == 4
    for level, message, values in same:
        assert level == OK, message
        judged = [float(v) for k, v in values.items() if k.startswith("nrms_f")]
        assert judged and max(judged) < 0.1, values
    assert all(level == ERROR and "disagree" in message for level, message, _ in softened)
    one = _windows(_judged(scene, calibrated_scene(scene, {"stiffness:fl": 0.7}), deck))
    assert len(one) == 4 and all(level >= WARN for level, _, _ in one)  # one mount of eight


def test_the_body_recorders_lag_is_taken_out() -> None:
    """A body IMU 12 ms late (2.4 samples): compared as if on time, the unchanged machine
    WARNs or ERRs; with body_sensor.lag_s 0.012 it agrees as well as one on time."""
    deck, machine = _deck(), _pump()
    late = [_windows(_judged(_pump(lag_s=lag), machine, deck, 0.012)) for lag in (0.0, 0.012)]
    worst = [max(float(v[f"nrms_{a}"]) for _, _, v in w for a in ("fx", "fy", "fz")) for w in late]
    assert any(level >= WARN for level, _, _ in late[0])
    assert all(level == OK for level, _, _ in late[1])
    assert worst[1] < 0.1 < worst[0]


def test_bad_body_messages_are_counted_skipped_and_reported() -> None:
    """Garbage, NaN, an unset stamp, a stamp going back and another frame_id: each counted under
    its reason, the window WARNs naming them, and every good sample is still compared."""
    scene, deck = _pump(frame_id="pump_imu"), _deck(6.0)
    _, whole = _whole_record(scene, deck)
    ns = _stamps(deck)
    good = _body_raws(ns, whole, "pump_imu")
    nan = whole[100:103].copy()
    nan[:, 1] = np.nan
    bad = [
        b"\x00\x01garbage",
        *_body_raws(ns[100:103], nan, "pump_imu"),
        _body_raws(np.array([0]), whole[:1], "pump_imu")[0],
        good[50],
        *_body_raws(ns[104:106], whole[104:106], "other_imu"),
    ]
    stream = TwinStream(scene)
    out = stream.process(_deck_raws(scene, deck))
    for raw in [*good[:100], *bad, *good[106:]]:
        out += stream.process_body([raw])
    out += stream.finish()
    assert stream.body is not None
    counts = stream.body.counts
    assert counts["received"] == 100 + len(bad) + len(good) - 106
    assert counts["accepted"] == len(good) - 6
    assert counts["rejected_undecodable"] == 1 and counts["rejected_nonfinite"] == 3
    assert counts["rejected_nonpositive_stamp"] == 1 and counts["rejected_stamp_back"] == 1
    assert counts["rejected_wrong_frame_id"] == 2
    assert _imu_values(out, BODY_RESIDUAL_TOPIC)[0].shape[0] == len(good) - 6
    first = _windows(out)[0]
    assert first[0] == WARN and "rejected_wrong_frame_id 2" in first[1]


def test_a_reading_marked_not_provided_is_never_compared_as_a_value() -> None:
    """REP-145: an Imu whose covariance[0] is -1 has no such reading. Every tenth body sample
    marked (alternately its acceleration, holding zeros, and its rate, holding 5 rad/s) was
    compared as a value (a free fall, a spin), then skipped whole. Now such a sample is
    compared on its other reading only: each field's figures are those of the stream without
    the samples marking it, the residual's marked reading is NaN, and the marks are counted
    (unprovided_acceleration, unprovided_angular_velocity) and said in each window, which they
    do not make a WARN."""
    scene, deck = _pump(), _deck()
    ns, measured = _measured(scene, deck)
    raws = _body_raws(ns, measured)
    fields = {5: "linear_acceleration", 15: "angular_velocity"}
    marked = [
        unprovided_imu([raw], fields[i % 20])[0] if i % 20 in fields else raw
        for i, raw in enumerate(raws)
    ]
    without = [[raw for i, raw in enumerate(raws) if i % 20 != k] for k in fields]
    deck_raws = _deck_raws(scene, deck)
    runs = [_chunked(scene, deck_raws, body, 500, False) for body in (marked, *without)]
    (stamps, residual), *_ = (_imu_values(out, BODY_RESIDUAL_TOPIC) for out in runs)
    _, truth = _imu_values(_chunked(scene, deck_raws, raws, 500, False), BODY_RESIDUAL_TOPIC)
    assert np.array_equal(stamps, ns)
    at = np.arange(ns.shape[0]) % 20
    assert np.isnan(residual[at == 5, :3]).all() and np.isnan(residual[at == 15, 3:]).all()
    given = np.ones(residual.shape, bool)
    given[at == 5, :3] = given[at == 15, 3:] = False
    assert np.array_equal(residual[given], truth[given])
    windows = [_windows(out) for out in runs]
    assert len(windows[0]) == len(windows[1]) == len(windows[2]) == 4
    for (level, message, values), *alone in zip(*windows, strict=True):
        assert level == OK, message
        for i, axes in enumerate(("f", "w")):  # without the samples marking that reading
            assert {k: v for k, v in values.items() if k[:-1].endswith(f"_{axes}")} == {
                k: v for k, v in alone[i][2].items() if k[:-1].endswith(f"_{axes}")
            }
            assert values[f"samples_{('specific_force', 'rate')[i]}"] == alone[i][2]["samples"]
        assert "specific force judged on " in message and "rate judged on " in message
    stream = TwinStream(scene)
    stream.process(deck_raws)
    stream.process_body(marked)
    stream.finish()
    assert stream.body is not None
    counts = stream.body.counts
    assert counts["unprovided_acceleration"] == counts["unprovided_angular_velocity"] == 199
    assert counts["accepted"] == counts["received"] == len(raws) == counts["compared"]
    assert counts["compared_specific_force"] == counts["compared_rate"] == len(raws) - 199


def test_a_body_imu_whose_every_message_is_rejected_is_reported_window_by_window() -> None:
    """Live, it was reported only at the node's shutdown: windows close on compared samples.
    Now each window of the body's own stamps in which none was taken is a WARN when the next
    begins, the same in any batching; a window where one was taken is not."""
    scene, deck = _pump(frame_id="pump_imu"), _deck(12.0)
    _, whole = _whole_record(scene, deck)
    ns = _stamps(deck)
    wrong = _body_raws(ns, whole, "other_imu")
    body = [
        *wrong[:1000],
        b"\x00\x01garbage",
        *wrong[1000:1100],
        *_body_raws(ns, whole, "pump_imu")[1100:1101],
        *wrong[1101:],
    ]
    deck_raws, runs = _deck_raws(scene, deck), {}
    for chunk in (1, 7, len(body)):
        stream = TwinStream(scene)
        out = []
        for k in range(0, len(body), chunk):
            out += stream.process(deck_raws[k : k + chunk])
            out += stream.process_body(body[k : k + chunk])
        runs[chunk] = (_windows(out), stream.take_body_reports())
    assert runs[1] == runs[7] == runs[len(body)]
    ((level, message, values),) = runs[1][0]  # 5–10 s has the one taken, 10–12 s is open
    assert level == WARN
    assert message == (
        "none of the 1001 body IMU messages over 5 s of their stamps was taken: "
        "rejected_undecodable 1, rejected_wrong_frame_id 1000 (body_sensor.frame_id is "
        "'pump_imu')"
    )
    assert values["body_rejected_wrong_frame_id"] == "1000"


def test_messages_not_compared_are_counted_in_their_own_window_however_interleaved() -> None:
    """Samples inside a gap of the twin's rows (the deck silent 6–7 s: a restart) and rejected
    messages (an unset stamp and garbage after the sample at 5.1 s) were counted in the window
    open when they were counted: the first or the second, by how the two streams were fed
    (0 or 2 rejected in 0–5 s, in_gap moving with them). A sample counts where its stamp
    falls, a rejected message where the accepted sample after it does."""
    scene, ns, silent, deck_raws, body, whole = _deck_silent_between(6.0, 7.0)
    body[1020:1020] = [_body_raws(np.array([0]), whole[:1])[0], b"\x00\x01garbage"]
    runs = [
        _interleaved(scene, deck_raws, ns[~silent], (body, np.insert(ns, 1020, [ns[1020]] * 2))),
        _chunked(scene, deck_raws, body, 333, body_first=False),
    ]
    deck_first = TwinStream(scene)
    runs.append(
        deck_first.process(deck_raws) + deck_first.process_body(body) + deck_first.finish()
    )
    first_body = TwinStream(scene)
    runs.append(
        first_body.process_body(body) + first_body.process(deck_raws) + first_body.finish()
    )
    windows = [sorted(_windows(run), key=lambda w: w[1]) for run in runs]
    assert all(w == windows[0] for w in windows[1:])
    # and the samples at the rows either side of the gap are compared in every feeding (the
    # one at its last row was in_gap once the row after it was published, the one at its
    # first row in_gap until the row after that was)
    topics = (BODY_PREDICTED_TOPIC, BODY_RESIDUAL_TOPIC)
    body_msgs = [[m for m in run if m[0] in topics] for run in runs]
    assert all(b == body_msgs[0] for b in body_msgs[1:])
    compared = _imu_values(runs[0], BODY_PREDICTED_TOPIC)[0]
    assert {ns[~silent][1199], ns[~silent][1200]} <= set(compared.tolist())  # 5.995, 7.0 s
    second = next(v for _, _, v in windows[0] if int(v["body_in_gap"]))
    assert second["body_rejected_nonpositive_stamp"] == "1"
    assert second["body_rejected_undecodable"] == "1"
    assert int(second["body_in_gap"]) >= 190  # 6–7 s at 200 Hz, the rows around it aside
    firsts = [v for _, _, v in windows[0] if v is not second]
    assert all(v["body_rejected_undecodable"] == "0" for v in firsts)


def test_the_live_one_message_paths_are_the_bulk_ones_on_a_hostile_stream() -> None:
    """A wake-up of one message takes paths of its own, as Python floats on its one row and
    its one sample (`sensor_reading.predicted_reading` of one row, `Matcher.take` and
    `Windows.add` of one sample): fed a message at a time (the deck's first, or the body's, or
    the body's 0.75 s behind), every body message and window report is the same bytes as fed
    in chunks or whole (the arrays' paths), with the same counts, through a gap in the deck
    (samples in_gap), both streams' stamps jumping back, a body recorder 1.3 ms late (each
    run's first sample before the twin, the others between rows) tilted on the body, and body
    messages not finite, of another frame_id, stamped back and not CDR."""
    scene = _pump(frame_id="pump_imu", lag_s=0.0013, orientation_rpy=(0.1, -0.2, 0.3))
    deck = _deck(12.0)
    ns = _stamps(deck) - np.where(deck.t >= 8.0, 6_000_000_000, 0)  # back 6 s at 8 s
    silent = (deck.t >= 3.0) & (deck.t < 3.7)  # longer than input.max_gap_s
    deck_steps = [[r] for _, r in imu_messages(ns, deck.accel, deck.gyro, "deck_imu")]
    values = np.random.default_rng(8).normal(0.0, 1.0, (ns.shape[0], 6))
    values[300:303, 4] = np.nan
    body_ns = ns - 1_200_000  # the motion 2.5 ms before each deck stamp: between rows
    body_steps = [[r] for r in _body_raws(body_ns, values, "pump_imu")]
    for i in (500, 501, 1900):
        body_steps[i] = _body_raws(body_ns[i : i + 1], values[i : i + 1], "other_imu")
    body_steps[700].append(body_steps[690][0])  # stamped back
    body_steps[1000].insert(0, b"\x00\x01garbage")
    deck_steps = [[] if quiet else step for step, quiet in zip(deck_steps, silent, strict=True)]
    deck_raws = [r for step in deck_steps for r in step]
    body_raws = [r for step in body_steps for r in step]

    def stepwise(body_first: bool, behind: int = 0) -> tuple[Messages, TwinStream]:
        """Step by step, each message alone, a step's body messages before or after its deck's,
        those of `behind` steps before (past the gap: its samples decided one by one)."""
        stream, out = TwinStream(scene), []
        for k in range(len(deck_steps) + behind):
            feeds = [(stream.process, [r]) for r in deck_steps[k]] if k < len(deck_steps) else []
            body = (
                [(stream.process_body, [r]) for r in body_steps[k - behind]] if k >= behind else []
            )
            for feed, raws in body + feeds if body_first else feeds + body:
                out += feed(raws)
        return out + stream.finish(), stream

    chunks, whole = TwinStream(scene), TwinStream(scene)
    runs = [
        stepwise(body_first=False),
        stepwise(body_first=True),
        stepwise(body_first=False, behind=150),
        (_chunked(scene, deck_raws, body_raws, 7, False, chunks), chunks),
        (whole.process(deck_raws) + whole.process_body(body_raws) + whole.finish(), whole),
    ]
    topics = (BODY_PREDICTED_TOPIC, BODY_RESIDUAL_TOPIC)
    body_msgs = [[m for m in run if m[0] in topics] for run, _ in runs]
    windows = [sorted(_windows(run), key=lambda w: w[1]) for run, _ in runs]
    counts = [dict(stream.body.counts) for _, stream in runs if stream.body is not None]
    assert all(b == body_msgs[0] for b in body_msgs[1:])
    assert all(w == windows[0] for w in windows[1:]) and len(windows[0]) >= 2
    assert all(c == counts[0] for c in counts[1:])
    expected = {"rejected_nonfinite": 3, "rejected_wrong_frame_id": 3, "rejected_stamp_back": 1}
    assert {k: counts[0][k] for k in expected} == expected
    assert counts[0]["rejected_undecodable"] == 1 and counts[0]["reset_stamp_jumped_back"] == 1
    assert counts[0]["in_gap"] >= 130 and counts[0]["before_twin"] == 2
    assert len(body_msgs[0]) == 2 * counts[0]["compared"] > 2 * 2200


def test_a_deck_sample_rejected_for_inf_warns_nothing_with_a_body_sensor() -> None:
    """Its gyro's inf times the sensor rotation's zeros printed numpy's RuntimeWarning
    ("invalid value encountered in multiply") on every replay of such a record."""
    scene, deck = _pump(), _deck(1.0)
    gyro = deck.gyro.copy()
    gyro[50] = np.inf
    raws = [r for _, r in imu_messages(_stamps(deck), deck.accel, gyro, "deck_imu")]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        stream = TwinStream(scene)
        stream.process(raws)
    assert stream.engine.counts["rejected_non_finite"] == 1


def test_a_body_sensor_needs_every_samples_wrenches() -> None:
    """Decimated rows hold each wrench component's peak: a scene with a body sensor and
    outputs.decimation past 1 fails at load, naming the key."""
    data = read_scene_yaml(SCENE_FILE)
    data["body_sensor"] = {"position": [0.8, 0.3, 1.0]}
    data["outputs"]["decimation"] = 5
    with pytest.raises(SceneError, match=r"outputs\.decimation: 5 with a body_sensor"):
        scene_from_dict(data, "pump")


def test_bad_body_messages_are_reported_in_the_same_window_in_any_batching() -> None:
    """Rejected body messages are counted at their place in the stream: windows read the same
    however the body messages come batched. Counted at a batch's start, ten garbage messages
    among the second window's samples (5–10 s, 200 Hz) were reported in the first window by one
    batch, in the second by batches of 1 or 7."""
    scene, deck = _pump(frame_id="pump_imu"), _deck(12.0)
    _, whole = _whole_record(scene, deck)
    good = _body_raws(_stamps(deck), whole, "pump_imu")
    garbage = set(range(1100, 2000, 90))
    body = [b"\x00\x01garbage" if i in garbage else raw for i, raw in enumerate(good)]
    windows = {}
    for chunk in (1, 7, len(body)):
        stream = TwinStream(scene)
        out = stream.process(_deck_raws(scene, deck))
        for k in range(0, len(body), chunk):
            out += stream.process_body(body[k : k + chunk])
        out += stream.finish()
        windows[chunk] = _windows(out)
    assert windows[1] == windows[7] == windows[len(body)]
    counted = [int(values["body_rejected_undecodable"]) for _, _, values in windows[1]]
    assert counted == [0, len(garbage)]


def test_under_gyro_filter_ignore_the_ageing_tracker_takes_a_deck_sample_whose_rate_is_marked(
    tmp_path: Path,
) -> None:
    """Under input.gyro_filter: ignore the twin reads no rate, so it takes a deck sample whose
    rate is marked not provided (REP-145); the ageing tracker dropped it, its window then short
    of the samples the twin ran on. It takes the same samples as from the unmarked record."""
    sections = {**AGEING_PUMP, "input": {"gyro_filter": "ignore"}}
    scene = load_scene_file(pump_scene_file(tmp_path, **sections))
    messages = ageing_bag(tmp_path / "in", scene, 23.0, 30.0, "/machine/imu")
    deck = [raw for topic, _, raw in messages if topic == "/deck/imu"]
    body = [raw for topic, _, raw in messages if topic != "/deck/imu"]
    marked = [
        unprovided_imu([raw], "angular_velocity")[0] if i % 10 == 3 else raw
        for i, raw in enumerate(deck)
    ]
    windows = []
    for feed in (deck, marked):
        stream = TwinStream(scene)
        stream.process(feed)
        stream.process_body(body)
        (job,) = stream.take_ageing_jobs()
        windows.append(job.records[0])
    assert np.array_equal(windows[1].t, windows[0].t)
    assert np.array_equal(windows[1].accel, windows[0].accel)


def _gained(
    machine: Scene, deck: Signal, gains: tuple[float, float]
) -> tuple[np.ndarray, np.ndarray]:
    """(stamps ns, (k, 6) readings) of a body IMU on `machine` at the deck's stamps (from the
    21st), reading its true specific force × gains[0] and its true rate × gains[1], noiseless:
    each residual is then (gain − 1) × the truth, so on any set of samples and in any band an
    axis's normalised RMS error is (gain − 1) / gain exactly."""
    _, truth = _whole_record(machine, deck)
    ns = _stamps(deck)[20:]
    return ns, truth[20:] * np.repeat(gains, 3)


def _window_samples(ns: np.ndarray, provides: np.ndarray, window_s: float) -> list[list[int]]:
    """Per window of `window_s` from the first stamp: [samples, of them providing the specific
    force, the rate] (`provides`: (k, 2) bool), counted from the stamps."""
    index = (ns - ns[0]) // round(window_s * 1e9)
    return [
        [int((index == i).sum()), *(int(v) for v in provides[index == i].sum(axis=0))]
        for i in np.unique(index).tolist()
    ]


def test_an_accelerometer_only_body_imu_is_judged_on_its_specific_force() -> None:
    """A body IMU marking its angular velocity not provided on every message (REP-145, an
    accelerometer alone, holding 5 rad/s) had every sample rejected (no_angular_velocity): no
    window was ever judged. Reading 1.5 × the true specific force, each window now judges fx, fy
    and fz at (1.5 − 1) / 1.5 = 1/3 (a WARN past 0.3), its rate not judged and said so, on the
    window's every sample; the residual's rate is marked not provided, NaN."""
    scene, deck = _pump(), _deck()
    ns, measured = _gained(scene, deck, (1.5, 1.0))
    raws = unprovided_imu(_body_raws(ns, measured), "angular_velocity")
    out = _chunked(scene, _deck_raws(scene, deck), raws, 500, False)
    windows = _windows(out)
    want = _window_samples(ns, np.tile([True, False], (ns.shape[0], 1)), 5.0)
    assert len(windows) == len(want) == 4
    for (level, message, values), (n, n_f, n_w) in zip(windows, want, strict=True):
        assert level == WARN, message
        for axis in ("fx", "fy", "fz"):  # the figures' 4 digits
            assert values[f"nrms_{axis}"] == values[f"nrms_broadband_{axis}"] == "0.3333"
        for axis in ("wx", "wy", "wz"):
            assert values[f"nrms_{axis}"] == "not judged"
        assert (values["samples"], values["samples_specific_force"]) == (str(n), str(n_f))
        assert values["samples_rate"] == str(n_w) == "0"
        assert f"rate not judged: not provided in {n} of {n} samples" in message
        assert "body messages not compared" not in message
    stamps, residual = _imu_values(out, BODY_RESIDUAL_TOPIC)
    assert np.array_equal(stamps, ns)  # every sample compared, on its specific force
    assert np.isnan(residual[:, 3:]).all()
    np.testing.assert_allclose(residual[:, :3], 0.5 / 1.5 * measured[:, :3], rtol=1e-9, atol=1e-12)
    marks = [
        TYPESTORE.deserialize_cdr(raw, IMU).angular_velocity_covariance[0]
        for topic, _, raw in out
        if topic == BODY_RESIDUAL_TOPIC
    ]
    assert set(marks) == {-1.0}


def test_a_body_imu_marking_either_reading_is_judged_field_by_field_in_any_batching() -> None:
    """Every 7th body message marks its acceleration not provided, every 5th its rate (every
    35th both: nothing to compare, rejected as no_reading); the IMU reads 1.5 × the true
    specific force and 1.25 × the true rate. Each field is judged on the samples providing it,
    at its own exact error (1/3, and 0.25 / 1.25 = 0.2), each window counting them; the marks
    are counted; and the messages are the same bytes however the two streams come."""
    scene, deck = _pump(), _deck()
    ns, measured = _gained(scene, deck, (1.5, 1.25))
    raws = _body_raws(ns, measured)
    place = np.arange(ns.shape[0])
    provides = np.column_stack([place % 7 != 3, place % 5 != 2])
    fields = ("linear_acceleration", "angular_velocity")
    for i in np.flatnonzero(~provides.all(axis=1)).tolist():
        for field, given in zip(fields, provides[i], strict=True):
            if not given:
                raws[i] = unprovided_imu([raws[i]], field)[0]
    deck_raws, deck_ns = _deck_raws(scene, deck), _stamps(deck)
    runs = [
        _interleaved(scene, deck_raws, deck_ns, (raws, ns)),
        _chunked(scene, deck_raws, raws, 700, body_first=True),
        _chunked(scene, deck_raws, raws, 333, body_first=False),
    ]
    kept = [[m for m in run if m[0] != DIAGNOSTICS_TOPIC or NAME.encode() in m[2]] for run in runs]
    assert all(sorted(k) == sorted(kept[0]) for k in kept[1:])
    windows = _windows(runs[0])
    taken = provides.any(axis=1)
    want = _window_samples(ns[taken], provides[taken], 5.0)
    assert len(windows) == len(want) == 4
    for (level, message, values), (n, n_f, n_w) in zip(windows, want, strict=True):
        assert level == WARN, message  # the specific force's 1/3
        exact = {"f": "0.3333", "w": "0.2"}  # the figures' 4 digits
        for axis in ("fx", "fy", "fz", "wx", "wy", "wz"):
            assert values[f"nrms_broadband_{axis}"] == exact[axis[0]]
            # in the band, where the body moved past the floor (wz's yaw does not)
            assert values[f"nrms_{axis}"] in (exact[axis[0]], "not judged")
        assert (values["nrms_fx"], values["nrms_wx"]) == ("0.3333", "0.2")  # both judged
        assert [values[f"samples{k}"] for k in ("", "_specific_force", "_rate")] == [
            str(n),
            str(n_f),
            str(n_w),
        ]
        assert f"specific force judged on {n_f} of {n} samples" in message
        assert f"rate judged on {n_w} of {n} samples" in message
    assert sum(int(v["body_rejected_no_reading"]) for _, _, v in windows) == (~taken).sum()
    stream = TwinStream(scene)
    stream.process(deck_raws)
    stream.process_body(raws)
    stream.finish()
    assert stream.body is not None
    counts = stream.body.counts
    assert counts["accepted"] == taken.sum() == counts["compared"]
    assert counts["compared_specific_force"] == provides[:, 0].sum()
    assert counts["compared_rate"] == provides[:, 1].sum()
    assert counts["unprovided_acceleration"] == (taken & ~provides[:, 0]).sum()
    assert counts["unprovided_angular_velocity"] == (taken & ~provides[:, 1]).sum()
    assert counts["rejected_no_reading"] == (~taken).sum()


def test_stamps_jumping_back_restart_the_comparison_in_any_batching() -> None:
    """Both streams' stamps jump back 8 s at 6 s (a bag played with --loop, a recorder's clock
    reset): the twin restarted, the body check did not. Every body message after the jump was
    rejected stamp_back (its stamps behind the last accepted), and the prediction ran on rows
    whose stamps went back. Now the body stream restarts as the deck's does: each body sample
    (the twin's own reading on each run, from a twin on that run alone) is compared with its
    exact prediction, the window before the jump is judged and the first one after it too
    (NRMS ≈ 0, the restart counted in its values), the same however the streams come."""
    scene, deck = _pump(), _deck(12.0)
    jumped = deck.t >= 6.0
    ns = _stamps(deck) - np.where(jumped, 8_000_000_000, 0)
    truth = np.vstack(
        [
            _whole_record(scene, Signal(deck.t[k], deck.accel[k], deck.gyro[k]), ns[k])[1]
            for k in (~jumped, jumped)
        ]
    )
    body = _body_raws(ns, truth)
    deck_raws = [r for _, r in imu_messages(ns, deck.accel, deck.gyro, "deck_imu")]
    runs, streams = _fed_five_ways(scene, deck_raws, ns, body, ns)
    for stream in streams:
        assert stream.body is not None
        counts = stream.body.counts
        assert counts["rejected_stamp_back"] == 0 and counts["reset_stamp_jumped_back"] == 1
        assert counts["accepted"] == counts["compared"] == ns.shape[0]
    stamps, predicted = _imu_values(runs[0], BODY_PREDICTED_TOPIC)
    assert np.array_equal(stamps, ns)
    assert np.array_equal(predicted, truth)  # each run's ends by one-sided differences
    windows = _windows(runs[0])  # 0–5 s, then -2–3 s (each run's last second: too short)
    assert [v["body_reset_stamp_jumped_back"] for _, _, v in windows] == ["0", "1"]
    for level, message, values in windows:
        assert level == OK and "agree" in message, message
        nrms = [float(values[f"nrms_broadband_{a}"]) for a in ("fx", "fy", "fz", "wx", "wy")]
        assert max(nrms) < 1e-6, values
        assert values["samples"] == str(1000)


def test_a_body_imu_whose_every_message_is_rejected_is_reported_after_a_jump_back() -> None:
    """Every body message of another frame_id, both streams' stamps jumping back 8 s at 6 s:
    the windows of the body's own stamps stayed in the one open at the jump (5–10 s) until the
    stamps passed 10 s again, so nothing more was said. Now the jump ends that window (5–6 s,
    said) and a grid starts afresh from the first message after it (-2–3 s, said when 3–4 s
    begins), the same in any batching."""
    scene, deck = _pump(frame_id="pump_imu"), _deck(12.0)
    ns = _stamps(deck) - np.where(deck.t >= 6.0, 8_000_000_000, 0)
    body = _body_raws(ns, np.zeros((ns.shape[0], 6)), "other_imu")
    deck_raws = [r for _, r in imu_messages(ns, deck.accel, deck.gyro, "deck_imu")]
    runs = {}
    for chunk in (1, 7, len(body)):
        stream, out = TwinStream(scene), []
        for k in range(0, len(body), chunk):
            out += stream.process(deck_raws[k : k + chunk])
            out += stream.process_body(body[k : k + chunk])
        runs[chunk] = _windows(out)
    assert runs[1] == runs[7] == runs[len(body)]
    counted = [int(values["body_rejected_wrong_frame_id"]) for _, _, values in runs[1]]
    assert counted == [1000, 200, 1000]  # 0–5 s, 5–6 s, -2–3 s at 200 Hz
    assert all(level == WARN for level, _, _ in runs[1])


@pytest.mark.parametrize("first", ["deck", "body"])
def test_stamps_jumping_back_apart_are_said_and_not_held(first: str) -> None:
    """One stream's stamps jump back 8 s at 6 s, the other's go on to 12 s (a body IMU on
    another clock, a recorder restarted): the runs never pair again. Every later body sample
    was counted unanswered (the deck jumped) or held waiting for a twin run that never came
    (the body jumped), and nothing said why. Now, once the other stream's stamps pass the
    jump by more than input.back_jump_reset_s (1 s), a WARN says which stream jumped back and
    when, and the body samples past that pairing are counted jumped_back_apart, held no more;
    the same however the streams come."""
    scene, deck = _pump(), _deck(12.0)
    steady = _stamps(deck)
    jumped = steady - np.where(deck.t >= 6.0, 8_000_000_000, 0)
    deck_ns, body_ns = (jumped, steady) if first == "deck" else (steady, jumped)
    body = _body_raws(body_ns, np.zeros((steady.shape[0], 6)))
    deck_raws = [r for _, r in imu_messages(deck_ns, deck.accel, deck.gyro, "deck_imu")]
    runs, streams = _fed_five_ways(scene, deck_raws, deck_ns, body, body_ns)
    # the last stamp before the jump on the twin's time base (from the first deck stamp's
    # whole second)
    end = 6.0 - 1 / RATE + NS0 % 10**9 * 1e-9
    apart = [w for w in _windows(runs[0]) if "jumped back apart" in w[1]]
    assert len(apart) == 1
    level, message, values = apart[0]
    assert level == WARN
    assert values == {"jumped_back_first": first, "jumped_back_at_s": f"{end:.3f}"}
    name = {"deck": "the deck's", "body": "the body IMU's"}[first]
    assert f"{name} jumped back at {end:.3f} s" in message
    # the deck jumped: body samples up to its last stamp compared, those within 1 s after it
    # unanswered, the rest apart; the body jumped: those before its jump compared, not after
    t = deck.t
    within = (t > 6.0 - 1e-9) & (t <= 7.0 - 1 / RATE + 1e-9) if first == "deck" else t < 0
    for stream in streams:
        assert stream.body is not None
        counts = stream.body.counts
        assert counts["compared"] == (t < 6.0).sum()
        assert counts["unanswered"] == within.sum()
        assert counts["jumped_back_apart"] == (t >= 6.0).sum() - within.sum()


def _five_ways(
    scene: Scene,
    deck_raws: list[bytes],
    deck_ns: np.ndarray,
    body: list[bytes],
    body_ns: np.ndarray,
    make: Callable[[Scene], TwinStream] = TwinStream,
) -> tuple[list[Messages], list[TwinStream]]:
    """The outputs of the deck and body streams fed five ways into streams `make` gives
    (interleaved by stamp; chunks of 700 body first, of 333 deck first; all deck then all
    body, and the reverse); and the streams, the last two fed whole, for their counts."""
    streams = [make(scene) for _ in range(5)]
    whole = streams[3:]
    runs = [
        _interleaved(scene, deck_raws, deck_ns, (body, body_ns), streams[0]),
        _chunked(scene, deck_raws, body, 700, body_first=True, stream=streams[1]),
        _chunked(scene, deck_raws, body, 333, body_first=False, stream=streams[2]),
        whole[0].process(deck_raws) + whole[0].process_body(body) + whole[0].finish(),
        whole[1].process_body(body) + whole[1].process(deck_raws) + whole[1].finish(),
    ]
    return runs, streams


def _fed_five_ways(
    scene: Scene,
    deck_raws: list[bytes],
    deck_ns: np.ndarray,
    body: list[bytes],
    body_ns: np.ndarray,
) -> tuple[list[Messages], list[TwinStream]]:
    """`_five_ways`, checked to be the same messages (the body sensor's statuses among
    /diagnostics); and the two streams fed whole, for their counts."""
    runs, streams = _five_ways(scene, deck_raws, deck_ns, body, body_ns)
    kept = [[m for m in run if m[0] != DIAGNOSTICS_TOPIC or NAME.encode() in m[2]] for run in runs]
    assert all(sorted(k) == sorted(kept[0]) for k in kept[1:])
    return runs, streams[3:]


LOSS = "(the middleware reported body messages lost)"
"""The topic of the mark `_Losing` puts in its outputs where the loss was counted."""


class _Losing(TwinStream):
    """A stream whose body IMU's subscription reports `lost` messages lost by the middleware
    before the call that brings body message `before` (None: before `finish`), counted as the
    node counts them (`MountTwinNode._on_body_lost`, between its wake-ups); a LOSS message
    marks the place in its outputs."""

    def __init__(self, scene: Scene, lost: int, before: int | None) -> None:
        super().__init__(scene)
        self._lost, self._before = lost, before

    def _lose(self) -> Messages:
        assert self.body is not None
        self.body.counts["lost_middleware"] += self._lost
        return [(LOSS, 0, b"")]

    def process_body(self, raws: Sequence[bytes]) -> Messages:
        assert self.body is not None
        received, before = self.body.counts["received"], self._before
        lose = before is not None and received <= before < received + len(raws)
        return (self._lose() if lose else []) + super().process_body(raws)

    def finish(self) -> list[Encoded]:
        return [*(self._lose() if self._before is None else []), *super().finish()]


@pytest.mark.parametrize(
    ("total", "before"),
    [(12.0, 1100), (13.5, None), (12.0, None)],
    ids=["mid_stream", "at_the_end_last_window_judged", "at_the_end_last_window_short"],
)
def test_body_messages_lost_by_the_middleware_are_reported_in_the_window_judged_next(
    total: float, before: int | None
) -> None:
    """37 body IMU messages reported lost by the middleware (DDS message-lost events on the
    body subscription, counted by the node between wake-ups) went into the run's counts and
    no window: every window's body_lost_middleware read 0 live. Now the window judged next
    after the count says all 37, every other 0, in every feeding order: counted mid-stream
    (before body message 1100, 5.5 s), or at the end, in the last window where it is judged
    (10–13.5 s of windows of 5 s), else in a WARN of their own (10–12 s: too short)."""
    scene, deck = _pump(), _deck(total)
    _, whole = _whole_record(scene, deck)
    ns = _stamps(deck)
    runs, streams = _five_ways(
        scene,
        _deck_raws(scene, deck),
        ns,
        _body_raws(ns, whole),
        ns,
        lambda s: _Losing(s, 37, before),
    )
    for run, stream in zip(runs, streams, strict=True):
        assert stream.body is not None and stream.body.counts["lost_middleware"] == 37
        at = [m[0] for m in run].index(LOSS)
        earlier, later = _windows(run[:at]), _windows(run[at:])
        assert all(v["body_lost_middleware"] == "0" for _, _, v in earlier), earlier
        assert later, "no body sensor status after the loss"
        (level, message, values), rest = later[0], later[1:]
        assert values["body_lost_middleware"] == "37" and level >= WARN, message
        assert all(v["body_lost_middleware"] == "0" for _, _, v in rest), rest
        if total == 12.0 and before is None:  # no window after it: a status of its own
            said = "37 body IMU messages lost by the middleware"
            assert "nrms_fx" not in values and message.startswith(said), message
        else:
            assert "nrms_fx" in values and "lost_middleware 37" in message, message


def _limit_waiting(monkeypatch: pytest.MonkeyPatch, limit: int) -> None:
    """PENDING_LIMIT set to `limit` where it is read: by the matcher (body samples waiting for
    the twin's predictions) and by `BodyCheck.over_limit` (waiting for the deck's first
    message)."""
    monkeypatch.setattr(body_matching, "PENDING_LIMIT", limit)
    monkeypatch.setattr(body_check, "PENDING_LIMIT", limit)


def test_body_samples_dropped_waiting_after_the_last_judged_window_are_warned_of(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The deck stops at 12 s (windows of 5 s: 10–12 s too short to judge) and the body IMU
    goes on 7 s more, held waiting for the twin past PENDING_LIMIT (here 1000 samples): the
    oldest were dropped (dropped_waiting), said by no window and no WARN, only in the run's
    counts. Now a WARN at the end says how many, the same in each feeding order whose body
    stream never leads the deck's by the limit (fed whole, body first, it would: the limit
    drops by arrival, as it is meant to)."""
    limit, extra = 1000, 1400
    _limit_waiting(monkeypatch, limit)
    scene, deck = _pump(), _deck(12.0)
    _, whole = _whole_record(scene, deck)
    ns = _stamps(deck)
    body_ns = np.concatenate([ns, ns[-1] + 5_000_000 * np.arange(1, extra + 1)])  # 200 Hz on
    body = _body_raws(body_ns, np.vstack([whole, np.zeros((extra, 6))]))
    deck_raws = _deck_raws(scene, deck)
    streams = [TwinStream(scene) for _ in range(3)]
    runs = [
        _interleaved(scene, deck_raws, ns, (body, body_ns), streams[0]),
        _chunked(scene, deck_raws, body, 700, body_first=True, stream=streams[1]),
        _chunked(scene, deck_raws, body, 333, body_first=False, stream=streams[2]),
    ]
    # held at the end: the samples at the deck's last two rows (predicted only once the
    # stream ends: the prediction trails the twin by two rows) and the 1400 after; the oldest
    # dropped, the `limit` kept left unanswered
    dropped = 2 + extra - limit
    said = [_windows(run) for run in runs]
    assert said[1] == said[0] and said[2] == said[0]
    for stream in streams:
        assert stream.body is not None
        assert stream.body.counts["dropped_waiting"] == dropped
        assert stream.body.counts["unanswered"] == limit
    *judged, (level, message, values) = said[0]
    assert len(judged) == 2 and all(v["body_dropped_waiting"] == "0" for _, _, v in judged)
    assert level == WARN and "nrms_fx" not in values, message
    assert message == (
        f"{dropped} body IMU samples held too long waiting for the twin were dropped "
        f"(counted dropped_waiting); {limit} body IMU messages not compared after the last "
        f"window judged: unanswered {limit}"
    )
    assert values["body_dropped_waiting"] == str(dropped)
    assert values["body_unanswered"] == str(limit)


@pytest.mark.parametrize("reason", ["lost_unprocessed_at_stop", "lost_middleware"])
def test_body_messages_never_read_are_said_at_the_twins_last_stamp(reason: str) -> None:
    """Every one of 500 body IMU messages lost before it was read (waiting in the node's queue
    at a second stop, or lost by the middleware) while the deck's 6 s went through the twin:
    the body check has no stamp of its own, and its WARN of them was stamped 0 (1970), or (lost
    by the middleware) there was none. Now a WARN says them, stamped with the twin's last input
    stamp, the deck's last message's, as the input's last report is."""
    scene, deck = _pump(), _deck(6.0)
    stream = TwinStream(scene)
    out = stream.process(_deck_raws(scene, deck))
    assert stream.body is not None
    stream.body.counts[reason] += 500  # as the node counts them (`MountTwinNode`)
    out += stream.finish()
    said = statuses_named([raw for topic, _, raw in out if topic == DIAGNOSTICS_TOPIC], NAME)
    assert len(said) == 1, said
    stamp, level, message, values = said[0]
    assert stamp == int(_stamps(deck)[-1])
    assert level == WARN and message.startswith("500 body IMU messages"), message
    assert values[f"body_{reason}"] == "500", values


@pytest.mark.parametrize("reason", ["lost_unprocessed_at_stop", "lost_middleware"])
def test_body_messages_never_read_without_any_input_are_said_at_the_nodes_clock(
    reason: str,
) -> None:
    """No deck message came, and 500 body IMU messages were lost before they were read
    (waiting in the node's queue at a second stop, lost by the middleware): no stamp of the
    input nor of the body, and the body check's WARN of them was stamped 0 (1970). Now it is
    stamped with the node's clock, which the node passes to `finish` (as its report that no
    input came is)."""
    stream = TwinStream(_pump())
    assert stream.body is not None
    stream.body.counts[reason] += 500  # as the node counts them (`MountTwinNode`)
    clock_ns = NS0 + 7_000_000_000
    out = stream.finish(clock_ns)
    said = statuses_named([raw for topic, _, raw in out if topic == DIAGNOSTICS_TOPIC], NAME)
    assert len(said) == 1, said
    stamp, level, message, _ = said[0]
    assert (stamp, level) == (clock_ns, WARN)
    assert message.startswith("500 body IMU messages"), message


def test_body_messages_not_compared_in_a_last_window_too_short_to_judge_are_warned_of() -> None:
    """The deck stops at 12 s (windows of 5 s: 10–12 s too short to judge) and is silent
    10.5–11.2 s (a gap past input.max_gap_s 0.5 s); the body IMU at the deck's 200 Hz stamps
    has 3 garbage messages among the gap's and 2 unset stamps after its last. The 140 samples
    strictly inside the gap (10.500 … 10.995, 11.000 … 11.195 s) are in_gap, the 5 rejected;
    all were said by no window, only in the run's counts. Now a WARN at the end says them, the
    same bytes in every feeding order."""
    scene, ns, silent, deck_raws, body, whole = _deck_silent_between(10.5, 11.2)
    body_ns = ns.copy()
    body[2150:2150] = [b"\x00\x01garbage"] * 3  # among the gap's samples (10.75 s)
    body_ns = np.insert(body_ns, 2150, [ns[2150]] * 3)
    body += _body_raws(np.zeros(2, np.int64), whole[:2])
    body_ns = np.concatenate([body_ns, [ns[-1]] * 2])
    runs, streams = _fed_five_ways(scene, deck_raws, ns[~silent], body, body_ns)
    for stream in streams:
        assert stream.body is not None
        assert stream.body.counts["in_gap"] == 140
    *judged, (stamp, level, message, values) = statuses_named(
        [raw for topic, _, raw in runs[0] if topic == DIAGNOSTICS_TOPIC], NAME
    )
    assert len(judged) == 2 and all(v["body_in_gap"] == "0" for *_, v in judged), judged
    assert stamp == int(ns[-1])  # the latest body stamp
    assert level == WARN and "nrms_fx" not in values, message
    assert message == (
        "145 body IMU messages not compared after the last window judged: "
        "rejected_undecodable 3, rejected_nonpositive_stamp 2, in_gap 140"
    )


def test_a_body_stream_fed_far_ahead_of_the_deck_drops_its_oldest_counted_and_said(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """12 s of body IMU at 200 Hz (2400 samples) fed whole before any deck message, the
    samples held waiting for the twin limited to PENDING_LIMIT (here 1000): held for the deck's
    first message (the time base) they were not limited at all (a body IMU live with the deck's
    dead grew without bound) nor counted until it came. Now the oldest 1400 (0–6.995 s) are
    dropped and counted at once; with the deck after, the 1000 kept (7–11.995 s) are compared
    in one window (5 s from 7 s, cut by the end at 4.995 s: judged), a WARN saying the 1400;
    with no deck at all, the end's WARN says them beside the 1000 unanswered."""
    _limit_waiting(monkeypatch, 1000)
    scene, deck = _pump(), _deck(12.0)
    _, whole = _whole_record(scene, deck)
    body = _body_raws(_stamps(deck), whole)
    ahead, alone = TwinStream(scene), TwinStream(scene)
    out = ahead.process_body(body)
    assert ahead.body is not None and ahead.body.counts["dropped_waiting"] == 1400
    out += ahead.process(_deck_raws(scene, deck)) + ahead.finish()
    assert (ahead.body.counts["compared"], ahead.body.counts["dropped_waiting"]) == (1000, 1400)
    ((level, message, values),) = _windows(out)
    assert level == WARN and "nrms_fx" in values and values["samples"] == "1000", message
    assert values["span_s"] == "4.995" and values["body_dropped_waiting"] == "1400"
    assert "body messages not compared: dropped_waiting 1400" in message
    ((level, message, values),) = _windows(alone.process_body(body) + alone.finish())
    assert level == WARN and message.startswith("no window of the body IMU was judged"), message
    assert "dropped_waiting 1400" in message and "unanswered 1000" in message
