"""The criterion of the paper's Fig. 3, as a protocol that drives the engine.

For a trial 2D porosity n2D (Eq. 12 of the paper unless given):

1. prepare a specimen at n2D by multilayer compaction; the top plate sits at H;
2. measure the top-plate force F_top; accept at once when 0 < F_top < 1 % of the
   self weight G = rho_s (1 - n2D) W H g;
3. otherwise servo the top plate (down when F_top = 0, up when it is too large)
   until the condition holds at equilibrium (:class:`~poro2d.criterion.servo.PlateServo`),
   and compute the porosity n' of the new box; accept n2D when |n' - n2D| < 0.005;
4. else start again from 1 with n' rounded to the porosity resolution (0.01).

Every trial is written to its own folder as it finishes, so an interrupted run
resumes where it stopped; a run that does not converge stops with a clear
message and keeps every trial's results.

A trial is only accepted when, besides the paper's condition, its specimen passes
the checks of :func:`specimen_checks` (every planned disk built and inside the box,
the porosity after generation equal to the trial porosity, the vertical forces in
balance). A trial whose preparation or plate stage did not reach equilibrium, or
whose specimen fails a check, is refused and ends the run with the reason.
"""

from __future__ import annotations

import logging
import math
import time
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from poro2d.config import check_finite
from poro2d.criterion.lid import (
    SegmentedLid,
    fill_porosity,
    flat_top,
    lid_force,
    lid_indices,
    lid_numbers,
    lid_profile,
    lid_window_note,
)
from poro2d.criterion.result import CriterionResult
from poro2d.criterion.servo import PlateServo, in_window
from poro2d.dem import Simulation, checkpoint
from poro2d.errors import InputError, Integer, OneOf, Ranges, Real, check_fields, check_range
from poro2d.io_utils import as_json, provenance, write_csv, write_json
from poro2d.measure.disks import mass_d50
from poro2d.measure.porosity import box_porosity
from poro2d.measure.surface import lid_height_at
from poro2d.porosity import PAPER_N_LAB, parabolic
from poro2d.specimen.compaction import SpecimenSpec, preparation_note, prepare_specimen
from poro2d.specimen.grading import GradingCurve
from poro2d.store.stage import Fingerprint, ResumableStage

#: how a trial's specimen is judged full: "plate", the paper's rigid top plate (its n' includes
#: the gap under the plate); "fill", a segmented lid that rests on the grains over the width
#: (:mod:`poro2d.criterion.lid`; n' is the porosity of the box the specimen fills)
ACCEPTANCE_MODES = ("plate", "fill")

_log = logging.getLogger(__name__)


#: what each setting of :class:`CriterionSettings` may be (checked in this order);
#: ``refine_tolerance`` is checked against ``porosity_tolerance`` after these
CRITERION_RANGES: Ranges = {
    "n_lab": Real(0.0, 1.0, hi_open=True),
    "trial_porosity": Real(0.0, 1.0, lo_open=True, hi_open=True, or_none=True),
    "force_fraction": Real(0.0, 1.0, lo_open=True),
    "porosity_tolerance": Real(0.0, 0.1, lo_open=True),
    "resolution": Real(0.0, 0.1, lo_open=True),
    "max_iterations": Integer(1, 50),
    "servo_target_fraction": Real(0.0, 1.0, lo_open=True, hi_open=True),
    "servo_max_speed": Real(0.0, 10.0, lo_open=True),
    "servo_gain": Real(0.0, 1.0, lo_open=True),
    "settle_gain": Real(0.0, 1.0, lo_open=True),
    "settle_max_speed": Real(0.0, 10.0, lo_open=True),
    "plate_drift": Real(0.0, 0.1, lo_open=True),
    "settle_checks": Integer(2),
    "max_plate_steps": Integer(1000),
    "check_every": Integer(1),
    "window_checks": Integer(1),
    "generation_tolerance": Real(0.0, 0.05, lo_open=True),
    "balance_tolerance": Real(0.0, 0.5, lo_open=True),
    "acceptance": OneOf(ACCEPTANCE_MODES),
}


