"""The node's ROS parameters: read what it was given, load the scene, declare everything.

Every parameter is declared with the value in force, defaults included, a description and
`read_only` (the scene is structural: change it by restarting the node), so `ros2 param
get/describe/dump` show the whole twin and a dump reloads as a params file. What the node was
given is checked before anything is declared: an unknown key or a bad value ends the node with
one line naming the parameter (`SceneError`), an integer written for a double is taken as the
double, and a `scene_file` is loaded with the other scene parameters overriding its values.
"""

from __future__ import annotations

import math
import re
from collections.abc import Sequence
from dataclasses import dataclass
from itertools import pairwise
from typing import Any

from rcl_interfaces.msg import FloatingPointRange, IntegerRange, ParameterDescriptor
from rclpy.exceptions import InvalidParameterValueException
from rclpy.logging import LoggingSeverity, get_logger_level, set_logger_level
from rclpy.node import Node
from rclpy.utilities import remove_ros_args

from mount_twin.errors import MountTwinError, SceneError
from mount_twin.ros.rclpy_private import given_parameters
from mount_twin.scene.description import Scene
from mount_twin.scene.params import (
    PARAMETERS,
    effective_parameters,
    flatten,
    parameter_description,
)
from mount_twin.scene.yaml_reading import load_yaml, read_scene_yaml


@dataclass(frozen=True)
class NodeOptions:
    """How the node moves messages (not part of the scene).

    Attributes:
        batch_period_s: 0: process input as it arrives; > 0: queue it and process the queue
            every batch_period_s (s, steady clock) in one engine call.
        input_queue_depth: messages the input subscription keeps (best effort, keep last).
        output_queue_depth: messages each output publisher keeps (reliable, keep last).
        stall_period_s: period of the node's clock (s) after which, without any report or
            accepted sample, the node reports why; 0: the scene's diagnostics period.
    """

    batch_period_s: float = 0.0
    input_queue_depth: int = 1000
    output_queue_depth: int = 100
    stall_period_s: float = 0.0

    def stall_period(self, scene: Scene) -> float:
        """The stall check's period, s (`stall_period_s`, or the scene's diagnostics period)."""
        return self.stall_period_s or scene.outputs.diagnostics_period_s


def _described(
    description: str, bounds: tuple[float, float] | None = None, *, integer: bool = False
) -> ParameterDescriptor:
    """A read-only parameter's descriptor, with its range [lo, hi] where `bounds` say one
    (an integer range if `integer`; none if both ends are infinite)."""
    ranges: dict[str, Any] = {}
    if bounds is not None and integer:
        lo_int, hi_int = map(int, bounds)
        ranges["integer_range"] = [IntegerRange(from_value=lo_int, to_value=hi_int)]
    elif bounds is not None and not all(map(math.isinf, bounds)):
        lo, hi = map(float, bounds)
        ranges["floating_point_range"] = [FloatingPointRange(from_value=lo, to_value=hi)]
    return ParameterDescriptor(description=description, read_only=True, **ranges)


def _option(description: str, lo: float, hi: float) -> ParameterDescriptor:
    """A read-only node option in [lo, hi]: a double if lo is a float, else an integer."""
    return _described(description, (lo, hi), integer=not isinstance(lo, float))


_OPTIONS: dict[str, ParameterDescriptor] = {
    "batch_period_s": _option(
        "0.0: process input messages as they arrive (every message waiting is taken at each "
        "wake-up); > 0: queue them and process the queue every batch_period_s (s, steady "
        "clock) in one engine call, at that much added latency",
        0.0,
        1.0,
    ),
    "input_queue_depth": _option(
        "Input subscription history depth (best effort, keep last), messages; at 10 kHz, "
        "1000 holds 0.1 s",
        1,
        1_000_000,
    ),
    "output_queue_depth": _option(
        "History depth of each output publisher (reliable, keep last), messages", 1, 1_000_000
    ),
    "stall_period_s": _option(
        "Period of the node's clock (s, wall or sim time) after which, if it brought no report "
        "and no accepted sample, the node publishes a report saying why (no input, all "
        "rejected, stalled); 0.0: outputs.diagnostics_period_s",
        0.0,
        3600.0,
    ),
}
BUILT_IN = frozenset({"use_sim_time", "start_type_description_service"})
"""Parameters rclpy declares itself (in `Node.__init__`), both booleans."""
QOS_OVERRIDES = "qos_overrides."
"""Prefix of ROS 2's QoS override parameters, which rclpy declares and checks itself (the node
lets the input subscription's reliability be overridden)."""


