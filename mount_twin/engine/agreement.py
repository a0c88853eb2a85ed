"""How well the twin's body sensor prediction and the machine's body IMU agree over a window.

Per axis (specific force fx, fy, fz in m/s², then rate wx, wy, wz in rad/s, the sensor's axes),
with each signal's mean taken out (gravity, the sensor's biases: constant offsets the twin does
not model), the normalised RMS error ‖pred − meas‖ / ‖meas‖:

- in the scene's judged band (`body_sensor.band_hz`: the mounting's modes and below), from the
  discrete Fourier transform of the window (Parseval: the band's share of both norms), and
- broadband (every frequency the body IMU samples), reported beside it.

Each field (`FIELDS`: the specific force, the rate) is taken on the window's samples that
provide it (a sample whose message marks a reading not provided, REP-145, is compared on the
other), and needs `MIN_SAMPLES` of them. An axis is judged only where the scene says so
(`body_sensor.axes`) and the body moved in the band: its measured RMS there at least the axis
floor (`FLOORS`, above a MEMS IMU's noise); elsewhere the ratio is noise over noise. The
window's level is that of its worst judged axis against `warn_nrms` and `error_nrms`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mount_twin.engine.batch import ERROR, OK, WARN, HealthStatus
from mount_twin.scene.description import SENSOR_AXES, BodySensor

AXES = SENSOR_AXES
"""The compared axes: specific force (m/s²), then angular rate (rad/s), in the sensor's axes."""
FLOORS = np.array([0.05, 0.05, 0.05, 0.005, 0.005, 0.005])
"""Smallest measured RMS in the band (m/s², rad/s) of an axis that is judged."""
FIELDS = ("specific_force", "rate")
"""The readings compared, each on the samples that provide it: `AXES[:3]`, then `AXES[3:]`."""
MIN_SAMPLES = 16
"""Fewest samples providing a field that a window needs to judge it (one with fewer of each is
not judged: its messages are said with the next)."""
NAME = "mount_twin: body sensor"
OUTSIDE_THE_RUN = {"before_twin", "unanswered"}
"""Body samples not compared because they lie before the twin's first row or after its last:
said, not warned of (the two recorders never start and stop together)."""


@dataclass(frozen=True)
class Agreement:
    """A window's figures, one per axis (`AXES`; nan for a field on fewer than `MIN_SAMPLES`).

    Attributes:
        nrms_band: normalised RMS error in the judged band.
        nrms_broadband: normalised RMS error at every frequency.
        rms_band: the measured signal's RMS in the band (m/s², rad/s).
        judged: the axis moved enough in the band to be judged (`FLOORS`).
        samples: (2,) the samples each field (`FIELDS`) was taken on.
    """

    nrms_band: np.ndarray
    nrms_broadband: np.ndarray
    rms_band: np.ndarray
    judged: np.ndarray
    samples: np.ndarray

    @property
    def worst(self) -> tuple[float, str]:
        """The largest in-band NRMS of a judged axis and its name ((nan, "") if none is)."""
        if not self.judged.any():
            return float("nan"), ""
        i = int(np.argmax(np.where(self.judged, self.nrms_band, -np.inf)))
        return float(self.nrms_band[i]), AXES[i]


def _ratio(num: np.ndarray, den: np.ndarray) -> np.ndarray:
    """√(num/den) per axis; inf where den is 0 but num is not, 0 where both are."""
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(
            den > 0, np.sqrt(num / np.where(den > 0, den, 1.0)), np.where(num > 0, np.inf, 0.0)
        )


