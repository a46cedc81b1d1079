"""The contact law's description (what a contact's parameters are, how bodies mix) and the time step.

:class:`ContactModel` is the one description of the law that the driver hands the kernels
and that every exporter translates: per body (PFC 4.0, the paper's) or per pair type
(PFC 5 style), and how two bodies' properties make a contact's (:meth:`ContactModel.pair`,
the rule of :mod:`poro2d.dem.contact_law`).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import NamedTuple

import numpy as np

from poro2d.dem.contact_law import in_series, mix
from poro2d.dem.state import Particles, Walls, check_contact_values
from poro2d.errors import InputError

#: the per-body rule in words, as every exported file's header states it
PER_BODY_RULE = "kn = kA kB / (kA + kB), ks likewise, mu = min(muA, muB)"


class ContactValues(NamedTuple):
    """The values of the linear law: a body's own, or a contact's once two bodies are mixed.

    Springs kn, ks (N/m), sliding friction mu, rolling friction mu_r; a contact's rolling
    stiffness is ``ks R^2`` (:func:`poro2d.dem.contact_law.rolling_moment`).
    """

    kn: float
    ks: float
    mu: float
    mu_r: float = 0.0


@dataclass(frozen=True)
class ContactModel:
    """How a contact gets its stiffness and friction.

    ``convention="per_body"`` (PFC 4.0, the paper's): each body carries kn, ks, mu;
    a contact gets kn = kA kB / (kA + kB), ks likewise, mu = min(muA, muB).
    ``convention="per_pair_type"`` (PFC 5 style): one (kn, ks, mu) for every
    disk-disk contact (``pp``) and one for every disk-wall contact (``pw``); the
    bodies' own values are then ignored.
    """

    convention: str = "per_body"
    pp: tuple[float, float, float] | None = None
    pw: tuple[float, float, float] | None = None

    def __post_init__(self) -> None:
        if self.convention not in ("per_body", "per_pair_type"):
            raise InputError("contact convention", self.convention, "'per_body' or 'per_pair_type'")
        if self.convention == "per_pair_type":
            for name in ("pp", "pw"):
                v = getattr(self, name)
                if v is None or len(v) != 3:
                    raise InputError(f"contact {name}", v, "(kn, ks, mu) for per_pair_type")
                check_contact_values(f"contact {name}", *(float(x) for x in v))

    def to_dict(self) -> dict:
        return asdict(self)

    def pair(self, a: ContactValues, b: ContactValues, wall: bool = False) -> ContactValues:
        """The values of a contact of body ``a`` with body ``b`` (a wall when ``wall``), as files state them.

        Per body: :data:`PER_BODY_RULE`, springs in series as one quotient (the numbers every
        exported file has carried; for two equal springs the kernels halve instead, which may
        differ in the last bit); per pair type the constants. The rolling friction is the
        smaller of the bodies' either way.
        """
        mu_r = min(a.mu_r, b.mu_r)
        if self.convention == "per_pair_type":
            kn, ks, mu = self.pw if wall else self.pp  # type: ignore[misc]
            return ContactValues(float(kn), float(ks), float(mu), mu_r)
        kn, ks = in_series(float(a.kn), float(b.kn)), in_series(float(a.ks), float(b.ks))
        return ContactValues(kn, ks, min(a.mu, b.mu), mu_r)

    def kernel_constants(
        self, particles: Particles, walls: Walls
    ) -> tuple[ContactValues | None, ContactValues | None]:
        """The (kn, ks, mu) the kernel takes for every disk-disk and every disk-wall contact.

        None where it mixes the bodies' values per contact itself. Bodies all alike get
        their mixed values once here (the kernel's own :func:`~poro2d.dem.contact_law.mix`),
        the same numbers without reading both bodies' properties for every pair.
        """
        if self.convention == "per_pair_type":
            return ContactValues(*self.pp), ContactValues(*self.pw)  # type: ignore[misc]
        p, w = particles, walls
        if p.n == 0 or not all(np.all(a == a[0]) for a in (p.kn, p.ks, p.mu)):
            return None, None
        disk = (float(p.kn[0]), float(p.ks[0]), float(p.mu[0]))
        pp = ContactValues(*mix(*disk, *disk))
        if not (w.n and all(np.all(a == a[0]) for a in (w.kn, w.ks, w.mu))):
            return pp, None
        return pp, ContactValues(*mix(*disk, float(w.kn[0]), float(w.ks[0]), float(w.mu[0])))

    def max_stiffness(self, particles: Particles, walls: Walls) -> float:
        """Upper bound of any one contact's kn or ks (N/m)."""
        kpp, kpw = self._pair_bounds(particles, walls)
        return max(kpp, kpw)

    def stiffness_sum_bound(self, particles: Particles, walls: Walls) -> float:
        """Upper bound of the summed contact stiffness on one disk (N/m), walls counted half.

        A disk has at most six disk contacts (hexagonal order), or four and two walls in
        a corner; a wall does not move back, so its contact weighs half of a disk's in
        the frequency bound of :func:`critical_time_step`: ``max(6 k_pp, 4 k_pp + k_pw)``.
        """
        kpp, kpw = self._pair_bounds(particles, walls)
        return max(6.0 * kpp, 4.0 * kpp + kpw) if walls.n else 6.0 * kpp

    def _pair_bounds(self, particles: Particles, walls: Walls) -> tuple[float, float]:
        if self.convention == "per_pair_type":
            assert self.pp is not None and self.pw is not None
            return float(max(self.pp[0], self.pp[1])), float(max(self.pw[0], self.pw[1]))
        if particles.n == 0:
            return 0.0, 0.0
        kp = max(float(particles.kn.max()), float(particles.ks.max()))
        kpp = in_series(kp, kp)  # series springs grow with both members
        kpw = 0.0
        if walls.n:
            kw = max(float(walls.kn.max()), float(walls.ks.max()))
            kpw = in_series(kp, kw)
        return kpp, kpw


def critical_time_step(min_inertial_mass: float, k_sum: float) -> float:
    """Critical leapfrog step ``2 / omega_max = sqrt(2 m_min / (3 k_sum))``.

    A shear spring moves both the centre and the rim of a disk: its effective inverse
    mass is 1/m + r^2/I = 3/m per disk (I = m r^2 / 2), 6/m for a disk-disk contact.
    Summing over a disk's contacts bounds the highest angular frequency of the
    packing (Gershgorin): omega_max^2 <= 6 k_sum / m_min, with k_sum from
    :meth:`ContactModel.stiffness_sum_bound`. Central differences are stable below
    2 / omega_max; the caller applies a safety factor (0.8 by default).
    """
    if k_sum <= 0.0:
        return math.inf
    return math.sqrt(2.0 * min_inertial_mass / (3.0 * k_sum))


def single_contact_limit(min_inertial_mass: float, k_max: float) -> float:
    """``sqrt(2 m / k)``: a lone disk spinning on one tangential spring diverges above it."""
    if k_max <= 0.0:
        return math.inf
    return math.sqrt(2.0 * min_inertial_mass / k_max)


def rebound_of_beta(beta: float) -> float:
    """Restitution of a linear spring-dashpot contact that never pulls (damping ratio beta < 1).

    The contact ends when the total force kn x + c x' reaches zero (before the overlap
    closes): with x = e^{-beta t} sin(wd t) / wd (omega = 1, wd = sqrt(1 - beta^2)) that is
    at wd t* = pi - atan2(2 beta wd, 1 - 2 beta^2), and e = -x'(t*).
    """
    wd = math.sqrt(1.0 - beta * beta)
    phase = math.pi - math.atan2(2.0 * beta * wd, 1.0 - 2.0 * beta * beta)
    t = phase / wd
    return -math.exp(-beta * t) * (math.cos(phase) - beta / wd * math.sin(phase))


_BETA_MAX = 0.999


def restitution_to_beta(e: float) -> float:
    """Damping ratio whose no-tension dashpot rebounds with restitution ``e``.

    Inverts :func:`rebound_of_beta` by bisection (it decreases monotonically in beta).
    A dashpot that may not pull cannot dissipate everything: below
    ``rebound_of_beta(0.999)`` (about 0.1) no damping ratio gives ``e``.
    """
    e_min = rebound_of_beta(_BETA_MAX)
    if not e_min <= e <= 1.0:
        raise InputError("restitution", e, f"[{e_min:.3f}, 1] (a dashpot that never pulls)")
    if e == 1.0:
        return 0.0
    lo, hi = 0.0, _BETA_MAX
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        if rebound_of_beta(mid) > e:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def inertial_masses(particles: Particles, density_scale: float) -> tuple[np.ndarray, np.ndarray]:
    return particles.mass * density_scale, particles.inertia * density_scale


def mass_for_time_step(dt: float, k_sum: float, safety: float) -> float:
    """The smallest inertial mass whose critical step, times ``safety``, is ``dt``.

    :func:`critical_time_step` solved for the mass: ``m = 3 k_sum (dt / safety)^2 / 2``.
    """
    return 1.5 * k_sum * (dt / safety) ** 2


def raised_inertia(mass: np.ndarray, inertia: np.ndarray, floor: float) -> tuple[np.ndarray, np.ndarray]:
    """Inertial masses raised to at least ``floor``, each inertia by its disk's own ratio.

    Scaling a disk's mass and moment of inertia by one ratio keeps it a uniform disk
    (I = m r^2 / 2), so its rotational frequency falls as its translational one does. The
    disks already at or above ``floor`` keep their values exactly.
    """
    ratio = np.where(mass < floor, floor / mass, 1.0)
    return np.where(mass < floor, floor, mass), inertia * ratio
