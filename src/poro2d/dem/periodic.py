"""A periodic shear cell: disks in a Lees-Edwards cell, no walls (kernels in ``periodic_kernels``).

The walled engine (:class:`~poro2d.dem.Simulation`) measures a specimen inside a box, whose
walls order the disks near them and carry part of the load. A cell periodic in x and
Lees-Edwards periodic in y has no boundary at all: what it measures belongs to the packing
alone. It shares the engine's contact law (:mod:`poro2d.dem.contact_law`: springs, Coulomb
slip, the rolling spring and the normal dashpot) with one set of contact values for every
pair, and keeps its own small state: struct-of-arrays, one thread, whole blocks of steps in
one compiled call (:func:`poro2d.dem.periodic_kernels.advance`).

Velocities are peculiar ones, relative to the cell's affine flow (see the kernels' module
docstring); :meth:`PeriodicCell.absolute_velocity` adds the flow back.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from poro2d.dem import periodic_kernels as K
from poro2d.dem.contact_law import MAX_ROLLING_FRICTION
from poro2d.dem.model import critical_time_step, restitution_to_beta
from poro2d.errors import InputError, Real, check_fields

#: with rolling resistance the rolling spring ks R^2 adds up to 2 ks / m per contact beside
#: the 3 ks / m of the shear spring (the walled engine's factor): the step shrinks by sqrt(5/3)
ROLLING_STIFFNESS_FACTOR = 5.0 / 3.0
#: a disk touches at most six others of a similar size (hexagonal order): the frequency bound
MAX_NEIGHBOURS = 6

CELL_LAW_RANGES = {
    "kn": Real(0.0, None, lo_open=True),
    "ks": Real(0.0, None),
    "friction": Real(0.0, 10.0),
    "rolling_friction": Real(0.0, MAX_ROLLING_FRICTION),
    "restitution": Real(0.1, 1.0),
}


@dataclass(frozen=True)
class CellLaw:
    """The contact values of every pair in the cell (contact stiffnesses in N/m, not per body).

    restitution 1 means no dashpot; below about 0.1 a dashpot that may not pull cannot reach it.
    """

    kn: float
    ks: float
    friction: float
    rolling_friction: float = 0.0
    restitution: float = 1.0

    def __post_init__(self) -> None:
        check_fields(self, CELL_LAW_RANGES)

    @property
    def beta(self) -> float:
        """The dashpot's fraction of critical damping."""
        return 0.0 if self.restitution >= 1.0 else restitution_to_beta(self.restitution)


@dataclass(frozen=True)
class CellBlock:
    """What a block of steps measured, each a mean over its steps (stresses tension positive, Pa).

    ``stress`` is the Love-Weber contact stress plus the kinetic stress of the peculiar
    velocities, ``kinetic`` that part alone (both 2 x 2, [[xx, xy], [yx, yy]]); ``coordination``
    2 N_c / N over all disks; ``pressure_error`` the mean |p - P| / P the barostat saw.
    """

    steps: int
    stress: np.ndarray
    kinetic: np.ndarray
    coordination: float
    solid_fraction: float
    pressure_error: float
    rebuilds: int

    @property
    def stress_ratio(self) -> float:
        """mu = -sigma_xy / sigma_yy (sigma_xy: the x traction on planes of normal y)."""
        return -float(self.stress[0, 1]) / float(self.stress[1, 1])

    @property
    def normal_stress(self) -> float:
        """-sigma_yy (Pa, compression positive): the pressure the barostat holds."""
        return -float(self.stress[1, 1])


class _CellValue:
    """A number of the cell's state array (``PeriodicCell.cell``, its slots named in
    :mod:`poro2d.dem.periodic_kernels`), read as a float: the cell's size, offset, strain and time."""

    def __init__(self, slot: int, doc: str) -> None:
        self.slot = slot
        self.__doc__ = doc

    def __get__(self, cell: PeriodicCell | None, owner: type | None = None):
        return self if cell is None else float(cell.cell[self.slot])


