"""Pieces shared by several commands: where the bundled files are, loading a scene and saying
what is implausible in it, writing a signal as a bag."""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Callable, Iterable, Iterator, Mapping
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING

from mount_twin.errors import BagError, MountTwinError

if TYPE_CHECKING:
    import numpy as np

    from mount_twin.io.signals import Signal
    from mount_twin.scene.description import Scene

DEFAULT_SCENE = "pump_8_mounts.scene.yaml"
DEFAULT_BAG = "ship_motion_1khz"


def json_text(doc: object, indent: int = 1) -> str:
    """`doc` as standard JSON, every NaN or ±inf float as null: JSON has no such numbers, and
    json.dumps would write NaN or -Infinity, which strict parsers (JavaScript's, jq) refuse
    (an axis without motion has a margin of −inf dB)."""
    import json
    import math

    def finite(value: object) -> object:
        if isinstance(value, float):
            return value if math.isfinite(value) else None
        if isinstance(value, dict):
            return {k: finite(v) for k, v in value.items()}
        if isinstance(value, (list, tuple)):
            return [finite(v) for v in value]
        return value

    return json.dumps(finite(doc), indent=indent, allow_nan=False)


def positive_int(text: str) -> int:
    """argparse type of a count (workers, jobs, messages, substeps): an integer ≥ 1. A 0 or a
    negative one is refused at parse, naming the option (exit 2): `replay --chunk 0` had looped
    for ever, `qualify --workers -1` hung, `sweep --workers 0` meant one per core."""
    return _integer_from(text, 1)


def non_negative_int(text: str) -> int:
    """argparse type of an index (a first seed): an integer ≥ 0 (a negative seed reached
    numpy's generator, whose error named no option)."""
    return _integer_from(text, 0)


def positive_float(text: str) -> float:
    """argparse type of a rate (Hz): a finite number > 0, else refused at parse, naming the
    option and its value (`synthesize --rate 0` had said "--seeds must be ≥ 1, --head ≥ 0 s
    and --rate > 0 Hz", whichever was wrong)."""
    return _number_from(text, 0.0, above=True)


def non_negative_float(text: str) -> float:
    """argparse type of a duration (s): a finite number ≥ 0, else refused at parse, naming the
    option and its value."""
    return _number_from(text, 0.0, above=False)


def _number_from(text: str, low: float, *, above: bool) -> float:
    """`text` as a finite float > low (`above`) or ≥ low, else argparse's error (it names the
    option)."""
    import math

    try:
        value = float(text)
    except ValueError:
        msg = f"{text!r} is not a number"
        raise argparse.ArgumentTypeError(msg) from None
    if not (math.isfinite(value) and (value > low if above else value >= low)):
        msg = f"must be {'>' if above else '≥'} {low:g}, got {text}"
        raise argparse.ArgumentTypeError(msg)
    return value


def _integer_from(text: str, low: int) -> int:
    """`text` as an integer ≥ low, else argparse's error (it names the option)."""
    try:
        value = int(text)
    except ValueError:
        msg = f"{text!r} is not an integer"
        raise argparse.ArgumentTypeError(msg) from None
    if value < low:
        msg = f"must be ≥ {low}, got {value}"
        raise argparse.ArgumentTypeError(msg)
    return value


def share_dir() -> Path:
    """Where config/ and bags/ are: the source tree, or share/mount_twin of an install."""
    here = Path(__file__).resolve().parent.parent
    # An editable or source checkout has config/ beside the package; a colcon install has
    # <prefix>/share/mount_twin above <prefix>/lib/pythonX.Y/site-packages/mount_twin.
    for candidate in (here.parent, *(p / "share" / "mount_twin" for p in here.parents)):
        if (candidate / "config" / DEFAULT_SCENE).exists():
            return candidate
    msg = "cannot find mount_twin's config/ and bags/ (source tree or share/mount_twin)"
    raise MountTwinError(msg)


FIGURE_FORMATS = ("png", "svg", "pdf", "svgz", "eps", "ps", "jpg", "jpeg", "tif", "tiff", "webp")
"""The file name endings a figure may have: formats matplotlib writes (tested)."""


