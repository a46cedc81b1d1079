"""The elastic part of a biaxial test's strain, the plastic strains, and an unloading probe that checks them.

With linear contacts the packing's elastic strain is about 1 / kappa (kappa = kn / (sigma_3 t),
:mod:`poro2d.biaxial.stiffness`): 0.5-3 % of strain at the quick specimen's kappa of 125-500,
the size of the dilatancy being read. When the stress ratio falls past the peak the elastic
strain stored at the peak comes back, and the area it gives back reads as dilation.

**Plastic strains.** Each row of the curve records the elastic strain the contacts hold
(:func:`poro2d.biaxial.stiffness.contact_strain`: the uniform strain whose contact overlaps fit
the measured ones best, eps_1^e along the plate's axis, eps_3^e across). The plastic strains are
eps_1^p = eps_1 - (eps_1^e - eps_1,0^e) and eps_3^p = eps_3 - (eps_3^e - eps_3,0^e), the first
row's elastic strain the zero: eps_v^p = eps_1^p + eps_3^p and eps_s^p = eps_1^p - eps_3^p, the
dilatancy read off them as off the total strains (:func:`poro2d.biaxial.angles.read_plastic`).
The contacts' strain follows the fabric row by row (the dense start is stiffer than the
critical state), which a single compliance cannot.

**The probe** (``probe_unload``) measures the compliance along the test's own stress path once the
curve is recorded, so the test's own numbers do not change:

1. the plate stops and the specimen comes to rest with the side walls servoed at sigma_3
   (state A: sigma_1, eps_1, eps_3);
2. the plate is raised at the shearing's velocity until sigma_1 is down to sigma_1 - ``probe_unload`` q
   (q the deviator at A), the side walls still at sigma_3, then held until rest again (state B);
3. C1 = d eps_1 / d sigma_1 and C3 = d eps_3 / d sigma_1 are the secants from A to B, and the
   contacts' elastic strain gives its own secants over the same unloading.

Measured on the quick specimens (docs/biaxial.md) an unloading from the critical state is not
elastic: the specimen contracts as the deviator falls (at 50 kPa more than the unloading's
elastic swell), so C from the probe is no elastic compliance there and the plastic strains do
not use it; it is recorded beside the contacts' compliance as the check of the latter.
"""

from __future__ import annotations

import math

import numpy as np

from poro2d.biaxial.box import BiaxialBox, BoxSize
from poro2d.biaxial.curve import BiaxialCurve
from poro2d.biaxial.parts import ElasticProbe
from poro2d.biaxial.settings import BiaxialSettings
from poro2d.biaxial.stages import ProgressFn, servo_targets, settle
from poro2d.biaxial.stiffness import contact_strain
from poro2d.dem import Simulation

#: the plate's travel (axial strain) between two looks at sigma_1 while it is raised
UNLOAD_CHUNK_STRAIN = 1e-5
#: how the probe is read (kept with its numbers)
PROBE_DEFINITION = (
    "after shearing: the plate held until rest (A), raised at the shearing's velocity to sigma_1 - "
    "unload q at constant sigma_3 and held until rest (B); C1 = d eps_1 / d sigma_1 and "
    "C3 = d eps_3 / d sigma_1 (1/MPa) the secants A-B; K = 1 / (2 (C1 + C3)), G = 1 / (2 (C1 - C3)) "
    "(MPa, 2D); contact_*: the same secants of the contacts' elastic strain"
)


def _state(sim: Simulation, start: BoxSize) -> tuple[list[float], float, tuple[float, float]]:
    """([sigma_1 in kPa, eps_1, eps_3], sigma_3 in kPa, the contacts' (eps_1^e, eps_3^e)) of the box now
    (strains from ``start``)."""
    now = BiaxialBox.size(sim)
    s1, s3, _, _ = BiaxialBox.stresses(sim)
    e1 = math.log(start.height / now.height)
    e3 = math.log(start.width / now.width)
    return [s1 / 1e3, e1, e3], s3 / 1e3, contact_strain(sim)


