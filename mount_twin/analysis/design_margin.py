"""A shock response spectrum against a design spectrum: the margin at each frequency, in dB,
and a verdict within a tolerance.

A shock test or a synthesised input meets a specification when its spectrum lies within a
tolerance band about the design spectrum at every frequency the design covers (commonly
−1.5 dB / +3 dB: MIL-STD-810H Method 516.8 and the usual synthesis practice). The design table
(frequency, acceleration) is interpolated log-log between its points (straight lines on the
usual log-log plot); frequencies outside its range are not judged. A design reaching more than
one of the spectrum's own steps (the ratio of its first two or last two frequencies) past the
spectrum's lowest or highest frequency is not met there, nor passed: a record at 1 kHz has
spectra to 100 Hz, and a 10–1000 Hz design judged on them alone had passed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

TOLERANCE_DB = (-1.5, 3.0)
"""Default band about the design spectrum: (below, above), dB."""


@dataclass(frozen=True)
class DesignCheck:
    """The margins of a spectrum at the frequencies the design covers.

    Attributes:
        frequency_hz: those frequencies.
        design, spectrum: the design's and the spectrum's values there (one unit, any).
        tolerance_db: (low, high): the band about the design, dB (low < 0 < high).
        skipped: how many of the spectrum's frequencies lie outside the design's range.
        unreached: the design's ranges (from Hz, to Hz) beyond the spectrum's frequencies
            by more than a step of theirs: not judged, so not passed.
    """

    frequency_hz: np.ndarray
    design: np.ndarray
    spectrum: np.ndarray
    tolerance_db: tuple[float, float]
    skipped: int
    unreached: tuple[tuple[float, float], ...] = ()
    reached: tuple[float, float] = (math.nan, math.nan)
    """The spectrum's lowest and highest frequency, Hz."""

    @property
    def margin_db(self) -> np.ndarray:
        """20 log10(spectrum / design) per frequency: < 0 short of the design, > 0 over."""
        with np.errstate(divide="ignore"):
            return 20.0 * np.log10(self.spectrum / self.design)

    @property
    def within(self) -> np.ndarray:
        """Per frequency: the margin within the tolerance band."""
        low, high = self.tolerance_db
        return (self.margin_db >= low) & (self.margin_db <= high)

    @property
    def passed(self) -> bool:
        """Within the band at every frequency judged (at least one), and the design's whole
        range judged (nothing `unreached`)."""
        return bool(self.frequency_hz.shape[0]) and bool(self.within.all()) and not self.unreached

    def bands(self) -> list[tuple[float, float, str, float]]:
        """The runs of consecutive frequencies out of the band: (first Hz, last Hz, 'short'
        or 'over', the worst margin there in dB)."""
        low, _ = self.tolerance_db
        margin = self.margin_db
        side = np.where(margin < low, -1, np.where(self.within, 0, 1))
        out: list[tuple[float, float, str, float]] = []
        k = 0
        while k < side.shape[0]:
            if side[k] == 0:
                k += 1
                continue
            end = k
            while end + 1 < side.shape[0] and side[end + 1] == side[k]:
                end += 1
            run = margin[k : end + 1]
            worst = float(run.min() if side[k] < 0 else run.max())
            kind = "short" if side[k] < 0 else "over"
            out.append((float(self.frequency_hz[k]), float(self.frequency_hz[end]), kind, worst))
            k = end + 1
        return out

    def summary(self) -> str:
        """One line: how many frequencies are within the band, PASS or FAIL, and where not."""
        low, high = self.tolerance_db
        n = self.frequency_hz.shape[0]
        head = f"{int(self.within.sum())} of {n} frequencies within {low:+g}/{high:+g} dB"
        if self.skipped:
            head += f" ({self.skipped} outside the design's range, not judged)"
        if self.passed:
            return f"{head}: PASS"
        if not n:
            return f"{head}: FAIL (no frequency in the design's range)"
        where = [self._band_text(*band) for band in self.bands()]
        low_hz, high_hz = self.reached
        where += [
            f"the design's {f0:.4g}–{f1:.4g} Hz is beyond the spectrum's frequencies "
            f"({low_hz:.4g}–{high_hz:.4g} Hz), not judged"
            for f0, f1 in self.unreached
        ]
        return f"{head}: FAIL: {'; '.join(where)}"

    def _band_text(self, f0: float, f1: float, kind: str, worst: float) -> str:
        """'short by 6.02 dB at 10–40 Hz'; where the spectrum is 0 (no response: its margin
        −∞ dB), that, naming the frequencies unless the whole run is."""
        where = f"{f0:.4g} Hz" if f0 == f1 else f"{f0:.4g}–{f1:.4g} Hz"
        if math.isfinite(worst):
            return f"{kind} by {abs(worst):.2f} dB at {where}"
        f = self.frequency_hz
        run = (f >= f0) & (f <= f1)
        margin = self.margin_db[run]
        if not np.isfinite(margin).any():
            return f"no response at {where}"
        silent = [f"{x:.4g}" for x in f[run][~np.isfinite(margin)]]
        named = (
            f"{', '.join(silent[:-1])} and {silent[-1]} Hz"
            if len(silent) > 1
            else f"{silent[0]} Hz"
        )
        if len(silent) > 3:
            named = f"{len(silent)} of them"
        short = float(margin[np.isfinite(margin)].min())
        return f"{kind} by {abs(short):.2f} dB at {where} (no response at {named})"


def check_design(
    frequency_hz: np.ndarray,
    spectrum: np.ndarray,
    design_hz: np.ndarray | list[float],
    design: np.ndarray | list[float],
    tolerance_db: tuple[float, float] = TOLERANCE_DB,
) -> DesignCheck:
    """`spectrum` at `frequency_hz` against the design table (`design_hz` increasing, `design`
    > 0, same unit as `spectrum`), interpolated log-log."""
    design_hz, design = np.asarray(design_hz, float), np.asarray(design, float)
    inside = (frequency_hz >= design_hz[0]) & (frequency_hz <= design_hz[-1])
    f = frequency_hz[inside]
    at = np.exp(np.interp(np.log(f), np.log(design_hz), np.log(design)))
    skipped = int((~inside).sum())
    ordered = np.sort(np.asarray(frequency_hz, float))
    low, high = float(ordered[0]), float(ordered[-1])
    # a design ending one of the spectrum's steps past it is reached (1e-9: rounding)
    step_low, step_high = (
        (float(ordered[1] / ordered[0]), float(ordered[-1] / ordered[-2]))
        if ordered.size > 1
        else (1.0, 1.0)
    )
    unreached = []
    if design_hz[0] < low / step_low / (1.0 + 1e-9):
        unreached.append((float(design_hz[0]), low))
    if design_hz[-1] > high * step_high * (1.0 + 1e-9):
        unreached.append((high, float(design_hz[-1])))
    return DesignCheck(
        f, at, spectrum[inside], tolerance_db, skipped, tuple(unreached), (low, high)
    )
