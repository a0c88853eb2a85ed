"""A replay's verdict as its output bag's diagnostics tell it: the worst level over the run,
the integration's failures, and why the twin followed none of the input if it did not."""

from __future__ import annotations

from typing import NamedTuple

from mount_twin.analysis.html_page import frame_id_setting
from mount_twin.engine.batch import FAILED, LEVEL_NAMES, OK
from mount_twin.engine.count_texts import nothing_accepted
from mount_twin.engine.health_texts import INTEGRATION, NEVER_STARTED
from mount_twin.io.output_tables import Table, input_values, integration_values
from mount_twin.scene.description import Scene


def _nothing_accepted(diagnostics: Table | None, scene: Scene | None) -> str:
    """Why no input sample of the run was accepted, as its replay's summary says it, from the
    counts of its last input status ('' if some were, or the bag holds no counts), pointing at
    what set the frame id it expected (`frame_id_setting`: the run of `scene`; without it,
    the frame the status records)."""
    values = input_values(diagnostics)
    counts = {
        k: int(v)
        for k, v in values.items()
        if (k in ("received", "accepted") or k.startswith("rejected_")) and v.isdigit()
    }
    if counts.get("accepted") != 0:  # some were, or no counts: the scene's file is not read
        return ""
    setting = frame_id_setting(scene, values.get("frame_id"))
    return nothing_accepted(counts, values.get("last_wrong_frame_id"), setting)


def followed_nothing(diagnostics: Table | None, scene: Scene | None) -> str:
    """Why the twin followed none of the input, as its replay says it ('' if it did): no input
    sample accepted (`_nothing_accepted`), or too few to start it, which the stream's last
    integration status says (`health_texts.NEVER_STARTED`). Either has no figures, and exits 3."""
    if nothing := _nothing_accepted(diagnostics, scene):
        return nothing
    if diagnostics is None:
        return ""
    c = diagnostics.columns
    said = [m for st, m in zip(c["status"], c["message"], strict=True) if st == INTEGRATION]
    return said[-1] if said and said[-1].startswith(NEVER_STARTED) else ""


class RunVerdict(NamedTuple):
    """A run's verdict as its output bag's diagnostics tell it.

    text: as the page heads it; worst_level: the worst diagnostics level over the run (index
    in LEVEL_NAMES; None: the bag holds no diagnostics); failure: how often the integration
    failed ('' if never: else the run is FAILED); nothing: why the twin followed none of the
    input ('' if it did: `followed_nothing`)."""

    text: str
    worst_level: int | None
    failure: str
    nothing: str


def verdict_of(diagnostics: Table | None, nothing: str) -> tuple[RunVerdict, dict[str, str]]:
    """The run's verdict from its diagnostics (FAILED if the integration ever failed, else the
    worst level of any status but the live-only `mount_twin: ros`, with `nothing`: why the
    twin followed none of the input, if it did not), and the last integration status' values."""
    if diagnostics is None or not len(diagnostics):
        return RunVerdict("no diagnostics in the bag", None, "", nothing), {}
    c = diagnostics.columns
    worst = OK
    for status, level in zip(c["status"], c["level"], strict=True):
        if status != "mount_twin: ros" and level in LEVEL_NAMES:
            worst = max(worst, LEVEL_NAMES.index(level))
    integration = integration_values(diagnostics)
    if failures := int(integration.get("failures_total", "0")):
        failure = f"{failures} integration failures"
        return RunVerdict(f"{FAILED} ({failure})", worst, failure, nothing), integration
    if nothing:
        return RunVerdict(f"{LEVEL_NAMES[worst]}: {nothing}", worst, "", nothing), integration
    return RunVerdict(LEVEL_NAMES[worst], worst, "", nothing), integration
