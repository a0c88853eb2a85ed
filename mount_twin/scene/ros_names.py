"""The ROS names a scene gives and their rules: a mount's name (a token of its topics and frame
ids), topic names (rcl's rules, no substitutions), the tf2 frame ids the twin publishes and the
header.frame_id its input is compared with. Each is read from a scene key with an error naming
it (`read_topic`, `read_frame_id`, `read_header_frame_id`); the commands that take such names
check them by the same rules (`topic_name_problem`, `header_frame_id_problem`).
"""

from __future__ import annotations

import re

from mount_twin.scene.reader import Reader, shown

NAME_TOKEN = re.compile(r"[A-Za-z][A-Za-z0-9_]{0,99}")
"""A mount name: it becomes a token of topic names and a frame id (ASCII: str.isalnum() takes
"x²", which rclpy refuses), at most 100 characters (its topic ~/mounts/<name>/wrench, with the
node's namespace and name, must stay within TOPIC_MAX_CHARS)."""
TOPIC_MAX_CHARS = 247
"""Longest ROS 2 topic name (rmw: 255 less 8 reserved for the DDS prefix)."""


def read_topic(r: Reader, key: str, default: str) -> str:
    """A ROS 2 topic name as rclpy's validate_topic_name takes it (rcl_validate_topic_name),
    that also expands to a valid full name (no '//', at most TOPIC_MAX_CHARS), without
    substitutions: a {node} or {ns} would not match the topic of a recorded bag."""
    name = r.string(key, default)
    problem = topic_name_problem(name)
    if problem:
        raise r.error(key, f"{shown(name)} is not a ROS topic name: {problem}")
    return name


def topic_name_problem(name: str) -> str:
    """What makes `name` an unusable topic name ('' if nothing): the rules of
    rcl_validate_topic_name (alphanumerics, '_' and '/'; '~' only first and followed by '/';
    no token starting with a digit; not empty, not ending with '/'), rmw's full-name rules that
    apply to it (no '//', length), and no {substitution}."""
    tokens = (name[2:] if name.startswith("~/") else name.removeprefix("/")).split("/")
    rules = (
        (not name, "it is empty"),
        (len(name) > TOPIC_MAX_CHARS, f"longer than {TOPIC_MAX_CHARS} characters"),
        (name.endswith("/"), "it ends with '/'"),
        ("{" in name or "}" in name, "{substitutions} are not accepted in a scene"),
        (
            "~" in name[1:] or (name.startswith("~") and name[:2] != "~/"),
            "'~' only as the '~/' that begins a private name",
        ),
        ("" in tokens, "it has an empty token ('//')"),
        (
            not all(re.fullmatch(r"[A-Za-z0-9_]*", t) for t in tokens),
            "only ASCII letters, digits, '_' and '/' are allowed",
        ),
        (any(t[:1].isdigit() for t in tokens), "a token starts with a digit"),
    )
    return next((why for broken, why in rules if broken), "")


def read_frame_id(r: Reader, key: str, default: str, *, empty_ok: bool = False) -> str:
    """A tf2 frame id the twin publishes: no whitespace, no leading '/' (empty only where
    `empty_ok`: a mount frame prefix)."""
    frame = r.string(key, default)
    if (not frame and not empty_ok) or any(c.isspace() for c in frame) or frame.startswith("/"):
        raise r.error(
            key,
            f"{shown(frame)} is not a tf2 frame id (non-empty, no whitespace, no leading '/')",
        )
    return frame


def read_header_frame_id(r: Reader, key: str, default: str) -> str:
    """A frame id the input's header.frame_id is compared with, as its sensor writes it: no
    whitespace; empty for any; a leading '/' is ROS 1's (a bag from there says '/imu')."""
    frame = r.string(key, default)
    if problem := header_frame_id_problem(frame):
        raise r.error(key, f"{shown(frame)} {problem}")
    return frame


def header_frame_id_problem(frame: str) -> str:
    """What makes `frame` no header.frame_id a sensor writes ('' if nothing)."""
    return "is not a frame id (it has whitespace)" if any(c.isspace() for c in frame) else ""
