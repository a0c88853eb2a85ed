"""Rubber-metal (elastomeric) mount: nonlinear elasticity per axis, viscous damping, optional
Bouc–Wen hysteresis and snubbers.

Along each local axis (deflection x, m; rate ẋ, m/s) the mount resists with
    F = a·F_el(x) + (1 − a)·k₀·z + c·ẋ + F_snub      (a = 1 without hysteresis)
where F_el is a monotone force–deflection table (PCHIP, built once at load, extended linearly) or
k₁·x + k₃·x³, k₀ = F_el'(0), and z (m) follows Bouc–Wen
    ż = A·ẋ − β·|ẋ|·|z|ⁿ⁻¹·z − γ·ẋ·|z|ⁿ,   bounded by z_max = (A/(β + γ))^(1/n).
A snubber closes a gap g: F_snub = k_s·⟨|x| − g⟩ᵖ·(1 + h·δ̇) in compression only (Hunt–Crossley
damping h, s/m, never pulling). Rotations: linear springs and dampers per axis.
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import pairwise
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # only annotations: importing mount_twin.scene here is a cycle
    from mount_twin.scene.reader import Reader

KIND = "elastomer"
EVENTS = ("snubber_contact", "over_travel")
EVENT_ERROR = (False, True)
EVENT_STIFFENS = (True, False)
"""A snubber that touches stiffens the mount (`auto` looks again); over-travel is in contact."""
EVENT_COMPANION = ("integrated", "carried")
"""How the error estimate's companion takes an interval that starts with each event holding
(`kinds.COMPANION_TREATMENTS`, `engine.companion`): integrated by its own method while a
snubber is in contact; over-travel on an axis without one, carried. A Hertzian snubber
stiffens as it closes, past the kick taken at the interval's start: carried in contact,
rubber on snubbers of 1e9 N/m^1.5 at 1 kHz read 0.20 and 19.6 times its true force error at
rtol 3e-4 and 1e-5 (attitude 48 times), 0.89–1.03 so at rtol 1e-3 … 1e-7. Integrated by the
twin's own method (`switching`, as a joint's faces are), 1e10 N/m^1.5 read 0.54 at 1e-5,
0.97 by the companion's."""
EVENT_SWITCHES = (False, False)
"""No event is a discrete switch (`update` never switches)."""
RESTUCK: tuple[str, ...] = ()
"""States a restart sets to zero (none: all of this kind's states are kept)."""
ROTATIONAL = True
"""`load` reads the local rotation and its rate and gives a couple (the rotational stiffness)."""
AXES = ("x", "y", "z")
TABLE_MAX = 16
"""Most points in a force–deflection table."""

PARAMETERS = {
    "stiffness_linear": ("double_array", "k1 per local axis [x, y, z], N/m"),
    "stiffness_cubic": ("double_array", "k3 per local axis, N/m³ (zeros)"),
    "damping": ("double_array", "Viscous damping per local axis, N·s/m (zeros)"),
    "rotational_stiffness": ("double_array", "Per local axis, N·m/rad (zeros)"),
    "rotational_damping": ("double_array", "Per local axis, N·m·s/rad (zeros)"),
    "rated_deflection": ("double_array", "Allowable |deflection| per axis, m (0: none)"),
    **{
        f"force_table.{axis}.{key}": ("double_array", f"Force table along {axis}: {unit}")
        for axis in ("x", "y", "z")
        for key, unit in (("deflection", "deflections, m"), ("force", "forces, N"))
    },
    "hysteresis.ratio": ("double", "Bouc–Wen elastic share a, 0..1"),
    "hysteresis.A": ("double", "Bouc–Wen A (1.0)"),
    "hysteresis.beta": ("double", "Bouc–Wen β, 1/mⁿ"),
    "hysteresis.gamma": ("double", "Bouc–Wen γ, 1/mⁿ"),
    "hysteresis.n": ("double", "Bouc–Wen exponent n ≥ 1 (1.0)"),
    "hysteresis.axes": ("string", "Hysteretic local axes, space-separated (x y z)"),
    "snubber.gap": ("double", "Snubber gap, m"),
    "snubber.stiffness": ("double", "Snubber contact stiffness k_s, N/mᵖ"),
    "snubber.exponent": ("double", "Contact exponent p ≥ 1 (1.5)"),
    "snubber.damping": ("double", "Hunt–Crossley damping h, s/m (0.0)"),
    "snubber.axes": ("string", "Snubbed local axes, space-separated (x y z)"),
}
"""ROS parameters of the kind, mounts.<name>.<key>: (type, description)."""

