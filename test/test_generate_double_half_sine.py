"""`half_sine_shock(..., rebound=, lateral=)` and `mount-twin generate half-sine --rebound
--lateral`: the naval double half-sine with an athwartships share, and the bundled bag
bags/genset_shock_10khz made from it by the command documented in docs/offline.md."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from io_helpers import ROOT, G, read_bag, stamp_ns

from mount_twin.cli import main
from mount_twin.io.signals import half_sine_shock

PEAK, PULSE, REBOUND, RATE, PRE = 400.0, 0.005, 100.0, 100_000.0, 0.01
GENSET_BAG = ROOT / "bags" / "genset_shock_10khz"
GENSET_ARGS = (
    "generate half-sine -o bags/genset_shock_10khz --rate 10000 --duration 0.25 --peak 400 "
    "--pulse 0.005 --rebound 100 --lateral 0.3 --topic /deck/imu --frame-id deck_imu"
)


def test_rebound_follows_the_kick_and_brings_the_deck_back_to_rest() -> None:
    sig = half_sine_shock(PEAK, PULSE, RATE, PRE, 0.05, rebound=REBOUND, lateral=0.3)
    a = sig.accel[:, 2] - G
    t = sig.t
    length = PEAK * PULSE / REBOUND  # 20 ms
    kick = (t >= PRE) & (t <= PRE + PULSE)
    back = (t > PRE + PULSE) & (t <= PRE + PULSE + length)
    assert a[kick].max() == pytest.approx(PEAK, rel=1e-6)
    assert (a[kick] >= 0.0).all() and (a[back] <= 0.0).all()
    assert a[back].min() == pytest.approx(-REBOUND, rel=1e-6)
    assert t[back][np.argmin(a[back])] == pytest.approx(PRE + PULSE + length / 2, abs=1 / RATE)
    assert (a[~(kick | back)] == 0.0).all()
    # deck velocity: up by 2·peak·pulse/π = 1.27 m/s, back to 0; the deck ends lifted
    v = np.concatenate([[0.0], np.cumsum((a[1:] + a[:-1]) / 2.0) / RATE])
    assert v.max() == pytest.approx(2.0 * PEAK * PULSE / math.pi, rel=1e-4)
    assert abs(v[-1]) < 1e-4 * v.max()
    assert np.sum(v) / RATE > 0.0
    # the athwartships share rides on both half-sines; nothing along x, no rotation
    assert np.allclose(sig.accel[:, 1], 0.3 * a, rtol=0.0, atol=1e-12)
    assert (sig.accel[:, 0] == 0.0).all() and (sig.gyro == 0.0).all()


def test_without_the_new_options_the_half_sine_is_unchanged() -> None:
    plain = half_sine_shock(PEAK, PULSE, RATE, PRE, 0.05, G)
    same = half_sine_shock(PEAK, PULSE, RATE, PRE, 0.05, G, rebound=0.0, lateral=0.0)
    assert np.array_equal(plain.accel, same.accel)
    assert (plain.accel[:, :2] == 0.0).all() and plain.accel[:, 2].min() == G


@pytest.mark.parametrize(
    ("shape", "refused"),
    [
        ({"rebound": -1.0}, "rebound must be ≥ 0"),
        ({"duration": 0.0}, "pulse duration must be > 0 s"),  # NaN samples, written
        ({"duration": -0.005}, "pulse duration must be > 0 s"),
        ({"peak": math.nan}, "peak must be finite"),
        ({"peak": -100.0, "rebound": 50.0}, "> 0 with a rebound"),  # the rebound fell away
        # these three wrote a record without the shock asked for, and exited 0
        ({"total": 0.03}, r"the pulse ends at 0\.058 s, after the record's end at 0\.03 s"),
        (
            {"rebound": 50.0, "total": 0.07},  # the rebound lasts 24 ms
            r"the pulse and its rebound end at 0\.082 s, after the record's end at 0\.07 s",
        ),
        ({"rate_hz": 10.0}, r"0\.008 s at 10 Hz is 0\.08 samples: give ≥ 4 \(rate ≥ 500 Hz\)"),
        ({"lateral": math.nan}, "lateral share must be finite"),  # NaN samples, written
    ],
)
def test_a_pulse_that_is_no_pulse_is_refused(shape: dict[str, float], refused: str) -> None:
    with pytest.raises(ValueError, match=refused):
        half_sine_shock(**shape)


def test_generate_writes_the_double_half_sine_and_rejects_a_negative_rebound(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "dhs"
    args = ["generate", "half-sine", "-o", str(out), "--rate", "2000", "--duration", "0.08"]
    shape = ["--peak", "200", "--pulse", "0.004", "--rebound", "50", "--lateral", "0.5"]
    assert main([*args, *shape, "--topic", "/t"]) == 0
    _, msgs = read_bag(out)
    acc = np.array([[m.linear_acceleration.y, m.linear_acceleration.z] for _, m in msgs["/t"]])
    expected = half_sine_shock(200.0, 0.004, 2000.0, 0.05, 0.08, rebound=50.0, lateral=0.5)
    assert np.array_equal(acc, expected.accel[:, 1:])
    assert acc[:, 1].min() < G - 49.0 and acc[:, 0].max() > 99.0
    capsys.readouterr()
    assert main([*args, "--rebound", "-5", "-o", str(tmp_path / "bad")]) == 2
    assert "rebound must be ≥ 0" in capsys.readouterr().err


@pytest.mark.parametrize("kind", ["half-sine", "ship-motion"])
@pytest.mark.parametrize("option", ["--rate", "--duration"])
def test_generate_refuses_a_zero_rate_or_duration_rather_than_taking_the_default(
    tmp_path: Path, kind: str, option: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """`--rate 0` wrote 4000 samples at 10 kHz: 0 read as not given."""
    out = tmp_path / "bag"
    assert main(["generate", kind, "-o", str(out), option, "0"]) == 2
    assert "mount-twin: error: " in capsys.readouterr().err
    assert not out.exists()


def test_the_bundled_genset_bag_is_what_the_documented_command_writes(tmp_path: Path) -> None:
    page = (ROOT / "docs" / "offline.md").read_text(encoding="utf-8")
    assert GENSET_ARGS in " ".join(page.split()), "docs/offline.md must give the command"
    args = GENSET_ARGS.split()
    args[args.index("-o") + 1] = str(tmp_path / "again")
    assert main(args) == 0
    types, bundled = read_bag(GENSET_BAG)
    _, again = read_bag(tmp_path / "again")
    assert types == {"/deck/imu": "sensor_msgs/msg/Imu"}
    assert len(bundled["/deck/imu"]) == len(again["/deck/imu"]) == 2500
    for (t0, m0), (t1, m1) in zip(bundled["/deck/imu"], again["/deck/imu"], strict=True):
        assert t0 == t1 == stamp_ns(m0) == stamp_ns(m1)
        assert m0.header.frame_id == m1.header.frame_id == "deck_imu"
        a0, a1 = m0.linear_acceleration, m1.linear_acceleration
        assert (a0.x, a0.y, a0.z) == (a1.x, a1.y, a1.z)


def test_generate_refuses_a_first_stamp_of_zero(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`--start 0` wrote a bag whose first sample every replay rejected as unset (WARN)."""
    out = tmp_path / "bag"
    assert main(["generate", "half-sine", "-o", str(out), "--start", "0"]) == 2
    assert "stamped 0 ns, which ROS reads as unset" in capsys.readouterr().err
    assert not out.exists()


