"""Whether a scene is the one its output bag's run ran: by the digest the bag records, else by
the few settings its diagnostics record; the values that differ named."""

from __future__ import annotations

from pathlib import Path
from typing import Any, NamedTuple

from mount_twin.errors import MountTwinError
from mount_twin.io.scene_record import RecordedScene, recorded_scene
from mount_twin.model.scene_file import read_scene
from mount_twin.scene.description import Scene, scene_differences, scene_digest, scene_value


class SceneCheck(NamedTuple):
    """How far a scene was found to be its output bag's run's own (`check_scene`).

    text: how it was checked and what was found; differs: it is not the run's; by_digest: the
    bag recorded its scene's digest (else only the facts `text` names were compared)."""

    text: str
    differs: bool
    by_digest: bool

    @property
    def page_text(self) -> str:
        """The report page's line on it."""
        if self.differs:
            return f"NOT the run's, drawn with on request (--other-scene): {self.text}"
        return self.text


CHECKED_SETTINGS = ("rtol", "atol")
"""The scene's integration settings its run's integration status records (`health`)."""


def check_scene(scene: Scene, output_bag: str | Path, integration: dict[str, str]) -> SceneCheck:
    """Whether `scene` (with the input topic and frame the run read, as `report` gives it) is
    the one the run of `output_bag` ran (its mount names are checked before:
    `check_scene_is_the_bags`). By the digest the bag records (`io.scene_record`: its
    `~/scene` topic, a replay's or the node's recorded, else its metadata): any value
    differing (a mount's stiffness, the mass, the diagnostics period, a rating) makes another,
    the values named (`_differing`). A bag that records none (a recording of the node's topics
    by a mount_twin that did not publish its scene, or a replay by one that did not record it)
    tells only some settings: the solver's tolerances its last integration status records
    (`integration`: its values), compared, the first that differs named."""
    recorded = recorded_scene(output_bag)
    if recorded is not None:
        digest = scene_digest(scene)
        ran = recorded.named
        if digest == recorded.sha256:
            text = f"the run's: its digest is the one {output_bag} records (sha256 {digest})"
            how = "its replay's" if recorded.replayed else "the run's"
            return SceneCheck(f"{text}, {how} of {ran}", False, True)
        verb = "replayed" if recorded.replayed else "run"
        text = (
            f"{scene.source}: scene {scene.name} is not the one {output_bag} was {verb} with, "
            f"{ran}: its digest (sha256 {digest}) differs from the one {recorded.where} "
            f"records ({recorded.sha256}); {_differing(scene, recorded, output_bag)}"
        )
        return SceneCheck(text, True, True)
    compared = [key for key in CHECKED_SETTINGS if key in integration]
    for key in compared:
        value = f"{getattr(scene.integration, key):g}"
        if integration[key] != value:
            text = (
                f"{scene.source}: scene {scene.name} is not the one {output_bag} was run with: "
                f"its integration.{key} is {value}, the run's {integration[key]} (as its "
                "integration status records it)"
            )
            return SceneCheck(text, True, False)
    facts = ", ".join(["its mount names", *(f"integration.{key}" for key in compared)])
    text = (
        f"by {facts} only: {output_bag} records no digest of its scene (a recording of the "
        "node's topics without its ~/scene, a replay by a mount_twin that did not record it, "
        "or a storage file without its metadata.yaml), so a scene "
        "differing in another value (a stiffness, the mass, the diagnostics period, a rating) "
        "is not told apart"
    )
    return SceneCheck(text, False, False)


SHOWN_DIFFERENCES = 3
"""How many of the values a scene differs from its run's in `check_scene` names."""


def _differing(scene: Scene, recorded: RecordedScene, output_bag: str | Path) -> str:
    """Which values `scene` differs in from the run's (`SHOWN_DIFFERENCES` of them, by key
    path: `scene_differences`): the value the bag records (`recorded`), else that of the run's
    scene file where it still loads to the recorded digest (`_run_value`); else why that
    cannot be said."""
    if recorded.value is not None:
        run, read = recorded.value, f"as {recorded.where} records it"
    else:
        found = _run_value(scene, recorded, output_bag)
        if isinstance(found, str):
            return f"{found}: cannot say which value differs"
        run, read = found
    found_values = scene_differences(scene, run)
    if not found_values:  # equal as numbers, not as the digest's JSON text
        return (
            "its values equal the run's as numbers and differ only as the digest writes them "
            "(-0.0 against 0.0, 1 against 1.0)"
        )
    shown = "; ".join(
        f"{key}: {here!r} here, {there!r} in the run's scene"
        for key, here, there in found_values[:SHOWN_DIFFERENCES]
    )
    more = len(found_values) - SHOWN_DIFFERENCES
    return (
        f"it differs in {shown}"
        + (f" (and {more} more values)" if more > 0 else "")
        + f" (the run's scene {read})"
    )


