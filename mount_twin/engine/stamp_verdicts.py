"""The verdicts on a sample that the intake takes (ACCEPT, a START or restart, a gap bridged
or reset) or holds back (HOLD), and how its stamp earns one: `stamp_verdict` for one sample
after the last taken, `rising_or_back` for a whole array of stamps, as the streams beside the
twin's (the ageing tracker, the body IMU) take theirs."""

from __future__ import annotations

import numpy as np

from mount_twin.scene.description import InputSpec

ACCEPT, START, JUMPED_BACK, GAP_RESET, GAP_BRIDGED = (
    "accept",
    "start",
    "jumped_back",
    "gap_reset",
    "gap_bridged",
)
"""Verdicts on a sample besides the rejection reasons (non_finite, wrong_frame, ...)."""

HOLD = "hold"
"""The last sample of a push whose stamp jumped forward: kept for the next push to confirm."""

JUMP_FACTOR = 2.0
"""A stamp interval more than this many times the previous one is a jump to confirm: taken if
the next stamp is later still, rejected as `stamp_glitch` if the next one falls back before it
(one bad stamp then costs that one sample, not the samples until time catches up with it). At
2, a stamp glitched forward by 3 intervals or more is caught (at 20, one of 18 ms on a 1 kHz
stream was taken and the 17 valid samples after it rejected as going back); a jump followed by
later stamps, jitter included, only delays its sample by one when it ends a push."""

RESTARTS = frozenset((START, JUMPED_BACK, GAP_RESET))
"""Verdicts whose sample (re)starts the twin."""


def _latest_before(stamps: np.ndarray, keep: np.ndarray, last: int) -> np.ndarray:
    """Per sample, the latest of `last` and the stamps `keep` marks before it."""
    kept = np.where(keep, stamps, np.iinfo(np.int64).min)
    return np.maximum.accumulate(np.concatenate([[last], kept]))[:-1]


def rising_or_back(
    stamps: np.ndarray, keep: np.ndarray, last: int, reset: int
) -> tuple[np.ndarray, np.ndarray]:
    """Of the samples `keep` marks, those whose integer stamp is after `last` and after every
    kept stamp before it (one going back is not after the others either, so the running
    maximum over all kept ones is the same as over the rising ones), except that a kept stamp
    more than `reset` before `last` and every kept stamp before it starts afresh, as a stamp
    jumping back by more than input.back_jump_reset_s restarts the twin (`stamp_verdict`'s
    JUMPED_BACK: a bag played with --loop): (taken, of them those that jumped back) bool masks
    (`last`, `reset` and the stamps in one unit)."""
    taken = np.zeros(stamps.shape[0], bool)
    jumped = np.zeros(stamps.shape[0], bool)
    start = 0
    while True:
        part, kept = stamps[start:], keep[start:]
        before = _latest_before(part, kept, last)
        back = np.flatnonzero(kept & (part < before - reset))
        stop = int(back[0]) if back.shape[0] else part.shape[0]
        taken[start : start + stop] = (kept & (part > before))[:stop]
        if not back.shape[0]:
            return taken, jumped
        taken[start + stop] = jumped[start + stop] = True
        last, start = int(part[stop]), start + stop + 1


def stamp_verdict(
    spec: InputSpec, t: float, last_t: float, last_step: float | None, next_t: float | None
) -> str:
    """Verdict on a readable sample of stamp t (s) by its stamp alone: after the last taken
    sample's `last_t`, into which the interval was `last_step` (None: it was a start), and
    before the next sample's `next_t` (None: it ends the push)."""
    if t == last_t:
        return "duplicate_stamp"
    if t < last_t - spec.back_jump_reset_s:
        return JUMPED_BACK
    if t < last_t:
        return "stamp_went_back"
    if (
        last_step is not None
        and t - last_t > JUMP_FACTOR * last_step
        and (next_t is None or last_t < next_t < t)
    ):
        return HOLD if next_t is None else "stamp_glitch"
    if t - last_t > spec.max_gap_s:
        return GAP_RESET if spec.gap_policy == "reset" else GAP_BRIDGED
    return ACCEPT
