"""Two streams' stamps split into runs where they jump back, the n-th runs paired, and whether
the streams jumped back apart (`Apart`): the deck's and the body IMU's, for the body IMU's check
(`body_check`) and the live ageing fits (`analysis.ageing_live`)."""

from __future__ import annotations

import math

import numpy as np


class Apart:
    """Whether the deck's and the body IMU's stamps jumped back apart: the n-th runs of the
    two streams (their stamps split where they go back) are paired, and they are out of step
    once one stream has left run n (jumped back) and the other's stamps of run n have gone
    more than input.back_jump_reset_s past its last one there (a body IMU on another clock
    than the deck, a recorder restarted). In a bag played with --loop both streams jump back
    within a few ms of stamps of each other: in step. Stamps alone decide, so the answer is
    the same however the streams come batched or interleaved. The body's stamps are taken
    less body_sensor.lag_s (the motion they measured)."""

    def __init__(self, reset_s: float, lag_s: float) -> None:
        self._reset, self._lag = reset_s, lag_s
        self._run = {"deck": 0, "body": 0}
        self._ends: dict[str, dict[int, float]] = {"deck": {}, "body": {}}
        """Per stream, the latest stamp (s) of each run not yet found in step."""
        self._paired = 0
        """The first run not yet found in step."""
        self.found: tuple[str, int, float] | None = None
        """(the stream that jumped back first, 'deck' or 'body'; the run it left; its last
        stamp there, s) once out of step (None: in step so far)."""

    def add(self, stream: str, t: np.ndarray) -> None:
        """Stamps (s, on the twin's time base) of `stream` ('deck', 'body'), in its order: a
        stamp before the one before it starts a new run."""
        if not t.shape[0] or self.found is not None:
            return
        lag = self._lag if stream == "body" else 0.0
        run, ends = self._run[stream], self._ends[stream]
        last = ends.get(run, -math.inf)
        for given in t.tolist():  # as Python floats: a wake-up's one or few at a tenth the cost
            stamp = given - lag  # (numpy's subtraction, the same bits)
            if stamp < last:
                run += 1
            ends[run] = last = stamp
        self._run[stream] = run
        self._check()

    def _check(self) -> None:
        run = self._paired
        while self.found is None:
            left = {s: self._run[s] > run for s in self._run}
            for first, other in (("deck", "body"), ("body", "deck")):
                end = self._ends[first].get(run, math.inf) if left[first] else math.inf
                if self._ends[other].get(run, -math.inf) > end + self._reset:
                    self.found = (first, run, end)
            if self.found is not None or not all(left.values()):
                break
            for ends in self._ends.values():
                ends.pop(run, None)
            run = self._paired = run + 1

    def beyond(self, t: np.ndarray, run: np.ndarray) -> np.ndarray:
        """Of body samples (stamps s, runs), those (bool) past the pairing: in a run after the
        one the streams went apart at, or in it more than back_jump_reset_s past the deck's
        last stamp there (all False while in step)."""
        if self.found is None:
            return np.zeros(t.shape[0], bool)
        _, n, _ = self.found
        deck = self._ends["deck"].get(n, math.inf)
        return (run > n) | ((run == n) & (t - self._lag > deck + self._reset))

    def message(self) -> str:
        """What the streams did, once out of step."""
        assert self.found is not None
        first, run, end = self.found
        names = {"deck": "the deck's", "body": "the body IMU's"}
        other = names["body" if first == "deck" else "deck"]
        return (
            f"the body IMU's and the deck's stamps jumped back apart: {names[first]} jumped "
            f"back at {end:.3f} s (after its run {run}), {other} went on past "
            f"{end + self._reset:.3f} s (input.back_jump_reset_s later; the body's less "
            f"body_sensor.lag_s, s of the twin's time base): their runs no longer pair"
        )
