"""Particle and wall state as struct-of-arrays.

Every field is a contiguous NumPy array handed straight to the compiled kernels.
Disks have a thickness ``t`` (out of plane): mass ``rho pi r^2 t``, moment of
inertia ``m r^2 / 2`` (a solid disk about its axis).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from poro2d.errors import InputError, as_float_array, is_number

# Particle kinematic modes.
FREE = 0
PRESCRIBED = 1  # velocity and spin are held at their set values (0 = fixed)

# Wall modes.
WALL_VELOCITY = 0  # moves with its prescribed velocity (0 = fixed)
WALL_SERVO = 1  # velocity set every step by the force servo

# Columns of Walls.servo, one row per wall (see Simulation.set_wall_servo).
SERVO_TARGET = 0  # compressive force the servo holds (N)
SERVO_GAIN = 1  # fraction of the force error removed per step
SERVO_MAX_SPEED = 2  # bound on the wall's speed (m/s)
SERVO_INTEGRAL = 3  # integral gain (per step)
SERVO_ERROR_SUM = 4  # summed force error (N): the servo's state, carried from step to step
SERVO_COLUMNS = 5

#: the walls of a box (``Walls.box``), in the order it adds them; every layer that reads a
#: box back from its walls (the criterion's plate, the split shear box, the exports) uses these
BOX_WALLS = ("bottom", "right", "top", "left")


def _as_f64(name: str, a, n: int | None = None, shape_tail: tuple = ()) -> np.ndarray:
    arr = np.ascontiguousarray(as_float_array(name, a))  # numbers only, text is refused
    if n is not None and arr.shape != (n, *shape_tail):
        raise InputError(name, f"shape {arr.shape}", f"shape {(n, *shape_tail)}")
    if not np.all(np.isfinite(arr)):
        raise InputError(name, "non-finite entries", "finite numbers")
    return arr


def _per_disk(name: str, a, n: int) -> np.ndarray:
    """One value per disk: a scalar is repeated ``n`` times, an array must have ``n`` entries."""
    arr = as_float_array(name, a)
    if arr.ndim == 0:
        arr = np.full(n, float(arr))
    if arr.shape != (n,):
        raise InputError(name, f"shape {arr.shape}", f"one number or shape ({n},), one per disk")
    return _as_f64(name, arr.copy())


# the per-disk arrays of Particles (thickness is one number for all disks)
PARTICLE_FIELDS = ("pos", "radius", "density", "kn", "ks", "mu", "vel", "theta", "omega", "mode", "mu_r")


@dataclass
class Particles:
    """Disks: positions, velocities, spins, sizes and per-body contact properties.

    ``kn``, ``ks`` and ``mu`` are per-body values (PFC 4.0 convention); the
    contact model decides whether they are combined or replaced by contact-level
    values. ``mu_r`` is the rolling friction coefficient (0 by default: no rolling
    resistance); a contact takes the smaller of its two bodies' values, as for ``mu``.
    """

    pos: np.ndarray
    radius: np.ndarray
    density: np.ndarray
    thickness: float
    kn: np.ndarray
    ks: np.ndarray
    mu: np.ndarray
    vel: np.ndarray = field(default=None)  # type: ignore[assignment]
    theta: np.ndarray = field(default=None)  # type: ignore[assignment]
    omega: np.ndarray = field(default=None)  # type: ignore[assignment]
    mode: np.ndarray = field(default=None)  # type: ignore[assignment]
    mu_r: np.ndarray = field(default=None)  # type: ignore[assignment]

    def __post_init__(self) -> None:
        self.pos = _as_f64("positions", self.pos)
        if self.pos.ndim != 2 or self.pos.shape[1] != 2:
            raise InputError("positions", f"shape {self.pos.shape}", "shape (N, 2)")
        n = self.pos.shape[0]
        self.radius = _per_disk("radius", self.radius, n)
        if n and self.radius.min() <= 0.0:
            raise InputError("radius", float(self.radius.min()), "(0, inf) for every disk")
        self.density = _per_disk("density", self.density, n)
        if n and self.density.min() <= 0.0:
            raise InputError("density", float(self.density.min()), "(0, inf) kg/m3")
        if not (is_number(self.thickness) and self.thickness > 0.0 and np.isfinite(self.thickness)):
            raise InputError("thickness", self.thickness, "(0, inf) m")
        self.thickness = float(self.thickness)
        for name in ("kn", "ks", "mu"):
            setattr(self, name, _per_disk(name, getattr(self, name), n))
        if n and self.kn.min() <= 0.0:
            raise InputError("particle kn", float(self.kn.min()), "(0, inf) N/m")
        if n and self.ks.min() < 0.0:
            raise InputError("particle ks", float(self.ks.min()), "[0, inf) N/m")
        if n and self.mu.min() < 0.0:
            raise InputError("particle friction", float(self.mu.min()), "[0, inf)")
        self.vel = np.zeros((n, 2)) if self.vel is None else _as_f64("velocity", self.vel, n, (2,))
        self.theta = np.zeros(n) if self.theta is None else _as_f64("theta", self.theta, n)
        self.omega = np.zeros(n) if self.omega is None else _as_f64("omega", self.omega, n)
        if self.mode is None:
            self.mode = np.zeros(n, dtype=np.int64)
        else:
            mode = np.asarray(self.mode)
            known = (mode == FREE) | (mode == PRESCRIBED)
            if mode.shape != (n,) or mode.dtype.kind not in "iu" or not np.all(known):
                raise InputError("mode", f"{mode.dtype.name} array of shape {mode.shape}",
                                 f"shape ({n},) of {FREE} (free) or {PRESCRIBED} (prescribed)")  # fmt: skip
            self.mode = np.ascontiguousarray(mode, dtype=np.int64)
        self.mu_r = np.zeros(n) if self.mu_r is None else _per_disk("rolling friction", self.mu_r, n)
        if n and self.mu_r.min() < 0.0:
            raise InputError("rolling friction", float(self.mu_r.min()), "[0, inf)")

    @property
    def n(self) -> int:
        return int(self.pos.shape[0])

    @property
    def mass(self) -> np.ndarray:
        return self.density * np.pi * self.radius**2 * self.thickness

    @property
    def inertia(self) -> np.ndarray:
        return 0.5 * self.mass * self.radius**2

    def area(self) -> float:
        """Total disk area (m^2)."""
        return float(np.pi * np.sum(self.radius**2))


@dataclass
class Walls:
    """Straight wall segments that are bodies: fixed, moving or servo-controlled.

    A wall pushes on any disk that overlaps the segment (either side, end caps
    included). Its stiffness and frictions (sliding ``mu``, rolling ``mu_r``) are
    per-body values, as in PFC 4.0.
    """

    p0: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))
    p1: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))
    kn: np.ndarray = field(default_factory=lambda: np.zeros(0))
    ks: np.ndarray = field(default_factory=lambda: np.zeros(0))
    mu: np.ndarray = field(default_factory=lambda: np.zeros(0))
    vel: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))
    mode: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    # servo_dir: direction the wall moves to compress (unit); servo: the servo's settings and
    # state, columns SERVO_TARGET, SERVO_GAIN, SERVO_MAX_SPEED, SERVO_INTEGRAL, SERVO_ERROR_SUM
    servo_dir: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))
    servo: np.ndarray = field(default_factory=lambda: np.zeros((0, SERVO_COLUMNS)))
    names: list[str] = field(default_factory=list)
    mu_r: np.ndarray = field(default_factory=lambda: np.zeros(0))  # rolling friction

    @property
    def n(self) -> int:
        return int(self.p0.shape[0])

    def rolling_friction(self) -> np.ndarray:
        """``mu_r`` with one entry per wall: walls set up field by field (an old checkpoint) get 0."""
        if self.mu_r.shape != (self.n,):
            mu_r = np.zeros(self.n)
            k = min(self.n, self.mu_r.size)
            mu_r[:k] = self.mu_r.reshape(-1)[:k]
            self.mu_r = mu_r
        return self.mu_r

    def add(
        self,
        p0,
        p1,
        kn: float,
        ks: float,
        mu: float,
        name: str | None = None,
        velocity=(0.0, 0.0),
        mu_r: float = 0.0,
    ) -> int:
        """Add a segment from ``p0`` to ``p1``; returns its index. ``mu_r``: rolling friction."""
        a = _as_f64("wall p0", p0, None)
        b = _as_f64("wall p1", p1, None)
        name = name or f"wall{self.n}"
        if a.shape != (2,) or b.shape != (2,):
            raise InputError(f"wall {name} end points", (a.tolist(), b.tolist()), "two (x, y) pairs")
        if np.hypot(*(b - a)) <= 0.0:
            raise InputError(f"wall {name} length", 0.0, "(0, inf) m; its end points coincide")
        check_contact_values(f"wall {name}", kn, ks, mu)
        if not (is_number(mu_r) and 0.0 <= mu_r < np.inf):
            raise InputError(f"wall {name} rolling friction", mu_r, "[0, inf)")
        if name in self.names:
            raise InputError("wall name", name, "a name not used by another wall")
        for i in range(self.n):
            if _segments_overlap(self.p0[i], self.p1[i], a, b):
                raise InputError(
                    f"wall {name}",
                    (a.tolist(), b.tolist()),
                    f"a segment that does not lie along wall {self.names[i]!r}",
                    "collinear overlapping walls would double the contact force",
                )
        mu_r_before = self.rolling_friction()  # one entry per wall present, before this one
        rows = {"p0": a, "p1": b, "vel": np.asarray(velocity, float), "servo_dir": np.zeros(2)}
        for f, row in {**rows, "servo": np.zeros(SERVO_COLUMNS)}.items():
            setattr(self, f, np.ascontiguousarray(np.vstack([getattr(self, f), row])))
        for f, value in (("kn", kn), ("ks", ks), ("mu", mu)):
            setattr(self, f, np.append(getattr(self, f), float(value)))
        self.mu_r = np.append(mu_r_before, float(mu_r))
        self.mode = np.append(self.mode, WALL_VELOCITY).astype(np.int64)
        self.names.append(name)
        return self.n - 1

    def set_servo(
        self,
        w: int,
        direction: np.ndarray,
        target_force: float,
        gain: float,
        max_speed: float,
        integral: float,
    ) -> None:
        """Servo wall ``w`` along the unit ``direction``: its row of ``servo``, column by column
        (checked by :meth:`poro2d.dem.Simulation.set_wall_servo`)."""
        self.mode[w] = WALL_SERVO
        self.servo_dir[w] = direction
        # a new servo starts without a summed error
        columns = [SERVO_TARGET, SERVO_GAIN, SERVO_MAX_SPEED, SERVO_INTEGRAL, SERVO_ERROR_SUM]
        self.servo[w, columns] = (target_force, gain, max_speed, integral, 0.0)

    def index(self, name_or_index: str | int) -> int:
        if isinstance(name_or_index, (int, np.integer)):
            if not 0 <= int(name_or_index) < self.n:
                raise InputError("wall", name_or_index, f"an index in [0, {self.n - 1}]")
            return int(name_or_index)
        try:
            return self.names.index(name_or_index)
        except ValueError:
            raise InputError("wall", name_or_index, f"one of {self.names}") from None

    @classmethod
    def box(
        cls, x0: float, y0: float, x1: float, y1: float, kn: float, ks: float, mu: float, mu_r: float = 0.0
    ) -> Walls:
        """Four walls named bottom, right, top, left around [x0, x1] x [y0, y1].

        The side walls are extended past the top and bottom by the box size so a
        moving plate never slides off its neighbours, and corners hold no gaps.
        """
        if not (x1 > x0 and y1 > y0):
            raise InputError("box", (x0, y0, x1, y1), "x1 > x0 and y1 > y0")
        w = cls()
        ext = max(x1 - x0, y1 - y0)
        w.add((x0 - ext, y0), (x1 + ext, y0), kn, ks, mu, "bottom", mu_r=mu_r)
        w.add((x1, y0 - ext), (x1, y1 + ext), kn, ks, mu, "right", mu_r=mu_r)
        w.add((x1 + ext, y1), (x0 - ext, y1), kn, ks, mu, "top", mu_r=mu_r)
        w.add((x0, y1 + ext), (x0, y0 - ext), kn, ks, mu, "left", mu_r=mu_r)
        return w


def _segments_overlap(a0, a1, b0, b1, tol: float = 1e-12) -> bool:
    """True when two segments are collinear and share a stretch of positive length."""
    d = a1 - a0
    L = np.hypot(*d)
    u = d / L
    for p in (b0, b1):
        if abs(u[0] * (p[1] - a0[1]) - u[1] * (p[0] - a0[0])) > tol * max(1.0, L):
            return False
    s0 = float(np.dot(b0 - a0, u))
    s1 = float(np.dot(b1 - a0, u))
    lo, hi = min(s0, s1), max(s0, s1)
    return min(hi, L) - max(lo, 0.0) > tol * max(1.0, L)


def check_contact_values(whose: str, kn: float, ks: float, mu: float) -> None:
    """Refuse (InputError, naming ``whose`` value) springs or a friction out of range: kn > 0, ks, mu >= 0."""
    if not kn > 0.0:
        raise InputError(f"{whose} kn", kn, "(0, inf) N/m")
    if not ks >= 0.0:
        raise InputError(f"{whose} ks", ks, "[0, inf) N/m")
    if not mu >= 0.0:
        raise InputError(f"{whose} friction", mu, "[0, inf)")