# parameter columns, per axis block of N_AXIS starting at j·N_AXIS
K1, K3, C, RATIO, BW_A, BETA, GAMMA, N_EXP, K0, ZSLOT, GAP, KS, PEXP, HC, RATED, NTAB = range(16)
TAB_X = 16
TAB_C = TAB_X + TABLE_MAX
N_AXIS = TAB_C + 4 * (TABLE_MAX - 1)
ROT = 3 * N_AXIS
N_PAR = ROT + 6
CONTACT_STIFFNESS = tuple(j * N_AXIS + KS for j in range(3))
"""Parameter columns of stiffnesses acting only past a gap (each axis's snubber k_s), which the
start's equilibrium may soften and restore (`model.assemble.CONTINUATION`)."""


@dataclass(frozen=True)
class Hysteresis:
    """Bouc–Wen: ratio a (elastic share), A, β (1/mⁿ), γ (1/mⁿ), exponent n; axes it acts on."""

    ratio: float
    a: float
    beta: float
    gamma: float
    n: float
    axes: tuple[str, ...]

    @property
    def z_max(self) -> float:
        """Bound of z, m."""
        return (self.a / (self.beta + self.gamma)) ** (1.0 / self.n)


@dataclass(frozen=True)
class Snubber:
    """Gap (m), contact stiffness k_s (N/mᵖ), exponent p, Hunt–Crossley h (s/m); axes."""

    gap: float
    stiffness: float
    exponent: float
    damping: float
    axes: tuple[str, ...]


@dataclass(frozen=True)
class Elastomer:
    """A rubber-metal mount; per-axis tuples are along local x, y, z.

    Attributes:
        stiffness_linear: k₁, N/m. stiffness_cubic: k₃, N/m³.
        force_table: per axis name, (deflections m, forces N), overriding the polynomial.
        damping: c, N·s/m. rotational_stiffness: N·m/rad. rotational_damping: N·m·s/rad.
        rated_deflection: allowable |x| per axis, m (0: not monitored).
    """

    name: str
    position: tuple[float, float, float]
    orientation_rpy: tuple[float, float, float]
    stiffness_linear: tuple[float, float, float]
    stiffness_cubic: tuple[float, float, float]
    force_table: tuple[tuple[str, tuple[float, ...], tuple[float, ...]], ...]
    damping: tuple[float, float, float]
    rotational_stiffness: tuple[float, float, float]
    rotational_damping: tuple[float, float, float]
    rated_deflection: tuple[float, float, float]
    hysteresis: Hysteresis | None
    snubber: Snubber | None
    kind: str = KIND


def _axes(r: Reader, key: str) -> tuple[str, ...]:
    axes = r.names(key, AXES)
    for i, a in enumerate(axes):
        if a not in AXES or axes.index(a) != i:
            raise r.error(f"{key}[{i}]", f"expected distinct axes among x, y, z, got {a!r}")
    return axes


