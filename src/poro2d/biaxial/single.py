"""One biaxial test: the protocol of a :class:`~poro2d.biaxial.case.BiaxialCase`.

1. the specimen in the biaxial box (:func:`poro2d.biaxial.box.build_biaxial_box`): every disk
   inside, gravity off;
2. the inertial number of the asked strain rate at sigma_3 checked against ``inertial_limit``
   (refused above it, before any step);
3. consolidation (:func:`poro2d.biaxial.stages.consolidate`): plate and side walls servoed to
   sigma_3 until equilibrium, refused loudly if not reached;
4. shearing (:class:`poro2d.biaxial.stages.Shearing`) to ``max_strain``;
5. the angles read off the curve (:func:`poro2d.biaxial.angles.read_angles`).

With a store the test keeps ``curve.csv`` and then ``result.json`` there (each atomic), bound to
the test by ``test.json`` (:mod:`poro2d.biaxial.record`): a rerun reads a finished test back.
"""

from __future__ import annotations

import math
import time
from dataclasses import asdict

import numpy as np

from poro2d.biaxial.angles import read_angles, read_plastic
from poro2d.biaxial.box import BiaxialBox, BoxSize, build_biaxial_box
from poro2d.biaxial.case import BiaxialCase
from poro2d.biaxial.curve import BiaxialCurve, read_curve
from poro2d.biaxial.elastic import plastic_strains, probe_compliance
from poro2d.biaxial.parts import ShearChecks, StiffnessScale
from poro2d.biaxial.record import folder_stage
from poro2d.biaxial.results import BiaxialTestResult
from poro2d.biaxial.settings import auto_strain_rate, inertial_number
from poro2d.biaxial.stages import SIDE_START_STRAIN, ProgressFn, Shearing, consolidate
from poro2d.biaxial.stiffness import DiskStiffness, scaled_stiffness
from poro2d.dem import Simulation
from poro2d.errors import InputError
from poro2d.io_utils import Provenance
from poro2d.measure.fabric import ROSE_FILE, FabricRoses
from poro2d.store import Store


def median_diameter(radius: np.ndarray) -> float:
    """d50 (m): the diameter that half the disks' area lies below (the 2D sieve curve's median)."""
    d = np.sort(2.0 * radius)
    area = np.cumsum(d**2)
    return float(np.interp(0.5, area / area[-1], d))


def quasi_static_rate(case: BiaxialCase, width: float, d50: float, rho: float) -> tuple[float, float]:
    """(strain rate, inertial number at sigma_3) of ``case`` in a box ``width`` wide, of disks of
    median diameter ``d50`` and inertial density ``rho``; refused above ``inertial_limit``."""
    s, sigma = case.settings, case.confining_kpa
    rate = auto_strain_rate(width, s)
    i0 = inertial_number(rate, d50, rho, sigma * 1e3)
    if i0 > s.inertial_limit:
        raise InputError(
            "strain_rate", rate, f"(0, {rate * s.inertial_limit / i0:.3g}] 1/s",
            f"I = rate d50 sqrt(rho / sigma_3) = {i0:.2e} at {sigma:g} kPa, above the "
            f"quasi-static limit {s.inertial_limit:g}",
        )  # fmt: skip
    return rate, i0


def check_quasi_static(case: BiaxialCase) -> None:
    """Refuse ``case``'s strain rate, if not quasi-static, before any file or step: read off the
    specimen's disks as saved or as its recipe draws them, no box built (the test checks again)."""
    width, radius, density = case.grains()
    rho = float(np.mean(density)) * case.settings.density_scale
    quasi_static_rate(case, width, median_diameter(radius), rho)


def _curve_kept(store: Store) -> bool:
    """The test's ``curve.csv`` is there as it was written (a finished test needs it beside its result)."""
    return store.has("curve.csv") and store.intact("curve.csv")


