"""A scene's mount mapping read by its kind: a linear mount's keys here, every other kind's
through its module (`kinds.KINDS`); a mount whose `kind:` line was lost is named by the kind
its keys read as."""

from __future__ import annotations

from mount_twin.errors import SceneError
from mount_twin.kinds import KINDS
from mount_twin.scene.description import LinearMount, Mount, Vec3
from mount_twin.scene.geometry_reading import read_angles, read_position
from mount_twin.scene.reader import Reader, shown
from mount_twin.scene.ros_names import NAME_TOKEN

MOUNT_KINDS = ("linear", *KINDS)


def read_mount(r: Reader) -> Mount:
    """One entry of `mounts`: its name, pose and the keys of its `kind` (default `linear`),
    read by the kind's own module."""
    kind = r.choice("kind", MOUNT_KINDS, "linear")
    name = r.string("name")
    if not NAME_TOKEN.fullmatch(name):
        raise r.error(
            "name",
            "must be a ROS name token (an ASCII letter, then up to 99 letters, digits and _), "
            f"got {shown(name)}",
        )
    position = read_position(r, "position")
    rpy = read_angles(r, "orientation_rpy", (0.0, 0.0, 0.0))
    if kind != "linear":
        mount: Mount = KINDS[kind].read(r, name, position, rpy)
        r.finish()  # the kind's read finishes before its checks across keys; this is the net
        return mount
    try:
        mount = LinearMount(
            name=name,
            position=position,
            orientation_rpy=rpy,
            stiffness=r.vector("stiffness", 6, lo=0.0),
            damping=r.vector("damping", 6, (0.0,) * 6, lo=0.0),
            kind=kind,
            rated_travel=r.vector("rated_travel", 3, (0.0,) * 3, lo=0.0),
            rated_load=r.vector("rated_load", 3, (0.0,) * 3, lo=0.0),
        )
        r.finish()
    except SceneError as err:
        guess = None if r.has("kind") else _kind_reading(r, name, position, rpy)
        if guess is None:
            raise
        raise r.error(
            "kind",
            f"missing, so the mount was read as linear ({err.path}: {err.message}); its keys "
            f"read as a {guess}: give kind: {guess}",
        ) from err
    return mount


def _kind_reading(r: Reader, name: str, position: Vec3, rpy: Vec3) -> str | None:
    """The one kind of KINDS whose `read` takes the mount mapping of `r` whole, if one does:
    what a mount whose `kind:` line was lost most likely is."""
    fits = []
    for kind, module in KINDS.items():
        probe = Reader(r.data, r.source, r.path)
        for key in ("name", "position", "orientation_rpy"):
            probe.raw(key, ())
        try:
            module.read(probe, name, position, rpy)
        except SceneError:
            continue
        fits.append(kind)
    return fits[0] if len(fits) == 1 else None