def check_targets(
    *,
    figures: tuple[str, ...] = ("plot",),
    reads: Iterable[str | Path | None] = (),
    **targets: str | None,
) -> None:
    """ValueError naming the option (`--json` for json=...) of the first given path a file
    cannot be written at (a directory there; a file or a dangling symlink in place of its
    directory or one above it, which is made if missing: `textfiles.directory_refusal`;
    through a symlink, its target's directory missing: the file is written there; for the
    options named in `figures`, a name not ending in one of FIGURE_FORMATS), or whose file
    would replace one the command reads (`reads`: its input files and bags; None where not
    given): checked before long work, which had run to its end to fail there with exit 2, its
    own exit status lost, or to replace the recording or scene it had read (exit 0)."""
    from mount_twin.textfiles import directory_refusal

    for option, path in targets.items():
        if path is None:
            continue
        flag, target = "--" + option.replace("_", "-"), Path(path)
        if target.is_dir():
            msg = f"{flag} {path}: is a directory"
            raise ValueError(msg)
        if target.is_symlink():
            directory = Path(os.path.realpath(target)).parent
            if not directory.is_dir():
                via = f"a symlink to {os.readlink(target)}"
                msg = f"{flag} {path}: {via}: there is no directory {directory}"
                raise ValueError(msg)
        elif why := directory_refusal(target.parent):
            msg = f"{flag} {path}: {why}"
            raise ValueError(msg)
        if option in figures and target.suffix.lower().lstrip(".") not in FIGURE_FORMATS:
            msg = (
                f"{flag} {path}: a figure's file name ends in its format: "
                f"{', '.join('.' + f for f in FIGURE_FORMATS)}"
            )
            raise ValueError(msg)
        if replaced := _input_replaced(target, reads):
            msg = f"{flag} {path}: would replace {replaced}, which this command reads"
            raise ValueError(msg)


def _input_replaced(target: Path, reads: Iterable[str | Path | None]) -> str:
    """Which of the files or bags `reads` a file written at `target` would replace ('' for
    none): the file itself, or a file of a bag directory ("a file of BAG")."""
    if not target.is_file():
        return ""
    real = Path(os.path.realpath(target))
    for given in reads:
        if given is None or not os.path.exists(given):
            continue
        if os.path.samefile(target, given):
            return str(given)
        if os.path.isdir(given) and Path(os.path.realpath(given)) in real.parents:
            return f"a file of {given}"
    return ""


def load_scene(path: str | Path, input_overrides: Mapping[str, str] | None = None) -> Scene:
    """The scene file at `path` as a run uses it (`model.scene_file.read_scene`: its `input`
    fields replaced by `input_overrides`, its start solved where its ratings are judged there);
    each of its warnings (units? a message type's convention?) is printed on stderr, so that no
    command runs a scene it found implausible without saying so."""
    from mount_twin.model.scene_file import read_scene

    scene = read_scene(path, input_overrides)
    for warning in scene.warnings:
        print(f"mount-twin: warning: {warning}", file=sys.stderr)
    return scene


def warn_if_partial(bag: str | Path) -> str:
    """Say on stderr that an output bag stops early (a replay stopped by a signal or at damage
    in its input), and why: its figures are then not the whole run's. Returns the marker ('' if
    the bag is whole)."""
    from mount_twin.io.bag_metadata import partial_marker

    if marker := partial_marker(bag):
        print(f"mount-twin: warning: {bag} is partial: {marker}", file=sys.stderr)
    return marker


@contextmanager
def new_directory(path: str | Path, command: str) -> Iterator[Path]:
    """A directory `command` creates for its outputs (ValueError if it exists, or if a dangling
    symlink or a file is in its way: `textfiles.new_directory_refusal`), removed again with
    what the command put in it if the command stops before its end (an error, a signal): an
    empty one blocked the rerun, and one holding the outputs so far (the first seeds of
    synthesize, half a qualification without its verdict) read as a finished result and
    blocked the rerun too. It holds nothing else: it is new, made by this run. The directories
    missing above it are made, and removed with it (`textfiles.directories_above`)."""
    from mount_twin.textfiles import directories_above, new_directory_refusal

    out = Path(path)
    if why := new_directory_refusal(out):
        said = f"exists; {command} writes a new directory" if why == "exists" else why
        msg = f"{out}: {said}"
        raise ValueError(msg)
    with directories_above(out):  # removed too if it is
        out.mkdir()
        try:
            yield out
        except BaseException:
            _remove_unfinished(out, command)
            raise


