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
        """Upper bound of any contact's kn or ks (N/m)."""
        if self.convention == "per_pair_type":
            assert self.pp is not None and self.pw is not None
            return float(max(self.pp[0], self.pp[1], self.pw[0], self.pw[1]))
        if particles.n == 0:
            return 0.0
        kp = max(float(particles.kn.max()), float(particles.ks.max()))
        k = kp * kp / (kp + kp)  # series is increasing in both springs
        if walls.n:
            kw = max(float(walls.kn.max()), float(walls.ks.max()))
            k = max(k, kp * kw / (kp + kw))
        return k


def critical_time_step(min_inertial_mass: float, k_max: float) -> float:
    """``sqrt(m_min / k_max)``: the scale of the stiffest, lightest contact.

    A single disk on one linear spring becomes unstable with central differences
    at ``2 sqrt(m/k)``; its spin on a tangential spring (inertia m r^2 / 2) at
    ``sqrt(2) sqrt(m/k)``. Several contacts per disk lower both, hence the safety
    factor applied by the caller.
    """
    if k_max <= 0.0:
        return math.inf
    return math.sqrt(min_inertial_mass / k_max)


def restitution_to_beta(e: float) -> float:
    """Restitution coefficient of a linear spring-dashpot contact to its damping ratio.

    e = exp(-beta pi / sqrt(1 - beta^2))  <=>  beta = -ln e / sqrt(pi^2 + ln^2 e).
    """
    if not 0.0 < e <= 1.0:
        raise InputError("restitution", e, "(0, 1]")
    le = math.log(e)
    return -le / math.sqrt(math.pi**2 + le * le)


def inertial_masses(particles: Particles, density_scale: float) -> tuple[np.ndarray, np.ndarray]:
    return particles.mass * density_scale, particles.inertia * density_scale
