"""Typed access to a nested mapping that reports every error with its source and key path."""

from __future__ import annotations

import difflib
import math
import re
import reprlib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, Literal, overload

from mount_twin.errors import SceneError

Vec3 = tuple[float, float, float]
"""Three floats: what `Reader.vector(key, 3)` returns."""
Vec6 = tuple[float, float, float, float, float, float]
"""Six floats: what `Reader.vector(key, 6)` returns."""


NUMBER_LIMIT = 1e15
"""Largest |number| a scene takes (SI: a bolt's stiffness is ~1e9 N/m); more is a unit error or
garbage, refused with its key path before it can overflow anything."""
INTEGER_LIMIT = 10**9
"""Largest integer a scene takes (decimation, substeps, sample counts)."""

_SHOWN = reprlib.Repr()
_SHOWN.maxlevel, _SHOWN.maxlist, _SHOWN.maxdict = 3, 8, 6
_SHOWN.maxstring, _SHOWN.maxother, _SHOWN.maxlong = 60, 60, 40


@dataclass
class Used:
    """What a scene read used, by key path: every value (given or defaulted, mappings
    excepted), and the closed interval [lo, hi] each scalar number was checked against (an
    open end, as `positive`'s 0, is recorded closed: the check itself is the stricter)."""

    values: dict[str, Any] = field(default_factory=dict)
    bounds: dict[str, tuple[float, float]] = field(default_factory=dict)


def shown(value: object) -> str:
    """`repr(value)` bounded for a message: nesting, length and digits cut with '...' (a value
    read from a hostile file may be nested deep enough to exhaust repr's recursion, or be an
    integer too long for str())."""
    try:
        return _SHOWN.repr(value)
    except ValueError:  # an int beyond sys.get_int_max_str_digits()
        return f"<{type(value).__name__} too long to show>"


_SHORTENED = re.compile(r"'.*' \(shortened, [0-9]+ characters\)", re.DOTALL)
"""What `shown_text` makes of a text it shortened."""


def shown_text(text: str) -> str:
    """`shown(text)`, and where that shortened it, how long it was: "'xx...xx' (shortened,
    100000 characters)" (a frame id received off the wire may be a megabyte, and a message
    repeating it whole is as large). A text that is already that, as read back from a value
    `kept_text` stored, is shown as it is: shortening it again would misstate its length."""
    if len(text) <= 2 * _SHOWN.maxstring and _SHORTENED.fullmatch(text):
        return text
    said = shown(text)
    if said == repr(text[: _SHOWN.maxstring + 1]):  # not shortened: it is the text's repr
        return said
    return f"{said} (shortened, {len(text)} characters)"


def kept_text(text: str) -> str:
    """`text` as a value to store or publish: itself where `shown_text` shows it whole, else
    `shown_text(text)`, shortened with its length (a hostile frame id, kept whole, is carried
    into every later report)."""
    said = shown_text(text)
    return text if said == repr(text) else said