def read(r: Reader, name: str, position: tuple, rpy: tuple) -> Elastomer:
    """Parse and check the kind's keys."""
    tables = []
    tr = r.sub("force_table")
    for axis in AXES:
        if tr.has(axis):
            tables.append((axis, *_force_table(tr.sub(axis))))
    tr.finish()
    hyst = _hysteresis(r.sub("hysteresis")) if r.has("hysteresis") else None
    snub = _snubber(r.sub("snubber")) if r.has("snubber") else None
    mount = Elastomer(
        name=name,
        position=position,
        orientation_rpy=rpy,
        stiffness_linear=r.vector("stiffness_linear", 3, (0.0, 0.0, 0.0), lo=0.0),
        stiffness_cubic=r.vector("stiffness_cubic", 3, (0.0, 0.0, 0.0), lo=0.0),
        force_table=tuple(tables),
        damping=r.vector("damping", 3, (0.0, 0.0, 0.0), lo=0.0),
        rotational_stiffness=r.vector("rotational_stiffness", 3, (0.0,) * 3, lo=0.0),
        rotational_damping=r.vector("rotational_damping", 3, (0.0,) * 3, lo=0.0),
        rated_deflection=r.vector("rated_deflection", 3, (0.0,) * 3, lo=0.0),
        hysteresis=hyst,
        snubber=snub,
    )
    r.finish()  # a misspelt key (`stiffness:`) before the check it makes fail
    table_axes = {t[0] for t in tables}
    for j, axis in enumerate(AXES):
        if axis not in table_axes and not mount.stiffness_linear[j] > 0.0:
            raise r.error(f"stiffness_linear[{j}]", "each axis needs k1 > 0 or a force_table")
    return mount


def _force_table(t: Reader) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """One axis's force table, (deflections m, forces N): 3 to TABLE_MAX points, both
    increasing strictly, through (0, 0)."""
    raw_x = t.raw("deflection")
    n = len(raw_x) if isinstance(raw_x, list) else 0
    if not 3 <= n <= TABLE_MAX:
        raise t.error("deflection", f"expected 3 to {TABLE_MAX} points, got {raw_x!r}")
    xs, fs = t.vector("deflection", n), t.vector("force", n)
    if any(b <= a for a, b in pairwise(xs)):
        raise t.error("deflection", f"must increase strictly, got {list(xs)!r}")
    if any(b <= a for a, b in pairwise(fs)):
        raise t.error("force", f"must increase strictly (a stable mount), got {list(fs)!r}")
    if 0.0 not in xs or fs[xs.index(0.0)] != 0.0:
        raise t.error("deflection", "must contain 0.0 with force 0.0 (unstressed at rest)")
    t.finish()
    return xs, fs


def _hysteresis(h: Reader) -> Hysteresis:
    """The `hysteresis` keys, checked (β + γ > 0: z stays bounded)."""
    hyst = Hysteresis(
        ratio=h.number("ratio", lo=0.0, hi=1.0),
        a=h.positive("A", 1.0),
        beta=h.number("beta"),
        gamma=h.number("gamma"),
        n=h.number("n", 1.0, lo=1.0),
        axes=_axes(h, "axes"),
    )
    if not hyst.beta + hyst.gamma > 0.0:
        raise h.error("beta", "beta + gamma must be > 0 (z stays bounded)")
    h.finish()
    return hyst


def _snubber(sn: Reader) -> Snubber:
    """The `snubber` keys, checked."""
    snub = Snubber(
        gap=sn.number("gap", lo=0.0),
        stiffness=sn.positive("stiffness"),
        exponent=sn.number("exponent", 1.5, lo=1.0),
        damping=sn.number("damping", 0.0, lo=0.0),
        axes=_axes(sn, "axes"),
    )
    sn.finish()
    return snub


def piecewise(e: Elastomer) -> bool:
    """Whether the mount's force law has pieces its motion moves between (`Model.piecewise`):
    a snubber's contact. A force table's PCHIP interpolant has a continuous slope, and Bouc–Wen
    hysteresis turns its state with the motion, its force continuous: no pieces."""
    return e.snubber is not None and bool(e.snubber.axes)