@dataclass
class CriterionSettings:
    """Thresholds of Fig. 3 (the paper's values by default) and the plate servo."""

    n_lab: float = PAPER_N_LAB
    trial_porosity: float | None = None
    force_fraction: float = 0.01
    porosity_tolerance: float = 0.005
    resolution: float = 0.01
    max_iterations: int = 6
    servo_target_fraction: float = 0.5
    servo_max_speed: float = 0.05
    servo_gain: float = 0.3
    settle_gain: float = 0.02
    settle_max_speed: float = 0.001
    settle_checks: int = 20
    plate_drift: float = 1e-4
    max_plate_steps: int = 600_000
    check_every: int = 500
    window_checks: int = 4
    generation_tolerance: float = 1e-3
    balance_tolerance: float = 0.01
    refine_tolerance: float | None = None
    acceptance: str = "plate"

    def __post_init__(self) -> None:
        check_fields(self, CRITERION_RANGES)
        if self.refine_tolerance is not None:
            check_range("refine_tolerance", self.refine_tolerance, 1e-4, self.porosity_tolerance)

    @property
    def tolerance(self) -> float:
        """|n' - n2D| below this accepts a trial: the paper's 0.005, or ``refine_tolerance``."""
        return self.porosity_tolerance if self.refine_tolerance is None else self.refine_tolerance

    def to_record(self) -> dict:
        """The settings as recorded with results; ``refine_tolerance`` only when set.

        Left out while unset (and ``acceptance`` while "plate"), so folders written before
        the options existed still resume.
        """
        d = asdict(self)
        if d["refine_tolerance"] is None:
            del d["refine_tolerance"]
        if d["acceptance"] == "plate":
            del d["acceptance"]
        return d

    def initial_trial(self) -> float:
        """Eq. 12 (n2D = 0.42 nLab^2 + 0.25 nLab), rounded to the resolution, unless given."""
        if self.trial_porosity is not None:
            return float(self.trial_porosity)
        return round_to(float(parabolic(self.n_lab)), self.resolution)


def round_to(x: float, step: float) -> float:
    return round(round(x / step) * step, 10)


def trial_grid(resolution: float, refine_tolerance: float | None) -> float:
    """The grid trials step on: the resolution (0.01), or half the refined tolerance."""
    return resolution if refine_tolerance is None else refine_tolerance / 2.0


def next_trial(rows: list[dict], s: CriterionSettings) -> float:
    """The next trial porosity after the trials ``rows`` (none accepted).

    The paper's rule: n' rounded to the resolution (0.01), one resolution towards n' when
    rounding falls back on the trial. With ``refine_tolerance``, n' rounded to half that
    tolerance; once two trials bracket the fixed point (one whose plate settled looser than
    the trial, n' > n2D, and one denser), a trial outside the bracket or already tried is
    replaced by the bracket's midpoint: bisection, which converges where the paper's rule
    can cycle between two values a resolution apart.
    """
    row = rows[-1]
    n, new = row["trial_porosity"], row["new_porosity"]
    if s.refine_tolerance is None:
        nxt = round_to(new, s.resolution)
        if nxt == n:  # rounding fell back: step one resolution towards n'
            nxt = round_to(n + math.copysign(s.resolution, new - n), s.resolution)
        return nxt
    step = trial_grid(s.resolution, s.refine_tolerance)
    nxt = round_to(new, step)
    if nxt == n:
        nxt = round_to(n + math.copysign(step, new - n), step)
    lo = max((r["trial_porosity"] for r in rows if r["new_porosity"] > r["trial_porosity"]), default=None)
    hi = min((r["trial_porosity"] for r in rows if r["new_porosity"] < r["trial_porosity"]), default=None)
    tried = {r["trial_porosity"] for r in rows}
    if lo is not None and hi is not None and lo < hi and (not lo < nxt < hi or nxt in tried):
        nxt = round_to(0.5 * (lo + hi), step / 2.0)
    return nxt


def wall_forces(sim: Simulation) -> dict:
    """Top, bottom and side wall forces per metre of thickness (N/m).

    ``f_top`` is the upward push of the disks on the top plate (and lid), ``f_bottom`` the
    downward push on the bottom wall, ``side_friction_up`` the upward friction of
    the side walls on the disks (what the side walls carry of the weight).
    """
    t = sim.particles.thickness
    top = sim.wall_force("top") / t
    if lid_indices(sim):  # the fill acceptance's lid carries what the parked plate does not
        top = top + np.array([0.0, lid_force(sim) / t])
    bottom = sim.wall_force("bottom") / t
    left = sim.wall_force("left") / t
    right = sim.wall_force("right") / t
    return {
        "f_top_n_per_m": float(top[1]),
        "f_bottom_n_per_m": float(-bottom[1]),
        "side_friction_up_n_per_m": float(-(left[1] + right[1])),
        "f_left_n_per_m": float(-left[0]),
        "f_right_n_per_m": float(right[0]),
    }


# A disk counts as inside the box while it presses into a wall by less than this
# fraction of its radius: contact overlaps under the self-weight and plate forces
# of the paper's stiffnesses are well below 1 % of a radius.
WALL_OVERLAP_FRACTION = 0.05

# checks that say the specimen itself is broken: a trial failing one is refused
# (no n' can be trusted from it) and the run stops
INTEGRITY_CHECKS = (
    "preparation_converged",
    "all_disks_present",
    "disks_inside_box",
    "porosity_after_generation",
)


