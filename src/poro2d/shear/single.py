"""One direct shear test at one normal stress sigma_n, driving the engine.

1. build the specimen (read once, :class:`poro2d.specimen.saved.Specimen`) in a split box
   (:func:`poro2d.shear.box.build_split_box`);
2. consolidate (:class:`poro2d.shear.controllers.Consolidation`): servo the top plate
   to ``sigma_n W t`` until the specimen is in equilibrium (maximum unbalanced-force
   ratio below ``consolidation_ratio``) and the plate's stress is within
   ``stress_tolerance`` of the target, the servo on;
3. shear (:class:`poro2d.shear.shear_stage.ShearStage`, driven by
   :class:`poro2d.shear.controllers.ShearDrive`): the lower half moves at
   ``velocity`` in +x, the upper half is fixed, the plate servo stays on; one row per
   ``record_interval`` (see :data:`poro2d.shear.curve.CURVE_COLUMNS`), a checkpoint per
   ``checkpoint_interval``.
"""

from __future__ import annotations

import time
from dataclasses import replace

import numpy as np

from poro2d.dem import Simulation
from poro2d.errors import InputError
from poro2d.io_utils import Provenance, as_json
from poro2d.labtest.records import ConsolidationRecord
from poro2d.measure.coordination import coordination_number
from poro2d.measure.fabric import ROSE_FILE
from poro2d.measure.stiffness import (
    contact_kn,
    contacts_of,
    mean_overlap_ratio,
    overlap_ratio,
    stiffness_number,
)
from poro2d.shear import record
from poro2d.shear.box import SplitBox, build_split_box
from poro2d.shear.box_dominated import box_verdict
from poro2d.shear.case import ShearCase
from poro2d.shear.controllers import Consolidation, ProgressFn
from poro2d.shear.curve import (
    CURVE_COLUMNS,
    ShearRow,
    contradiction,
    curve_columns,
    curve_summary,
    plane_load_at_peak,
    read_curve,
)
from poro2d.shear.peak_frame import PeakFrame
from poro2d.shear.residual import dilation_stopped_residual
from poro2d.shear.results import ShearTestResult
from poro2d.shear.settings import inertial_number
from poro2d.shear.shear_stage import PEAK_FRAME, ShearStage, remove_stage_files
from poro2d.store import Store
from poro2d.store.stage import ResumableStage

#: the consolidated specimen, kept so that a rerun shears without consolidating again
CONSOLIDATED = "consolidated.npz"


