"""Every numeric scene parameter a node declares has its range, and the range is the loader's
own check: a value at either end loads, a value past it is refused naming the parameter."""

from __future__ import annotations

import math
from typing import Any

import pytest
import yaml
from io_helpers import PARAMS_FILE, ROOT

from mount_twin.errors import SceneError
from mount_twin.scene.params import effective_parameters, flatten

GENSET = ROOT / "config" / "genset_bolted_keyed.scene.yaml"


def _numeric(values: dict[str, Any]) -> list[str]:
    return [
        k for k, v in values.items() if isinstance(v, (int, float)) and not isinstance(v, bool)
    ]


def _flat_params() -> dict[str, Any]:
    return dict(flatten(yaml.safe_load(PARAMS_FILE.read_text())["/**"]["ros__parameters"]))


SETS = {
    "params.yaml": _flat_params,
    "genset scene_file": lambda: {"scene_file": str(GENSET)},
}


@pytest.mark.parametrize("name", list(SETS))
def test_every_numeric_parameter_has_a_range(name: str) -> None:
    effective = effective_parameters(SETS[name](), name)
    numeric = _numeric(effective.values)
    assert len(numeric) >= 18
    assert [k for k in numeric if k not in effective.bounds] == []
    for key in numeric:
        lo, hi = effective.bounds[key]
        assert lo <= effective.values[key] <= hi, key
        assert not (math.isinf(lo) and math.isinf(hi)), key


def _edges(lo: float, hi: float, integer: bool) -> list[tuple[float, bool]]:
    """(value, loads) just past and at each end of [lo, hi] (the lower end may be open)."""
    past = 1 if integer else 1e-9 * max(1.0, abs(lo), abs(hi) if math.isfinite(hi) else 0.0)
    return [(lo - past, False), (hi, True), (hi + past, False)]


def test_the_declared_range_is_what_the_loader_accepts() -> None:
    """Scalars of the bundled params file: the upper end loads and past either end is refused
    (the lower end may be open, as for `positive`: the range is closed there, the loader the
    stricter)."""
    flat = _flat_params()
    effective = effective_parameters(flat, "params")
    checked = 0
    for key in _numeric(effective.values):
        lo, hi = effective.bounds[key]
        integer = isinstance(effective.values[key], int)
        for value, loads in _edges(lo, hi, integer):
            given = {**flat, key: int(value) if integer else float(value)}
            if loads:
                try:
                    effective_parameters(given, "params")
                except SceneError as err:
                    # an end that a cross-check refuses (a passband at the stopband) is not
                    # the range's: it must name another key or say why
                    assert err.path != key or "must be in" not in str(err), (key, value, err)
                continue
            with pytest.raises(SceneError) as err:
                effective_parameters(given, "params")
            assert err.value.path == key, (key, value, err.value)
            checked += 1
    assert checked >= 2 * 18
