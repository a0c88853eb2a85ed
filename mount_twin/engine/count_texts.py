"""An engine's counts as a reader takes them: the non-zero ones by prefix (`counted_text`), and
why no input sample was accepted (`nothing_accepted`), for the engine's last report, the
replay's summary and the analyses reading a run back."""

from __future__ import annotations

from collections.abc import Mapping

from mount_twin.engine.health_texts import NO_SAMPLE_ACCEPTED


def counted_text(counts: Mapping[str, int], prefix: str = "") -> str:
    """The non-zero counts of `counts` whose key starts with `prefix`, as a reader takes them:
    'non_finite 3, wrong_frame 40' (the prefix off), or 'none'."""
    kept = [(k, v) for k, v in counts.items() if k.startswith(prefix) and v]
    return ", ".join(f"{k.removeprefix(prefix)} {v}" for k, v in kept) or "none"


def nothing_accepted(
    counts: Mapping[str, int],
    wrong_frame_id: str | None = None,
    frame_id_setting: str = "input.frame_id",
) -> str:
    """Why no input sample was accepted, from an engine's `counts` ('' if some were): how many
    were received and why each was rejected, and the last `wrong_frame_id` rejected if any,
    pointing at what set the frame id expected (`frame_id_setting`: the scene's key, the
    option that replaced it, or both where that cannot be told). A run like that has no
    figures: a peak of 0 N would read as a machine at rest."""
    if counts.get("accepted", 0):
        return ""
    detail = ""
    if wrong_frame_id is not None:
        from mount_twin.scene.reader import shown_text  # a 1 MB frame id, shortened

        said = shown_text(wrong_frame_id)
        detail = f"; the bag's header.frame_id is {said}: see {frame_id_setting}"
    why = (
        f"{counts.get('received', 0)} received, rejected: "
        f"{counted_text(counts, 'rejected_')}{detail}"
    )
    return f"{NO_SAMPLE_ACCEPTED} ({why})"
