"""One direct shear test at one normal stress sigma_n, driving the engine.

1. load the specimen checkpoint and build the split box around it
   (:func:`poro2d.shear.box.build_split_box`);
2. consolidate: servo the top plate to ``sigma_n W t`` until the specimen is in
   equilibrium (maximum unbalanced-force ratio below ``consolidation_ratio``) and
   the plate's stress is within ``stress_tolerance`` of the target, the servo on;
3. shear (:class:`poro2d.shear.shear_stage.ShearStage`): the lower half moves at
   ``velocity`` in +x, the upper half is fixed, the plate servo stays on; one row per
   ``record_interval`` (see :data:`poro2d.shear.curve.CURVE_COLUMNS`), a checkpoint per
   ``checkpoint_interval``.
"""

from __future__ import annotations

import json
import math
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from poro2d.config import check_finite
from poro2d.dem import Simulation, checkpoint
from poro2d.dem.measure import coordination_number
from poro2d.errors import InputError, check_range
from poro2d.io_utils import provenance, write_csv, write_json
from poro2d.shear import record
from poro2d.shear.box import SplitBox, build_split_box
from poro2d.shear.curve import CURVE_COLUMNS, curve_summary
from poro2d.shear.peak_frame import PeakFrame
from poro2d.shear.settings import ShearSettings, inertial_number
from poro2d.shear.shear_stage import ShearStage
from poro2d.shear.specimen_file import resolve_specimen, specimen_box

