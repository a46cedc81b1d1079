"""The elastic part of a biaxial test's strain: an unloading probe after shearing, and the plastic strains.

With linear contacts the packing's elastic strain is about 1 / kappa (kappa = kn / (sigma_3 t),
:mod:`poro2d.biaxial.stiffness`): 0.5-3 % of strain at the quick specimen's kappa of 125-500,
the size of the dilatancy being read. When the stress ratio falls past the peak the elastic
strain stored at the peak comes back, and the volume it gives back reads as dilation. The probe
measures that compliance along the test's own stress path (sigma_1 changed at constant
sigma_3) once the curve is recorded, so the test's own numbers do not change:

1. the plate stops and the specimen comes to rest with the side walls servoed at sigma_3
   (state A: sigma_1, eps_1, eps_3);
2. the plate is servoed to sigma_1 - ``probe_unload`` q (q the deviator at A), the side walls
   still at sigma_3, to rest again (state B);
3. C1 = d eps_1 / d sigma_1 and C3 = d eps_3 / d sigma_1 are the secants from A to B.

The critical-state fabric at the end of shearing is the one closest to the softening where
psi_max is read. An unloading is nearly elastic in a packing of frictional disks: few contacts
slide back over a small unloading (a larger one lets more slide and gives a larger compliance).

The plastic strains of each row are then eps_1^p = eps_1 - C1 (sigma_1 - sigma_1,0) and
eps_3^p = eps_3 - C3 (sigma_1 - sigma_1,0), sigma_1,0 the first row's: eps_v^p = eps_1^p + eps_3^p
and eps_s^p = eps_1^p - eps_3^p, the dilatancy read off them as off the total strains
(:func:`poro2d.biaxial.angles.read_plastic`). The compliance of the critical-state fabric
stands for the whole test: the only one measured, and a linear contact law has no stress
level of its own.
"""

from __future__ import annotations

import math

import numpy as np

from poro2d.biaxial.box import BiaxialBox, BoxSize
from poro2d.biaxial.curve import BiaxialCurve
from poro2d.biaxial.parts import ElasticProbe
from poro2d.biaxial.settings import BiaxialSettings
from poro2d.biaxial.stages import ProgressFn, settle
from poro2d.dem import Simulation

#: how the probe is read (kept with its numbers)
PROBE_DEFINITION = (
    "after shearing: the plate held until rest (A), then servoed to sigma_1 - unload q at constant "
    "sigma_3 until rest (B); C1 = d eps_1 / d sigma_1 and C3 = d eps_3 / d sigma_1 (1/MPa) the secants "
    "A-B; K = 1 / (2 (C1 + C3)), G = 1 / (2 (C1 - C3)) (MPa, 2D)"
)


def _state(sim: Simulation, start: BoxSize) -> tuple[list[float], float]:
    """([sigma_1 in kPa, eps_1, eps_3], sigma_3 in kPa) of the box now (strains from ``start``)."""
    now = BiaxialBox.size(sim)
    s1, s3, _, _ = BiaxialBox.stresses(sim)
    e1 = math.log(start.height / now.height)
    e3 = math.log(start.width / now.width)
    return [s1 / 1e3, e1, e3], s3 / 1e3


def probe_compliance(
    sim: Simulation, start: BoxSize, confining_kpa: float, settings: BiaxialSettings,
    progress: ProgressFn | None = None,
) -> ElasticProbe:  # fmt: skip
    """The probe on ``sim`` as shearing left it (its strains from the box ``start`` after consolidation)."""
    unload = float(settings.probe_unload)
    sigma = confining_kpa * 1e3
    held = settle(sim, sigma, settings, top_pa=None, phase="probing", progress=progress, fixed_plate=True)
    before, s3a = _state(sim, start)
    target = (before[0] - unload * (before[0] - s3a)) * 1e3
    eased = settle(sim, sigma, settings, top_pa=target, phase="probing", progress=progress)
    after, s3b = _state(sim, start)
    reached = held.reached and eased.reached
    ds1 = (after[0] - before[0]) / 1e3  # MPa
    c1 = (after[1] - before[1]) / ds1 if reached else None
    c3 = (after[2] - before[2]) / ds1 if reached else None
    return ElasticProbe(
        definition=PROBE_DEFINITION, unload=unload, before=before, after=after, sigma_3_kpa=[s3a, s3b],
        steps=held.steps + eased.steps, reached=reached, axial_compliance=c1, lateral_compliance=c3,
        bulk_modulus_mpa=_modulus(c1, c3, 1.0), shear_modulus_mpa=_modulus(c1, c3, -1.0),
    )  # fmt: skip


def _modulus(c1: float | None, c3: float | None, sign: float) -> float | None:
    """1 / (2 (C1 + sign C3)): K (sign +1) or G (sign -1) in MPa; None without a compliance."""
    if c1 is None or c3 is None or c1 + sign * c3 == 0:
        return None
    return 1.0 / (2.0 * (c1 + sign * c3))


def plastic_strains(curve: BiaxialCurve, c1: float, c3: float) -> tuple[np.ndarray, np.ndarray]:
    """(eps_v^p, eps_s^p) of each row: the elastic strain C (sigma_1 - sigma_1,0) taken out of
    eps_1 and eps_3 (C1, C3 in 1/MPa; the curve's sigma_1 in kPa)."""
    ds1 = (curve.sigma_1_kpa - curve.sigma_1_kpa[0]) / 1e3
    e1 = curve.axial_strain - c1 * ds1
    e3 = curve.lateral_strain - c3 * ds1
    return e1 + e3, e1 - e3


__all__ = ["PROBE_DEFINITION", "plastic_strains", "probe_compliance"]
