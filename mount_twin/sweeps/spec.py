"""A sweep description (YAML), validated at load with key-path errors like scenes.

base: pump_8_mounts.scene.yaml        # a scene file, relative to the sweep file
vary:                                 # each a key path into the scene and its values
  - key: mounts[*].stiffness          # [*]: every mount; [fl]: the mount named fl
    scale: [0.5, 1.0, 2.0]            # multiply (element-wise for vectors)
  - key: body.mass
    values: [1100.0, 1300.0]          # set
  - key: mounts[fl].position
    values: [[0.9, 0.4, 0.0], [1.0, 0.4, 0.0]]
  - key: input.gyro_stopband_hz
    range: {start: 60.0, stop: 100.0, num: 3}   # evenly spaced, both ends included
combine: product                      # every combination (default), or zip (in step)
inputs:                               # each case runs against every input
  - bag: ../bags/half_sine_shock_10khz
  - name: dhs_400                     # a generated record (mount-twin generate's options)
    generate: {kind: half-sine, peak: 400.0, pulse: 0.005, rebound: 100.0, rate: 10000.0,
               duration: 0.3}
"""

from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from mount_twin.scene.loader import scene_from_dict
from mount_twin.scene.reader import Reader
from mount_twin.scene.yaml_reading import read_scene_yaml

GENERATE_KINDS = ("half-sine", "ship-motion")
GENERATE_KEYS = ("kind", "peak", "pulse", "rebound", "lateral", "rate", "duration")


@dataclass(frozen=True)
class Variation:
    """One varied key path: `op` 'set' or 'scale', with its values."""

    key: str
    op: str
    values: tuple[Any, ...]


@dataclass(frozen=True)
class InputCase:
    """An input record: a bag (path) or a generated signal (`generate` options)."""

    name: str
    bag: str = ""
    generate: tuple[tuple[str, Any], ...] = ()
    content: str = ""
    """A bag's: the digest of its files when the sweep was loaded (`bag_digest`), so that a
    bag recorded again at the same path is another input (its cases' ids, a worker's cache of
    what it read)."""


@dataclass(frozen=True)
class SweepSpec:
    """A loaded sweep: the base scene's mapping, the variations, how they combine, inputs."""

    source: str
    base_source: str
    base: dict[str, Any]
    variations: tuple[Variation, ...]
    combine: str
    inputs: tuple[InputCase, ...]


MAX_CASES = 100_000
"""Most cases a sweep may have (variations × inputs), and values a `range` may give."""


def load_sweep(path: str | Path) -> SweepSpec:
    """Read and validate a sweep file; errors name the file and key path (and a variation that
    makes no valid scene, with the scene's own error)."""
    path = Path(path)
    data = read_scene_yaml(path)  # the same YAML rules as scene files
    top = Reader(data, str(path))
    base_path = (path.parent / top.string("base")).resolve()
    base = read_scene_yaml(base_path)
    scene_from_dict(base, str(base_path), refuse_unheld=True)  # the base must be a valid scene
    raw_vary = top.raw("vary", [])
    if not isinstance(raw_vary, list):
        raise top.error("vary", f"expected a list of variations, got {raw_vary!r}")
    variations = tuple(
        _variation(Reader(v, str(path), f"vary[{i}]")) for i, v in enumerate(raw_vary)
    )
    combine = top.choice("combine", ("product", "zip"), "product")
    if combine == "zip" and len({len(v.values) for v in variations}) > 1:
        raise top.error("combine", "zip needs the same number of values in every variation")
    raw_inputs = top.raw("inputs")
    if not isinstance(raw_inputs, list) or not raw_inputs:
        raise top.error("inputs", f"expected a non-empty list of inputs, got {raw_inputs!r}")
    digests: dict[tuple[str, int, int], str] = {}  # each file read once, named twice or not
    inputs = tuple(
        _input(Reader(v, str(path), f"inputs[{i}]"), path.parent, digests)
        for i, v in enumerate(raw_inputs)
    )
    if len({i.name for i in inputs}) != len(inputs):
        raise top.error("inputs", "input names must differ (give each a `name`)")
    sizes = [len(v.values) for v in variations]
    cases = (math.prod(sizes) if combine == "product" else min(sizes, default=1)) * len(inputs)
    if cases > MAX_CASES:
        raise top.error("vary", f"{cases} cases, more than MAX_CASES ({MAX_CASES}) allows")
    top.finish()
    return SweepSpec(str(path), str(base_path), base, variations, combine, inputs)


def _variation(r: Reader) -> Variation:
    key = r.string("key")
    ops = [op for op in ("values", "scale", "range") if op in r.data]
    if len(ops) != 1:
        raise r.error("key", f"give exactly one of values, scale or range for {key!r}")
    if ops[0] == "range":
        spec = r.sub("range")
        start, stop = spec.number("start"), spec.number("stop")
        num = spec.integer("num", lo=1, hi=MAX_CASES)
        spec.finish()
        values: tuple[Any, ...] = tuple(float(v) for v in np.linspace(start, stop, num))
        op = "set"
    else:
        raw = r.raw(ops[0])
        if not isinstance(raw, list) or not raw:
            raise r.error(ops[0], f"expected a non-empty list, got {raw!r}")
        values, op = tuple(raw), "scale" if ops[0] == "scale" else "set"
        numbers = all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values)
        if op == "scale" and not numbers:  # (a bool is an int: true scaled by 1)
            raise r.error("scale", f"expected numbers, got {raw!r}")
    r.finish()
    return Variation(key, op, values)


def _input(r: Reader, folder: Path, digests: dict[tuple[str, int, int], str]) -> InputCase:
    if "bag" in r.data:
        bag = str((folder / r.string("bag")).resolve())
        if not Path(bag).exists():
            raise r.error("bag", f"no such file or directory: {bag}")
        if not (Path(bag).is_dir() or Path(bag).is_file()):  # /dev/zero: digested for ever
            raise r.error("bag", f"{bag}: no bag (neither a directory nor a regular file)")
        try:
            content = bag_digest(Path(bag), digests)
        except OSError as err:
            raise r.error("bag", f"cannot read {err.filename or bag}: {err.strerror}") from err
        case = InputCase(r.string("name", Path(bag).name), bag=bag, content=content)
    else:
        g = r.sub("generate", optional=False)
        kind = g.choice("kind", GENERATE_KINDS)
        options: dict[str, Any] = {"kind": kind}
        for key in GENERATE_KEYS[1:]:
            if key in g.data:
                options[key] = g.number(key)
        g.finish()
        case = InputCase(r.string("name", kind), generate=tuple(sorted(options.items())))
    r.finish()
    return case


def bag_digest(bag: Path, digests: dict[tuple[str, int, int], str]) -> str:
    """SHA-256 of the bag at `bag`: of the file, or of a directory's regular files (a rosbag2
    directory: metadata.yaml and the storage files), each by its name and bytes, streamed
    (`hashlib.file_digest`: never read whole into memory).
    `digests` caches a file's by (path, size, mtime_ns): a bag two inputs name is read once."""
    files = sorted(f for f in bag.iterdir() if f.is_file()) if bag.is_dir() else [bag]
    whole = hashlib.sha256()
    for file in files:
        st = file.stat()
        key = (str(file), st.st_size, st.st_mtime_ns)
        if key not in digests:
            with file.open("rb") as fh:
                digests[key] = hashlib.file_digest(fh, "sha256").hexdigest()
        whole.update(f"{file.name}\0{digests[key]}\0".encode())
    return whole.hexdigest()