class DirectShearTest:
    """One direct shear test: the protocol of a :class:`~poro2d.shear.case.ShearCase`.

    With ``store`` every stage is kept there as it finishes (``consolidated.npz``,
    ``consolidation.json``, ``shear_checkpoint.npz`` during shearing, ``curve.csv``,
    ``result.json`` and, with ``keep_peak``, the state at the smoothed peak, ``peak_frame.npz``,
    from which ``draw_peak_forces`` (``report/shear_figures.py``) draws its force chains); a
    rerun skips what is done and continues a shear stage from its last checkpoint.
    ``store=None``: nothing is kept. ``progress(phase, fraction)`` is called between blocks of
    steps. Without ``keep_peak`` no state is kept at the peak and the mean overlap is the end's.
    """

    def __init__(
        self,
        case: ShearCase,
        store: Store | None = None,
        *,
        progress: ProgressFn | None = None,
        keep_peak: bool = True,
        threads: int = 1,
    ) -> None:
        self.case = case
        self.sigma_kpa = case.normal_stress_kpa
        self.settings = case.settings
        self.store = store
        self.progress = progress
        self.keep_peak = keep_peak
        self.threads = threads
        self.box: SplitBox | None = None
        self._stage: ResumableStage | None = None

    # ------------------------------------------------------------ bookkeeping
    @property
    def specimen_digest(self) -> str:
        """Digest of the specimen's state (:func:`poro2d.dem.checkpoint.state_digest`)."""
        return self.case.specimen.digest

    def stage(self) -> ResumableStage:
        """The test's stages in ``store``, bound by ``test.json`` to its specimen, stress and settings.

        ``stage().check()`` refuses a store holding work of another test; ``stage().bind()``
        records this one (a series checks every folder before it binds any).
        """
        assert self.store is not None
        if self._stage is None:
            self._stage = record.folder_stage(self.store, self.case.record(), self.case.specimen.source)
        return self._stage

    def stored(self) -> ShearTestResult | None:
        """The result of this test when ``store`` holds it finished, else None (it has to run)."""
        data = self.stage().stored(accept=self._agrees) if self.store is not None else None
        return None if data is None else ShearTestResult.read(self.store, data)

    def _agrees(self, data: dict) -> bool:
        """Whether a stored ``result.json`` is what its ``curve.csv`` records (:func:`contradiction`):
        one that is not (edited, cut short, from another copy) is not used; the test runs again."""
        assert self.store is not None
        return contradiction(data, read_curve(self.store), self.settings.peak_window) is None

    # ----------------------------------------------------------------- stages
    def _build_box(self) -> tuple[Simulation, SplitBox]:
        """The specimen in a split box, with the test's damping."""
        s = self.settings
        spec = self.case.specimen.simulation(threads=self.threads)
        sim, box = build_split_box(
            spec, s.max_displacement, s.kn_wall, s.ks_wall, s.friction_wall, s.gap,
            s.particle_friction, s.density_scale, s.dt_safety, self.threads,
            rolling_friction=s.rolling_friction, particle_kn=s.particle_kn, particle_ks=s.particle_ks,
        )  # fmt: skip
        if s.local_damping is not None:
            sim.set_local_damping(float(s.local_damping))
        return sim, box

    def consolidate(self) -> tuple[Simulation, ConsolidationRecord]:
        """The consolidated specimen and its record; with ``store`` read back once done.

        Done means ``consolidation.json`` (written last) beside ``consolidated.npz``; a state
        that cannot be read back as written (changed, truncated) is consolidated again.
        """
        store = self.store
        if store is None:
            return self._consolidate()
        fresh: list[Simulation] = []

        def compute() -> ConsolidationRecord:
            sim, info = self._consolidate()
            extra = {"stage": "consolidated", "normal_stress_kpa": self.sigma_kpa}
            store.save_state(CONSOLIDATED, sim, extra=extra)
            fresh.append(sim)
            return info

        info = self.stage().run(
            compute, "consolidation.json", accept=lambda _: store.has(CONSOLIDATED),
            decode=ConsolidationRecord.from_dict,
        )  # fmt: skip
        if fresh:
            return fresh[0], info
        try:
            sim = store.load_state(CONSOLIDATED, threads=self.threads)
        except InputError:  # changed since written, or unreadable: the stage is not done after all
            store.remove("consolidation.json")
            store.remove(CONSOLIDATED)
            return self.consolidate()
        self.box = SplitBox(**info.box.to_dict())
        return sim, info

    def _consolidate(self) -> tuple[Simulation, ConsolidationRecord]:
        """Build the split box and servo the top plate to the normal stress until equilibrium."""
        s = self.settings
        t0 = time.perf_counter()
        sim, box = self._build_box()
        self.box = box
        target = self.sigma_kpa * 1e3 * box.width * box.thickness
        done = Consolidation(s, progress=self.progress).settle(sim, target)
        if not done.reached:
            raise RuntimeError(
                f"consolidation at {self.sigma_kpa:g} kPa did not reach equilibrium within "
                f"{s.consolidation_max_steps} steps (ratio {done.ratio:.2e}, "
                f"stress error {done.error:.2%})"
            )
        y0 = done.plate_height_before_m
        info = ConsolidationRecord(
            normal_stress_kpa=self.sigma_kpa, target_force_n=target, steps=done.steps,
            max_unbalanced_ratio=done.ratio,
            normal_stress_measured_kpa=box.plate_force(sim) / (box.width * box.thickness) / 1e3,
            normal_stress_error=done.error, plate_height_before_m=y0,
            plate_height_m=box.plate_height(sim), plate_settlement_m=y0 - box.plate_height(sim),
            coordination_number=coordination_number(sim), wall_time_s=time.perf_counter() - t0,
            box=box.record(), engine=sim.summary(),
        )  # fmt: skip
        return sim, info

    def shear(self, sim: Simulation, info: ConsolidationRecord) -> ShearTestResult:
        """Shear the consolidated specimen to ``max_displacement``; returns the test result.

        With ``store``: ``curve.csv`` and ``peak_frame.npz`` are written here, ``result.json``
        after them by :meth:`run`.
        """
        assert self.box is not None
        stage = ShearStage(
            sim, self.box, self.settings, info.plate_height_m,
            store=self.store, threads=self.threads, keep_peak=self.keep_peak, progress=self.progress,
        )  # fmt: skip
        wall = stage.run()
        result = self._result(stage.rows, info, stage.sim, wall, stage.peak.frame)
        if self.store is not None:
            self.store.write_csv("curve.csv", stage.rows, header=CURVE_COLUMNS)
            roses = stage.fabric_roses()
            if roses is not None:
                self.store.write_result(ROSE_FILE, roses)
            stage.peak.save(self.store, PEAK_FRAME)  # its force chains are drawn from it afterwards
        return result

    def _result(
        self, rows: list[ShearRow], info: ConsolidationRecord, sim: Simulation, wall: float,
        peak: PeakFrame | None = None,
    ) -> ShearTestResult:  # fmt: skip
        """The test's ``result.json``: what the curve says, and how it was obtained; the stiffness
        number at the normal stress and the mean overlap at the peak (``peak``'s frame, else the
        end) say how much of its strain is the contacts' (:mod:`poro2d.measure.stiffness`)."""
        s = self.settings
        rho = float(np.mean(sim.particles.density)) * sim.density_scale
        d_mean = float(2.0 * np.mean(sim.particles.radius))
        curve = curve_columns(rows)
        verdict = box_verdict(curve, s.peak_window)  # a reading of the curve: no number of the test changes
        return ShearTestResult.of(
            curve_summary(rows, self.sigma_kpa, s),
            inertial_number_at_target_stress=inertial_number(
                s.velocity, self.sigma_kpa * 1e3, rho, s.shear_zone_factor
            ),
            consolidation=replace(info, engine=None),
            velocity_m_per_s=s.velocity,
            density_scale=sim.density_scale,
            local_damping=sim.local_damping,
            dt_s=sim.dt,
            d_mean_m=d_mean,
            shear_steps=int(rows[-1].step) if rows else 0,
            records=len(rows),
            wall_time_shear_s=wall,
            wall_time_s=wall + float(info.wall_time_s or 0.0),
            settings=s,
            specimen=self.case.specimen.source,
            engine=sim.summary(),
            provenance=Provenance.now(),
            plane_load_fraction_at_peak=plane_load_at_peak(rows, s.peak_window),
            residual_dilation_stopped=dilation_stopped_residual(curve, d_mean),
            box_dominated=verdict.dominated,
            box_note=verdict.note,
            stiffness_number=stiffness_number(contact_kn(sim), self.sigma_kpa * 1e3, sim.particles.thickness),
            mean_overlap_ratio_at_peak=(
                overlap_ratio(sim)
                if peak is None
                else mean_overlap_ratio(contacts_of(peak.contacts, peak.radius))
            ),
            curve=curve,
        )

    def run(self) -> ShearTestResult:
        """Consolidate, shear, write and return the result; with ``store`` resume what is done.

        A finished test (its ``result.json``) is read back; a consolidated one shears from
        ``consolidated.npz``; a test killed while shearing continues from its checkpoint.
        """
        if self.store is None:
            return self._as_stored(self._consolidate_and_shear())
        fresh: list[ShearTestResult] = []

        def compute() -> ShearTestResult:
            fresh.append(self._consolidate_and_shear())
            return fresh[0]

        data = self.stage().run(compute, accept=self._agrees)
        remove_stage_files(self.store)  # the shear stage's checkpoints, once result.json is written
        # a test run now keeps its curve in memory; a finished one is read back with its curve.csv
        return self._as_stored(fresh[0], data) if fresh else ShearTestResult.read(self.store, data)

    @staticmethod
    def _as_stored(result: ShearTestResult, data: dict | None = None) -> ShearTestResult:
        """``result`` as its ``result.json`` holds it (``data``, else JSON types), with its curve."""
        stored = ShearTestResult.from_dict(data if data is not None else as_json(result))
        stored.curve = result.curve
        return stored

    def _consolidate_and_shear(self) -> ShearTestResult:
        sim, info = self.consolidate()
        return self.shear(sim, info)


__all__ = ["DirectShearTest", "ProgressFn"]
