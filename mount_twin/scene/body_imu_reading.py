"""A scene's optional body IMU sections: `body_sensor` (an IMU on the machine's body, which the
twin's prediction is compared with) and `ageing` (the mounts' scales fitted live to it)."""

from __future__ import annotations

from mount_twin.scene.description import (
    SENSOR_AXES,
    Ageing,
    BodySensor,
    LinearMount,
    Mount,
    ageing_bands_problem,
)
from mount_twin.scene.geometry_reading import read_angles, read_position
from mount_twin.scene.reader import Reader, shown
from mount_twin.scene.ros_names import read_header_frame_id, read_topic

MAX_SENSOR_LAG_S = 1.0
"""A body IMU's lag beyond this (s) is a clock, not a latency: align the clocks."""


def read_body_sensor(r: Reader) -> BodySensor:
    """The `body_sensor` section (a body-mounted IMU checked against the twin), defaults for
    keys not given; an error naming the key path for a value out of its range."""
    d = BodySensor()
    sensor = BodySensor(
        topic=read_topic(r, "topic", d.topic),
        frame_id=read_header_frame_id(r, "frame_id", d.frame_id),
        position=read_position(r, "position", d.position),
        orientation_rpy=read_angles(r, "orientation_rpy", d.orientation_rpy),
        lag_s=r.number("lag_s", d.lag_s, lo=-MAX_SENSOR_LAG_S, hi=MAX_SENSOR_LAG_S),
        window_s=r.number("window_s", d.window_s, lo=0.1, hi=3600.0),
        band_hz=_band(r, "band_hz", d.band_hz),
        warn_nrms=r.positive("warn_nrms", d.warn_nrms),
        error_nrms=r.positive("error_nrms", d.error_nrms),
        axes=r.names("axes", d.axes),
    )
    wrong = [a for a in sensor.axes if a not in SENSOR_AXES]
    if wrong or not sensor.axes:
        raise r.error("axes", f"{list(sensor.axes)}: give some of {', '.join(SENSOR_AXES)}")
    if sensor.error_nrms < sensor.warn_nrms:
        raise r.error("error_nrms", f"{sensor.error_nrms} is below warn_nrms {sensor.warn_nrms}")
    r.finish()
    return sensor


def _band(
    r: Reader, key: str, default: tuple[float, float], unit: str = "Hz"
) -> tuple[float, float]:
    """A band (low, high), 0 ≤ low < high (a frequency band, Hz, or scale factors)."""
    low, high = r.vector(key, 2, default, lo=0.0)
    if high <= low:
        raise r.error(key, f"[{low}, {high}]: expected low < high, {unit}")
    return low, high


def read_ageing(r: Reader, mounts: tuple[Mount, ...]) -> Ageing:
    """The `ageing` section (the linear mounts' stiffness and damping scales fitted live to the
    body IMU), its `fit` entries checked against the scene's linear `mounts`."""
    d = Ageing()
    ageing = Ageing(
        window_s=r.number("window_s", d.window_s, lo=10.0, hi=3600.0),
        fit=r.names("fit", d.fit),
        warn=_band(r, "warn", d.warn, "scale factors"),
        error=_band(r, "error", d.error, "scale factors"),
    )
    linear = {m.name for m in mounts if isinstance(m, LinearMount)}
    for i, name in enumerate(ageing.fit):
        kind, _, group = name.partition(":")
        wrong = [m for m in group.split("+") if m not in linear] if group else []
        if kind not in ("stiffness", "damping") or wrong or not linear:
            why = f"{', '.join(wrong)}: no linear mount of the scene" if wrong else ""
            raise r.error(
                f"fit[{i}]",
                why
                or f"{shown(name)}: expected stiffness or damping (of all linear mounts), "
                "or stiffness:A+B (damping:A+B) for a group",
            )
    if problem := ageing_bands_problem(ageing.warn, ageing.error):
        raise r.error("error", problem)
    r.finish()
    return ageing
