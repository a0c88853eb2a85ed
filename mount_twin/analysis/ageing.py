"""Mounts that age: the calibration re-fitted window by window along a recorded pair.

Rubber hardens or creeps and a bolt loosens slowly; a calibrated scene and a body IMU show it as
a stiffness or damping scale that leaves 1. `track` fits `fit` (`analysis.calibration`) on
consecutive windows of the records, each after a settling lead (the twin starts at rest at the
window's first sample, so the first `LEAD_S` are fitted out; what is left after the last whole
window is in none, `left_over`), and gives each window a level:
WARN where a scale's 3σ interval lies wholly outside `Band.warn`, ERROR where it lies outside
`Band.error`. A window whose fit refuses a parameter says so and is not judged on it; one whose
fit refuses every scale (a record that does not move, a fit no better than the scene) is
not judged at all, and that is a WARN: it cannot say the mounts are OK (as a window the live
tracker cannot fit, `ageing_live.run_job`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from mount_twin.analysis.calibration import calibrate
from mount_twin.analysis.calibration_parameters import is_mount_scale, is_scale, scaled_mounts
from mount_twin.io.signals import Signal
from mount_twin.scene.description import Scene, ageing_bands_problem

LEAD_S = 2.0
"""Each window's records start this much earlier: the twin's start transient settles there,
and the fit skips it."""
SHORTEST_S = 2.0 * LEAD_S
"""A window must be longer than this, s."""
LEVELS = ("OK", "WARN", "ERROR")


@dataclass(frozen=True)
class Band:
    """Scale factors a mount may drift to: inside `warn` OK, outside it WARN, outside `error`
    ERROR (each (low, high), a factor on the calibrated scene's value)."""

    warn: tuple[float, float] = (0.85, 1.15)
    error: tuple[float, float] = (0.75, 1.25)

    def __post_init__(self) -> None:
        """ValueError for bands no judgement can take (`ageing_bands_problem`: the scene
        loader refuses the same in a scene's ageing section, naming the key)."""
        if problem := ageing_bands_problem(self.warn, self.error):
            raise ValueError(problem)


@dataclass(frozen=True)
class WindowFit:
    """One window's fit: its span (s, on the records' clock), each parameter's value and 1σ
    (refused ones left out, with why in `refused`), its level and why."""

    start_s: float
    end_s: float
    values: dict[str, float]
    sigma: dict[str, float]
    refused: dict[str, str] = field(default_factory=dict)
    level: str = "OK"
    why: str = ""


def _window(record: Signal, start: float, end: float) -> Signal:
    """The samples of `record` with stamps in [start, end)."""
    keep = (record.t >= start) & (record.t < end)
    return Signal(record.t[keep], record.accel[keep], record.gyro[keep])


def judged(name: str, value: float, sigma: float, band: Band) -> tuple[int, str]:
    """The level of a scale `value` ± 3`sigma` against the band, and why (empty: OK)."""
    low, high = value - 3.0 * sigma, value + 3.0 * sigma
    for level, (lo, hi) in ((2, band.error), (1, band.warn)):
        if high < lo or low > hi:
            return level, f"{name} ×{value:.3f} ± {sigma:.2g} (1σ) is outside {lo:g}–{hi:g}"
    return 0, ""


def fit_window(
    scene: Scene,
    records: tuple[Signal, Signal],
    span: tuple[float, float],
    fit: tuple[str, ...],
    band: Band,
) -> WindowFit:
    """The fit of one window `span` (start, end s) of the (foundation, body) `records` (the
    foundation's from LEAD_S before the start) and its level."""
    cal = calibrate(scene, *records, fit)
    scales = [n for n in cal.sigma if is_scale(n)]
    verdicts = [judged(n, cal.values[n], cal.sigma[n], band) for n in scales]
    if not scales:
        verdicts = [(1, "not judged: the window identified none of the scales")]
    level = max(v for v, _ in verdicts)
    why = "; ".join(w for _, w in verdicts if w)
    fitted = {n: cal.values[n] for n in cal.sigma}
    return WindowFit(*span, fitted, dict(cal.sigma), dict(cal.refused), LEVELS[level], why)


def track(
    scene: Scene,
    foundation: Signal,
    body: Signal,
    window_s: float = 30.0,
    fit: tuple[str, ...] = ("stiffness", "damping"),
    band: Band = Band(),
) -> list[WindowFit]:
    """The fit of each `window_s` window of the pair, in order (module docstring); ValueError
    for a `fit` that is no mount scale (`calibration_parameters.is_mount_scale`,
    `scaled_mounts`)."""
    for name in fit:
        if not is_mount_scale(name):
            msg = (
                f"--fit {name}: track re-fits mount scales: stiffness, damping, or "
                "stiffness:A+B (damping:A+B) for a group of mounts"
            )
            raise ValueError(msg)
        scaled_mounts(name, scene)
    if window_s <= SHORTEST_S:
        msg = f"window {window_s:g} s: give more than {SHORTEST_S:g} s (the lead settles)"
        raise ValueError(msg)
    first, stop = overlap(foundation, body)
    start = first + LEAD_S  # the twin settles on the foundation over the lead
    fits = []
    while start + window_s <= stop + 1e-9:
        end = start + window_s
        records = (_window(foundation, start - LEAD_S, end), _window(body, start, end))
        fits.append(fit_window(scene, records, (start, end), fit, band))
        start = end
    if not fits:
        left = max(stop - start, 0.0)
        held = f"the records hold {left:.4g} s after the {LEAD_S:g} s lead"
        if left <= SHORTEST_S:  # no window fits: "give a shorter one" was not true
            msg = (
                f"{held}, and a window is longer than {SHORTEST_S:g} s: track needs records "
                f"overlapping by more than {LEAD_S + SHORTEST_S:g} s"
            )
        else:
            msg = (
                f"{held}: less than one window of {window_s:g} s (give one of more than "
                f"{SHORTEST_S:g} s and at most {left:.4g} s)"
            )
        raise ValueError(msg)
    return fits


def overlap(foundation: Signal, body: Signal) -> tuple[float, float]:
    """The first and last stamp (s) the records both cover; ValueError where they do not
    overlap on one clock, saying each one's span."""
    first, stop = float(max(foundation.t[0], body.t[0])), float(min(foundation.t[-1], body.t[-1]))
    if stop <= first:
        msg = (
            "the records do not overlap on one clock: the foundation's runs "
            f"{foundation.t[0]:.6g} to {foundation.t[-1]:.6g} s, the body's {body.t[0]:.6g} "
            f"to {body.t[-1]:.6g} s"
        )
        raise ValueError(msg)
    return first, stop


def left_over(fits: list[WindowFit], foundation: Signal, body: Signal, window_s: float) -> str:
    """What of the records `track` fitted in no window, in words ('' for nothing): the part
    after its last window (of `fits`), shorter than one, which it had dropped without a
    word."""
    _, stop = overlap(foundation, body)
    end = fits[-1].end_s
    if stop - end <= 1e-9:  # track's own tolerance on a window's end
        return ""
    return (
        f"the last {stop - end:.4g} s of the records, {end:.6g}–{stop:.6g} s, are in no "
        f"window: less than one of {window_s:g} s"
    )


WINDOW_HEADING = ("window s", "level", "fit: scale ×value ± 1σ", "why")
"""`window_table`'s column headings."""


def window_table(fits: list[WindowFit]) -> list[str]:
    """A heading, then one line per window: span, level, values ± 1σ, then why it is not OK
    and each refused parameter ("NAME refused: WHY"); each column as wide as its widest
    cell, the span right-aligned."""
    rows = [
        (
            f"{f.start_s:.1f}–{f.end_s:.1f}",
            f.level,
            ", ".join(f"{n} ×{v:.3f} ± {f.sigma[n]:.2g}" for n, v in f.values.items()) or "-",
            "; ".join(
                [*filter(None, [f.why]), *(f"{n} refused: {w}" for n, w in f.refused.items())]
            ),
        )
        for f in fits
    ]
    widths = [max(len(r[k]) for r in (WINDOW_HEADING, *rows)) for k in range(3)]
    return [
        f"{span:>{widths[0]}}  {level:<{widths[1]}}  {shown:<{widths[2]}}  {why}".rstrip()
        for span, level, shown, why in (WINDOW_HEADING, *rows)
    ]
