"""Shock response spectra against closed forms (half-sine) and an independent integration of
the single-DOF oscillator; the command's table, CSV and plot."""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np
import pytest
from io_helpers import ROOT
from scipy.integrate import solve_ivp

from mount_twin.analysis.srs import octave_frequencies, srs
from mount_twin.cli import main

T = 0.01  # s, half-sine duration
FS = 1000.0 / T  # 1000 samples per pulse


def _half_sine() -> np.ndarray:
    t = np.arange(round(T * FS) + 1) / FS
    return np.sin(math.pi * t / T)


@pytest.mark.parametrize("r", [0.2, 0.35, 1.0, 1.5, 2.5, 3.2])
def test_undamped_residual_of_a_half_sine_is_the_closed_form(r: float) -> None:
    """|4r·cos(πr)/(1 − 4r²)| with r = f·T (zero at r = 1.5, 2.5, …)."""
    s = srs(_half_sine(), FS, np.array([r / T]), damping=0.0)
    exact = abs(4 * r * math.cos(math.pi * r) / (1 - 4 * r * r))
    assert s.residual[0] == pytest.approx(exact, abs=1e-5)


def test_undamped_maximax_of_a_half_sine_peaks_at_1_7685_near_ft_0_81() -> None:
    r = np.linspace(0.6, 1.0, 161)
    s = srs(_half_sine(), FS, r / T, damping=0.0)
    assert s.maximax.max() == pytest.approx(1.7685, abs=2e-4)
    assert r[int(s.maximax.argmax())] == pytest.approx(0.81, abs=0.01)
    np.testing.assert_array_equal(s.maximax, np.maximum(s.primary, s.residual))


def test_damped_spectrum_equals_an_independent_integration_of_the_oscillator() -> None:
    """x″ + 2ζωx′ + ω²x = −a(t), a linear between samples; absolute acceleration
    −(2ζωx′ + ω²x); scipy at rtol 1e-11 over the record and 1.5 periods after it."""
    rng = np.random.default_rng(3)
    fs, zeta = 5000.0, 0.05
    a = np.convolve(rng.normal(0.0, 10.0, 600), np.ones(8) / 8, mode="same")
    t = np.arange(a.size) / fs
    for f in (20.0, 85.0, 300.0):
        w = 2 * math.pi * f
        end = t[-1] + 1.5 / f

        def rhs(tt: float, y: np.ndarray, w: float = w) -> list[float]:
            base = np.interp(tt, t, a, right=0.0) if tt <= t[-1] else 0.0
            return [y[1], -2 * zeta * w * y[1] - w * w * y[0] - base]

        grid = np.arange(0.0, end, 1.0 / (20 * fs))
        sol = solve_ivp(
            rhs, (0.0, end), [0.0, 0.0], t_eval=grid, rtol=1e-11, atol=1e-14, max_step=1 / (4 * fs)
        )
        absolute = np.abs(2 * zeta * w * sol.y[1] + w * w * sol.y[0]).max()
        got = srs(a, fs, np.array([f]), zeta).maximax[0]
        assert got == pytest.approx(absolute, rel=2e-3), f


def test_octave_spacing() -> None:
    f = octave_frequencies(10.0, 80.0, 3)
    np.testing.assert_allclose(f, 10.0 * 2.0 ** (np.arange(10) / 3), rtol=1e-15)


def test_the_command_on_the_genset_bag_writes_csv_and_plot(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    table, png = tmp_path / "srs.csv", tmp_path / "srs.png"
    bag = ROOT / "bags" / "genset_shock_10khz"
    args = ["srs", str(bag), "--csv", str(table), "--plot", str(png), "--fmin", "20"]
    assert main([*args, "--fmax", "1000", "--per-octave", "3"]) == 0
    rows = list(csv.DictReader(table.open(encoding="utf-8")))
    assert list(rows[0]) == ["frequency_hz", "maximax", "primary", "residual", "pseudo_velocity"]
    maximax = np.array([float(r["maximax"]) for r in rows])
    # A 400 m/s² (40.8 g) kick of 5 ms: the spectrum reaches about 1.5–1.8 × its peak near
    # f·T = 0.8 (160 Hz) and tends to the peak itself at high frequency.
    assert 40.8 * 1.4 < maximax.max() < 40.8 * 1.8
    assert maximax[-1] == pytest.approx(40.8, rel=0.1)
    assert png.stat().st_size > 20_000
    assert "ζ = 0.05 (Q = 10)" in capsys.readouterr().out


def test_a_resting_record_has_a_null_spectrum(tmp_path: Path) -> None:
    csv_file = tmp_path / "rest.csv"
    t = np.arange(2000) / 2000.0
    csv_file.write_text(
        "t,ax,ay,az\n" + "\n".join(f"{x:.6f},0.0,0.0,9.80665" for x in t) + "\n", encoding="utf-8"
    )
    out = tmp_path / "s.csv"
    assert main(["srs", str(csv_file), "--csv", str(out), "--fmin", "20", "--fmax", "200"]) == 0
    rows = list(csv.DictReader(out.open(encoding="utf-8")))
    assert max(float(r["maximax"]) for r in rows) == 0.0  # gravity removed