def _remove_unfinished(out: Path, command: str) -> None:
    """Remove the directory `out` that `command` made and stopped before finishing, saying so
    on stderr if it held anything (or that it could not be removed: the error that stopped the
    command is the one reported)."""
    import shutil

    if not any(out.iterdir()):
        out.rmdir()
        return
    try:
        shutil.rmtree(out)
    except OSError as err:
        print(
            f"mount-twin: warning: {out}: {command} stopped before its end: what it wrote there "
            f"is no result, and could not be removed ({err})",
            file=sys.stderr,
        )
        return
    print(
        f"mount-twin: warning: {out}: removed, with what {command} wrote in it: it stopped "
        "before its end, and its outputs so far are no result",
        file=sys.stderr,
    )


def write_signal(
    sig: Signal,
    out: str,
    topic: str,
    frame_id: str,
    start_ns: int,
    storage: str,
    stamps_ns: np.ndarray | None = None,
) -> int:
    """Write `sig` as sensor_msgs/Imu messages stamped start_ns + t into a new bag (+ the int
    `stamps_ns` where given: a record's exact times, which sig.t as floats holds only to some
    240 ns from the epoch on); a topic that is no ROS topic name, a frame id with whitespace,
    stamps a bag cannot hold and a stamp of 0 (unset in ROS) are refused before it is
    created."""
    import numpy as np

    from mount_twin.io.messages import IMU
    from mount_twin.io.output_bag import check_stamp, write_bag
    from mount_twin.io.output_encoding import imu_messages
    from mount_twin.scene.ros_names import header_frame_id_problem, topic_name_problem

    if problem := topic_name_problem(topic):
        msg = f"--topic {topic!r}: not a ROS topic name: {problem}"
        raise ValueError(msg)
    if problem := header_frame_id_problem(frame_id):
        msg = f"--frame-id {frame_id!r} {problem}"
        raise ValueError(msg)

    since = np.rint(sig.t * 1e9).astype(np.int64) if stamps_ns is None else stamps_ns
    try:  # in Python's ints: start_ns + since could wrap in int64
        check_stamp(out, topic, start_ns + int(since.min()))
        check_stamp(out, topic, start_ns + int(since.max()))
    except BagError as err:  # the stamps are the options' doing: name them
        msg = f"{err}: start the stamps elsewhere (--start, --offset)"
        raise BagError(msg) from None
    stamps = start_ns + since
    if (stamps == 0).any():
        msg = (
            f"{out}: {topic}: a sample would be stamped 0 ns, which ROS reads as unset (the twin "
            "rejects it): start the stamps later (--start, --offset)"
        )
        raise ValueError(msg)
    return write_bag(
        out, topic, IMU, iter(imu_messages(stamps, sig.accel, sig.gyro, frame_id)), storage
    )


def not_finite(ok: np.ndarray, noun: str) -> tuple[np.ndarray, str]:
    """The samples `ok` (bool, one per sample) does not mark, and how many of how many they
    are ('K of N <noun> not finite'; '' where there is none): the count a refusal of a
    record's damaged samples gives, beside its first one's place."""
    import numpy as np

    bad = np.flatnonzero(~ok)
    return bad, f"{bad.shape[0]} of {ok.shape[0]} {noun} not finite" if bad.shape[0] else ""


def refuse_not_finite(
    ok: np.ndarray, noun: str, where: str, place: Callable[[int], str], why: str
) -> None:
    """Refuse a record where `ok` does not mark every sample: ValueError '<where> K of N <noun>
    not finite, the first <place(its index)>: <why>'."""
    bad, said = not_finite(ok, noun)
    if said:
        raise ValueError(f"{where} {said}, the first {place(int(bad[0]))}: {why}")