def _field(
    t: np.ndarray, measured: np.ndarray, residual: np.ndarray, band_hz: tuple[float, float]
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(in-band NRMS, broadband NRMS, measured in-band RMS) per column of k ≥ 2 samples."""
    k = t.shape[0]
    x = measured - measured.mean(axis=0)
    r = residual - residual.mean(axis=0)
    dt = float(t[-1] - t[0]) / (k - 1)
    freq = np.fft.rfftfreq(k, dt)
    in_band = (freq >= band_hz[0]) & (freq <= band_hz[1]) & (freq > 0)
    px = np.abs(np.fft.rfft(x, axis=0)) ** 2
    pr = np.abs(np.fft.rfft(r, axis=0)) ** 2
    x_band = px[in_band].sum(axis=0)
    return (
        _ratio(pr[in_band].sum(axis=0), x_band),
        _ratio((r**2).sum(axis=0), (x**2).sum(axis=0)),
        np.sqrt(2.0 * x_band) / k,
    )


def agreement(
    t: np.ndarray,
    measured: np.ndarray,
    residual: np.ndarray,
    sensor: BodySensor,
    present: np.ndarray,
) -> Agreement:
    """The figures of k compared samples at stamps `t` (s, increasing): `measured` and
    `residual` (measured − predicted), each (k, 6), in the sensor's band_hz, its `axes`
    judged; each field (`FIELDS`) on the samples `present` ((k, 2) bool) says provide it,
    if `MIN_SAMPLES` do. The frequencies are those of the mean sampling interval of a field's
    samples (a body IMU's stamps jitter; its samples are taken as uniform)."""
    figures = np.full((3, len(AXES)), np.nan)
    samples = present.sum(axis=0)
    for i, n in enumerate(samples.tolist()):
        if n >= MIN_SAMPLES:
            rows, cols = present[:, i], slice(3 * i, 3 * i + 3)
            figures[:, cols] = _field(
                t[rows], measured[rows, cols], residual[rows, cols], sensor.band_hz
            )
    nrms_band, nrms_broadband, rms_band = figures
    with np.errstate(invalid="ignore"):  # nan: a field not taken
        moved = rms_band >= FLOORS
    return Agreement(
        nrms_band, nrms_broadband, rms_band, moved & np.isin(AXES, sensor.axes), samples
    )


def window_status(
    figures: Agreement, sensor: BodySensor, span: tuple[float, int], problems: dict[str, int]
) -> HealthStatus:
    """The window's diagnostics status: `span` is its (seconds, compared samples), `problems`
    the body messages counted against it (rejected or not compared, by reason): any but those
    `OUTSIDE_THE_RUN` make it at least a WARN."""
    low, high = sensor.band_hz
    band = f"{low:g}–{high:g} Hz"
    worst, axis = figures.worst
    if not axis:
        level = OK
        message = f"the body moved too little in {band} to judge (measured RMS below the floors)"
    else:
        level = ERROR if worst > sensor.error_nrms else WARN if worst > sensor.warn_nrms else OK
        verb = "agree" if level == OK else "disagree"
        limit = {
            OK: "",
            WARN: f" > warn {sensor.warn_nrms:g}",
            ERROR: f" > error {sensor.error_nrms:g}",
        }
        message = (
            f"model and machine {verb} in {band}: worst normalised RMS error {worst:.3f} "
            f"({axis}){limit[level]} over {span[0]:.1f} s"
        )
    notes = _field_notes(figures, span[1])
    if notes:
        message += "; " + "; ".join(notes)
    missed = {k: v for k, v in problems.items() if v}
    if missed:
        message += "; body messages not compared: " + ", ".join(
            f"{k} {v}" for k, v in missed.items()
        )
    if set(missed) - OUTSIDE_THE_RUN:
        level = max(level, WARN)
    values = {"band_hz": f"{low:g} {high:g}", "span_s": f"{span[0]:.3f}", "samples": str(span[1])}
    values.update(
        {f"samples_{f}": str(n) for f, n in zip(FIELDS, figures.samples.tolist(), strict=True)}
    )
    values["lag_s"] = f"{sensor.lag_s:.6g}"
    for i, name in enumerate(AXES):
        values[f"nrms_{name}"] = (
            f"{figures.nrms_band[i]:.4g}" if figures.judged[i] else "not judged"
        )
        values[f"nrms_broadband_{name}"] = _figure(figures.nrms_broadband[i])
        values[f"rms_{name}"] = _figure(figures.rms_band[i])
    values.update({f"body_{k}": str(v) for k, v in problems.items()})
    return HealthStatus(NAME, level, message, values)


def _figure(value: float) -> str:
    """A figure of a value, `n/a` for a field not taken (nan)."""
    return "n/a" if np.isnan(value) else f"{value:.4g}"


def _field_notes(figures: Agreement, samples: int) -> list[str]:
    """What the window's message says of each field that not all its `samples` provide:
    how many it was judged on, or that it was not judged."""
    notes = []
    for i, (field, n) in enumerate(zip(FIELDS, figures.samples.tolist(), strict=True)):
        label = field.replace("_", " ")
        if n == samples:
            continue
        if n < MIN_SAMPLES:
            why = (
                f"provided in only {n} ({MIN_SAMPLES} needed)"
                if n
                else f"not provided in {samples}"
            )
            notes.append(f"{label} not judged: {why} of {samples} samples")
            continue
        verb = "judged" if figures.judged[3 * i : 3 * i + 3].any() else "compared"
        notes.append(f"{label} {verb} on {n} of {samples} samples (not provided in the others)")
    return notes
