"""The diagnostics statuses' names, keys and texts: what a report calls each status and value,
what it says where nothing was computed, and the texts of its figures (ratios, samples lost,
mount events), shared by the health window, the replay's summary and the analyses reading a
bag back."""

from __future__ import annotations

from mount_twin.engine.batch import MountEvent
from mount_twin.engine.estimate import WARN_FORCE_ERROR_REL, ErrorEstimate

PREFIX = "mount_twin"
INTEGRATION = f"{PREFIX}: integration"
"""Name of the integration status."""
INPUT = f"{PREFIX}: input"
"""Name of the input status."""
ATTITUDE = f"{PREFIX}: attitude"
"""Name of the attitude status."""
MOUNT = f"{PREFIX}: mount "
"""A mount status' name: MOUNT + the mount's name."""
NO_SAMPLE_ACCEPTED = "no input sample was accepted"
"""Why a run computed nothing at all (NOT_RUN, NOT_COMPUTED; the replay's summary)."""
NOT_RUN = f"not run: {NO_SAMPLE_ACCEPTED}"
"""The integration status' text while no input sample has been accepted (it had read "ok",
as if the twin had integrated the run clean)."""
NO_INTERVAL_RUN = "not run: no input interval was integrated"
"""The integration status' text while samples were accepted but no interval between two was
integrated (one sample: it had read "ok", as if the twin had integrated the run clean)."""
NOT_COMPUTED = f"not computed: {NO_SAMPLE_ACCEPTED}"
"""The attitude and mount statuses' text while no input sample has been accepted, their
figures "n/a" (they had read "ok" with a tilt and peaks of 0, as a machine at rest)."""
NOT_COMPUTED_HERE = "not computed in this period"
"""The attitude and mount statuses' text, with why, for a period that computed no motion and
no mount load after samples were accepted before it (a stall, a twin that follows no more)."""
NOT_RUN_HERE = "not run in this period"
"""The integration status' text, with why, for a period that integrated no input interval in a
run that integrated some before it (a stall, a restart gathering its samples): its stepper
figures "n/a" (it had read "ok")."""
NOT_PUBLISHED_HERE = "no row published in this period"
"""The attitude and mount statuses' text, with why, for a period that integrated samples but
published none of them (`outputs.decimation` above its samples): its tilt and peaks, figures of
published rows, "n/a" (they had read 0, a machine at rest), the utilisation its own."""
NEVER_STARTED = "the twin never started"
"""What a run that accepted samples but ended before a start says (`HealthWindow.never_started`):
fewer samples than `initial_state.gravity_samples` (it had written no report at all, and its
replay read OK)."""
NOT_DESIGNED = (
    "the gyro filter was never designed: no two input samples were accepted without a restart "
    "between them"
)
"""Why a run of `input.gyro_filter: linear_phase` has no latency figure (`HealthWindow.latency`
None): the filter is designed at the rate of its first accepted samples (it had read 0 s, as
if the outputs followed their input at once)."""

PEAK_KEYS = tuple(f"peak_{axis}" for axis in ("fx_N", "fy_N", "fz_N", "tx_Nm", "ty_Nm", "tz_Nm"))
"""A mount status' keys of its peak wrench components in this period (N, N·m, mount axes)."""
TILT_KEY = "tilt_max_rad"
"""The attitude status' key of the largest tilt in this period (rad)."""
UTILISATION_KEY = "utilisation_max"
"""A mount status' key of its largest utilisation in this period ("n/a": none rated)."""
EVENTS_KEY = "events"
"""A mount status' key of the number of its events in this period."""
NOW_KEY = "now"
"""A mount status' key of the conditions holding at the report ("none": none)."""