def specimen_checks(
    sim: Simulation,
    spec: SpecimenSpec,
    prep: dict,
    trial: float,
    plate_height: float,
    forces: dict,
    settings: CriterionSettings,
) -> tuple[dict, dict]:
    """The checks a trial must pass to be accepted: (booleans, the numbers behind them).

    * ``preparation_converged``: every layer and the working-friction stage reached
      equilibrium (with the fallback of :func:`poro2d.specimen.compaction.equilibrate`);
    * ``all_disks_present``: as many disks as drawn for the trial porosity;
    * ``disks_inside_box``: every disk between the side walls, above the bottom and
      below the top plate (at ``plate_height``), pressing into a wall by less than
      ``WALL_OVERLAP_FRACTION`` of its radius;
    * ``porosity_after_generation``: the porosity of the built specimen, 1 - (area of
      its disks) / (W H) with whole disks and overlaps not subtracted (as PFC measures),
      is the trial porosity within ``generation_tolerance``: every disk drawn for the
      trial is in, at its drawn size. The porosity with disks clipped by the box
      (``porosity_after_generation_clipped``) is recorded beside it: it is higher by the
      area the disks press into the walls, which grows with the plate force (a dense
      trial of a frictional preparation pushes hard) and with the box's perimeter over
      its area; ``disks_inside_box`` bounds that penetration instead;
    * ``force_balance``: on the state the decision is taken on, F_bottom + side
      friction = weight + F_top within ``balance_tolerance`` of the right-hand side.
      Signs: F_bottom > 0 when the disks push the bottom wall down, side friction > 0
      when the side walls hold the disks up, F_top > 0 when the disks push the top
      plate up; the weight is sum(m) g / t from the disks' masses. With local damping,
      a specimen that still moves does not balance: damping forces carry the rest.
    """
    p = sim.particles
    x, y, r = p.pos[:, 0], p.pos[:, 1], p.radius
    slack = WALL_OVERLAP_FRACTION * r
    outside = (
        (x - r < -slack) | (x + r > spec.width + slack) | (y - r < -slack) | (y + r > plate_height + slack)
    )
    weight = float(np.sum(p.mass)) * spec.gravity / p.thickness
    rhs = weight + forces["f_top_n_per_m"]
    lhs = forces["f_bottom_n_per_m"] + forces["side_friction_up_n_per_m"]
    balance_error = abs(lhs - rhs) / rhs if rhs > 0.0 else math.inf
    built = 1.0 - float(np.sum(np.pi * r * r)) / (spec.width * spec.height)
    generation_error = abs(built - trial)
    numbers = {
        "planned_particle_count": int(prep["planned_count"]),
        "disks_outside_box": int(np.count_nonzero(outside)),
        "porosity_after_generation": built,
        "porosity_after_generation_clipped": float(prep["measured_porosity"]),
        "generation_porosity_error": float(generation_error),
        "weight_from_masses_n_per_m": weight,
        "force_balance_error": float(balance_error),
    }
    checks = {
        "preparation_converged": bool(prep["converged"]),
        "all_disks_present": bool(p.n == prep["planned_count"]),
        "disks_inside_box": bool(not outside.any()),
        "porosity_after_generation": bool(generation_error <= settings.generation_tolerance),
        "force_balance": bool(balance_error <= settings.balance_tolerance),
    }
    return checks, numbers


#: the measures of a trial's decision state that its row carries (see :func:`porosity_numbers`)
POROSITY_KEYS = (
    "box_porosity", "interior_porosity", "interior_porosity_std", "interior_regions",
    "laguerre_interior_porosity", "surface_gap_mean_d50", "plate_contact_fraction",
)  # fmt: skip


def porosity_numbers(
    sim: Simulation, width: float, plate_y: float, lid: tuple[np.ndarray, np.ndarray] | None = None
) -> dict:
    """The specimen's porosities beside the paper's n' (:mod:`poro2d.measure.specimen_porosity`).

    ``box_porosity`` is the paper's: W x plate height, the gap under the plate included;
    ``interior_porosity`` (mean over measurement circles 2 d50 clear of every wall and of the
    free surface, with its spread) is the packing's own. A specimen too small to measure
    gets ``interior_porosity = None`` and the reason in ``interior_porosity_note``. With a
    ``lid`` (edges, heights), the box porosity and the gap are those under the lid.
    """
    from poro2d.measure.specimen_porosity import measure_specimen

    p = sim.particles
    try:
        m = measure_specimen(p.pos, p.radius, width, plate_y, lid=lid).to_dict()
    except (InputError, RuntimeError) as e:  # too small to measure; a degenerate tessellation
        return {"box_porosity": box_porosity(p.area(), width, plate_y), "interior_porosity": None,
                "interior_porosity_note": str(e)}  # fmt: skip
    return {k: m[k] for k in POROSITY_KEYS}


def _check_reason(name: str, row: dict, settings: CriterionSettings) -> str:
    """One line on why check ``name`` failed, with its numbers."""
    if name == "preparation_converged":
        return (
            f"{row['failed_stage']} did not reach equilibrium: {row.get('equilibrium', 'max')} "
            f"unbalanced-force ratio {row.get('failed_ratio', row['failed_max_ratio']):.3g} "
            f"after {row['failed_steps']} steps (fallback included)"
        )
    if name == "all_disks_present":
        return f"{row['particle_count']} disks built of {row['planned_particle_count']} planned"
    if name == "disks_inside_box":
        return f"{row['disks_outside_box']} disk(s) outside the box"
    if name == "porosity_after_generation":
        return (
            f"porosity after generation {row['porosity_after_generation']:.4f} differs from the trial "
            f"by {row['generation_porosity_error']:.2g} > {settings.generation_tolerance:g}"
        )
    return (
        f"vertical forces out of balance by {100 * row['force_balance_error']:.2f} % "
        f"> {100 * settings.balance_tolerance:g} % (F_bottom + side friction vs weight + F_top)"
    )


