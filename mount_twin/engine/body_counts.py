"""The counts the body IMU's check keeps of its messages (`body_check.BodyCheck.counts`): why
one was not taken (`REJECTED`) or, taken, not compared (`PROBLEMS`; both: `NOT_COMPARED`,
`not_compared`), its stamps' jumps back (`RESETS`), the readings marked not provided
(`UNPROVIDED`), and how a WARN at the end says those lost outside the stream
(`WARNED_AT_END`)."""

from __future__ import annotations

from collections.abc import Mapping

REJECTED = (
    "undecodable",
    "nonpositive_stamp",
    "nonfinite",
    "wrong_frame_id",
    "no_reading",
    "stamp_back",
)
"""Why a body message was not taken (`BodyCheck.screen`, and undecodable; no_reading: both
its readings marked not provided): reported as body_rejected_<reason> in every window, zero
included."""
RESETS = "reset_stamp_jumped_back"
"""The count of body messages whose stamp jumped back by more than input.back_jump_reset_s,
each restarting the comparison (`BodyCheck.screen`)."""
UNPROVIDED = ("unprovided_acceleration", "unprovided_angular_velocity")
"""The counts of accepted body messages that mark their acceleration, their angular velocity
not provided (REP-145): compared on the other reading alone."""
APART = "jumped_back_apart"
MIDDLEWARE = "lost_middleware"
STOPPED = "lost_unprocessed_at_stop"
PROBLEMS = (
    "before_twin",
    "late",
    "in_gap",
    "unanswered",
    "dropped_waiting",
    MIDDLEWARE,
    STOPPED,
    APART,
)
"""Why a body sample accepted was not compared: before the twin's first row, behind the kept
predictions, inside a gap of the twin's rows, after its last row, held too long, or after the
body IMU's and the deck's stamps jumped back apart (`Apart`); and why a body message was
never received: lost by the middleware, or waiting unprocessed in the node's queue when it
was stopped a second time (STOPPED, `ros.node`)."""
NOT_COMPARED = (*(f"rejected_{r}" for r in REJECTED), *PROBLEMS)
"""Every reason a body message was not compared, in the order a window's status says them."""
WARNED_AT_END = {
    "dropped_waiting": "{} body IMU samples held too long waiting for the twin were dropped "
    "(counted {})",
    MIDDLEWARE: "{} body IMU messages lost by the middleware (counted {})",
    STOPPED: "{} body IMU messages waiting when the node was stopped again were not processed "
    "(counted {})",
}
"""The body samples lost that are not at a place in the stream (held too long; never read by
the node: lost by the middleware, left unprocessed at a second stop), by count: how a WARN at
the end of the stream says those no window reported (`Windows.finish`)."""


def not_compared(counts: Mapping[str, int]) -> dict[str, int]:
    """The counts of body messages not compared, by reason (`PROBLEMS`, rejected_<reason>)."""
    return {k: v for k, v in counts.items() if k in PROBLEMS or k.startswith("rejected_")}