def ratio_text(value: float, spec: str = ".3g", limit: float = 1.0) -> str:
    """A utilisation (or another ratio judged against `limit`) as text, `format(value, spec)`
    with more digits where rounding would carry it onto or across the limit: 0.99983 reads
    0.9998, not 1 (the limit, whose reaching is an ERROR, said of a mount at WARN)."""
    text = format(value, spec)
    kind = spec[-1]
    digits = int(spec[1:-1])
    while (float(text) >= limit) != (value >= limit) and digits < 17:
        digits += 1
        text = format(value, f".{digits}{kind}")
    return text


def why_none(nothing: str) -> str:
    """A run's reason for having followed none of its input (`nothing`: no sample accepted,
    or NEVER_STARTED and its details) without the details, after "none, " or "no figure: "."""
    return NEVER_STARTED if nothing.startswith(NEVER_STARTED) else NO_SAMPLE_ACCEPTED


def estimate_warning(run: ErrorEstimate) -> str | None:
    """The integration status' warning on the estimated error of everything published so far
    (`run`), None while it is within WARN_FORCE_ERROR_REL of the largest force: the figure of
    the diagnostics and of the replay summary, one definition."""
    if not run.force_error_rel > WARN_FORCE_ERROR_REL:  # NaN: nothing estimated yet
        return None
    return (
        f"estimated mount-force error {run.force_error_rel:.2g} of the largest force over the "
        "run so far: tighten integration.rtol"
    )


def samples_text(n: int) -> str:
    """'1 sample', '3 samples'."""
    return f"{n} sample{'' if n == 1 else 's'}"


def seconds_text(t: float) -> str:
    """A duration for a message: '1.0 s', '12.5 s', '250 ms'."""
    return f"{t:.1f} s" if t >= 1.0 else f"{t * 1e3:.0f} ms"


def lost_text(
    lost: int, share: float, from_stamps: int, nominal_s: float, reported: dict[str, int]
) -> str:
    """'~12 samples lost in this period (1.2 %, from stamp gaps at a 1.000 ms nominal interval;
    reported lost_middleware 3)': `share` of the samples due, `from_stamps` of them estimated
    from the stamps at the nominal interval `nominal_s` (s), `reported` by the adapter."""
    sources = []
    if from_stamps:
        sources.append(f"from stamp gaps at a {nominal_s * 1e3:.3f} ms nominal interval")
    if reported:
        sources.append("reported " + ", ".join(f"{k} {v}" for k, v in reported.items()))
    return f"~{lost} samples lost in this period ({100.0 * share:.1f} %, {'; '.join(sources)})"


def _by_kind(events: list[MountEvent]) -> dict[str, list[MountEvent]]:
    """The events by kind, kinds in the order of their first event."""
    kinds: dict[str, list[MountEvent]] = {}
    for event in events:
        kinds.setdefault(event.event, []).append(event)
    return kinds


def event_values(events: list[MountEvent], origin_s: int) -> dict[str, str]:
    """Per event kind of the period, in full: `<event>.count`, `<event>.first_stamp_ns` (the
    header stamp of its first, ns) and `<event>.force_max_N` (the largest |F|, N, repr)."""
    values = {}
    for name, same in _by_kind(events).items():
        values[f"{name}.count"] = str(len(same))
        values[f"{name}.first_stamp_ns"] = str(origin_s * 10**9 + round(same[0].stamp * 1e9))
        values[f"{name}.force_max_N"] = repr(max(e.force for e in same))
    return values


def events_text(events: list[MountEvent], utilisation: float, origin_s: int) -> str:
    """'joint_opened ×3 (first 1.234567 s, |F| max 4.5e+04 N); …', or the utilisation."""
    if not events:
        return "ok" if not utilisation > 0.0 else f"utilisation {ratio_text(utilisation)}"
    parts = []
    for name, same in _by_kind(events).items():
        parts.append(
            f"{name} ×{len(same)} (first {origin_s + same[0].stamp:.6f} s, "
            f"|F| max {max(e.force for e in same):.4g} N)"
        )
    return "; ".join(parts)