def _run_value(
    scene: Scene, recorded: RecordedScene, output_bag: str | Path
) -> tuple[dict[str, Any], str] | str:
    """The value of the run's scene as its file loads it today, with what was put over it
    (an override whose value the bag does not hold: `scene`'s, which has the run's input),
    and how it was read; or why it cannot be had (the file found by `_found`)."""
    if recorded.file is None:
        return "the run's scene came from no file"
    found = _found(recorded, output_bag)
    if isinstance(found, str):
        return found
    path, how = found
    fields = {key.removeprefix("input."): value for key, value in recorded.overrides.items()}
    try:  # a replay's overrides are `input` fields
        run = read_scene(
            path, {k: getattr(scene.input, k) if v is None else v for k, v in fields.items()}
        )
    except (MountTwinError, ValueError, OSError) as err:
        return f"the run's scene file {path} no longer loads ({err})"
    if scene_digest(run) != recorded.sha256:
        return f"the run's scene file {path} has changed since"
    return scene_value(run), f"as its file {path} loads it{how}"


def _found(recorded: RecordedScene, output_bag: str | Path) -> tuple[Path, str] | str:
    """The run's scene file, and how it was found ('' as recorded, absolute; else ": NAME
    found from …", and the paths tried before it); or why it is not found, naming each path
    tried (`_tried`)."""
    tried = _tried(recorded, output_bag)
    for k, (path, name, where) in enumerate(tried):
        if path.is_file():
            if where == AS_RECORDED:  # the first tried
                return path, ""
            missed = f", not found at {_listed(tried[:k])}" if k else ""
            return path, f": {name} found {where}{missed}"
    return f"the run's scene file is not found at {_listed(tried)}"


AS_RECORDED = "as recorded"
"""How `_tried` names a path recorded absolute."""


def _tried(recorded: RecordedScene, output_bag: str | Path) -> list[tuple[Path, str, str]]:
    """Where the run's scene file is looked for, in order, as (path, the name it was had from,
    how): the path recorded (`recorded.file`), then the one the replay was given
    (`recorded.given`: a project moved since, its absolute path gone); a relative one (as a
    replay recorded it before it recorded it absolute) from here, then from the bag's
    directory (where the replay ran if its `-o` named no directory). Each path once."""
    bases = {
        "from here": Path.cwd(),
        "from the bag's directory": Path(output_bag).resolve().parent,
    }
    tried: dict[Path, tuple[str, str]] = {}
    for name in (n for n in (recorded.file, recorded.given) if n is not None):
        places = {AS_RECORDED: Path()} if Path(name).is_absolute() else bases
        for where, base in places.items():
            tried.setdefault(base / name, (name, where))
    return [(path, name, where) for path, (name, where) in tried.items()]


def _listed(tried: list[tuple[Path, str, str]]) -> str:
    """Paths tried, each with how it was had: "A (as recorded), B (NAME from here) nor …"."""
    named = [f"{p} ({w if w == AS_RECORDED else f'{n} {w}'})" for p, n, w in tried]
    return " nor ".join([", ".join(named[:-1]), named[-1]] if len(named) > 1 else named)


def check_scene_is_the_bags(scene: Scene, in_bag: set[str], output_bag: str | Path) -> None:
    """ValueError unless the bag's mounts (those it holds wrenches or statuses of) are the
    scene's: another scene's name, kinds, modes and scene table would head the bag's numbers."""
    names = [m.name for m in scene.mounts]
    if in_bag and in_bag != set(names):
        msg = (
            f"scene {scene.name} (report --scene): its mounts ({', '.join(names)}) are not "
            f"those of {output_bag} ({', '.join(sorted(in_bag))}): give the replay's own scene"
        )
        raise ValueError(msg)