def _ros_arguments(args: Sequence[str]) -> list[str]:
    """The tokens of `args` inside `--ros-args` … (up to `--` or the end)."""
    out, inside = [], False
    for arg in args:
        if arg in ("--ros-args", "--"):
            inside = arg == "--ros-args"
        elif inside:
            out.append(arg)
    return out


RCL_WHERE = re.compile(r"(, at \S+:\d+)+$")
"""The C source positions rcl appends to its error messages."""
RCL_UNPARSED = re.compile(r"Couldn't parse (?P<what>.+?): '(?P<arg>.*)'\. Error: (?P<why>.*)")
"""rcl's message for a command-line argument it cannot parse."""


def rcl_message(err: Exception) -> str:
    """rcl's error (an `RCLError` of rclpy) as one line for a user: without the C source
    positions rcl appends (`, at /project/src/rcl/arguments.c:415`) nor rclpy's prefix, and
    an argument rcl could not parse named first (`-r /a:=//b: not a valid remap rule`)."""
    text = RCL_WHERE.sub("", " ".join(str(err).split()))
    for prefix in ("failed to initialize rcl: ", "Failed to parse ROS arguments: "):
        text = text.removeprefix(prefix)
    unparsed = RCL_UNPARSED.fullmatch(text)
    if unparsed is None:
        return text
    why = "" if unparsed["why"] == "error not set" else f": {unparsed['why']}"
    return f"{unparsed['arg']}: not a valid {unparsed['what']}{why}"


def check_command_line(args: Sequence[str]) -> None:
    """Check the command line `args` before rclpy is initialised with it, so that a bad one
    ends the node with one line: every `--params-file` is read by the scene files' rules (a
    missing file, a YAML error and a key given twice are named with the file and line), then
    rcl parses the ROS arguments with its own logger quiet (on an argument it cannot parse,
    rcl logged `[ERROR] [rcl]: Failed to parse global arguments` before the node's line, and
    its message ended in C source positions).

    Raises:
        SceneError: a params file cannot be read or breaks the scene files' YAML rules.
        MountTwinError: rcl refuses an argument (`rcl_message`).
    """
    for flag, value in pairwise(_ros_arguments(args)):
        if flag == "--params-file":
            read_scene_yaml(value)
    level = get_logger_level("rcl")
    set_logger_level("rcl", LoggingSeverity.FATAL)
    try:
        remove_ros_args(list(args))
    except RuntimeError as err:  # rclpy's RCLInvalidROSArgsError
        raise MountTwinError(rcl_message(err)) from err
    finally:
        set_logger_level("rcl", level)


def shadowed_command_line(args: Sequence[str], names: set[str]) -> dict[str, Any]:
    """The `-p NAME:=VALUE` (or `-p NODE:NAME:=VALUE` for a node in `names`) of the command
    line `args` that a `--params-file` section for the node (its name, or `/**`) also sets,
    values read as YAML.

    rcl reads the params files after every `-p`, so a file outranks the command line whatever
    their order: `--params-file params.yaml -p body.mass:=heavy` ran on the file's 1200 kg
    without a word. The node takes the command line's values back, as a user means them.

    Raises:
        SceneError: a params file breaks the scene files' YAML rules (a key given twice in
            one mapping, which rcl reads as its last value), naming the file and lines.
    """
    tokens = _ros_arguments(args)
    given: dict[str, Any] = {}
    in_files: set[str] = set()
    for flag, value in pairwise(tokens):
        if flag in ("-p", "--param") and ":=" in value:
            name, _, text = value.partition(":=")
            target, _, name = name.rpartition(":")
            if not target or target.lstrip("/") in names:
                given[name] = load_yaml(text)  # 1.5e3 a float, as rcl reads it
        elif flag == "--params-file":  # rcl has read it; read by the scene files' rules
            sections = read_scene_yaml(value) or {}  # (a key given twice: rcl keeps the last)
            for section, body in sections.items():
                if str(section).lstrip("/") in {*names, "**"} and isinstance(body, dict):
                    in_files |= {n for n, _ in flatten(body.get("ros__parameters") or {})}
    return {name: value for name, value in given.items() if name in in_files}