def nominal_tangent(e: Elastomer) -> tuple[tuple[float, ...], tuple[str, ...]]:
    """Stiffness at the unstressed pose, (kx, ky, kz) N/m then (krx, kry, krz) N·m/rad, and the
    scene key each value comes from: the hysteretic spring at z = 0 (α·k₀ + (1 − α)·k₀·A), or
    a force table's slope at zero."""
    row = pack(e)
    k = []
    for j in range(3):
        b = j * N_AXIS
        ratio, k0 = row[b + RATIO], row[b + K0]
        k.append(float(ratio * k0 + (1.0 - ratio) * k0 * row[b + BW_A]))
    tables = {axis for axis, _, _ in e.force_table}
    keys = tuple(
        f"force_table.{a}" if a in tables else f"stiffness_linear[{j}]" for j, a in enumerate(AXES)
    )
    rot = tuple(f"rotational_stiffness[{j}]" for j in range(3))
    return (*k, *e.rotational_stiffness), (*keys, *rot)


def hysteretic(e: Elastomer) -> bool:
    """Whether `e` carries a Bouc–Wen state on any axis."""
    return e.hysteresis is not None and bool(e.hysteresis.axes)


def kinked(e: Elastomer) -> bool:
    """Whether the mount's law has kinks inside an interval that none of its events marks
    (`Model.kinked`): a Bouc–Wen state's rate turns with |ẋ|, wherever a hysteretic axis's
    deflection rate turns."""
    return hysteretic(e)


def state_names(e: Elastomer) -> tuple[str, ...]:
    """Bouc–Wen z per hysteretic axis (none without hysteresis)."""
    if e.hysteresis is None:
        return ()
    return tuple(f"{e.name}.z_{a}" for a in AXES if a in e.hysteresis.axes)


def pack(e: Elastomer) -> np.ndarray:
    """Parameter row of one mount (PCHIP coefficients computed here, once)."""
    row = np.zeros(N_PAR)
    tables = {axis: (xs, fs) for axis, xs, fs in e.force_table}
    slot = 0
    for j, axis in enumerate(AXES):
        b = j * N_AXIS
        row[b + K1], row[b + K3], row[b + C] = (
            e.stiffness_linear[j],
            e.stiffness_cubic[j],
            e.damping[j],
        )
        row[b + K0] = e.stiffness_linear[j]
        row[b + RATED] = e.rated_deflection[j]
        if axis in tables:
            xs, fs = tables[axis]
            from scipy.interpolate import PchipInterpolator  # 0.5 s to import: on first use

            pchip = PchipInterpolator(np.array(xs), np.array(fs))
            n = len(xs)
            row[b + NTAB] = n
            row[b + TAB_X : b + TAB_X + n] = xs
            row[b + TAB_C : b + TAB_C + 4 * (n - 1)] = pchip.c.T.ravel()
            row[b + K0] = float(pchip.derivative()(0.0))
        h = e.hysteresis
        row[b + RATIO] = 1.0
        row[b + ZSLOT] = -1.0
        if h is not None and axis in h.axes:
            row[b + RATIO], row[b + BW_A], row[b + BETA] = h.ratio, h.a, h.beta
            row[b + GAMMA], row[b + N_EXP], row[b + ZSLOT] = h.gamma, h.n, slot
            slot += 1
        sn = e.snubber
        row[b + GAP] = -1.0
        if sn is not None and axis in sn.axes:
            row[b + GAP], row[b + KS] = sn.gap, sn.stiffness
            row[b + PEXP], row[b + HC] = sn.exponent, sn.damping
    row[ROT : ROT + 3] = e.rotational_stiffness
    row[ROT + 3 : ROT + 6] = e.rotational_damping
    return row


