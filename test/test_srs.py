"""Shock response spectra: Smallwood's filter against the half-sine's closed forms, an
independent integration of the oscillator and pyyeti; the `srs` command on bags and CSVs."""

from __future__ import annotations

import csv
import json
import math
import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from io_helpers import ROOT, run_python, unprovided_imu
from pyyeti import srs as pyyeti_srs
from rosbags.rosbag2 import Writer
from scipy.integrate import solve_ivp

from mount_twin.analysis.design_margin import TOLERANCE_DB as DEFAULT_BAND
from mount_twin.analysis.design_margin import check_design
from mount_twin.analysis.sampling import uniform
from mount_twin.analysis.srs import damping_ratio, gravity_offset, octave_frequencies, srs
from mount_twin.cli import main
from mount_twin.commands.common import write_signal
from mount_twin.commands.design_options import TOLERANCE_DB
from mount_twin.commands.srs import EXIT_OUT_OF_TOLERANCE
from mount_twin.io.messages import IMU, TYPESTORE
from mount_twin.io.output_bag import write_bag
from mount_twin.io.output_encoding import imu_messages
from mount_twin.io.signals import Signal

G = 9.80665
T = 0.01  # s, half-sine duration
FS = 1000.0 / T  # Hz: 1000 samples per pulse
INTERPOLATION = (math.pi / 1000.0) ** 2 / 8.0
"""Largest gap between the unit half-sine and its samples joined by straight lines (what the
ramp-invariant filter sees), 1.2e-6."""
GENSET = ROOT / "bags" / "genset_shock_10khz"


def _half_sine() -> np.ndarray:
    t = np.arange(round(T * FS) + 1) / FS
    return np.sin(math.pi * t / T)


def _half_sine_tolerance(r: float, exact: float) -> float:
    """A peak between two samples is picked low by at most 1 − cos(πf/fs) of it; the straight
    lines between samples move an undamped response by at most ω·T·INTERPOLATION."""
    return exact * (1.0 - math.cos(math.pi * r / (T * FS))) + 2.0 * math.pi * r * INTERPOLATION


def _primary_closed_form(r: float) -> float:
    """max |ÿ| during a unit half-sine of an undamped oscillator at f = r/T: with Ω = π/T,
    β = Ω/ω = 1/(2r), ÿ(t) = (sin Ωt − β sin ωt)/(1 − β²) from rest; its extremes lie where
    cos Ωt = cos ωt, t = 2πn/(ω ± Ω), or at the pulse's end."""
    big, w, beta = math.pi / T, 2.0 * math.pi * r / T, 1.0 / (2.0 * r)
    candidates = [T]
    for rate in (w + big, abs(w - big)):
        candidates += [2 * math.pi * n / rate for n in range(1, int(T * rate / (2 * math.pi)) + 1)]
    return max(
        abs((math.sin(big * t) - beta * math.sin(w * t)) / (1.0 - beta**2)) for t in candidates
    )


@pytest.mark.parametrize("r", [0.2, 0.35, 0.5, 1.0, 1.5, 2.5, 3.2])
def test_undamped_residual_of_a_half_sine_is_the_closed_form(r: float) -> None:
    """|4r·cos(πr)/(1 − 4r²)| with r = f·T: zero at r = 1.5, 2.5, …; π/2 in the limit r → 0.5
    (cos(π/2 + πε) ≈ −πε over 1 − 4r² ≈ −4ε)."""
    s = srs(_half_sine(), FS, np.array([r / T]), damping=0.0)
    exact = math.pi / 2 if r == 0.5 else abs(4 * r * math.cos(math.pi * r) / (1 - 4 * r * r))
    assert s.residual[0] == pytest.approx(exact, abs=_half_sine_tolerance(r, exact))


@pytest.mark.parametrize("r", [0.2, 0.35, 0.81, 1.0, 1.7, 3.2])
def test_undamped_primary_of_a_half_sine_is_the_closed_form(r: float) -> None:
    s = srs(_half_sine(), FS, np.array([r / T]), damping=0.0)
    exact = _primary_closed_form(r)
    assert s.primary[0] == pytest.approx(exact, abs=_half_sine_tolerance(r, exact))


def test_undamped_maximax_of_a_half_sine_peaks_at_1_7685_near_ft_0_81() -> None:
    r = np.linspace(0.6, 1.0, 161)
    s = srs(_half_sine(), FS, r / T, damping=0.0)
    assert s.maximax.max() == pytest.approx(1.7685, abs=1e-4)
    assert max(_primary_closed_form(x) for x in r) == pytest.approx(1.7685, abs=1e-4)
    assert r[int(s.maximax.argmax())] == pytest.approx(0.81, abs=0.0025)
    np.testing.assert_array_equal(s.maximax, np.maximum(s.primary, s.residual))
    np.testing.assert_array_equal(s.maximax, np.maximum(s.positive, s.negative))


def _absolute(state: np.ndarray, w: float, zeta: float) -> np.ndarray:
    """|absolute acceleration| = |2ζωx′ + ω²x| of the oscillator's states (x, x′) (2, m)."""
    return np.abs(2 * zeta * w * state[1] + w * w * state[0])


