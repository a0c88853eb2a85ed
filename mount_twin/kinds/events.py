"""Mount events by name: for readers that have an event's name only (a diagnostics message)."""

from __future__ import annotations

from mount_twin.kinds import KINDS, KindContractError

EVENT_IS_ERROR: dict[str, bool] = {
    event: error
    for module in KINDS.values()
    for event, error in zip(module.EVENTS, module.EVENT_ERROR, strict=True)
}
"""Event name → whether the event is an ERROR (else a WARN): the kinds' own EVENT_ERROR, the
one the engine's `MountEvent.error` takes."""

if len(EVENT_IS_ERROR) != sum(len(module.EVENTS) for module in KINDS.values()):
    raise KindContractError("two kinds name an event alike: its level would be ambiguous")
