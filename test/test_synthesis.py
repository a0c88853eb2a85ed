"""Shock synthesis: time histories whose SRS meets a design spectrum, starting and ending at
rest, one per seed; the round trip through a bag and `srs --design` passes."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import cumulative_trapezoid

from mount_twin.analysis.srs import octave_frequencies, srs
from mount_twin.analysis.synthesis import G, imu_record, synthesize, wavelets
from mount_twin.cli import main

DESIGN = ([10.0, 100.0, 300.0, 1000.0], [2.0, 20.0, 60.0, 60.0])
"""A design spectrum of the usual shape (g against Hz): a constant-velocity ramp to 300 Hz,
then a constant-acceleration plateau."""


@pytest.mark.parametrize("halves", [3, 5, 9])
def test_a_wavelet_ends_at_rest_for_an_odd_number_of_half_cycles(halves: int) -> None:
    """∫ sin(ωt/N) sin(ωt) over N half-cycles is [sin((N−1)π)/(ω−Ω) − sin((N+1)π)/(ω+Ω)]/2
    = 0, and the displacement vanishes for odd N: both at the end of the span, to the
    trapezoidal rule's error at 200 samples per period."""
    f = 50.0
    t = np.linspace(0.0, halves / (2 * f), 200 * halves // 2 + 1)
    (w,) = wavelets(t, np.array([f]), np.array([float(halves)]), np.array([0.0]))
    v = cumulative_trapezoid(w, t, initial=0.0)
    d = cumulative_trapezoid(v, t, initial=0.0)
    assert abs(v[-1]) < 1e-4 * np.abs(v).max()
    assert abs(d[-1]) < 1e-4 * np.abs(d).max()


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_synthesis_meets_the_design_and_ends_at_rest(seed: int) -> None:
    rate = 20_000.0
    shock = synthesize(*DESIGN, rate, seed=seed)
    freqs = octave_frequencies(10.0, 1000.0, 6)
    got = srs(shock.accel, rate, freqs, 0.05).maximax / G  # computed afresh, not the check's
    want = np.exp(np.interp(np.log(freqs), np.log(DESIGN[0]), np.log(DESIGN[1])))
    margin = 20 * np.log10(got / want)
    assert margin.min() >= -1.5 and margin.max() <= 3.0, (margin.min(), margin.max())
    v, d = shock.velocity, shock.displacement
    assert abs(v[-1]) <= 1e-3 * np.abs(v).max()
    assert abs(d[-1]) <= 1e-3 * np.abs(d).max()
    assert shock.accel[0] == 0.0 and shock.accel[-1] == 0.0


def test_seeds_give_different_histories_of_one_spectrum() -> None:
    a, b = (synthesize(*DESIGN, 20_000.0, seed=s) for s in (0, 1))
    n = min(a.t.shape[0], b.t.shape[0])
    assert np.abs(a.accel[:n] - b.accel[:n]).max() > 0.1 * np.abs(a.accel).max()


def test_a_design_past_a_tenth_of_the_rate_is_refused() -> None:
    with pytest.raises(ValueError, match="a rate of at least 10000 Hz is needed"):
        synthesize(*DESIGN, 5000.0)


def test_a_record_past_max_samples_is_refused_before_it_is_allocated() -> None:
    """`synthesize --head 1e9` died in numpy's MemoryError (437 TiB), exit 1."""
    shock = synthesize(*DESIGN, 20_000.0, seed=0)
    with pytest.raises(ValueError, match=r"more than a generated signal may have \(MAX_SAMPLES"):
        imu_record(shock, 20_000.0, "z", 1e9)
    assert imu_record(shock, 20_000.0, "z", 0.05).t.shape[0] == 1000 + shock.t.shape[0]


def test_synthesized_bags_pass_srs_against_the_design(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """synthesize → Imu bags (+g on z at rest, the shock on z after a quiet head) → srs of each
    bag, gravity taken out, against the same design: PASS, exit 0."""
    table = tmp_path / "design.csv"
    rows = "".join(f"{f},{a}\n" for f, a in zip(*DESIGN, strict=True))
    table.write_text("frequency_hz,accel_g\n" + rows, encoding="utf-8")
    out = tmp_path / "bags"
    args = ["synthesize", "--spectrum", str(table), "-o", str(out), "--seeds", "2"]
    assert main(args) == 0
    said = capsys.readouterr().out
    assert said.count("PASS") == 2 and "velocity" in said
    for seed in (0, 1):
        srs_args = ["srs", str(out / f"seed_{seed}"), "--design", str(table)]
        assert main([*srs_args, "--fmin", "10", "--fmax", "1000"]) == 0
        assert "40 of 40 frequencies within -1.5/+3 dB: PASS" in capsys.readouterr().out
    assert main(args) == 2  # the directory exists now
    assert "exists" in capsys.readouterr().err


def test_a_synthesis_that_fails_before_writing_leaves_no_directory(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`--start 0` is refused at the first bag: the empty directory it left refused the
    rerun ("exists; synthesize writes a new directory")."""
    spectrum = Path(__file__).resolve().parents[1] / "config" / "shock_spectrum_vertical.csv"
    out = tmp_path / "synth"
    args = ["synthesize", "--spectrum", str(spectrum), "-o", str(out), "--seeds", "1"]
    assert main([*args, "--start", "0"]) == 2
    assert "stamped 0 ns" in capsys.readouterr().err
    assert not out.exists()


@pytest.mark.parametrize("command", ["synthesize", "srs"])
def test_a_design_spectrum_that_is_no_text_is_an_error_naming_it(
    tmp_path: Path, command: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """A binary file given as the design spectrum (a bag's mcap) said only "'utf-8' codec
    can't decode byte 0x89 in position 0", naming no file; one with a field past csv's limit
    ended in csv's traceback (exit 1)."""
    root = Path(__file__).resolve().parents[1]
    (mcap,) = (root / "bags" / "ship_motion_1khz").glob("*.mcap")
    long_field = tmp_path / "long_field.csv"
    long_field.write_text("frequency_hz,accel_g\n10," + "9" * 200_000 + "\n", encoding="utf-8")
    for design, said in ((mcap, "not UTF-8 text"), (long_field, "not a CSV table")):
        if command == "synthesize":
            args = ["synthesize", "--spectrum", str(design), "-o", str(tmp_path / "out")]
        else:
            args = ["srs", str(root / "bags" / "genset_shock_10khz"), "--design", str(design)]
        assert main(args) == 2
        err = capsys.readouterr().err
        assert err.startswith(f"mount-twin: error: {design}: {said}"), err
        assert not (tmp_path / "out").exists()


@pytest.mark.parametrize(
    ("option", "value", "says"),
    [
        ("--seeds", "0", "must be ≥ 1, got 0"),
        ("--head", "-0.5", "must be ≥ 0, got -0.5"),
        ("--rate", "0", "must be > 0, got 0"),
        ("--rate", "nan", "must be > 0, got nan"),
    ],
)
def test_a_synthesis_number_out_of_its_range_is_refused_naming_its_option_and_value(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], option: str, value: str, says: str
) -> None:
    """It said "--seeds must be ≥ 1, --head ≥ 0 s and --rate > 0 Hz", whichever was wrong."""
    spectrum = Path(__file__).resolve().parents[1] / "config" / "shock_spectrum_vertical.csv"
    out = tmp_path / "synth"
    with pytest.raises(SystemExit) as stop:
        main(["synthesize", "--spectrum", str(spectrum), "-o", str(out), option, value])
    assert stop.value.code == 2
    assert f"argument {option}: {says}" in capsys.readouterr().err
    assert not out.exists()


def test_a_spectrum_the_synthesis_cannot_meet_is_named(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The error named the seed ("the synthesis (seed 0) did not meet the design") but not
    the design file."""
    from io_helpers import unmeetable_design

    spectrum = unmeetable_design(tmp_path / "notch.csv")
    out = tmp_path / "synth"
    args = ["synthesize", "--spectrum", str(spectrum), "-o", str(out), "--rate", "1000"]
    assert main([*args, "--seeds", "1"]) == 2
    err = capsys.readouterr().err
    assert f"mount-twin: error: {spectrum}: the synthesis (seed 0) did not meet" in err, err
    assert "did not meet the design in " in err and "frequencies within -1.5/+3 dB: FAIL" in err
    assert not out.exists()


def test_a_synthesis_that_fails_part_way_leaves_no_directory(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """The disk fills at the second seed's bag: the first seed's bag was kept, the directory
    read as a result of one seed, and the rerun was refused ("exists")."""
    from io_helpers import disk_full_after

    spectrum = Path(__file__).resolve().parents[1] / "config" / "shock_spectrum_vertical.csv"
    out = tmp_path / "synth"
    written = disk_full_after(monkeypatch, 1)
    args = ["synthesize", "--spectrum", str(spectrum), "-o", str(out), "--seeds", "2"]
    assert main(args) == 2
    assert written == [str(out / "seed_0")]
    err = capsys.readouterr().err
    assert f"mount-twin: error: {out / 'seed_1'}: No space left on device" in err
    assert f"mount-twin: warning: {out}: removed, with what synthesize wrote in it" in err
    assert not out.exists() and tmp_path.is_dir()