class BiaxialTest:
    """One biaxial test; ``store`` (or None: nothing kept) holds its ``curve.csv`` and ``result.json``."""

    def __init__(
        self, case: BiaxialCase, store: Store | None = None, *, progress: ProgressFn | None = None,
        threads: int = 1,
    ) -> None:  # fmt: skip
        self.case = case
        self.store = store
        self.progress = progress
        self.threads = threads
        # known once the box is built (:meth:`build`)
        self.box: BiaxialBox | None = None
        self.d50 = math.nan
        self.rho = math.nan
        self.i0 = math.nan
        self.strain_rate = math.nan
        self.scale: StiffnessScale | None = None
        #: the contact orientations at the peak and at the end, once computed (``fabric_rose.json``)
        self.roses: FabricRoses | None = None

    def build(self) -> Simulation:
        """The specimen in its box, with the test's damping; the inertial number checked."""
        s = self.case.settings
        spec = self.case.specimen.simulation(threads=self.threads)
        disks = self.scaled(spec)
        sim, self.box = build_biaxial_box(
            spec, s.kn_wall, s.ks_wall, s.friction_wall, s.particle_friction, s.rolling_friction,
            s.density_scale, s.dt_safety, self.threads, particle_kn=disks.kn if disks else None,
            particle_ks=disks.ks if disks else None,
        )  # fmt: skip
        if s.local_damping is not None:
            sim.set_local_damping(float(s.local_damping))
        self.d50 = median_diameter(sim.particles.radius)
        self.rho = float(np.mean(sim.particles.density)) * sim.density_scale
        self.strain_rate, self.i0 = quasi_static_rate(self.case, self.box.width, self.d50, self.rho)
        return sim

    def scaled(self, spec: Simulation) -> DiskStiffness | None:
        """The disks' stiffness for ``stiffness_number`` (None: the specimen's), kept as ``scale``."""
        kappa = self.case.settings.stiffness_number
        if kappa is None:
            return None
        disks = scaled_stiffness(spec, kappa, self.case.confining_kpa * 1e3)
        self.scale = StiffnessScale(kappa, disks.kn, disks.ks, disks.factor)
        return disks

    def stored(self) -> BiaxialTestResult | None:
        """This test's result when ``store`` holds it finished (with its curve), else None."""
        if self.store is None:
            return None
        store = self.store
        data = folder_stage(store, self.case).stored(accept=lambda _: _curve_kept(store))
        if data is None:
            return None
        result = BiaxialTestResult.from_dict(data)
        result.curve = read_curve(store)
        return result if result.curve is not None else None

    def run(self) -> BiaxialTestResult:
        """The test's result: with a store, read back when it holds this test finished, else
        computed and kept there (``curve.csv``, then ``result.json``, the stage's marker).

        A test killed midway left no marker: it runs again from the start (a paper-size test
        is about half a minute, docs/biaxial.md, so it keeps no checkpoint).
        """
        if self.store is None:
            return self.compute()
        done = self.stored()
        if done is not None:
            return done
        store = self.store
        stage = folder_stage(store, self.case)  # a folder of another test is refused here
        fresh: list[BiaxialTestResult] = []

        def compute() -> BiaxialTestResult:
            fresh.append(self.compute())
            store.write_csv("curve.csv", fresh[0].curve.rows(), header=list(fresh[0].curve.columns))
            store.write_result(ROSE_FILE, self.roses)
            return fresh[0]

        stage.run(compute, accept=lambda _: _curve_kept(store))  # nothing stored (above): it computes
        return fresh[0]

    def compute(self) -> BiaxialTestResult:
        """Consolidate, shear and read the angles (nothing kept)."""
        t0 = time.perf_counter()
        s = self.case.settings
        sim = self.build()
        assert self.box is not None
        info = consolidate(sim, self.box, self.case.confining_kpa, s, self.progress)
        sigma = self.case.confining_kpa
        start = BiaxialBox.size(sim)
        shearing = Shearing(sim, sigma, s, self.strain_rate, self.d50, self.rho, self.progress, self.store)
        rows, velocity = shearing.run()
        curve = BiaxialCurve.of_rows(rows)
        angles = read_angles(curve, sigma, s.smoothing_strain, s.critical_window, s.critical_rate_limit)
        at_peak = int(np.argmin(np.abs(curve.axial_strain - angles.axial_strain_at_peak)))
        self.roses = FabricRoses.of("axial_strain", curve.axial_strain, shearing.roses, at_peak)
        curve, elastic = self.elastic(sim, start, curve, velocity)
        return BiaxialTestResult.of(
            angles, checks=self.checks(curve), consolidation=info, strain_rate_per_s=self.strain_rate,
            plate_velocity_m_per_s=velocity, d50_m=self.d50, dt_s=sim.dt, local_damping=sim.local_damping,
            density_scale=sim.density_scale, shear_steps=int(rows[-1].step), records=len(rows),
            wall_time_s=time.perf_counter() - t0, settings=s, specimen=self.case.specimen.source,
            specimen_digest=self.case.specimen.digest, provenance=Provenance.now(),
            stiffness_number=info.stiffness_number, stiffness_scale=self.scale,
            mean_overlap_ratio_at_peak=float(np.interp(angles.axial_strain_at_peak, curve.axial_strain,
                                                       curve.mean_overlap_ratio)), **elastic, curve=curve,
        )  # fmt: skip

    def elastic(
        self, sim: Simulation, start: BoxSize, curve: BiaxialCurve, velocity: float
    ) -> tuple[BiaxialCurve, dict]:
        """The curve with its plastic strains, and the result's elastic fields: the plastic angles and
        the unloading probe, run on ``sim`` as shearing left it (the curve is recorded: the test's
        own numbers stay as they were)."""
        s = self.case.settings
        curve = curve.with_plastic(*plastic_strains(curve))
        plastic = read_plastic(curve, s.smoothing_strain, s.critical_window)
        fields = asdict(plastic) if plastic is not None else {}
        if s.probe_unload is not None:
            fields["elastic_probe"] = probe_compliance(
                sim, start, self.case.confining_kpa, s, velocity, self.progress
            )
        return curve, fields

    def checks(self, curve: BiaxialCurve) -> ShearChecks:
        """sigma_3 held, equilibrium and the inertial number over the shearing stage."""
        s = self.case.settings
        later = curve.axial_strain >= SIDE_START_STRAIN
        err = np.abs(curve.sigma_3_kpa[later] / self.case.confining_kpa - 1.0)
        max_err = float(err.max()) if err.size else float("nan")
        mean_err = float(err.mean()) if err.size else float("nan")
        max_i = float(np.max(curve.inertial_number))
        return ShearChecks(
            sigma_3_max_error=max_err, sigma_3_mean_error=mean_err, stress_tolerance=s.stress_tolerance,
            sigma_3_held=bool(mean_err <= s.stress_tolerance),
            mean_unbalanced_ratio=float(np.mean(curve.max_unbalanced_ratio)),
            max_unbalanced_ratio=float(np.max(curve.max_unbalanced_ratio)),
            inertial_number_at_confining=self.i0, max_inertial_number=max_i, inertial_limit=s.inertial_limit,
            quasi_static=bool(self.i0 <= s.inertial_limit),
        )  # fmt: skip


__all__ = ["BiaxialTest", "check_quasi_static", "median_diameter", "quasi_static_rate"]
