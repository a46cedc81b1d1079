"""One direct shear test at one normal stress sigma_n, driving the engine.

1. load the specimen checkpoint and build the split box around it
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
from pathlib import Path

import numpy as np

from poro2d.config import check_finite
from poro2d.dem import Simulation, checkpoint
from poro2d.errors import InputError, check_range
from poro2d.io_utils import as_json, provenance, write_csv
from poro2d.measure.coordination import coordination_number
from poro2d.shear import record
from poro2d.shear.box import SplitBox, build_split_box
from poro2d.shear.controllers import Consolidation, ProgressFn
from poro2d.shear.curve import CURVE_COLUMNS, curve_columns, curve_summary
from poro2d.shear.peak_frame import PeakFrame
from poro2d.shear.results import ShearTestResult
from poro2d.shear.settings import NORMAL_STRESS_RANGE_KPA, ShearSettings, inertial_number
from poro2d.shear.shear_stage import ShearStage, remove_stage_files
from poro2d.shear.specimen_file import resolve_specimen, specimen_box
from poro2d.store.stage import ResumableStage


class DirectShearTest:
    """One direct shear test at ``normal_stress_kpa`` on the specimen at ``specimen``.

    With ``out`` every stage is written there as it finishes (``consolidated.npz``,
    ``consolidation.json``, ``shear_checkpoint.npz`` during shearing, ``curve.csv``,
    ``result.json``, ``forces_peak.png``); a rerun skips what is done and continues a
    shear stage from its last checkpoint. ``progress(phase, fraction)`` is called
    between blocks of steps.
    """

    def __init__(
        self,
        specimen: str | Path,
        normal_stress_kpa: float,
        settings: ShearSettings | None = None,
        out: str | Path | None = None,
        progress: ProgressFn | None = None,
        figures: bool = True,
        threads: int = 1,
        specimen_digest: str | None = None,
    ) -> None:
        self.specimen = resolve_specimen(specimen)
        self.sigma_kpa = check_range("normal stress (kPa)", normal_stress_kpa, *NORMAL_STRESS_RANGE_KPA)
        self.settings = settings if settings is not None else ShearSettings()
        check_finite("shear", self.settings.to_dict())  # open ranges let an infinity through
        W, H = specimen_box(self.specimen)
        if self.settings.max_displacement > W / 2:
            raise InputError(
                "max_displacement", self.settings.max_displacement, f"(0, {W / 2:.4g}] m (half the box width)"
            )
        # the box refuses a wider gap when it is built, in the test's process: here, before any test
        check_range("gap", self.settings.gap, 0.0, H / 4)
        self.out = Path(out) if out is not None else None
        self.progress = progress
        self.figures = figures
        self.threads = threads
        self.box: SplitBox | None = None
        self._digest = specimen_digest
        self._stage: ResumableStage | None = None

    # ------------------------------------------------------------ bookkeeping
    @property
    def specimen_digest(self) -> str:
        """Digest of the specimen's state (:func:`poro2d.dem.checkpoint.state_digest`)."""
        if self._digest is None:
            self._digest = checkpoint.state_digest(self.specimen)
        return self._digest

    def _record(self) -> dict:
        return record.content_record(self.specimen_digest, self.sigma_kpa, self.settings.to_dict())

    def stage(self) -> ResumableStage:
        """The test's stages in ``out``, bound by ``test.json`` to its specimen, stress and settings.

        ``stage().check()`` refuses an ``out`` holding work of another test; ``stage().bind()``
        records this one (a series checks every folder before it binds any).
        """
        assert self.out is not None
        if self._stage is None:
            self._stage = record.folder_stage(self.out, self._record(), self.specimen)
        return self._stage

    def stored(self) -> ShearTestResult | None:
        """The result of this test when ``out`` holds it finished, else None (it has to run)."""
        data = self.stage().stored() if self.out is not None else None
        return None if data is None else ShearTestResult.read(self.out, data)

    # ----------------------------------------------------------------- stages
    def _build_box(self) -> tuple[Simulation, SplitBox]:
        """The specimen in a split box, with the test's damping."""
        s = self.settings
        spec = checkpoint.load(self.specimen, threads=self.threads)
        sim, box = build_split_box(
            spec, s.max_displacement, s.kn_wall, s.ks_wall, s.friction_wall, s.gap,
            s.particle_friction, s.density_scale, s.dt_safety, self.threads,
            rolling_friction=s.rolling_friction,
        )  # fmt: skip
        if s.local_damping is not None:
            sim.set_local_damping(float(s.local_damping))
        return sim, box

    def consolidate(self) -> tuple[Simulation, dict]:
        """The consolidated specimen and its record; with ``out`` read back once done.

        Done means ``consolidation.json`` (written last) beside ``consolidated.npz``.
        """
        if self.out is None:
            return self._consolidate()
        npz = self.out / "consolidated.npz"
        fresh: list[Simulation] = []

        def compute() -> dict:
            sim, info = self._consolidate()
            checkpoint.save(sim, npz, extra={"stage": "consolidated", "normal_stress_kpa": self.sigma_kpa})
            fresh.append(sim)
            return info

        info = self.stage().run(compute, "consolidation.json", accept=lambda _: npz.is_file())
        if fresh:
            return fresh[0], info
        self.box = SplitBox(**info["box"])
        return checkpoint.load(npz, threads=self.threads), info

    def _consolidate(self) -> tuple[Simulation, dict]:
        """Build the split box and servo the top plate to the normal stress until equilibrium."""
        s = self.settings
        t0 = time.perf_counter()
        sim, box = self._build_box()
        self.box = box
        target = self.sigma_kpa * 1e3 * box.width * box.thickness
        done = Consolidation(s, progress=self.progress).settle(sim, target)
        if not done["settled"]:
            raise RuntimeError(
                f"consolidation at {self.sigma_kpa:g} kPa did not reach equilibrium within "
                f"{s.consolidation_max_steps} steps (ratio {done['max_unbalanced_ratio']:.2e}, "
                f"stress error {done['normal_stress_error']:.2%})"
            )
        y0 = done["plate_height_before_m"]
        info = {
            "normal_stress_kpa": self.sigma_kpa, "target_force_n": target, "steps": done["steps"],
            "max_unbalanced_ratio": done["max_unbalanced_ratio"],
            "normal_stress_measured_kpa": box.plate_force(sim) / (box.width * box.thickness) / 1e3,
            "normal_stress_error": done["normal_stress_error"], "plate_height_before_m": y0,
            "plate_height_m": box.plate_height(sim), "plate_settlement_m": y0 - box.plate_height(sim),
            "coordination_number": coordination_number(sim), "wall_time_s": time.perf_counter() - t0,
            "box": box.to_dict(), "engine": sim.summary(),
        }  # fmt: skip
        return sim, info

    def shear(self, sim: Simulation, info: dict) -> ShearTestResult:
        """Shear the consolidated specimen to ``max_displacement``; returns the test result.

        With ``out``: ``curve.csv`` and ``forces_peak.png`` are written here, ``result.json``
        after them by :meth:`run`.
        """
        assert self.box is not None
        stage = ShearStage(
            sim, self.box, self.settings, info["plate_height_m"],
            folder=self.out, threads=self.threads, figures=self.figures, progress=self.progress,
        )  # fmt: skip
        wall = stage.run()
        result = self._result(stage.rows, info, stage.sim, wall)
        result.curve = curve_columns(stage.rows)
        if self.out is not None:
            write_csv(self.out / "curve.csv", stage.rows, header=CURVE_COLUMNS)
            if self.figures and stage.peak.frame is not None:
                self._figure(stage.peak.frame, result)
        return result

    def _figure(self, frame: PeakFrame, result: dict) -> None:
        """``forces_peak.png``: the force chains at the (smoothed) peak."""
        assert self.out is not None and self.box is not None
        b = self.box
        frame.draw(
            self.out / "forces_peak.png",
            title=f"direct shear at {self.sigma_kpa:g} kPa, at the peak: d = {frame.displacement_mm:.2f} mm",
            box=(-0.02 * b.width, 0.0, b.width + b.max_displacement, b.height),
            notes=[f"tau_peak = {result['peak_shear_stress_kpa']:.1f} kPa (smoothed over "
                   f"{1e3 * self.settings.peak_window:g} mm)"],
        )  # fmt: skip

    def _result(self, rows: list[dict], info: dict, sim: Simulation, wall: float) -> ShearTestResult:
        """The test's ``result.json``: what the curve says, and how it was obtained."""
        s = self.settings
        rho = float(np.mean(sim.particles.density)) * sim.density_scale
        return ShearTestResult(
            **curve_summary(rows, self.sigma_kpa, s),
            inertial_number_at_target_stress=inertial_number(
                s.velocity, self.sigma_kpa * 1e3, rho, s.shear_zone_factor
            ),
            consolidation={k: v for k, v in info.items() if k != "engine"},
            velocity_m_per_s=s.velocity,
            density_scale=sim.density_scale,
            local_damping=sim.local_damping,
            dt_s=sim.dt,
            d_mean_m=float(2.0 * np.mean(sim.particles.radius)),
            shear_steps=int(rows[-1]["step"]) if rows else 0,
            records=len(rows),
            wall_time_shear_s=wall,
            wall_time_s=wall + float(info.get("wall_time_s", 0.0)),
            settings=s.to_dict(),
            specimen=str(self.specimen),
            engine=sim.summary(),
            provenance=provenance(),
        )

    def run(self) -> ShearTestResult:
        """Consolidate, shear, write and return the result; with ``out`` resume what is done.

        A finished test (its ``result.json``) is read back; a consolidated one shears from
        ``consolidated.npz``; a test killed while shearing continues from its checkpoint.
        """
        if self.out is None:
            return self._as_stored(self._consolidate_and_shear())
        fresh: list[ShearTestResult] = []

        def compute() -> ShearTestResult:
            fresh.append(self._consolidate_and_shear())
            return fresh[0]

        data = self.stage().run(compute)
        remove_stage_files(self.out)  # the shear stage's checkpoints, once result.json is written
        # a test run now keeps its curve in memory; a finished one is read back with its curve.csv
        return self._as_stored(fresh[0], data) if fresh else ShearTestResult.read(self.out, data)

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