def test_the_filter_is_the_oscillators_exact_response_to_the_record_between_samples() -> None:
    """x″ + 2ζωx′ + ω²x = −a(t), a linear between samples, rising from 0 one sample before the
    record and falling to 0 one after; absolute acceleration −(2ζωx′ + ω²x). scipy at rtol
    1e-12, read at the samples, over the record and the ceil(fs/f) zeros after it: the filter
    is exact at the samples, even above fs/10. Between them, the free vibration after the
    record peaks at most 1 − cos(πf/fs) (and a half-sample's decay) above its samples."""
    rng = np.random.default_rng(3)
    fs, zeta = 5000.0, 0.05
    a = np.convolve(rng.normal(0.0, 10.0, 600), np.ones(8) / 8, mode="same")
    n = a.size
    knots = np.arange(-1, n + 1) / fs
    base = np.concatenate([[0.0], a, [0.0]])
    for f in (20.0, 85.0, 300.0, 900.0):
        w = 2 * math.pi * f
        samples = n + math.ceil(fs / f)

        def rhs(t: float, y: np.ndarray, w: float = w) -> list[float]:
            return [y[1], -2 * zeta * w * y[1] - w * w * y[0] - np.interp(t, knots, base)]

        end = (samples - 1) / fs
        sol = solve_ivp(
            rhs,
            (-1 / fs, end),
            [0.0, 0.0],
            dense_output=True,
            rtol=1e-12,
            atol=1e-14,
            max_step=1 / (4 * fs),
        )

        at_samples = _absolute(sol.sol(np.arange(samples) / fs), w, zeta)
        got = srs(a, fs, np.array([f]), zeta)
        assert got.primary[0] == pytest.approx(at_samples[:n].max(), rel=1e-7), f
        assert got.residual[0] == pytest.approx(at_samples[n:].max(), rel=1e-7), f
        between = _absolute(sol.sol(np.linspace(n / fs, end, 40 * (samples - n))), w, zeta).max()
        lost = math.cos(math.pi * f / fs) * math.exp(-zeta * w / (2 * fs))
        assert between * lost <= got.residual[0] <= between * (1 + 1e-9), f


@pytest.mark.parametrize("q", [10.0, 25.0])
def test_every_spectrum_equals_pyyetis(q: float) -> None:
    """pyyeti.srs.srs: the same filter (ISO 18431-4) and the same zeros after the record."""
    rng = np.random.default_rng(7)
    fs = 10_000.0
    a = np.convolve(rng.normal(0.0, 50.0, 3000), np.hanning(40), mode="same")
    f = octave_frequencies(5.0, 1000.0, 6)
    ours = srs(a, fs, f, q=q)
    opts = {"ic": "zero", "rolloff": "none", "parallel": "no"}
    for kind, time_frame, peak in (
        ("maximax", "total", "abs"),
        ("primary", "primary", "abs"),
        ("residual", "residual", "abs"),
        ("positive", "total", "pos"),
        ("negative", "total", "neg"),
    ):
        theirs = pyyeti_srs.srs(a, fs, f, q, peak=peak, time=time_frame, **opts)
        np.testing.assert_allclose(getattr(ours, kind), theirs, rtol=1e-9, err_msg=kind)
    np.testing.assert_allclose(ours.pseudo_velocity, ours.maximax / (2 * np.pi * f), rtol=1e-15)


def test_damping_is_given_as_a_ratio_or_a_quality_factor() -> None:
    assert damping_ratio() == 0.05
    assert damping_ratio(q=10.0) == 0.05
    assert damping_ratio(0.02) == 0.02
    with pytest.raises(ValueError, match="not both"):
        damping_ratio(0.05, 10.0)
    with pytest.raises(ValueError, match=r"Q > 0\.5"):
        damping_ratio(q=0.5)
    with pytest.raises(ValueError, match="0 ≤ ζ < 1"):
        damping_ratio(1.0)


def test_frequencies_from_half_the_sampling_rate_up_are_refused() -> None:
    with pytest.raises(ValueError, match="half the sampling rate"):
        srs(np.ones(10), 1000.0, np.array([100.0, 500.0]))
    with pytest.raises(ValueError, match="finite"):
        srs(np.array([0.0, np.nan]), 1000.0, np.array([10.0]))
    assert srs(np.ones(10), 1000.0, np.array([100.0, 101.0])).accurate.tolist() == [True, False]
    # a 2-D grid was told its range; an empty one met numpy's "zero-size array"
    for grid in (np.array([[10.0, 20.0]]), np.array([])):
        with pytest.raises(ValueError, match=r"natural frequencies must be a non-empty 1-D arr"):
            srs(np.ones(10), 1000.0, grid)


def test_octave_spacing() -> None:
    f = octave_frequencies(10.0, 80.0, 3)
    np.testing.assert_allclose(f, 10.0 * 2.0 ** (np.arange(10) / 3), rtol=1e-15)
    with pytest.raises(ValueError, match="f_min ≤ f_max"):
        octave_frequencies(100.0, 10.0)


def _rows(path: Path) -> list[dict[str, str]]:
    with path.open(encoding="utf-8") as fh:
        return list(csv.DictReader(fh))