class Reader:
    """A view of one mapping in a scene document.

    Args:
        data: the mapping.
        source: file or parameter set it came from, for messages.
        path: key path of `data` in the document ('' at the top).
        record: if given, what is read is stored here (`Used`): the effective parameters of a
            scene and their bounds.
    """

    def __init__(
        self,
        data: Any,
        source: str,
        path: str = "",
        *,
        record: Used | None = None,
    ) -> None:
        if not isinstance(data, Mapping):
            top = "" if path else " at the top level"
            raise SceneError(source, path, f"expected a mapping{top}, got {shown(data)}")
        self.data = data
        self.source = source
        self.path = path
        self.record = record
        self._used: set[str] = set()

    def key_path(self, key: str | int) -> str:
        """Dotted path of `key` below this mapping (list items as [i])."""
        if isinstance(key, int):
            return f"{self.path}[{key}]"
        return f"{self.path}.{key}" if self.path else key

    def error(self, key: str, msg: str) -> SceneError:
        """An error at `key` of this mapping."""
        return SceneError(self.source, self.key_path(key), msg)

    def has(self, key: str) -> bool:
        """True if `key` is present."""
        return key in self.data

    def raw(self, key: str, default: Any = None) -> Any:
        """The value at `key` unchecked, or `default`; missing without default is an error."""
        self._used.add(key)
        if key in self.data:
            value = self.data[key]
        elif default is None:
            unread = [str(k) for k in self.data if k not in self._used]
            close = difflib.get_close_matches(key, unread, n=1, cutoff=0.6)
            hint = f" (given: {close[0]!r}, misspelt?)" if close else ""
            raise self.error(key, f"required key is missing{hint}")
        else:
            value = default
        if self.record is not None and not isinstance(value, Mapping):
            self.record.values[self.key_path(key)] = value
        return value

    def _bound(self, key: str, lo: float, hi: float) -> None:
        if self.record is not None:
            self.record.bounds[self.key_path(key)] = (lo, hi)

    def sub(self, key: str, *, optional: bool = True) -> Reader:
        """The mapping at `key` (an empty one if absent and optional)."""
        value = self.raw(key, {} if optional else None)
        return Reader(
            value,
            self.source,
            self.key_path(key),
            record=self.record,
        )

    def number(
        self,
        key: str,
        default: float | None = None,
        *,
        lo: float = -math.inf,
        hi: float = math.inf,
        lo_open: bool = False,
    ) -> float:
        """A finite float in [lo, hi] (or (lo, hi] with lo_open), and within ±NUMBER_LIMIT."""
        self._bound(key, max(lo, -NUMBER_LIMIT), min(hi, NUMBER_LIMIT))
        return self._check_number(key, self.raw(key, default), lo, hi, lo_open)

    def positive(self, key: str, default: float | None = None) -> float:
        """A finite float > 0."""
        return self.number(key, default, lo=0.0, lo_open=True)

    def integer(
        self, key: str, default: int | None = None, *, lo: int = 0, hi: int = INTEGER_LIMIT
    ) -> int:
        """An integer in [lo, hi]."""
        self._bound(key, lo, hi)
        value = self.raw(key, default)
        if isinstance(value, bool) or not isinstance(value, int):
            raise self.error(key, f"expected an integer, got {shown(value)}")
        if not lo <= value <= hi:
            raise self.error(key, f"must be in [{lo}, {hi}], got {shown(value)}")
        return value

    def boolean(self, key: str, default: bool | None = None) -> bool:
        """A boolean."""
        value = self.raw(key, default)
        if not isinstance(value, bool):
            raise self.error(key, f"expected true or false, got {shown(value)}")
        return value

    def string(self, key: str, default: str | None = None) -> str:
        """A string."""
        value = self.raw(key, default)
        if not isinstance(value, str):
            raise self.error(key, f"expected a string, got {shown(value)}")
        return value

    def choice(self, key: str, options: Sequence[str], default: str | None = None) -> str:
        """One of `options`."""
        value = self.string(key, default)
        if value not in options:
            raise self.error(key, f"expected one of {', '.join(options)}, got {shown(value)}")
        return value

    @overload
    def vector(
        self, key: str, n: Literal[3], default: Sequence[float] | None = None, *, lo: float = ...
    ) -> Vec3: ...

    @overload
    def vector(
        self, key: str, n: Literal[6], default: Sequence[float] | None = None, *, lo: float = ...
    ) -> Vec6: ...

    @overload
    def vector(
        self, key: str, n: int, default: Sequence[float] | None = None, *, lo: float = ...
    ) -> tuple[float, ...]: ...

    def vector(
        self,
        key: str,
        n: int,
        default: Sequence[float] | None = None,
        *,
        lo: float = -math.inf,
    ) -> tuple[float, ...]:
        """A list of exactly `n` finite floats, each ≥ lo; typed `Vec3` for a literal n = 3 and
        `Vec6` for 6, so it fills the dataclasses' fixed-length fields as it is."""
        value = self.raw(key, None if default is None else tuple(default))
        if isinstance(value, (str, bytes)) or not isinstance(value, Sequence):
            raise self.error(key, f"expected a list of {n} numbers, got {shown(value)}")
        if len(value) != n:
            raise self.error(key, f"expected {n} numbers, got {len(value)}: {shown(list(value))}")
        return tuple(
            self._check_number(f"{key}[{i}]", v, lo, math.inf, False) for i, v in enumerate(value)
        )

    def names(self, key: str, default: Sequence[str] | None = None) -> tuple[str, ...]:
        """A list of names (DOFs, axes): a list of strings, or one string of names separated
        by spaces, the form a node declares them in. (`ros2 param dump` writes a list's `y`
        bare, and rcl reads a bare y back as a boolean: a string of names reloads as written.)
        """
        value = self.raw(key, None if default is None else tuple(default))
        if isinstance(value, str):
            value = tuple(value.split())
        if not isinstance(value, Sequence):
            raise self.error(key, f"expected a list of strings, got {shown(value)}")
        for i, v in enumerate(value):
            if not isinstance(v, str):
                raise self.error(f"{key}[{i}]", f"expected a string, got {shown(v)}")
        return tuple(value)

    def finish(self) -> None:
        """Reject keys nobody read (typos must not pass silently)."""
        unknown = sorted(str(k) for k in self.data if k not in self._used)
        if unknown:
            raise self.error(
                unknown[0], f"unknown key (known here: {', '.join(sorted(self._used))})"
            )

    def _check_number(self, key: str, value: Any, lo: float, hi: float, lo_open: bool) -> float:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise self.error(key, f"expected a number, got {shown(value)}")
        if isinstance(value, float) and not math.isfinite(value):
            raise self.error(key, f"must be finite, got {value!r}")
        if abs(value) > NUMBER_LIMIT:  # before float(): an int may be too large for one
            raise self.error(
                key,
                f"{shown(value)} is beyond {NUMBER_LIMIT:g}: no quantity of a scene is (units?)",
            )
        value = float(value)
        if value < lo or value > hi or (lo_open and value == lo):
            low, high = "(" if lo_open else "[", ")" if math.isinf(hi) else "]"  # inf: not taken
            raise self.error(key, f"must be in {low}{lo}, {hi}{high}, got {value!r}")
        return value