@pytest.mark.parametrize(
    ("option", "value", "says"),
    [
        ("--topic", "bad topic", "--topic 'bad topic': not a ROS topic name"),
        ("--frame-id", "deck imu", "--frame-id 'deck imu' is not a frame id (it has whitespace)"),
    ],
)
def test_generate_refuses_a_topic_or_frame_id_no_scene_could_take(
    tmp_path: Path, option: str, value: str, says: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """It wrote the bag and exited 0; no scene can name that topic or frame id."""
    out = tmp_path / "bag"
    assert main(["generate", "half-sine", "-o", str(out), option, value]) == 2
    assert says in capsys.readouterr().err
    assert not out.exists()


@pytest.mark.parametrize("value", ["nan", "inf", "-0.1"])
def test_generate_refuses_a_duration_that_is_no_length_naming_it(
    tmp_path: Path, value: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """`--duration nan` said "cannot convert float NaN to integer"."""
    assert main(["generate", "ship-motion", "-o", str(tmp_path / "b"), "--duration", value]) == 2
    assert f"duration must be > 0 s and finite, got {float(value)!r}" in capsys.readouterr().err


def test_generate_refuses_stamps_a_header_cannot_hold(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """builtin_interfaces/Time holds its seconds in an int32: the last stamp it can carry is
    2**31 − 1 s (2038-01-19 03:14:07 UTC). `--start 3e18` wrote headers whose seconds wrapped
    to −1 294 967 296 (1928) beside log times in 2065, and exited 0."""
    out = tmp_path / "bag"
    last = (2**31 - 1) * 1_000_000_000 + 999_999_999
    # 4000 samples at 10 kHz end 0.3999 s after the start: one start too late, one in time
    start = last - 399_900_000 + 1
    assert main(["generate", "half-sine", "-o", str(out), "--start", str(start)]) == 2
    assert "after 2038-01-19T03:14:07Z" in capsys.readouterr().err
    assert not out.exists()
    assert main(["generate", "half-sine", "-o", str(out), "--start", str(start - 1)]) == 0
    _, msgs = read_bag(out)
    assert stamp_ns(msgs["/deck/imu"][-1][1]) == msgs["/deck/imu"][-1][0] == last