def elastic_force(p: np.ndarray, b: int, x: float) -> float:
    """F_el(x) of the axis block at b, N: PCHIP table (linear beyond it) or k₁x + k₃x³."""
    n = int(p[b + NTAB])
    if n == 0:
        return p[b + K1] * x + p[b + K3] * x * x * x
    x0, xn = p[b + TAB_X], p[b + TAB_X + n - 1]
    if x <= x0:
        return _segment(p, b, 0, 0.0) + p[b + TAB_C + 2] * (x - x0)
    if x >= xn:
        k = n - 2
        h = xn - p[b + TAB_X + k]
        c = b + TAB_C + 4 * k
        slope = 3.0 * p[c] * h * h + 2.0 * p[c + 1] * h + p[c + 2]
        return _segment(p, b, k, h) + slope * (x - xn)
    k = 0
    while x > p[b + TAB_X + k + 1]:
        k += 1
    return _segment(p, b, k, x - p[b + TAB_X + k])


def _segment(p: np.ndarray, b: int, k: int, dx: float) -> float:
    c = b + TAB_C + 4 * k
    return ((p[c] * dx + p[c + 1]) * dx + p[c + 2]) * dx + p[c + 3]


def bouc_wen_rate(p: np.ndarray, b: int, z: float, xd: float) -> float:
    """ż of the axis block at b, m/s."""
    az = abs(z)
    zn = az ** p[b + N_EXP]
    zn1 = zn / az if az > 0.0 else (1.0 if p[b + N_EXP] == 1.0 else 0.0)
    return p[b + BW_A] * xd - p[b + BETA] * abs(xd) * zn1 * z - p[b + GAMMA] * xd * zn


def snubber_force(p: np.ndarray, b: int, x: float, xd: float) -> float:
    """Contact force magnitude of the axis block's snubber, N (≥ 0; 0 without contact)."""
    gap = p[b + GAP]
    if gap < 0.0:
        return 0.0
    pen = abs(x) - gap
    if pen <= 0.0:
        return 0.0
    pen_rate = xd if x > 0.0 else -xd
    return max(p[b + KS] * pen ** p[b + PEXP] * (1.0 + p[b + HC] * pen_rate), 0.0)


def load(p, y, o, d, v, phi, w, dydt, f, c) -> None:
    """Force f and couple c on the body in local axes (N, N·m); ż into dydt from o."""
    for j in range(3):
        b = j * N_AXIS
        x, xd = d[j], v[j]
        a = p[b + RATIO]
        force = a * elastic_force(p, b, x) + p[b + C] * xd
        slot = int(p[b + ZSLOT])
        if slot >= 0:
            z = y[o + slot]
            force += (1.0 - a) * p[b + K0] * z
            dydt[o + slot] = bouc_wen_rate(p, b, z, xd)
        snub = snubber_force(p, b, x, xd)
        force += snub if x > 0.0 else -snub
        f[j] = -force
        c[j] = -(p[ROT + j] * phi[j] + p[ROT + 3 + j] * w[j])


def monitor(p, y, y0, o, d, v, g) -> float:
    """Snubber contact (|x| − gap, m) and over-travel (|x|/rated − 1); returns the largest
    |x|/rated (0 if no axis is rated)."""
    g[0] = -1.0
    g[1] = -1.0
    util = 0.0
    for j in range(3):
        b = j * N_AXIS
        if p[b + GAP] >= 0.0:
            g[0] = max(g[0], abs(d[j]) - p[b + GAP])
        if p[b + RATED] > 0.0:
            u = abs(d[j]) / p[b + RATED]
            util = max(util, u)
            g[1] = max(g[1], u - 1.0)
    return util


def settle(p, y, o, d) -> None:
    """A start's states need no settling: a Bouc–Wen z anywhere within ±z_max is a state of
    the law (a new machine's on its loading curve, `model.loading`; a restart's as its run left
    it; a given start's zero), and the snubbers have none."""


def carry(p, y, y0, yt, o, d, dt) -> None:
    """The error estimate's companion after its carried error's kick (bolted_joint.carry):
    a Bouc–Wen z has a rate: the kick carries its error, and nothing is returned."""


def update(p, y, o, d) -> bool:
    """No discrete state: never switches."""
    return False