def test_the_command_on_the_genset_bag_writes_csv_and_plot(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The genset shock: a 400 m/s² (40.8 g), 5 ms half-sine then a −100 m/s², 20 ms rebound
    of the same velocity change, 50 ms into a 0.25 s record at 10 kHz."""
    table, png = tmp_path / "srs.csv", tmp_path / "srs.png"
    assert main(["srs", str(GENSET), "--csv", str(table), "--plot", str(png)]) == 0
    out = capsys.readouterr().out
    assert "ζ = 0.05 (Q = 10)" in out and "the mean of the first 100 samples" in out
    rows = _rows(table)
    assert list(rows[0]) == [
        "frequency_hz",
        "maximax",
        "primary",
        "residual",
        "pseudo_velocity",
        "positive",
        "negative",
    ]
    col = {k: np.array([float(r[k]) for r in rows]) for k in rows[0]}
    f = col["frequency_hz"]
    np.testing.assert_allclose(f, 5.0 * 2.0 ** (np.arange(f.size) / 6), rtol=1e-12)
    assert f[-1] <= 1000.0 < f[-1] * 2 ** (1 / 6)  # up to fs/10 by default
    np.testing.assert_array_equal(col["maximax"], np.maximum(col["primary"], col["residual"]))
    np.testing.assert_allclose(
        col["pseudo_velocity"], col["maximax"] * G / (2 * np.pi * f), rtol=1e-12
    )
    # Peak amplification of a half-sine-like pulse 1.5-1.8 near f·T = 0.8 (160 Hz); towards
    # high frequency the oscillator follows the base: the pulse's peak.
    assert 40.8 * 1.5 < col["maximax"].max() < 40.8 * 1.8
    assert col["maximax"][-1] == pytest.approx(40.8, rel=0.05)
    # No net velocity change: at low frequency the spectrum falls about as f², not f.
    slope = math.log(col["maximax"][3] / col["maximax"][0]) / math.log(f[3] / f[0])
    assert 1.5 < slope < 2.1
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 20_000


def test_q_and_damping_and_octave_options_agree(tmp_path: Path) -> None:
    a, b = tmp_path / "a.csv", tmp_path / "b.csv"
    common = ["srs", str(GENSET), "--fmin", "20", "--fmax", "640"]
    assert main([*common, "--damping", "0.05", "--octave", "1/3", "--csv", str(a)]) == 0
    assert main([*common[:2], "--q", "10", "--freqs", "20", "40", "80", "--csv", str(b)]) == 0
    by_f = {float(r["frequency_hz"]): r["maximax"] for r in _rows(a)}
    assert len(by_f) == 16
    assert all(by_f[float(r["frequency_hz"])] == r["maximax"] for r in _rows(b))


def _resting_bag(path: Path, specific_force: np.ndarray, rate_hz: float = 2000.0) -> Path:
    t = np.arange(int(rate_hz)) / rate_hz
    accel = np.tile(specific_force, (t.size, 1))
    write_signal(Signal(t, accel, np.zeros_like(accel)), str(path), "/imu", "imu", 10**18, "mcap")
    return path


def test_a_resting_imu_has_a_null_spectrum_once_gravity_is_taken_out(tmp_path: Path) -> None:
    """A tilted sensor at rest: gravity on every axis, each taken out."""
    tilt = math.radians(10.0)
    bag = _resting_bag(tmp_path / "rest", G * np.array([math.sin(tilt), 0.0, math.cos(tilt)]))
    for gravity in ("mean-head", "first"):
        out = tmp_path / f"{gravity}.csv"
        args = ["srs", str(bag), "--axis", "all", "--gravity", gravity, "--csv", str(out)]
        assert main(args) == 0
        rows = _rows(out)
        assert {"maximax_x", "maximax_y", "maximax_z", "pseudo_velocity_z"} <= set(rows[0])
        assert max(float(v) for r in rows for k, v in r.items() if k != "frequency_hz") < 1e-12


def test_a_head_over_the_shock_is_refused(capsys: pytest.CaptureFixture[str]) -> None:
    """`--head 0.06` on the genset bag (50 ms at rest, then a 5 ms, 400 m/s² pulse) took
    (0, 5.4, 28.0) m/s² out as gravity and printed spectra 4 % low, exit 0."""
    assert main(["srs", str(GENSET), "--head", "0.06", "--freqs", "100"]) == 2
    err = capsys.readouterr().err
    assert "head_s (srs --head) 0.06 s: not quiet: its samples stray " in err
    assert main(["srs", str(GENSET), "--head", "0.045", "--freqs", "100"]) == 0


def test_a_head_over_the_shock_is_refused_beside_an_axis_of_nan() -> None:
    """A frozen DOF's CG response is NaN: its spread made the whole head's NaN, and a head
    over the shock passed as quiet."""
    t = np.arange(2000) * 1e-3
    accel = np.zeros((2000, 3))
    accel[:, 1], accel[:, 2], accel[5:40, 0] = np.nan, 9.8, 50.0  # 35 ms of shock in the head
    with pytest.raises(ValueError, match=r"0\.05 s: not quiet: its samples stray 35 m/s²"):
        gravity_offset(t, accel, "mean-head", 0.05)
    accel[5:40, 0] = 0.0
    offset, _ = gravity_offset(t, accel, "mean-head", 0.05)
    assert offset[0] == 0.0 and math.isnan(offset[1]) and offset[2] == pytest.approx(9.8)


def test_a_head_as_long_as_the_record_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Its mean would be the shock's own: `--head 100` on 1 s took out the whole record's mean,
    exit 0, titled "the mean of the first 2000 samples"."""
    bag = _resting_bag(tmp_path / "rest", np.array([0.0, 0.0, G]))
    assert main(["srs", str(bag), "--head", "100", "--freqs", "10"]) == 2
    assert "head_s (srs --head) 100 s: the whole record (0.9995 s)" in capsys.readouterr().err
    assert main(["srs", str(bag), "--head", "0.5", "--freqs", "10"]) == 0


def test_a_record_marking_readings_not_provided_is_refused_or_read_by_what_it_lacks(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """An Imu whose covariance[0] is -1 has no such reading (REP-145). 5 samples of a shock
    with their acceleration marked (zeros in it) made a spectrum of a hole: refused, naming the
    bag and how many; marked in their rate alone, which srs does not read, the spectrum is the
    unmarked record's."""
    t = np.arange(2000) / 2000.0
    accel = np.tile([0.0, 0.0, G], (2000, 1))
    accel[100:120, 0] = 50.0 * np.sin(np.pi * np.arange(20) / 20)
    stamps = 10**18 + np.round(t * 1e9).astype(np.int64)
    msgs = imu_messages(stamps, accel, np.zeros_like(accel), "imu")
    tables = {}
    for name, field in (
        ("plain", ""),
        ("no_rate", "angular_velocity"),
        ("no_accel", "linear_acceleration"),
    ):
        ns, raws = zip(*msgs[105:110], strict=True)
        marked = (
            list(zip(ns, unprovided_imu(list(raws), field), strict=True))
            if field
            else msgs[105:110]
        )
        write_bag(tmp_path / name, "/imu", IMU, iter([*msgs[:105], *marked, *msgs[110:]]))
        out = tmp_path / f"{name}.csv"
        code = main(["srs", str(tmp_path / name), "--freqs", "20", "100", "--csv", str(out)])
        tables[name] = (code, out.read_text(encoding="utf-8") if out.exists() else "")
    assert tables["no_rate"] == tables["plain"] and tables["plain"][0] == 0
    assert tables["no_accel"] == (2, "")
    assert (
        f"{tmp_path / 'no_accel'}: /imu: 5 of 2000 samples mark a reading not provided "
        "(covariance[0] = -1, REP-145: acceleration 5, angular velocity 0), the first its "
        f"message 105 (stamp {stamps[105]} ns): a spectrum takes" in capsys.readouterr().err
    )


def test_gravity_left_in_is_a_step_at_the_start(tmp_path: Path) -> None:
    """--gravity none: 1 g from rest is a step, whose absolute acceleration response is
    1 − e^(−ζωt)(cos ω_d t − ζω/ω_d sin ω_d t) (in g); its peak, 1.85 at ζ = 0.05."""
    bag = _resting_bag(tmp_path / "rest", np.array([0.0, 0.0, G]))
    out = tmp_path / "none.csv"
    assert (
        main(["srs", str(bag), "--gravity", "none", "--freqs", "10", "40", "--csv", str(out)]) == 0
    )
    zeta = 0.05
    for row in _rows(out):
        w = 2 * math.pi * float(row["frequency_hz"])
        wd = w * math.sqrt(1 - zeta**2)
        t = np.linspace(0.0, 2.0 * math.pi / wd, 100_001)
        step = 1 - np.exp(-zeta * w * t) * (np.cos(wd * t) - zeta * w / wd * np.sin(wd * t))
        # the step rises over one sample (0.5 ms): the peak shifts, its height barely
        assert float(row["maximax"]) == pytest.approx(step.max(), rel=1e-3)


def test_a_bag_with_several_imu_topics_needs_topic(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "two"
    stamps = 10**18 + np.arange(100, dtype=np.int64) * 1_000_000
    accel = np.tile([0.0, 0.0, G], (100, 1))
    with Writer(path, version=Writer.VERSION_LATEST) as writer:
        for topic in ("/deck/imu", "/base/imu"):
            conn = writer.add_connection(topic, IMU, typestore=TYPESTORE)
            for stamp, raw in imu_messages(stamps, accel, np.zeros_like(accel), "imu"):
                writer.write(conn, stamp, raw)
    assert main(["srs", str(path)]) == 2
    err = capsys.readouterr().err
    assert "give --topic" in err and "/base/imu (sensor_msgs/msg/Imu)" in err
    assert main(["srs", str(path), "--topic", "/base/imu", "--freqs", "10"]) == 0
    assert main(["srs", str(path), "--topic", "/nope"]) == 2
    assert "no Imu/AccelStamped topic /nope" in capsys.readouterr().err


def test_an_fmax_of_0_is_refused_not_read_as_the_default(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`--fmax 0` gave the spectrum up to the default (0.1 of the rate) with exit 0."""
    out = tmp_path / "s.csv"
    assert main(["srs", str(GENSET), "--fmax", "0", "--csv", str(out)]) == 2
    assert "--fmax 0 Hz: a natural frequency lies above 0 Hz" in capsys.readouterr().err
    assert not out.exists()


def test_an_xsens_export_is_read_as_its_bag_is(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`srs` refused a Movella/Xsens DOT export (which import-csv, calibrate and track read),
    pointing at a --columns option it does not have."""
    export = ROOT / "test/data/shake_table_1story/sine_2hz_trial1_ground_excerpt.csv"
    bag = tmp_path / "ground"
    assert main(["import-csv", str(export), "-o", str(bag)]) == 0
    tables = []
    for source in (export, bag):
        table = tmp_path / f"{source.stem}.csv"
        assert main(["srs", str(source), "--axis", "x", "--csv", str(table)]) == 0
        tables.append(_rows(table))
    assert len(tables[0]) == len(tables[1]) > 5
    for direct, via_bag in zip(*tables, strict=True):  # the bag's stamps are whole ns
        for key, value in direct.items():
            assert float(value) == pytest.approx(float(via_bag[key]), rel=1e-9), key
    odd = tmp_path / "odd.csv"
    odd.write_text("time,a1,a2,a3\n0,0,0,9.8\n0.001,0,0,9.8\n", encoding="utf-8")
    assert main(["srs", str(odd)]) == 2
    assert "map them with `mount-twin import-csv --columns t=" in capsys.readouterr().err


def test_a_recorder_csv_in_g_is_read_and_what_is_no_sampled_signal_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    t = np.arange(3000) / 10_000.0
    pulse = np.where((t >= 0.1) & (t <= 0.11), np.sin(np.pi * (t - 0.1) / 0.01), 0.0)
    good = tmp_path / "shock.csv"
    rows = "".join(f"{x!r},0,0,{1.0 + 10.0 * p!r}\n" for x, p in zip(t, pulse, strict=True))
    good.write_text("t [s],ax [g],ay [g],az [g]\n" + rows, encoding="utf-8")
    out = tmp_path / "s.csv"
    assert main(["srs", str(good), "--freqs", "81", "--damping", "0", "--csv", str(out)]) == 0
    # 10 g half-sine of 10 ms at f·T = 0.81: 1.7685 × 10 g, to the sampling's 1 − cos(πf/fs)
    assert float(_rows(out)[0]["maximax"]) == pytest.approx(17.685, rel=1e-3)
    for stamps, says in (
        ("0 0.001 0.002 0.005 0.006", "a hole of 0.003 s after 0.002 s (3 times the 0.001 s"),
        ("0 0.001 0.0005 0.002", "row 4, column t: time does not increase"),
    ):
        bad = tmp_path / "bad.csv"
        rows = "".join(f"{x},0,0,9.8\n" for x in stamps.split())
        bad.write_text("t,ax,ay,az\n" + rows, encoding="utf-8")
        assert main(["srs", str(bad)]) == 2
        assert says in capsys.readouterr().err


def _jittered(rate_hz: float, n: int, seed: int) -> np.ndarray:
    """Stamps (s) of a uniform clock with one sample in 100 stamped −20 … +11 µs off (the
    bundled 20 kHz records' steps of 30 to 61 µs)."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / rate_hz
    moved = rng.choice(np.arange(1, n - 1), n // 100, replace=False)
    t[moved] += rng.uniform(-20e-6, 11e-6, moved.shape[0])
    return t


def _shock(t: np.ndarray) -> np.ndarray:
    """A shock of decaying sines from 40 Hz to 2 kHz (fs/10 at 20 kHz), m/s²."""
    out = np.zeros_like(t)
    for f, a, tau in (
        (40.0, 30.0, 0.05),
        (310.0, 80.0, 0.02),
        (900.0, 60.0, 0.01),
        (2000.0, 40.0, 0.004),
    ):
        on = t >= 0.01
        out[on] += a * np.exp(-(t[on] - 0.01) / tau) * np.sin(2 * np.pi * f * (t[on] - 0.01))
    return out


def test_a_jittered_record_has_the_spectra_of_the_exact_uniform_one() -> None:
    """The same shock sampled on a jittered clock (stamps where the samples were taken) and on
    the exact uniform grid: the resampled record's spectra are the uniform one's to 1e-3 of the
    peak, from 10 Hz to fs/10."""
    rate = 20_000.0
    t = _jittered(rate, 8000, seed=3)
    record = uniform(t, _shock(t), "jittered")
    assert record.note.startswith("resampled: 159 of 7999 steps")  # 79 samples moved, 2 steps each
    assert record.rate_hz == pytest.approx(rate)
    exact = np.arange(8000) / rate
    np.testing.assert_allclose(record.t, exact, rtol=0, atol=1e-12)
    freqs = octave_frequencies(10.0, 0.1 * rate, 12)
    got = srs(record.values, record.rate_hz, freqs, 0.05)
    want = srs(_shock(exact), rate, freqs, 0.05)
    for kind in ("maximax", "primary", "residual"):
        worst = np.abs(getattr(got, kind) - getattr(want, kind)).max()
        assert worst <= 1e-3 * want.maximax.max(), (kind, worst / want.maximax.max())
    taken = uniform(exact + 1e-9 * np.sin(np.arange(8000)), _shock(exact), "quantised stamps")
    assert taken.note == "" and taken.rate_hz == pytest.approx(rate, rel=1e-8)


def test_the_bundled_real_excerpt_is_taken_whole(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The real 20 kHz record (an excerpt in the repository) steps 50 µs but twice 30 µs:
    refused before, resampled and reported now."""
    excerpt = Path(__file__).resolve().parent / "data" / "water_entry_rest_20khz_excerpt.csv"
    assert main(["srs", str(excerpt), "--axis", "all", "--freqs", "100", "1000"]) == 0
    assert "resampled: 2 of 5599 steps" in capsys.readouterr().out


def test_a_design_spectrum_needs_its_columns(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    design = tmp_path / "design.csv"
    design.write_text("f,g\n10,1\n", encoding="utf-8")
    png = tmp_path / "s.png"
    assert main(["srs", str(GENSET), "--plot", str(png), "--design", str(design)]) == 2
    assert "needs the columns frequency_hz and accel_g" in capsys.readouterr().err
    assert not png.exists()


def test_a_bad_octave_fraction_is_an_argument_error(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as stop:
        main(["srs", str(GENSET), "--octave", "6"])
    assert stop.value.code == 2
    assert "not a fraction of an octave" in capsys.readouterr().err


def test_help_imports_no_numpy() -> None:
    done = run_python("-X", "importtime", "-m", "mount_twin.cli", "srs", "--help")
    assert done.returncode == 0 and "--gravity" in done.stdout
    assert not re.search(r"\|\s*numpy(\.|$)", done.stderr, re.MULTILINE)


def test_a_design_table_is_interpolated_log_log_and_margins_are_in_db() -> None:
    """A power law is a straight line on log-log axes: 1 g at 10 Hz to 100 g at 1 kHz is
    f/10 g between; the margin of a spectrum k times the design is 20 log10 k dB."""
    freqs = np.array([5.0, 10.0, 31.6, 100.0, 316.0, 1000.0, 2000.0])
    design = freqs / 10.0
    scale = np.array([1.0, 1.0, 0.8, 1.2, 1.5, 1.0, 1.0])
    check = check_design(freqs, design * scale, [10.0, 1000.0], [1.0, 100.0])
    assert check.skipped == 2  # 5 Hz and 2 kHz are outside the table
    np.testing.assert_allclose(check.design, freqs[1:-1] / 10.0, rtol=1e-12)
    np.testing.assert_allclose(check.margin_db, 20.0 * np.log10(scale[1:-1]), atol=1e-12)
    assert check.within.tolist() == [True, False, True, False, True]  # −1.94 dB, +3.52 dB
    assert check.bands() == [
        (31.6, 31.6, "short", pytest.approx(20 * math.log10(0.8))),
        (316.0, 316.0, "over", pytest.approx(20 * math.log10(1.5))),
    ]
    assert not check.passed and "FAIL: short by 1.94 dB at 31.6 Hz" in check.summary()
    assert check_design(freqs, design * 1.1, [10.0, 1000.0], [1.0, 100.0]).passed


def _design_file(path: Path, freqs: list[float], accel_g: list[float]) -> Path:
    rows = "".join(f"{f!r},{a!r}\n" for f, a in zip(freqs, accel_g, strict=True))
    path.write_text("frequency_hz,accel_g\n" + rows, encoding="utf-8")
    return path


def test_a_half_sine_record_meets_its_closed_form_spectrum_and_not_twice_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A 10 g, 10 ms half-sine record against the design table of its own closed-form undamped
    maximax (10 g × max(primary, residual)): within −1.5/+3 dB (to the sampling's 1e-3, a few
    thousandths of a dB), exit 0; against twice that table short by 6.02 dB, exit 4, the band
    and verdict in the text, --csv and --json."""
    t = np.arange(4001) / FS
    pulse = np.where(t <= T, np.sin(np.pi * t / T), 0.0)
    record = tmp_path / "half_sine.csv"
    rows = "".join(f"{x!r},0,0,{10.0 * p!r}\n" for x, p in zip(t, pulse, strict=True))
    record.write_text("t [s],ax [g],ay [g],az [g]\n" + rows, encoding="utf-8")
    ratios = [0.2, 0.35, 1.0, 1.7, 3.2]
    freqs = [r / T for r in ratios]
    exact = [
        10.0 * max(_primary_closed_form(r), abs(4 * r * math.cos(math.pi * r) / (1 - 4 * r * r)))
        for r in ratios
    ]
    base = ["srs", str(record), "--gravity", "none", "--damping", "0", "--freqs", *map(str, freqs)]
    out = tmp_path / "s.csv"
    meets = _design_file(tmp_path / "design.csv", freqs, exact)
    assert main([*base, "--design", str(meets), "--csv", str(out)]) == 0
    assert "axis z maximax: 5 of 5 frequencies within -1.5/+3 dB: PASS" in capsys.readouterr().out
    assert all(abs(float(r["margin_db"])) < 0.01 for r in _rows(out))
    twice = _design_file(tmp_path / "twice.csv", freqs, [2.0 * a for a in exact])
    doc = tmp_path / "s.json"
    assert main([*base, "--design", str(twice), "--json", str(doc)]) == EXIT_OUT_OF_TOLERANCE
    said = capsys.readouterr().out
    assert "0 of 5 frequencies within -1.5/+3 dB: FAIL: short by 6.0" in said
    result = json.loads(doc.read_text(encoding="utf-8"))
    assert result["verdict"] == "FAIL" and result["tolerance_db"] == [-1.5, 3.0]
    (band,) = result["axes"]["z"]["out_of_band"]
    assert (band["from_hz"], band["to_hz"], band["kind"]) == (freqs[0], freqs[-1], "short")
    assert band["worst_db"] == pytest.approx(-20 * math.log10(2.0), abs=0.01)
    assert max(abs(m + 20 * math.log10(2.0)) for m in result["spectra"]["margin_db"]) < 0.01


def _strict(text: str) -> object:
    """JSON as the standard has it: NaN and ±Infinity are no numbers."""

    def refuse(constant: str) -> None:
        raise AssertionError(f"{constant} is not JSON")

    return json.loads(text, parse_constant=refuse)


def test_an_axis_without_motion_is_null_in_the_json_not_minus_infinity(tmp_path: Path) -> None:
    """Its spectrum is 0, its margin −inf dB: json wrote -Infinity, which parsers refuse."""
    design = _design_file(tmp_path / "d.csv", [100.0, 1000.0], [10.0, 10.0])
    doc = tmp_path / "s.json"
    args = ["srs", str(GENSET), "--axis", "all", "--design", str(design), "--json", str(doc)]
    assert main(args) == EXIT_OUT_OF_TOLERANCE
    result = _strict(doc.read_text(encoding="utf-8"))
    assert isinstance(result, dict)
    assert set(result["spectra"]["margin_db_x"]) == {None}
    assert [b["worst_db"] for b in result["axes"]["x"]["out_of_band"]] == [None]


def test_the_tolerance_defaults_agree() -> None:
    assert TOLERANCE_DB == DEFAULT_BAND


def test_a_dead_channel_is_refused_not_left_out_of_the_verdict(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """An x channel all NaN was taken for a frozen scene DOF: `--axis all --design` judged y
    and z alone, PASS, exit 0. A channel asked for that is not finite is refused, named; the
    other axes alone still give their spectra."""
    design = tmp_path / "design.csv"
    design.write_text("frequency_hz,accel_g\n10,1\n100,1\n")
    t = np.arange(2000) * 1e-3
    for bad, count, first in ((slice(None), 2000, 0), (slice(300, 301), 1, 300)):
        accel = np.tile([0.0, 0.0, G], (t.size, 1))
        accel[bad, 0] = np.nan
        bag = tmp_path / f"x_nan_{count}"
        write_signal(
            Signal(t, accel, np.zeros_like(accel)), str(bag), "/imu", "imu", 10**18, "mcap"
        )
        assert main(["srs", str(bag), "--axis", "all", "--design", str(design)]) == 2
        err = capsys.readouterr().err
        assert f"axis x has {count} of 2000 values not finite, the first at sample {first} " in err
        assert f"(t = {t[first]:.6g} s)" in err
        assert main(["srs", str(bag), "--axis", "z", "--freqs", "10"]) == 0


def test_an_axis_with_no_response_is_said_so_not_short_by_inf_db() -> None:
    """A record with nothing on an axis (the bundled shocks have no fore-aft component) has a
    spectrum of 0 there: judged against a design it fell short by "inf dB", its margins -inf.
    It is FAIL, saying the spectrum is 0 there; where some frequencies respond, by how much
    the others fall short, in dB."""
    freqs = np.array([10.0, 20.0, 40.0, 80.0])
    nothing = check_design(freqs, np.zeros(4), [10.0, 80.0], [1.0, 1.0])
    said = nothing.summary()
    assert not nothing.passed
    assert said == "0 of 4 frequencies within -1.5/+3 dB: FAIL: no response at 10–80 Hz"
    some = check_design(freqs, np.array([0.0, 0.5, 0.0, 1.0]), [10.0, 80.0], [1.0, 1.0])
    said = some.summary()
    assert "inf" not in said and "nan" not in said
    assert said == (
        "1 of 4 frequencies within -1.5/+3 dB: FAIL: short by 6.02 dB at 10–40 Hz "
        "(no response at 10 and 40 Hz)"
    )


def test_a_design_reaching_past_the_spectrums_frequencies_is_not_passed(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A record sampled at 1 kHz has spectra up to fs/10 = 100 Hz (the default --fmax; its
    1/6-octave frequencies from 5 Hz end at 5·2^(26/6) = 100.8 > 100, so at 89.8 Hz). Judged
    against a 10–1000 Hz design, the design's 89.8–1000 Hz (a decade of its two, reaching past
    one 1/6-octave step from 89.8 Hz) was never compared: it said PASS, exit 0. It is not
    passed, and says which part of the design was not judged."""
    freqs = octave_frequencies(10.0, 100.0)  # 10 … 89.8 Hz
    met = check_design(freqs, np.ones_like(freqs), [10.0, 1000.0], [1.0, 1.0])
    assert met.within.all() and not met.passed
    assert "the design's 89.8–1000 Hz is beyond the spectrum's frequencies" in met.summary()
    step = 2.0 ** (1.0 / 6.0)  # within one step of the design's ends: covered
    assert check_design(freqs, np.ones_like(freqs), [10.0, freqs[-1] * step], [1, 1]).passed
    t = np.arange(1000) / 1000.0
    pulse = np.where((t >= 0.1) & (t <= 0.111), np.sin(np.pi * (t - 0.1) / 0.011), 0.0)
    record = tmp_path / "half_sine_1khz.csv"
    rows = "".join(f"{x!r},0,0,{10.0 * p!r}\n" for x, p in zip(t, pulse, strict=True))
    record.write_text("t [s],ax [g],ay [g],az [g]\n" + rows, encoding="utf-8")
    design = _design_file(tmp_path / "design.csv", [10.0, 1000.0], [10.0, 10.0])
    args = ["srs", str(record), "--fmin", "10", "--design", str(design)]
    assert main([*args, "--tolerance-db", "-60", "60"]) == EXIT_OUT_OF_TOLERANCE
    said = capsys.readouterr().out
    assert "20 of 20 frequencies within -60/+60 dB" in said and "PASS" not in said
    assert "89.8–1000 Hz is beyond the spectrum's frequencies (10–89.8 Hz)" in said
    doc = tmp_path / "s.json"
    assert main([*args, "--json", str(doc)]) == EXIT_OUT_OF_TOLERANCE
    result = json.loads(doc.read_text(encoding="utf-8"))
    assert result["axes"]["z"]["design_not_reached_hz"] == [[pytest.approx(89.797), 1000.0]]


@pytest.mark.parametrize(
    ("options", "named"),
    [
        (["--freqs", "10", "600"], "--freqs 600 Hz"),
        (["--fmax", "600"], "--fmax 600 Hz"),
        (["--fmin", "2000"], "--fmin 2000 Hz"),
        (["--fmin", "0"], "--fmin 0 Hz"),
    ],
)
def test_frequencies_a_record_cannot_have_are_refused_naming_the_option(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], options: list[str], named: str
) -> None:
    """A record sampled at 1 kHz has no spectrum at or above its Nyquist frequency, 500 Hz;
    its default --fmax is fs/10 = 100 Hz. The refusal named no option ('natural frequencies
    must lie between 0 and half the sampling rate', or 'f_min = 2000.0 Hz, f_max = 100.0 Hz'
    for an --fmax the user never gave): it names the option, its value and the bound."""
    t = np.arange(1000) / 1000.0
    record = tmp_path / "rec_1khz.csv"
    rows = "".join(f"{x!r},0,0,{math.sin(40.0 * x)!r}\n" for x in t)
    record.write_text("t [s],ax [g],ay [g],az [g]\n" + rows, encoding="utf-8")
    assert main(["srs", str(record), "--gravity", "none", *options]) == 2
    err = capsys.readouterr().err
    assert f"{named}: a natural frequency lies above 0 Hz and below half the record's " in err
    assert "(500 Hz)" in err
    assert main(["srs", str(record), "--gravity", "none", "--fmin", "200"]) == 2
    assert "--fmin 200 Hz: above --fmax (default fs/10 = 100 Hz)" in capsys.readouterr().err


@pytest.mark.parametrize(
    "spacing",
    [["--octave", "1/3"], ["--fmin", "5"], ["--fmax", "1000"], ["--fmin", "20", "--fmax", "640"]],
)
def test_frequencies_given_beside_a_spacing_are_refused_naming_the_options(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], spacing: list[str]
) -> None:
    """`--freqs 50 100 --fmin 20 --fmax 640` ran at 50 and 100 Hz alone, without a word of the
    spacing it set aside; `--fmin 5` is the default's value, given all the same."""
    table = tmp_path / "srs.csv"
    args = ["srs", str(GENSET), "--freqs", "50", "100", *spacing, "--csv", str(table)]
    assert main(args) == 2
    said = capsys.readouterr()
    named = ", ".join(s for s in spacing if s.startswith("--"))
    assert said.err == (
        f"mount-twin: error: --freqs with {named}: give the frequencies (--freqs) or their "
        "spacing (--octave, --fmin, --fmax), not both\n"
    )
    assert said.out == "" and not table.exists()
    assert main(["srs", str(GENSET), "--freqs", "50", "100", "--csv", str(table)]) == 0
    assert [float(r["frequency_hz"]) for r in _rows(table)] == [50.0, 100.0]


def _spectra_drawn(
    monkeypatch: pytest.MonkeyPatch, spectra: dict, unit: str = "m/s²"
) -> tuple[object, str]:
    """The figure `srs --plot` draws of `spectra` (values in m/s²), and what it says it left
    out."""
    pytest.importorskip("matplotlib")
    from mount_twin import figure_files
    from mount_twin.commands.srs_outputs import plot

    drawn: list = []
    monkeypatch.setattr(figure_files, "save_png", lambda fig, png: drawn.append(fig) or png)
    clipped = plot("unused.png", spectra, None, None, "title", 1e9, unit)
    return drawn[0], clipped


def _spectrum(f: np.ndarray, maximax: np.ndarray, residual: np.ndarray) -> Any:
    from mount_twin.analysis.srs import Spectrum

    return Spectrum(f, maximax, maximax, residual, maximax, maximax, maximax, f > 0.0)


def test_the_plots_y_axis_takes_in_every_curve_four_decades_down(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The floor was 1e-3 of the top: the CG's x spectrum, 0.01 g below 15 Hz under a z of
    75 g, was cut off. Every positive value of every curve drawn is now within the y limits
    when they span less than DECADES_MAX decades, and nothing is said to be left out."""
    f = np.array([5.0, 10.0, 100.0, 1000.0])
    g = 9.80665
    spectra = {
        "x": _spectrum(f, g * np.array([0.01, 0.03, 1.0, 2.0]), np.zeros(4)),
        "z": _spectrum(f, g * np.array([1.5, 5.0, 60.0, 75.0]), np.zeros(4)),
    }
    fig, clipped = _spectra_drawn(monkeypatch, spectra)
    (ax,) = fig.axes
    low, high = ax.get_ylim()
    for line in ax.get_lines():
        y = np.asarray(line.get_ydata(), dtype=float)
        assert ((y[y > 0.0] >= low) & (y[y > 0.0] <= high)).all(), line.get_label()
    assert low <= 0.01 and high >= 75.0
    assert clipped == ""


def test_a_residual_at_round_off_is_clipped_and_said_so(monkeypatch: pytest.MonkeyPatch) -> None:
    """A residual falling to round-off (1e-16 g) would squash the curves into the top: the axis
    spans at most DECADES_MAX decades under its top, and the plot says which curve goes below
    it and how far."""
    from mount_twin.analysis.log_labels import DECADES_MAX

    f = np.array([5.0, 100.0, 1000.0])
    g = 9.80665
    spectra = {
        "z": _spectrum(f, g * np.array([1.0, 50.0, 40.0]), g * np.array([1.0, 1e-3, 1e-16]))
    }
    fig, clipped = _spectra_drawn(monkeypatch, spectra)
    (ax,) = fig.axes
    low, high = ax.get_ylim()
    assert high == pytest.approx(100.0)  # twice the top
    assert low == pytest.approx(100.0 * 10.0**-DECADES_MAX)
    assert "residual, z down to 1e-16 g" in clipped
    assert "maximax" not in clipped and "primary" not in clipped
    assert clipped in ax.get_title().replace("\n", " ")  # the title says so
