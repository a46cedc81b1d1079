"""Synthetic "laboratory" data: poro2d's own direct shear or biaxial test at known (f_p, mu_r).

Used to check that a calibration recovers what it claims (never as real laboratory data):
the CSV says so in its header, with the parameters, specimen and settings that made it.
"""

from __future__ import annotations

import os
from pathlib import Path

from poro2d.biaxial.case import BiaxialCase
from poro2d.biaxial.settings import BiaxialSettings
from poro2d.biaxial.single import BiaxialTest
from poro2d.shear.case import ShearCase
from poro2d.shear.settings import ShearSettings
from poro2d.shear.single import DirectShearTest
from poro2d.specimen.saved import Specimen
from poro2d.store import Store


def synthetic_lab(
    specimen: str | os.PathLike,
    normal_stresses_kpa,
    particle_friction: float,
    rolling_friction: float,
    path: str | os.PathLike,
    *,
    settings: dict | None = None,
    work: Store | None = None,
    curves: bool = True,
    particle_kn: float | None = None,
    particle_ks: float | None = None,
) -> Path:
    """Shear ``specimen`` at each stress with the given frictions; write the lab CSV at ``path``.

    ``particle_kn``, ``particle_ks``: the disks' stiffness (N/m; None: the specimen's), the truth of
    a calibration of kn and ks.

    ``curves``: the whole curves (the lab curve layout, with the plate's rise as
    ``vertical_displacement_mm``: the dilation a calibration fits), else one peak per stress.
    ``work``: the store the tests keep their files in (default: a folder beside ``path``).
    The curves are the tests' own (:attr:`poro2d.shear.results.ShearTestResult.curve`).
    """
    base = dict(settings or {}, particle_friction=particle_friction, rolling_friction=rolling_friction)
    base.update(
        {k: v for k, v in (("particle_kn", particle_kn), ("particle_ks", particle_ks)) if v is not None}
    )
    base.setdefault("stop_after_peak", 0.0)
    sset = ShearSettings(**base)
    header = [
        "# SYNTHETIC laboratory data, not measured: made by poro2d's own direct shear",
        f"# at particle_friction = {particle_friction}, rolling_friction = {rolling_friction}",
        *(
            [f"# and the disks' particle_kn = {sset.particle_kn}, particle_ks = {sset.particle_ks} N/m"]
            if sset.particle_kn is not None or sset.particle_ks is not None
            else []
        ),
        f"# on the specimen {specimen}",
        f"# shear settings: max_displacement = {sset.max_displacement} m, velocity = {sset.velocity} m/s",
        "normal_stress_kpa,shear_displacement_mm,shear_stress_kpa,vertical_displacement_mm"
        if curves
        else "normal_stress_kpa,peak_shear_stress_kpa",
    ]

    def rows(value: Specimen, sigma: float, work: Store) -> list[str]:
        test = DirectShearTest(ShearCase(value, sigma, sset), work.child(f"sn{sigma:g}kPa"), keep_peak=False)
        res = test.run()
        if not curves:
            return [f"{sigma:g},{res.peak_shear_stress_kpa:.4f}"]
        c = res.curve
        columns = (c["shear_displacement_mm"], c["shear_stress_kpa"], c["plate_displacement_mm"])
        return [f"{sigma:g},{d:.5f},{t:.4f},{v:.6f}" for d, t, v in zip(*columns, strict=True)]

    return _write_lab(specimen, normal_stresses_kpa, path, work, header, rows)


def synthetic_biaxial_lab(
    specimen, confining_stresses_kpa, particle_friction, rolling_friction, path, *, settings=None, work=None
) -> Path:
    """Run poro2d's biaxial test of ``specimen`` at each confining stress with the given frictions;
    write the curves at ``path`` in the biaxial laboratory layout (``--biaxial-lab``).

    The columns: ``confining_stress_kpa``, ``axial_strain``, ``stress_ratio``, ``volumetric_strain``
    (the tests' own curves, :class:`poro2d.biaxial.curve.BiaxialCurve`). The first readings of a test
    may have sigma_1 a little below sigma_3 (the servo's tolerance after consolidation): a
    laboratory file holds no negative stress ratio, so those are written as 0 (the header says so).
    The arguments are :func:`synthetic_lab`'s: ``settings``, biaxial settings other than the two
    frictions; ``work``, where the tests keep their files (default: a folder beside ``path``).
    """
    sset = BiaxialSettings(
        **dict(settings or {}, particle_friction=particle_friction, rolling_friction=rolling_friction)
    )
    header = [
        "# SYNTHETIC laboratory data, not measured: made by poro2d's own biaxial test",
        f"# at particle_friction = {particle_friction}, rolling_friction = {rolling_friction}",
        f"# on the specimen {specimen}",
        f"# biaxial settings: max_strain = {sset.max_strain}, record_strain = {sset.record_strain}",
        "# stress ratios below 0 (sigma_1 just under sigma_3 at the start) are written as 0",
        "confining_stress_kpa,axial_strain,stress_ratio,volumetric_strain",
    ]

    def rows(value: Specimen, sigma: float, work: Store) -> list[str]:
        c = BiaxialTest(BiaxialCase(value, sigma, sset), work.child(f"sigma3_{sigma:g}kPa")).run().curve
        columns = (c.axial_strain, c.sin_phi, c.volumetric_strain)
        return [
            f"{sigma:g},{e1:.7f},{max(ratio, 0.0):.6f},{ev:.7f}"
            for e1, ratio, ev in zip(*columns, strict=True)
        ]

    return _write_lab(specimen, confining_stresses_kpa, path, work, header, rows)


def _write_lab(specimen, stresses, path, work: Store | None, header: list[str], rows) -> Path:
    """The lab CSV at ``path``: ``header``, then ``rows(specimen, sigma, work)`` of each stress in
    increasing order, the specimen read once for every test; ``work`` (None: a folder beside
    ``path``) keeps the tests' files."""
    path = Path(path)
    work = work if work is not None else Store(path.with_name(path.stem + "-tests"))
    value = Specimen.read(specimen)
    lines = [line for sigma in sorted(float(s) for s in stresses) for line in rows(value, sigma, work)]
    Store(path.parent).write_text(path.name, "\n".join(header + lines) + "\n")
    return path


__all__ = ["synthetic_biaxial_lab", "synthetic_lab"]