def configure(node: Node, args: Sequence[str] = ()) -> tuple[NodeOptions, Scene]:
    """Check the node's given parameters (with the command line `args`' `-p` over a params
    file's section for the node: `shadowed_command_line`), load the scene, declare every
    parameter.

    Raises:
        SceneError: naming the parameter (or scene file key path) at fault.
    """
    source = f"parameters of {node.get_fully_qualified_name()}"
    names = {node.get_name(), node.get_fully_qualified_name().lstrip("/")}
    given = {
        k: v
        for k, v in {**given_parameters(node), **shadowed_command_line(args, names)}.items()
        if k not in BUILT_IN and not k.startswith(QOS_OVERRIDES)
    }
    _refuse_unknown_names(given, source)
    options = {k: given.pop(k) for k in list(given) if k in _OPTIONS}
    scene, effective, bounds = effective_parameters(given, source)
    values = _declare_options(node, options, source)
    for name, value in effective.items():
        integer = isinstance(value, int) and not isinstance(value, bool)
        meaning = parameter_description(name, effective)
        descriptor = _described(meaning, bounds.get(name), integer=integer)
        node.declare_parameter(name, value, descriptor, ignore_override=True)
    return NodeOptions(**values), scene


KNOWN_NAMES = frozenset({name.split(".")[0] for name in PARAMETERS} | {"mounts", *_OPTIONS})
"""The first part of every parameter name the node takes: the scene's sections and scene
keys (`mount_names`, `scene_file`, ...), `mounts`, and the node's own options."""


def built_in_type_error(node: Node, err: Exception) -> SceneError:
    """The error for a parameter of BUILT_IN given a value of another type than bool, which
    rclpy's `Node.__init__` raised (`err`) from its declaration, and which ended the node
    with a traceback (`-p use_sim_time:=1`); rclpy's text where no such value was given."""
    given = given_parameters(node)
    source = f"parameters of {node.get_fully_qualified_name()}"
    for name in sorted(BUILT_IN & given.keys()):
        if not isinstance(given[name], bool):
            return SceneError(source, name, f"expected true or false, got {given[name]!r}")
    return SceneError(source, "<rclpy>", str(err))


def _refuse_unknown_names(given: dict[str, Any], source: str) -> None:
    """A given parameter no scene section or node option starts: an error listing all of them
    (the scene loader's own list knows only the scene's sections, and a misspelt
    batch_period_s would read as a scene key).

    Raises:
        SceneError: naming the first unknown parameter.
    """
    unknown = sorted(name for name in given if name.split(".")[0] not in KNOWN_NAMES)
    if unknown:
        known = ", ".join(sorted(KNOWN_NAMES))
        raise SceneError(source, unknown[0], f"unknown parameter (known: {known})")


def _declare_options(node: Node, given: dict[str, Any], source: str) -> dict[str, Any]:
    defaults = NodeOptions()
    values = {}
    for name, descriptor in _OPTIONS.items():
        value = given.get(name, getattr(defaults, name))
        wanted = float if descriptor.floating_point_range else int
        if wanted is float and isinstance(value, int) and not isinstance(value, bool):
            value = float(value)
        if isinstance(value, bool) or not isinstance(value, wanted):
            kind = "a number" if wanted is float else "an integer"
            raise SceneError(source, name, f"expected {kind}, got {value!r}")
        try:
            values[name] = node.declare_parameter(
                name, value, descriptor, ignore_override=True
            ).value
        except InvalidParameterValueException as err:
            (bounds,) = descriptor.floating_point_range or descriptor.integer_range
            msg = f"must be in [{bounds.from_value}, {bounds.to_value}], got {value!r}"
            raise SceneError(source, name, msg) from err
    return values


def check_qos_overrides(node: Node) -> None:
    """Refuse a given `qos_overrides.*` parameter that no entity of the node declared (a typo
    in the topic or policy, or a policy the node does not let be overridden), which rclpy
    would otherwise ignore without a word. Call after every publisher and subscription exists.

    Raises:
        SceneError: naming the parameter and the overrides the node takes.
    """
    for name in given_parameters(node):
        if name.startswith(QOS_OVERRIDES) and not node.has_parameter(name):
            declared = node.list_parameters([QOS_OVERRIDES.rstrip(".")], 0).names
            source = f"parameters of {node.get_fully_qualified_name()}"
            raise SceneError(source, name, f"no such QoS override; the node takes {declared}")