def probe_compliance(
    sim: Simulation, start: BoxSize, confining_kpa: float, settings: BiaxialSettings, velocity: float,
    progress: ProgressFn | None = None,
) -> ElasticProbe:  # fmt: skip
    """The probe on ``sim`` as shearing left it (its strains from the box ``start`` after consolidation;
    the plate raised at the shearing's ``velocity``, m/s)."""
    unload = float(settings.probe_unload)
    sigma = confining_kpa * 1e3
    held = settle(sim, sigma, settings, top_pa=None, phase="probing", progress=progress, fixed_plate=True)
    before, s3a, ea = _state(sim, start)
    target = before[0] - unload * (before[0] - s3a)
    raised = raise_plate(sim, target * 1e3, velocity, sigma, settings)
    eased = settle(sim, sigma, settings, top_pa=None, phase="probing", progress=progress, fixed_plate=True)
    after, s3b, eb = _state(sim, start)
    reached = held.reached and eased.reached
    ds1 = (after[0] - before[0]) / 1e3  # MPa
    c1, c3 = ((after[1] - before[1]) / ds1, (after[2] - before[2]) / ds1) if reached else (None, None)
    return ElasticProbe(
        definition=PROBE_DEFINITION, unload=unload, before=before, after=after, sigma_3_kpa=[s3a, s3b],
        steps=held.steps + raised + eased.steps, reached=reached, axial_compliance=c1, lateral_compliance=c3,
        bulk_modulus_mpa=_modulus(c1, c3, 1.0), shear_modulus_mpa=_modulus(c1, c3, -1.0),
        contact_axial_compliance=(eb[0] - ea[0]) / ds1 if reached else None,
        contact_lateral_compliance=(eb[1] - ea[1]) / ds1 if reached else None,
    )  # fmt: skip


def raise_plate(
    sim: Simulation, target_pa: float, velocity: float, sigma_pa: float, settings: BiaxialSettings
) -> int:
    """Raise the plate at ``velocity`` (the shearing's, so the unloading is as quasi-static as the
    loading was) until sigma_1 is down to ``target_pa``, the side walls servoed to ``sigma_pa``; the
    steps it took. A servo on the plate's force would jump it up at the servo's top speed, and the
    specimen, free for a moment at its top, would be squeezed by its side walls: not an elastic
    unloading."""
    s = BiaxialBox.size(sim)
    chunk = max(1, round(UNLOAD_CHUNK_STRAIN * s.height / (velocity * sim.dt)))
    sim.set_wall_velocity("top", (0.0, velocity))
    steps = 0
    while BiaxialBox.stresses(sim)[0] > target_pa and steps < settings.consolidation_max_steps:
        sim.run(chunk)
        steps += chunk
        servo_targets(sim, sigma_pa, settings, top=False)
    sim.set_wall_velocity("top", (0.0, 0.0))
    return steps


def _modulus(c1: float | None, c3: float | None, sign: float) -> float | None:
    """1 / (2 (C1 + sign C3)): K (sign +1) or G (sign -1) in MPa; None without a compliance."""
    if c1 is None or c3 is None or c1 + sign * c3 == 0:
        return None
    return 1.0 / (2.0 * (c1 + sign * c3))


def plastic_strains(curve: BiaxialCurve) -> tuple[np.ndarray, np.ndarray]:
    """(eps_v^p, eps_s^p) of each row: the change of the contacts' elastic strain since the first row
    taken out of eps_1 and eps_3."""
    e1 = curve.axial_strain - (curve.elastic_axial_strain - curve.elastic_axial_strain[0])
    e3 = curve.lateral_strain - (curve.elastic_lateral_strain - curve.elastic_lateral_strain[0])
    return e1 + e3, e1 - e3


__all__ = ["PROBE_DEFINITION", "plastic_strains", "probe_compliance"]