ProgressFn = Callable[[str, float], None]
#: how often (steps) consolidation checks for equilibrium
CONSOLIDATION_CHECK = 500


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
    ) -> None:
        self.specimen = resolve_specimen(specimen)
        self.sigma_kpa = check_range("normal stress (kPa)", normal_stress_kpa, 0.0, None, lo_open=True)
        self.settings = settings if settings is not None else ShearSettings()
        check_finite("shear", self.settings.to_dict())  # open ranges let an infinity through
        W, _ = specimen_box(self.specimen)
        if self.settings.max_displacement > W / 2:
            raise InputError(
                "max_displacement", self.settings.max_displacement, f"(0, {W / 2:.4g}] m (half the box width)"
            )
        self.out = Path(out) if out is not None else None
        self.progress = progress
        self.figures = figures
        self.threads = threads
        self.box: SplitBox | None = None
        self._digest: str | None = None

    # ------------------------------------------------------------ bookkeeping
    def _report(self, phase: str, fraction: float) -> None:
        if self.progress is not None:
            self.progress(phase, fraction)

    def _path(self, name: str) -> Path | None:
        return None if self.out is None else self.out / name

    @property
    def specimen_digest(self) -> str:
        """Digest of the specimen's state (:func:`poro2d.dem.checkpoint.state_digest`)."""
        if self._digest is None:
            self._digest = checkpoint.state_digest(self.specimen)
        return self._digest

    def _record(self) -> dict:
        return record.content_record(self.specimen_digest, self.sigma_kpa, self.settings.to_dict())

    def check_reusable(self) -> None:
        """Refuse an ``out`` that holds work of another specimen, normal stress or settings."""
        assert self.out is not None
        record.check_reusable(self.out, self._record())

    def bind(self) -> None:
        """Record this test in ``out/test.json`` (unless that folder already holds its work)."""
        assert self.out is not None
        record.bind(self.out, self._record(), self.specimen)

    # ----------------------------------------------------------------- stages
    def _build_box(self) -> tuple[Simulation, SplitBox]:
        """The specimen in a split box, with the test's damping."""
        s = self.settings
        spec = checkpoint.load(self.specimen, threads=self.threads)
        sim, box = build_split_box(
            spec, s.max_displacement, s.kn_wall, s.ks_wall, s.friction_wall, s.gap,
            s.particle_friction, s.density_scale, s.dt_safety, self.threads,
        )  # fmt: skip
        if s.local_damping is not None:
            sim.set_local_damping(float(s.local_damping))
        return sim, box

    def consolidate(self) -> tuple[Simulation, dict]:
        """Build the split box and servo the top plate to the normal stress until equilibrium."""
        s = self.settings
        cpath, jpath = self._path("consolidated.npz"), self._path("consolidation.json")
        if cpath is not None and jpath is not None and cpath.is_file() and jpath.is_file():
            info = json.loads(jpath.read_text())
            self.box = SplitBox(**info["box"])
            return checkpoint.load(cpath, threads=self.threads), info
        t0 = time.perf_counter()
        sim, box = self._build_box()
        self.box = box
        target = self.sigma_kpa * 1e3 * box.width * box.thickness
        sim.set_wall_servo("top", target, (0.0, -1.0), s.servo_max_speed, s.servo_gain, s.servo_integral)
        y0 = box.plate_height(sim)
        state = {"ratio": math.inf, "err": math.inf}

        def settled(sm: Simulation) -> bool:
            rmax, _ = sm.unbalanced_ratios()
            err = abs(box.plate_force(sm) / target - 1.0)
            state.update(ratio=rmax, err=err)
            self._report("consolidating", min(sm.step_count / s.consolidation_max_steps, 1.0))
            return rmax < s.consolidation_ratio and err < s.stress_tolerance

        sim.reset_clock()
        res = sim.run(s.consolidation_max_steps, every=CONSOLIDATION_CHECK, callback=settled)
        if not (state["ratio"] < s.consolidation_ratio and state["err"] < s.stress_tolerance):
            raise RuntimeError(
                f"consolidation at {self.sigma_kpa:g} kPa did not reach equilibrium within "
                f"{s.consolidation_max_steps} steps (ratio {state['ratio']:.2e}, "
                f"stress error {state['err']:.2%})"
            )
        info = {
            "normal_stress_kpa": self.sigma_kpa, "target_force_n": target, "steps": res.steps,
            "max_unbalanced_ratio": state["ratio"],
            "normal_stress_measured_kpa": box.plate_force(sim) / (box.width * box.thickness) / 1e3,
            "normal_stress_error": state["err"], "plate_height_before_m": y0,
            "plate_height_m": box.plate_height(sim), "plate_settlement_m": y0 - box.plate_height(sim),
            "coordination_number": coordination_number(sim), "wall_time_s": time.perf_counter() - t0,
            "box": box.to_dict(), "engine": sim.summary(),
        }  # fmt: skip
        if cpath is not None and jpath is not None:
            checkpoint.save(sim, cpath, extra={"stage": "consolidated", "normal_stress_kpa": self.sigma_kpa})
            write_json(jpath, info)
        return sim, info

    def shear(self, sim: Simulation, info: dict) -> dict:
        """Shear the consolidated specimen to ``max_displacement``; returns the test result."""
        stage = ShearStage(self, sim, info)
        wall = stage.run()
        result = self._result(stage.rows, info, stage.sim, wall)
        if self.out is not None:
            write_csv(self.out / "curve.csv", stage.rows, header=CURVE_COLUMNS)
            if self.figures and stage.peak.frame is not None:
                self._figure(stage.peak.frame, result)
            write_json(self.out / "result.json", result)
            stage.remove_files()
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

    def _result(self, rows: list[dict], info: dict, sim: Simulation, wall: float) -> dict:
        """The test's ``result.json``: what the curve says, and how it was obtained."""
        s = self.settings
        rho = float(np.mean(sim.particles.density)) * sim.density_scale
        result = curve_summary(rows, self.sigma_kpa, s)
        result.update({
            "inertial_number_at_target_stress": inertial_number(
                s.velocity, self.sigma_kpa * 1e3, rho, s.shear_zone_factor
            ),
            "consolidation": {k: v for k, v in info.items() if k != "engine"},
            "velocity_m_per_s": s.velocity,
            "density_scale": sim.density_scale,
            "local_damping": sim.local_damping,
            "dt_s": sim.dt,
            "d_mean_m": float(2.0 * np.mean(sim.particles.radius)),
            "shear_steps": int(rows[-1]["step"]) if rows else 0,
            "records": len(rows),
            "wall_time_shear_s": wall,
            "wall_time_s": wall + float(info.get("wall_time_s", 0.0)),
            "settings": s.to_dict(),
            "specimen": str(self.specimen),
            "engine": sim.summary(),
            "provenance": provenance(),
        })  # fmt: skip
        return result

    def run(self) -> dict:
        """Consolidate (or reuse the consolidated state), shear, write and return the result."""
        if self.out is not None:
            self.check_reusable()  # before a stored result is trusted
            done = self.out / "result.json"
            if done.is_file():
                return json.loads(done.read_text())
            self.bind()
        sim, info = self.consolidate()
        return self.shear(sim, info)


__all__ = ["DirectShearTest", "ProgressFn"]
