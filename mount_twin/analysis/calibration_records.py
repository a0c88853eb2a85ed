"""A calibration's pair of records, the foundation's IMU and the body's, as the fit compares
them: the body samples compared (within the foundation record, `EDGE_S` off each end), why a
pair cannot be compared (`overlap_problem`), and which record of it does not move
(`still_record`: specific force, m/s², its dynamic RMS against thresholds).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mount_twin.io.signals import Signal

EDGE_S = 0.25
"""Body samples this close to either end of the foundation record are left out of the fit."""

MIN_OVERLAP = 10
"""Body samples the fit needs within the foundation record (`EDGE_S` off each end) at least."""
STILL_FOUNDATION = 0.05
"""A foundation record whose dynamic RMS (its specific force about its mean, all three axes:
gravity and bias out) over the compared span is at most this, m/s², does not move
(`still_record`): what it holds is its sensor's noise (a MEMS IMU's 0.01 m/s² per axis is
0.017 all axes; the shake table's Xsens DOT reads 0.022 in the first second of its trial
records, before the table starts), and a body's motion is none of the twin's to fit. A deck
that moves moves more: the slow roll and heave alone of `signals.ship_motion` 0.72 m/s², the
shake table 1.3. A sensor noisier than this at rest (a 100 g shock accelerometer at 20 kHz
reads 0.83) is not told from motion here; the fit's own refusals remain."""
STILL_SHARE = 0.01
"""A body record whose dynamic RMS (as `STILL_FOUNDATION`'s) is at most this share of the
foundation's over the compared span does not move (`still_record`). Below its mounts' modes a
body follows its foundation (a share near 1 or more: 2.1 on the shake table), and no mount
isolates 40 dB over the whole of a record that moves at all; a sensor that reads a constant, or
only its own noise (a MEMS IMU's 0.01 m/s² is this share of a 1 m/s² foundation), does."""


def compared(foundation: Signal, body: Signal) -> np.ndarray:
    """Which body samples the fit compares: those within the foundation record, `EDGE_S` off
    each end (a mask over body.t)."""
    return (body.t > foundation.t[0] + EDGE_S) & (body.t < foundation.t[-1] - EDGE_S)


def overlap_problem(
    foundation: Signal,
    body: Signal,
    named: tuple[str, str] = ("the body record", "the foundation's"),
) -> str:
    """Why the fit cannot compare the pair ('' where it can): fewer than `MIN_OVERLAP` body
    samples within the foundation record, `EDGE_S` off each end (records apart on the clock, or
    too short: said which). `named`: how the body record
    and the foundation's (possessive) are said (the command names their files)."""
    overlap = int(np.count_nonzero(compared(foundation, body)))
    if overlap >= MIN_OVERLAP:
        return ""
    if max(body.t[0], foundation.t[0]) < min(body.t[-1], foundation.t[-1]):  # too short
        length = float(foundation.t[-1] - foundation.t[0])
        why = (
            f"the foundation record is {length:.3g} s long: give records longer than "
            f"{2.0 * EDGE_S:g} s (its first and last {EDGE_S:g} s are not compared), with at "
            f"least {MIN_OVERLAP} body samples between"
        )
    else:
        why = "the two records must overlap on one clock"
    return (
        f"{named[0]} ({body.t[0]:.6g} to {body.t[-1]:.6g} s) has {overlap} samples within "
        f"{named[1]} ({foundation.t[0]:.6g} to {foundation.t[-1]:.6g} s, {EDGE_S:g} s off each "
        f"end), fewer than {MIN_OVERLAP}: {why}"
    )


def _dynamic_rms(accel: np.ndarray) -> float:
    """The RMS of (k, 3) specific force about its mean, all axes, m/s² (0 for no sample)."""
    if not accel.shape[0]:
        return 0.0
    return float(np.sqrt(((accel - accel.mean(axis=0)) ** 2).sum(axis=1).mean()))


@dataclass(frozen=True)
class Still:
    """A record of a pair that does not move (`still_record`): which ("foundation" or
    "body"), and why, with the measure and the threshold."""

    record: str
    why: str


def still_record(foundation: Signal, body: Signal) -> Still | None:
    """Which record of the pair shows no motion to fit the twin by, and why; None where both
    move (or too few body samples overlap the foundation's to say: the fit tells that itself).
    Over the compared span (`compared`), each record's dynamic RMS (`_dynamic_rms`, m/s²):
    the foundation's at most `STILL_FOUNDATION`, then the body's at most `STILL_SHARE` of the
    foundation's (a body is judged against its foundation's motion: the foundation first)."""
    keep = compared(foundation, body)
    if np.count_nonzero(keep) < MIN_OVERLAP:
        return None
    t = body.t[keep]
    during = (foundation.t >= t[0]) & (foundation.t <= t[-1])
    moved, shaken = _dynamic_rms(body.accel[keep]), _dynamic_rms(foundation.accel[during])
    if shaken <= STILL_FOUNDATION:
        record, rms = "foundation", shaken
        said = (
            f"at most {STILL_FOUNDATION:g} m/s²: its sensor's noise, a still deck (the wrong "
            "topic, or a record taken in harbour): nothing moves the mounts to fit them by"
        )
    elif moved <= STILL_SHARE * shaken:
        record, rms = "body", moved
        said = (
            f"{moved / shaken:.2g} of the foundation's ({shaken:.3g} m/s²), at most "
            f"{STILL_SHARE:g}: a dead or disconnected sensor, or not this machine's record"
        )
    else:
        return None
    why = (
        f"the {record} record does not move: its specific force varies by {rms:.3g} m/s² RMS "
        f"about its mean from {t[0]:.6g} to {t[-1]:.6g} s, {said}"
    )
    return Still(record, why)
