"""Contact-property conventions and the time step."""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from poro2d.dem.contact_law import PER_BODY, PER_PAIR_TYPE
from poro2d.dem.state import Particles, Walls
from poro2d.errors import InputError


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
                kn, ks, mu = (float(x) for x in v)
                if not kn > 0:
                    raise InputError(f"contact {name} kn", kn, "(0, inf) N/m")
                if not ks >= 0:
                    raise InputError(f"contact {name} ks", ks, "[0, inf) N/m")
                if not mu >= 0:
                    raise InputError(f"contact {name} friction", mu, "[0, inf)")

    @property
    def mode(self) -> int:
        return PER_BODY if self.convention == "per_body" else PER_PAIR_TYPE

    def to_dict(self) -> dict:
        return asdict(self)

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
        kpp = kp * kp / (kp + kp)  # series springs grow with both members
        kpw = 0.0
        if walls.n:
            kw = max(float(walls.kn.max()), float(walls.ks.max()))
            kpw = kp * kw / (kp + kw)
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
