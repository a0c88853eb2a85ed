"""The memory the gyro's delay line keeps between pushes (`delay_line.Backlog`, `RawWindow`).

A live node pushes a sample or a few at a time and the delay line appends them into arrays
with room (ROOM) after the N samples it holds; a replay chunk or a catch-up pushes thousands.
Checked against what the held samples need, counted by hand: after a large push the arrays
come back to a few kB once its samples are gone, and a rule that grows and shrinks them
never does both at every push.
"""

from __future__ import annotations

import tracemalloc
from collections.abc import Callable

import numpy as np

from mount_twin.engine.delay_line import ROOM, Extent, GyroDelay, Run

RATE_HZ = 1000.0
BANDS = (20.0, 100.0)
"""A 1 kHz stream through the (20, 100) Hz design: N = 38 samples pending."""


def _pusher(delay: GyroDelay) -> Callable[[int], None]:
    """Push m samples of a slow roll rate into `delay` as the engine does (frame, feed, close),
    every one accepted, one run."""
    position = [0]

    def push(m: int) -> None:
        first = position[0]
        t = (first + np.arange(m)) / RATE_HZ
        w = np.zeros((m, 3))
        w[:, 0] = 0.01 * np.sin(2.0 * np.pi * 2.0 * t)
        frame = delay.frame(t, np.zeros((m, 3)), w, first)
        delay.feed(Run(np.arange(m), restart=first == 0), frame)
        delay.close(frame)
        position[0] += m

    return push


def test_a_large_push_leaves_no_large_arrays_once_its_samples_are_gone() -> None:
    """A push of 4000 samples (appended where the pending ones wait) and one of 20 000 (the
    raw Ω window then holds all of them: (3, 20 038) floats, 481 kB) grew the arrays, and they
    stayed that size for the rest of the run. After as many one-sample pushes as those pushes'
    samples, the delay line holds what its 38 pending samples need: within 32 kB of what it
    held before them (Backlog: 38 rows of 8 numbers; the raw window: 3 × (2·38 + 1) numbers;
    each with ROOM = 256 rows to spare: about 20 kB in all at twice that)."""
    delay = GyroDelay(BANDS, lambda stamp, design: None)
    push = _pusher(delay)
    tracemalloc.start()
    try:
        for _ in range(600):
            push(1)
        assert delay.delay == 38
        before = tracemalloc.get_traced_memory()[0]
        push(4000)
        push(20_000)
        grown = tracemalloc.get_traced_memory()[0]
        for _ in range(24_000):
            push(1)
        after = tracemalloc.get_traced_memory()[0]
    finally:
        tracemalloc.stop()
    assert grown - before > 20_000 * 3 * 8, "the raw window held the large push"
    assert after - before < 32_000


def test_the_arrays_grow_and_shrink_by_one_rule_with_room_between() -> None:
    """`Extent` at each move: twice the most asked since the last move, plus ROOM, where the
    arrays are too small or more than twice that; else as they are (hand-counted sizes)."""
    extent = Extent()
    extent.asked(100_000)
    assert extent.moved(100_000, 0) == 200_000 + ROOM  # grown
    for _ in range(1000):
        extent.asked(39)
    assert extent.moved(39, 200_000 + ROOM) == 78 + ROOM  # shrunk back
    # pushes of mixed sizes between moves: the largest keeps the arrays its size
    size = 2 * 4038 + ROOM
    for _ in range(3):
        for need in (39, 4038, 40, 1000, 39):
            extent.asked(need)
        assert extent.moved(39, size) == size
    # at twice the largest asked (plus ROOM) and no more, the arrays are kept
    extent.asked(1000)
    assert extent.moved(1000, 2 * (2 * 1000 + ROOM)) == 2 * (2 * 1000 + ROOM)
    extent.asked(1000)
    assert extent.moved(1000, 2 * (2 * 1000 + ROOM) + 1) == 2 * 1000 + ROOM