class PeriodicCell:
    """Disks of radii ``radius`` (m) at ``pos`` in a ``width`` x ``height`` cell.

    ``density`` (kg/m3) and ``thickness`` (m) give the masses as the walled engine's do
    (``rho pi r^2 t``; moment of inertia ``m r^2 / 2``); stresses are per unit volume of the
    cell (``L H t``), i.e. in Pa. The time step is ``dt_safety`` times the engine's critical
    step bound (:func:`poro2d.dem.model.critical_time_step`) with six neighbours of the
    lightest disk; the skin defaults to half the mean radius.
    """

    def __init__(
        self, radius, pos, width: float, height: float, law: CellLaw, *, density: float, thickness: float,
        dt_safety: float = 0.8, skin: float | None = None,
    ) -> None:  # fmt: skip
        self.radius = np.ascontiguousarray(radius, dtype=float)
        self.pos = np.array(pos, dtype=float).reshape(-1, 2)
        n = self.radius.size
        if n < 2 or self.pos.shape[0] != n or not np.all(self.radius > 0.0):
            raise InputError("radius", n, "at least 2 disks of radius > 0, one position each")
        self.law = law
        self.thickness = float(thickness)
        self.mass = density * math.pi * self.radius**2 * self.thickness
        self.vel = np.zeros((n, 2))
        self.omega = np.zeros(n)
        self.theta = np.zeros(n)
        self._drift = np.zeros((n, 2))
        self.cell = np.zeros(K.CELL_SIZE)
        self.cell[[K.L_, K.L_BUILD]] = width
        self.cell[[K.H_, K.H_BUILD]] = height
        k_sum = MAX_NEIGHBOURS * max(law.kn, law.ks)
        if law.rolling_friction > 0.0:
            k_sum *= ROLLING_STIFFNESS_FACTOR
        self.dt = dt_safety * critical_time_step(float(self.mass.min()), k_sum)
        self.prm = np.zeros(K.PRM_SIZE)
        self.prm[[K.DT, K.KN, K.KS, K.MU, K.MU_R, K.BETA]] = (
            self.dt, law.kn, law.ks, law.friction, law.rolling_friction, law.beta
        )  # fmt: skip
        self.prm[K.THICKNESS] = self.thickness
        self.prm[K.SKIN] = 0.5 * float(self.radius.mean()) if skin is None else float(skin)
        self.prm[K.MAX_RATE] = math.inf
        self._check_size()
        empty = np.zeros(n + 1, dtype=np.int64)
        self.pairs = K.rebuild(self.pos, self.radius, self._drift, self.cell, self.prm, empty,
                               np.zeros(0, dtype=np.int64), np.zeros(0), np.zeros(0))  # fmt: skip

    def _check_size(self) -> None:
        """A cell narrower than two reaches would hold two images of one pair within contact."""
        reach = 2.0 * float(self.radius.max()) + self.prm[K.SKIN]
        for name, size in (("width", self.width), ("height", self.height)):
            if not size >= 2.0 * reach:
                allowed = f">= {2 * reach:.4g} m (twice the largest pair's reach)"
                raise InputError(f"cell {name}", size, allowed)

    # ---------------------------------------------------------------- the cell
    @property
    def n(self) -> int:
        return int(self.radius.size)

    width = _CellValue(K.L_, "The cell's width (m).")
    height = _CellValue(K.H_, "The cell's height (m).")
    offset = _CellValue(
        K.DELTA, "The Lees-Edwards offset of the images above the cell (m, modulo the width)."
    )
    strain = _CellValue(K.GAMMA, "The shear strain gamma the cell has been sheared by.")
    time = _CellValue(K.TIME, "The time the cell has run (s).")

    @property
    def solid_fraction(self) -> float:
        return float(np.sum(math.pi * self.radius**2) / (self.width * self.height))

    def absolute_velocity(self) -> np.ndarray:
        """The disks' velocities with the affine flow added (m/s)."""
        v = self.vel.copy()
        v[:, 0] += self.prm[K.GAMMA_DOT] * self.pos[:, 1] + self.cell[K.EXX] * self.pos[:, 0]
        v[:, 1] += self.cell[K.EYY] * self.pos[:, 1]
        return v

    def set_offset(self, offset: float) -> None:
        """Set the Lees-Edwards offset (m): the images above the cell sit ``offset`` further in x,
        as after a shear by offset / H. The pairs are listed anew (their history kept)."""
        self.cell[K.DELTA] = float(offset)
        self.pairs = K.rebuild(self.pos, self.radius, self._drift, self.cell, self.prm, *self._history())

    def _history(self):
        start, pj, _sx, _sy, fs, mr = self.pairs
        return start, pj, fs, mr

    # ---------------------------------------------------------------- driving
    def hold(self, shear_rate: float = 0.0, exx: float = 0.0, eyy: float = 0.0) -> None:
        """No barostat: the cell deforms at the given rates (1/s)."""
        self.prm[K.MODE] = K.FIXED
        self.prm[K.GAMMA_DOT] = shear_rate
        self.cell[K.EXX] = exx
        self.cell[K.EYY] = eyy

    def compress(self, pressure: float, gain: float, gas_rate: float, max_rate: float) -> None:
        """Width and height servoed to the mean pressure ``pressure`` (Pa), no shear.

        ``gain`` (1/(Pa s)): strain rate per pascal of pressure error; ``gas_rate`` (1/s): the
        shrinking rate while no force network carries the pressure yet; both capped at ``max_rate``.
        """
        self.prm[[K.MODE, K.GAMMA_DOT, K.PRESSURE, K.GAIN, K.GAS_RATE, K.MAX_RATE]] = (
            K.COMPRESS, 0.0, pressure, gain, gas_rate, max_rate
        )  # fmt: skip

    def shear(self, shear_rate: float, pressure: float, gain: float, max_rate: float) -> None:
        """Shear at ``shear_rate`` (1/s) with the height servoed to ``-sigma_yy = pressure``."""
        self.prm[[K.MODE, K.GAMMA_DOT, K.PRESSURE, K.GAIN, K.MAX_RATE]] = (
            K.SHEAR, shear_rate, pressure, gain, max_rate
        )  # fmt: skip
        self.cell[K.EXX] = 0.0

    def run(self, steps: int) -> CellBlock:
        """``steps`` steps in one compiled call; their mean measurements."""
        out = np.zeros(K.OUT_SIZE)
        self.pairs = K.advance(steps, self.pos, self.vel, self.omega, self.theta, self.radius, self.mass,
                               1.0 / self.mass, 2.0 / (self.mass * self.radius**2), self._drift, self.pairs,
                               self.cell, self.prm, out)  # fmt: skip
        m = max(steps, 1)
        contact = np.array([[out[K.SXX], out[K.SXY]], [out[K.SYX], out[K.SYY]]]) / m
        kinetic = np.array([[out[K.KXX], out[K.KXY]], [out[K.KXY], out[K.KYY]]]) / m
        return CellBlock(
            steps=steps, stress=contact + kinetic, kinetic=kinetic,
            coordination=2.0 * out[K.CONTACTS] / (m * self.n), solid_fraction=out[K.SOLID] / m,
            pressure_error=out[K.PRESSURE_ERR] / m, rebuilds=int(out[K.REBUILDS]),
        )  # fmt: skip

    # ---------------------------------------------------------------- looking
    def contacts(self) -> dict[str, np.ndarray]:
        """The touching pairs now, as arrays: i, j, the branch vector (lx, ly) from i to j's
        image, fn, fs, and the force on i (fx, fy). Reads the state; changes nothing."""
        start, pj, psx, psy, pfs, pmr = self.pairs
        pi = K.pair_owners(start)
        fn = np.zeros(pj.size)
        fs, mr = pfs.copy(), pmr.copy()
        force = np.zeros((self.n, 2))
        moment = np.zeros(self.n)
        K.contact_forces(self.pos, self.vel, self.omega, self.radius, self.mass, pi, pj, psx, psy, fs, mr, fn,
                         force, moment, self.cell, self.prm, np.zeros(K.OUT_SIZE))  # fmt: skip
        lx = self.pos[pj, 0] - self.pos[pi, 0] + psx * self.width + psy * self.offset
        ly = self.pos[pj, 1] - self.pos[pi, 1] + psy * self.height
        on = fn > 0.0
        d = np.hypot(lx, ly)
        nx, ny = lx / d, ly / d
        return {
            "i": pi[on], "j": pj[on], "lx": lx[on], "ly": ly[on], "fn": fn[on], "fs": fs[on],
            "fx": (-fn * nx - fs * ny)[on], "fy": (-fn * ny + fs * nx)[on],
        }  # fmt: skip

    def forces(self) -> tuple[np.ndarray, np.ndarray]:
        """The contact force (n x 2, N) and moment (N m) on every disk now; changes nothing."""
        start, pj, psx, psy, pfs, pmr = self.pairs
        force = np.zeros((self.n, 2))
        moment = np.zeros(self.n)
        pi = K.pair_owners(start)
        K.contact_forces(self.pos, self.vel, self.omega, self.radius, self.mass, pi, pj, psx, psy, pfs.copy(),
                         pmr.copy(), np.zeros(pj.size), force, moment, self.cell, self.prm,
                         np.zeros(K.OUT_SIZE))  # fmt: skip
        return force, moment

    def energy(self) -> float:
        """Kinetic (peculiar) plus rotational plus normal-spring energy (J); no shear springs."""
        kin = 0.5 * float(np.sum(self.mass * np.sum(self.vel**2, axis=1)))
        rot = 0.25 * float(np.sum(self.mass * self.radius**2 * self.omega**2))
        c = self.contacts()
        overlap = self.radius[c["i"]] + self.radius[c["j"]] - np.hypot(c["lx"], c["ly"])
        return kin + rot + 0.5 * self.law.kn * float(np.sum(overlap**2))


__all__ = ["CellBlock", "CellLaw", "PeriodicCell"]