def overfull_note(overfull_m: float) -> str:
    """What a trial's reason says of an over-full box (the trial denser than its layers fit in H)."""
    return (
        f"over-full box: at this trial porosity the layers did not fit below H, the specimen stood "
        f"{1000.0 * overfull_m:.3g} mm above H and the plate started there"
    )


class PorosityCriterion:
    """Run Fig. 3 for one grading and laboratory porosity, writing results to ``out``.

    ``on_stage(name)`` (optional) is called as each stage starts, for progress display.
    """

    def __init__(
        self,
        spec: SpecimenSpec,
        grading: GradingCurve,
        settings: CriterionSettings,
        seed: int = 0,
        out: str | Path | None = None,
        progress: bool = False,
        config: dict | None = None,
        figures: bool = True,
    ) -> None:
        self.spec = spec
        self.grading = grading
        self.settings = settings
        self.seed = int(seed)
        self.out = Path(out) if out is not None else None
        self.progress = progress
        self.config = config or {}
        self.figures = figures
        self.timings: dict[str, float] = {}
        self._stage: ResumableStage | None = None

    # ------------------------------------------------------------------ stages
    def stage(self) -> ResumableStage:
        """The run's stages in ``out``: ``config.json`` binds it to the config and seed.

        The binding leaves out the specimen's fields marked as not changing results
        (:mod:`poro2d.identity`: a rerun on another thread count resumes). A folder whose
        trials lack that record (it was deleted) is adopted: its finished trials are read back, the rest run.
        """
        assert self.out is not None
        if self._stage is None:
            record = self._config_record()
            self._stage = ResumableStage(
                self.out,
                Fingerprint(record["run"], tables={"specimen": SpecimenSpec}),
                record="config.json",
                extra={"config": record["config"], "provenance": record["provenance"]},
                parameter="out",
                allowed="an empty folder or one holding a run of the same config and seed",
                explain=_other_config,
                unrecorded="adopt",
            )
        return self._stage

    def _trial_name(self, k: int, n: float) -> str:
        """Trial ``k``'s folder, relative to ``out`` (``trials/02_n0.2300``)."""
        return f"trials/{k:02d}_n{n:.4f}"

    def _trial_dir(self, k: int, n: float) -> Path | None:
        if self.out is None:
            return None
        return self.out / self._trial_name(k, n)

    def _prepare(self, k: int, n: float) -> tuple[Simulation, dict]:
        """Trial ``k``'s specimen and its preparation report: built, or read back once saved."""
        d = self._trial_dir(k, n)
        if d is None:
            return self._build(n)
        npz = d / "prepared.npz"
        built: list[Simulation] = []

        def compute() -> dict:
            sim, rep = self._build(n)
            d.mkdir(parents=True, exist_ok=True)
            checkpoint.save(sim, npz, extra={"stage": "prepared", "trial_porosity": n})
            if self.figures:
                self._figure(sim, d / "forces_trial.png", f"trial n2D = {n:.3f}, top plate at H", rep)
            built.append(sim)
            return rep

        marker = f"{self._trial_name(k, n)}/prepared.json"
        rep = self.stage().run(compute, marker, accept=lambda _: npz.is_file())
        return (built[0] if built else checkpoint.load(npz, threads=self.spec.threads)), rep

    def _build(self, n: float) -> tuple[Simulation, dict]:
        """A specimen at trial porosity ``n``, with its report (seed, time, weight, wall forces)."""
        t0 = time.perf_counter()
        # the same seed per trial porosity: a rerun of a trial rebuilds the same specimen
        seed = self.seed * 1_000_003 + int(round(n * 1e6))
        sim, rep = prepare_specimen(self.spec, self.grading, n, seed, progress=self.progress)
        rep["seed"] = seed
        rep["time_s"] = time.perf_counter() - t0
        rep["weight_n_per_m"] = self.spec.self_weight(n)
        rep.update(wall_forces(sim))
        return sim, rep

    def _figure(self, sim: Simulation, path: Path, title: str, forces: dict) -> None:
        from poro2d.report.force_chains import plot_simulation_force_chains

        lid = self._lid(sim)
        plate = float(sim.walls.p0[sim.walls.index("top"), 1]) if lid is None else float(lid[1].max())
        plot_simulation_force_chains(
            sim, path, title=title, box=(0.0, 0.0, self.spec.width, plate),
            notes=[
                f"F_top = {forces['f_top_n_per_m']:.4g} N/m",
                f"F_bottom = {forces['f_bottom_n_per_m']:.4g} N/m",
                f"G = {forces.get('weight_n_per_m', float('nan')):.4g} N/m",
            ],
        )  # fmt: skip

    def plate_servo(self) -> PlateServo:
        """The plate (and lid) servo of step 3, with this run's settings and equilibrium."""
        sp = self.spec
        return PlateServo(self.settings, sp.ratio, sp.equilibrium, sp.height, progress=self.progress)

    def _trial(self, k: int, n: float) -> dict:
        """Trial ``k`` at porosity ``n``: its row, read back from its ``trial.json`` once written."""
        if self.out is None:
            return as_json(self._run_trial(k, n))
        return self.stage().run(lambda: self._run_trial(k, n), f"{self._trial_name(k, n)}/trial.json")

    def _run_trial(self, k: int, n: float) -> dict:
        """Prepare the specimen, move the plate when F_top is out of the window, check, decide."""
        d = self._trial_dir(k, n)
        s = self.settings
        t0 = time.perf_counter()
        sim, prep = self._prepare(k, n)
        t_prep = prep.get("time_s", time.perf_counter() - t0)
        weight = self.spec.self_weight(n)
        forces0 = wall_forces(sim)
        f_top = forces0["f_top_n_per_m"]
        row: dict = {
            "iteration": k,
            "trial_porosity": n,
            "particle_count": prep["particle_count"],
            "planned_particle_count": prep["planned_count"],
            "measured_porosity_after_generation": prep["measured_porosity"],
            "f_top_n_per_m": f_top,
            "f_bottom_n_per_m": forces0["f_bottom_n_per_m"],
            "side_friction_up_n_per_m": forces0["side_friction_up_n_per_m"],
            "self_weight_n_per_m": weight,
            "force_limit_n_per_m": s.force_fraction * weight,
            "preparation_converged": prep["converged"],
            "converged": True,
        }
        overfull = float(prep.get("overfull_m") or 0.0)
        if overfull > 0.0:  # recorded only when it happens: ordinary rows keep their keys
            row["overfull_m"] = overfull
        t1 = time.perf_counter()
        top = sim.walls.index("top")
        if not prep["converged"]:
            # a half-built specimen: no plate stage, no n'; refused below
            row.update(plate_moved="not run", plate_displacement_m=0.0, new_porosity=None)
            row.update(
                converged=False, failed_stage=prep["failed_stage"],
                failed_max_ratio=prep["failed_max_ratio"], failed_steps=prep["failed_steps"],
                failed_ratio=prep.get("failed_ratio", prep["failed_max_ratio"]),
                equilibrium=self.spec.equilibrium,
            )  # fmt: skip
            after = forces0
        elif s.acceptance == "plate" and overfull == 0.0 and in_window(f_top, weight, s.force_fraction):
            # an over-full box has its plate above H: n' is measured where the plate settles
            row.update(plate_moved="no", plate_displacement_m=0.0, new_porosity=n, plate_settled=True)
            after = forces0
        else:
            after = self._top_stage(sim, n, weight, row, d)
        row["f_top_after_n_per_m"] = after["f_top_n_per_m"]
        row["f_bottom_after_n_per_m"] = after["f_bottom_n_per_m"]
        row["side_friction_up_after_n_per_m"] = after["side_friction_up_n_per_m"]
        row["porosity_change"] = None if row["new_porosity"] is None else abs(row["new_porosity"] - n)
        checks, numbers = specimen_checks(sim, self.spec, prep, n, self._top_at_disks(sim), after, s)
        row.update(numbers)
        if row["converged"]:
            row.update(porosity_numbers(sim, self.spec.width, float(sim.walls.p0[top, 1]), self._lid(sim)))
        # the plate stage is part of the record: False when it did not settle or never ran
        checks = {"preparation_converged": checks.pop("preparation_converged"),
                  "plate_settled": bool(row.get("plate_settled", False)), **checks}  # fmt: skip
        row["checks"] = checks
        self._decide(row)
        row["time_prepare_s"] = t_prep
        row["time_plate_s"] = time.perf_counter() - t1
        return row

    def _top_stage(self, sim: Simulation, n: float, weight: float, row: dict, d: Path | None) -> dict:
        """Move the plate (or rest the lid) until the force window holds; returns the wall forces.

        Paper acceptance: the plate moves down when F_top = 0 and up when it is too large,
        and n' is the box porosity under it. Fill acceptance: the lid replaces the plate
        and n' is the porosity of the area under it (:func:`~poro2d.criterion.lid.fill_porosity`).
        """
        f_top = row["f_top_n_per_m"]
        servo = self.plate_servo()
        if self.settings.acceptance == "fill":
            row["plate_moved"] = "lid"
            if not in_window(f_top, weight, self.settings.force_fraction):
                # the plate first takes the specimen to the window (a dense trial pushes hard
                # and swells for long): the lid then only has the surface left to follow
                plate = servo.settle(sim, weight)
                if not plate["plate_settled"]:
                    row.update(plate)
                    row["new_porosity"] = box_porosity(
                        sim.particles.area(), self.spec.width, row["plate_height_m"]
                    )
                    return self._after_top(sim, weight, row, d)
            lid = SegmentedLid(sim, self.spec.width, mass_d50(sim.particles.radius))
            row.update(servo.settle(sim, weight, lid))
            profile = lid_profile(sim, self.spec.width)
            row["new_porosity"] = fill_porosity(sim.particles.radius, profile)
            row.update(lid_numbers(sim, profile, servo.target(sim, weight)))
            row["lid_note"] = lid_window_note(sim, profile, row["force_limit_n_per_m"])
        else:
            row["plate_moved"] = "down" if f_top <= 0.0 else "up"
            row.update(servo.settle(sim, weight))
            row["new_porosity"] = box_porosity(sim.particles.area(), self.spec.width, row["plate_height_m"])
        return self._after_top(sim, weight, row, d)

    def _after_top(self, sim: Simulation, weight: float, row: dict, d: Path | None) -> dict:
        """Save the state after the plate or lid stage, and mark a stage that did not settle."""
        after = wall_forces(sim)
        if d is not None:
            checkpoint.save(sim, d / "after_plate.npz", extra={"stage": "after_plate"})
            if self.figures:
                after_fig = dict(after, weight_n_per_m=weight)
                what = (
                    "resting the lid"
                    if row["plate_moved"] == "lid"
                    else f"moving the top plate {row['plate_moved']}"
                )
                self._figure(
                    sim,
                    d / "forces_after_plate.png",
                    f"after {what}: n' = {row['new_porosity']:.4f}",
                    after_fig,
                )
        if not row["plate_settled"]:
            row.update(
                converged=False, failed_stage="top plate",
                failed_max_ratio=row["plate_final_max_ratio"], failed_steps=row["plate_steps"],
            )  # fmt: skip
        return after

    def _lid(self, sim: Simulation) -> tuple[np.ndarray, np.ndarray] | None:
        """The lid's (edges, heights) when the trial rested one, else None."""
        if not lid_indices(sim):
            return None
        profile = lid_profile(sim, self.spec.width)
        return profile.edges, profile.heights

    def _top_at_disks(self, sim: Simulation) -> float | np.ndarray:
        """The height of the plate, or of the lid above each disk, for the in-box check."""
        lid = self._lid(sim)
        if lid is None:
            return float(sim.walls.p0[sim.walls.index("top"), 1])
        return lid_height_at(lid[0], lid[1], sim.particles.pos[:, 0])

    def _decide(self, row: dict) -> None:
        """Accept, reject or refuse a trial; records ``accepted``, ``refused``, ``failed_check``, ``reason``.

        Accepted: the paper's condition (the plate settled with 0 < F_top < 1 % G and
        |n' - n2D| below the tolerance) and every check passed. Refused (the run stops):
        a stage that did not reach equilibrium, a broken specimen (an integrity check
        failed), or the paper's condition met while a check failed.
        """
        s = self.settings
        checks = row["checks"]
        failed = next((c for c, ok in checks.items() if not ok), "")
        condition = bool(
            row["converged"] and bool(row.get("plate_settled", False))
            and row["porosity_change"] < s.tolerance
        )  # fmt: skip
        row["condition_met"] = condition
        row["failed_check"] = failed
        row["accepted"] = condition and not failed
        if not row["converged"]:
            if row["failed_stage"] == "top plate":
                what = "lid" if row.get("plate_moved") == "lid" else "top plate"
                row["reason"] = (
                    f"the {what} did not settle within {s.max_plate_steps} steps: F_top "
                    f"{row['f_top_after_n_per_m']:.4g} N/m, window (0, {row['force_limit_n_per_m']:.4g}), "
                    f"max unbalanced-force ratio {row['failed_max_ratio']:.3g} when held"
                ) + row.get("lid_note", "")
            else:
                row["reason"] = _check_reason("preparation_converged", row, s)
            row["refused"] = True
        elif failed:
            row["reason"] = f"check {failed} failed: {_check_reason(failed, row, s)}"
            row["refused"] = condition or failed in INTEGRITY_CHECKS
        else:
            row["refused"] = False
            row["reason"] = (
                "0 < F_top < limit with the plate settled, |n' - n2D| below the tolerance, all checks passed"
                if condition
                else f"|n' - n2D| = {row['porosity_change']:.4f} >= {s.tolerance:g}"
            )
        if row.get("overfull_m"):
            row["reason"] += "; " + overfull_note(row["overfull_m"])

    # -------------------------------------------------------------------- loop
    def run(self) -> CriterionResult:
        """Run Fig. 3, or read a finished run back from ``out/result.json``.

        Every input is checked first (:meth:`validate`), then ``out`` (:meth:`stage`): a
        folder holding a run of another config is refused before anything is written.
        """
        self.validate()
        if self.out is None:
            return CriterionResult.from_dict(as_json(self._search()))
        return self.stage().run(self._search, decode=CriterionResult.from_dict)

    def _search(self) -> CriterionResult:
        """The loop of Fig. 3: trials until one is accepted or refused, or the trials run out."""
        s = self.settings
        t_start = time.perf_counter()
        n = s.initial_trial()
        note = preparation_note(self.spec, self.grading)
        if note:
            _log.warning("preparation: %s", note)
        rows: list[dict] = []
        tried: list[float] = []
        accepted: dict | None = None
        failed_trial = None
        message = ""
        for k in range(1, s.max_iterations + 1):
            tried.append(n)
            # as a resumed run reads it back from trial.json: plain booleans and numbers
            row = as_json(self._trial(k, n))
            rows.append(row)
            self._write_table(rows)
            if row["accepted"]:
                accepted = row
                message = f"accepted n2D = {n:.4f} after {k} trial(s)"
                break
            if row["refused"]:
                failed_trial = k
                message = f"trial {k} (n2D = {n:.4f}) refused: {row['reason']}"
                break
            nxt = next_trial(rows, s)
            if nxt in tried:
                accepted = self._closed_bracket(rows)
                if accepted is not None:
                    self._write_table(rows)
                    message = (
                        f"accepted n2D = {accepted['trial_porosity']:.4f} after {k} trial(s), "
                        "when the bracket closed (docs/criterion.md)"
                    )
                    break
                message = (
                    f"no convergence: trial {nxt:.4f} was already tried (trials {tried}); "
                    "try a finer resolution or a larger tolerance"
                )
                break
            n = nxt
        else:
            message = f"no convergence within max_iterations = {s.max_iterations} (trials {tried})"
        final = None if accepted is None else accepted["trial_porosity"]
        result = self._result(rows, final=final, converged=accepted is not None, message=message)
        result.failed_trial = failed_trial
        if accepted is not None:
            for key in CriterionResult.OPTIONAL:
                setattr(result, key, accepted.get(key))
        result.preparation_note = preparation_note(self.spec, self.grading)
        result.time_total_s = time.perf_counter() - t_start
        if self.out is not None:
            self._final_outputs(rows, accepted)
        return result

    def _closed_bracket(self, rows: list[dict]) -> dict | None:
        """The trial accepted when refinement can go no finer, or None.

        With ``refine_tolerance``, bisection proposes a trial already tried once two trials
        a grid step apart bracket the fixed point: one settled looser than its trial, the
        other denser. Each trial is a new random specimen, so n' scatters from specimen to
        specimen (about 0.003 on the paper's box); a tolerance below that scatter cannot be
        met by refining further. The trial then accepted is the one closest to its own n',
        if it meets the paper's tolerance (``porosity_tolerance``) and passed every check;
        its row says so (``accepted_at = "closed bracket"``).
        """
        s = self.settings
        if s.refine_tolerance is None:
            return None
        fit = [
            r for r in rows
            if r["converged"] and r.get("plate_settled") and not r["failed_check"]
            and r["porosity_change"] is not None and r["porosity_change"] < s.porosity_tolerance
        ]  # fmt: skip
        if not fit:
            return None
        best = min(fit, key=lambda r: r["porosity_change"])
        best.update(accepted=True, condition_met=True, accepted_at="closed bracket")
        best["reason"] = (
            f"the trials bracket the fixed point a grid step apart: |n' - n2D| = "
            f"{best['porosity_change']:.4f}, below the paper's {s.porosity_tolerance:g} (refining to "
            f"{s.refine_tolerance:g} cannot go finer than the specimens' scatter), all checks passed"
        )
        return best

    def validate(self) -> None:
        """Reject bad input before anything is written: a corrected rerun then starts clean.

        Checks what the dataclasses cannot check alone: the thread count against this
        machine, the first trial against the box and grading, and that every number of
        the config is finite.
        """
        from poro2d.specimen.compaction import check_feasible

        Simulation.check_threads(self.spec.threads)
        check_feasible(self.spec, self.grading, self.settings.initial_trial())
        record = self._config_record()
        check_finite("config", record["config"])
        check_finite("run", record["run"])

    def _config_record(self) -> dict:
        return {
            "run": {
                "specimen": self.spec.to_dict(),
                "grading": {
                    "sizes_m": self.grading.sizes.tolist(),
                    "percent_passing": self.grading.percent.tolist(),
                    "source": getattr(self.grading, "source", ""),
                },
                "criterion": self.settings.to_record(),
                "seed": self.seed,
            },
            "config": self.config,
            "provenance": provenance(),
        }

    def _result(self, rows: list[dict], final, converged: bool, message: str) -> CriterionResult:
        return CriterionResult(
            final_porosity=final,
            converged=converged,
            message=message,
            n_lab=self.settings.n_lab,
            initial_trial_porosity=self.settings.initial_trial(),
            initial_from="given" if self.settings.trial_porosity is not None else "Eq. 12 (parabola)",
            iterations=rows,
            seed=self.seed,
            settings=self.settings.to_record(),
            specimen=self.spec.to_dict(),
            local_damping_note=f"local damping {self.spec.local_damping} (PFC 4.0 default; "
            "the paper does not state it)",
            provenance=provenance(),
        )

    def _write_table(self, rows: list[dict]) -> None:
        """``iterations.csv``: the trials so far, rewritten as each one finishes."""
        if self.out is not None:
            write_csv(self.out / "iterations.csv", [_flat(r) for r in rows])

    def _final_outputs(self, rows: list[dict], accepted: dict | None) -> None:
        """Copy the paper-style figures and the accepted specimen to the top of ``out``."""
        import shutil

        from poro2d.dem.export import write_vtu

        assert self.out is not None
        first = rows[0]
        d0 = self._trial_dir(first["iteration"], first["trial_porosity"])
        pairs = [(d0 / "forces_trial.png", "fig5_forces_initial_trial.png")]
        moved = next((r for r in rows if r.get("plate_moved") in ("up", "down", "lid")), None)
        if moved is not None:
            dm = self._trial_dir(moved["iteration"], moved["trial_porosity"])
            pairs.append((dm / "forces_after_plate.png", "fig6_forces_after_plate.png"))
        if accepted is not None:
            last = accepted
            dl = self._trial_dir(last["iteration"], last["trial_porosity"])
            # the accepted specimen is the state the decision was taken on: after the plate
            # moved to touch (when it moved), else as prepared with the plate at H
            moved_last = (
                last.get("plate_moved") in ("up", "down", "lid") and (dl / "after_plate.npz").is_file()
            )
            state = "after_plate" if moved_last else "prepared"
            figure = "forces_after_plate.png" if moved_last else "forces_trial.png"
            pairs.append((dl / figure, "fig7_forces_accepted.png"))
            sim = checkpoint.load(dl / f"{state}.npz")
            lid = self._lid(sim)
            if lid is None:
                shutil.copyfile(dl / f"{state}.npz", self.out / ".specimen.npz.tmp")
                (self.out / ".specimen.npz.tmp").replace(self.out / "specimen.npz")
            else:  # what leaves is a box of four walls (lid.flat_top); the lid is measured here
                checkpoint.save(flat_top(sim, self.spec.width), self.out / "specimen.npz",
                                extra={"stage": "accepted", "lid_heights_m": lid[1].tolist()})  # fmt: skip
            write_vtu(sim, self.out / "vtu", "accepted_specimen")
            self._specimen_state(sim, last["trial_porosity"])
        for src, dst in pairs:
            if src.is_file():
                shutil.copyfile(src, self.out / dst)

    def _specimen_state(self, sim: Simulation, n2d: float) -> None:
        """Homogeneity and stress state of the accepted specimen: specimen_state.json and .png."""
        from poro2d.measure.specimen_state import specimen_state
        from poro2d.report.specimen_figures import plot_specimen_state

        assert self.out is not None
        lid = self._lid(sim)
        top = float(sim.walls.p0[sim.walls.index("top"), 1]) if lid is None else float(lid[1].max())
        state = specimen_state(sim, self.spec.width, top)
        write_json(self.out / "specimen_state.json", dict(state, trial_porosity=n2d))
        if self.figures:
            title = f"accepted specimen, n2D = {n2d:.3f}: bands of equal height"
            plot_specimen_state(state, self.out / "specimen_state.png", title=title)
        self._specimen_porosity(sim, n2d, top)

    def _specimen_porosity(self, sim: Simulation, n2d: float, top: float) -> None:
        """The accepted specimen's porosities: specimen_porosity.json and the local porosity map."""
        from poro2d.measure.specimen_porosity import measure_specimen
        from poro2d.report.specimen_figures import plot_local_porosity

        assert self.out is not None
        p = sim.particles
        try:
            m = measure_specimen(p.pos, p.radius, self.spec.width, top, lid=self._lid(sim))
        except (InputError, RuntimeError) as e:
            write_json(self.out / "specimen_porosity.json", {"trial_porosity": n2d, "note": str(e),
                                                              "provenance": provenance()})  # fmt: skip
            return
        write_json(self.out / "specimen_porosity.json", dict(m.to_dict(), trial_porosity=n2d,
                                                            provenance=provenance()))  # fmt: skip
        if self.figures:
            title = f"accepted specimen, n2D = {n2d:.3f}: local porosity (Laguerre cells)"
            plot_local_porosity(p.pos, p.radius, self.spec.width, top, m, self.out / "local_porosity.png",
                                title=title)  # fmt: skip


def _other_config(keys: list[str] | None, stored) -> str:
    """Why a criterion folder is refused: the config keys in which its run differs."""
    return f"it holds results of a different config ({', '.join(keys or [])}); choose another --out"


def _flat(row: dict) -> dict:
    """A trial row for the CSV table: the ``checks`` dict as ``check_<name>`` columns."""
    out = {k: v for k, v in row.items() if k != "checks"}
    out.update({f"check_{k}": v for k, v in row.get("checks", {}).items()})
    return out


__all__ = [
    "CriterionResult", "CriterionSettings", "PorosityCriterion", "in_window", "round_to", "specimen_checks",
    "wall_forces",
]  # fmt: skip
