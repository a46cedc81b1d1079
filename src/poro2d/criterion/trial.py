"""One trial of Fig. 3 as a typed record made of its parts.

A trial is what its preparation built (``prepared.json``), the wall forces as prepared, its
plate (or lid) stage (:class:`PlateStage`), the stage that did not reach equilibrium if one
did not (:class:`StageFailure`), the wall forces after the plate stage, the checks and the
numbers behind them, the porosities of its decision state and the decision itself
(:class:`Decision`).

The files keep the row a trial always had: :meth:`Trial.to_dict` gives the keys of
``trial.json`` (and of a trial of ``result.json``) in their order, with the values as they
are read back (plain booleans and numbers, ``None`` for NaN); :meth:`Trial.flat` is its row
of ``iterations.csv``. :meth:`Trial.from_dict` reads any such row back, in the order its
file has it, keeping keys it does not model.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, fields
from typing import Any

from poro2d.criterion.lid import LidNumbers
from poro2d.criterion.measures import CheckNumbers, Checks, PorosityNumbers, WallForces
from poro2d.criterion.servo import PlateSettle
from poro2d.io_utils import as_json
from poro2d.record import Record, Spliced
from poro2d.specimen.compaction import PreparationReport
from poro2d.typed_result import TypedResult


def trial_name(k: int, n: float) -> str:
    """Trial ``k``'s folder in a criterion's store (``trials/02_n0.2300``)."""
    return f"trials/{k:02d}_n{n:.4f}"


@dataclass(frozen=True)
class StageFailure(Record):
    """A stage that did not reach equilibrium: the preparation's or the top plate's.

    ``ratio`` and ``equilibrium`` (the ratio measured and its measure) only for the preparation:
    the top plate's row stops after ``failed_steps``.
    """

    ROW = (("failed_stage", "stage"), ("failed_max_ratio", "max_ratio"), ("failed_steps", "steps"),
           ("failed_ratio", "ratio"), "equilibrium")  # fmt: skip

    stage: Any
    max_ratio: Any
    steps: Any
    ratio: Any = None
    equilibrium: Any = None

    def layout(self) -> tuple:
        return self.ROW if self.equilibrium is not None else self.ROW[:3]

    @classmethod
    def of_preparation(cls, report: PreparationReport, equilibrium: str) -> StageFailure:
        """The stage of a preparation that did not reach equilibrium (``equilibrium``: its measure)."""
        # a report of an older file lacks failed_ratio
        ratio = report.failed_ratio if "failed_ratio" in report.to_dict() else report.failed_max_ratio
        return cls(report.failed_stage, report.failed_max_ratio, report.failed_steps, ratio, equilibrium)

    @classmethod
    def from_row(cls, row: Mapping[str, Any]) -> StageFailure | None:
        if "failed_stage" not in row:
            return None
        return cls(row["failed_stage"], row.get("failed_max_ratio"), row.get("failed_steps"),
                   row.get("failed_ratio"), row.get("equilibrium"))  # fmt: skip


@dataclass(frozen=True)
class PlateStage(Record):
    """Step 3 of Fig. 3: how the top moved (``moved``: "no", "up", "down", "lid", "not run") and n'.

    ``servo``: the servo's record when the plate (or lid) moved; ``settled`` and
    ``displacement_m`` otherwise (a plate already in the window, or a stage not run);
    ``lid`` and ``lid_note``: the lid's numbers and a note on its window, under the fill
    acceptance. The row has two shapes: the servo's keys (``MOVED``), or the plate's
    displacement and whether it settled (``KEPT``).
    """

    MOVED = (("plate_moved", "moved"), Spliced("servo"), "new_porosity", Spliced("lid"), "lid_note")
    KEPT = (("plate_moved", "moved"), ("plate_displacement_m", "displacement_m"), "new_porosity",
            ("plate_settled", "settled"))  # fmt: skip
    OMITTED = {"plate_settled": None, "lid_note": None}

    moved: Any
    new_porosity: Any
    servo: PlateSettle | None = None
    settled: bool | None = None
    displacement_m: Any = 0.0
    lid: LidNumbers | None = None
    lid_note: str | None = None

    @property
    def is_settled(self) -> bool:
        """Whether the stage ended with the plate settled in the window (False when it never ran)."""
        return bool(self.servo.settled if self.servo is not None else self.settled)

    def layout(self) -> tuple:
        return self.KEPT if self.servo is None else self.MOVED

    @classmethod
    def from_row(cls, row: Mapping[str, Any]) -> PlateStage:
        servo = PlateSettle.from_row(row) if "plate_steps" in row else None
        return cls(
            row.get("plate_moved"), row.get("new_porosity"), servo,
            settled=None if servo is not None else row.get("plate_settled"),
            displacement_m=row.get("plate_displacement_m"), lid=LidNumbers.from_row(row),
            lid_note=row.get("lid_note"),
        )  # fmt: skip


@dataclass(frozen=True)
class Decision(Record):
    """Accepted, rejected or refused: the paper's condition, the first failed check and why.

    ``accepted_at`` is "closed bracket" for a trial accepted when refinement could go no finer
    (the trial writes it last). ``refused`` comes before ``reason`` for a trial that failed no
    check, after it otherwise (a trial whose stage did not reach equilibrium fails a check:
    ``preparation_converged`` or ``plate_settled``).
    """

    PASSED = ("condition_met", "failed_check", "accepted", "refused", "reason")
    FAILED = ("condition_met", "failed_check", "accepted", "reason", "refused")

    condition_met: bool
    failed_check: str
    accepted: bool
    refused: bool
    reason: str
    accepted_at: str | None = None

    def layout(self) -> tuple:
        return self.FAILED if self.failed_check else self.PASSED

    @classmethod
    def from_row(cls, row: Mapping[str, Any]) -> Decision:
        return cls(*(row.get(k) for k in DECISION_KEYS))


#: the keys of a row that the decision sets (its fields, in order)
DECISION_KEYS = ("condition_met", "failed_check", "accepted", "refused", "reason", "accepted_at")


@dataclass(eq=False)
class Trial(Record, TypedResult):
    """One trial of Fig. 3, made of its parts; its row (:meth:`to_dict`) is what files keep of it.

    ``ROW`` is the row a trial records, its parts in place: the counts, porosity and convergence
    of its preparation, the wall forces as prepared and after the plate stage under their own
    keys, ``overfull_m`` only when the box was over-full, ``balance_steps`` only for a specimen
    cycled further to balance, ``equilibrium_steps`` only for one cycled further to equilibrium
    after its preparation, ``accepted_at`` only for a trial accepted when the bracket closed, the
    density scaling's time step and disks only for a specimen whose masses were raised.
    A trial is the typed result of its file (``trial.json``), and so a part of the criterion's
    result; keys of a row read back that it does not model are kept in ``extra``.
    """

    ROW = (
        "iteration", "trial_porosity", "particle_count", "planned_particle_count",
        "measured_porosity_after_generation",
        ("f_top_n_per_m", "forces.f_top_n_per_m"), ("f_bottom_n_per_m", "forces.f_bottom_n_per_m"),
        ("side_friction_up_n_per_m", "forces.side_friction_up_n_per_m"),
        "self_weight_n_per_m", "force_limit_n_per_m", "preparation_converged", "converged", "overfull_m",
        Spliced("plate"), Spliced("failure"),
        ("f_top_after_n_per_m", "forces_after.f_top_n_per_m"),
        ("f_bottom_after_n_per_m", "forces_after.f_bottom_n_per_m"),
        ("side_friction_up_after_n_per_m", "forces_after.side_friction_up_n_per_m"),
        "porosity_change", Spliced("check_numbers"), Spliced("porosity"), "checks", "balance_steps",
        "equilibrium_steps",
        Spliced("decision"),
        "time_prepare_s", "time_plate_s", ("accepted_at", "decision.accepted_at"),
        "mass_scaling_dt_s", "mass_scaled_disks",
    )  # fmt: skip
    OMITTED = {
        "overfull_m": 0.0, "accepted_at": None, "balance_steps": None, "equilibrium_steps": None,
        "mass_scaling_dt_s": None, "mass_scaled_disks": None,
    }  # fmt: skip

    iteration: int
    trial_porosity: float
    particle_count: int
    planned_particle_count: int
    measured_porosity_after_generation: float
    forces: WallForces
    self_weight_n_per_m: float
    force_limit_n_per_m: float
    preparation_converged: bool
    converged: bool
    plate: PlateStage
    forces_after: WallForces
    porosity_change: float | None
    check_numbers: CheckNumbers
    checks: Checks
    decision: Decision
    overfull_m: float = 0.0
    failure: StageFailure | None = None
    porosity: PorosityNumbers | None = None
    #: the steps a specimen just out of balance was cycled further (None: it was not)
    balance_steps: int | None = None
    #: the steps a specimen just out of equilibrium when prepared was cycled further (None: it was not)
    equilibrium_steps: int | None = None
    time_prepare_s: float | None = None
    time_plate_s: float | None = None
    #: the time step the light disks' inertial masses were raised for in the specimen's
    #: quasi-static stages, and how many were (None: true masses; docs/density-scaling.md)
    mass_scaling_dt_s: float | None = None
    mass_scaled_disks: int | None = None
    #: the key order of a row read back
    order: tuple[str, ...] | None = field(default=None, repr=False)

    @property
    def new_porosity(self) -> float | None:
        """n': the porosity of the box after the plate stage (None when it never ran)."""
        return self.plate.new_porosity

    def to_dict(self) -> dict[str, Any]:
        """The trial's row as its file holds it (``trial.json``; a trial of ``result.json``)."""
        row = {**super().to_dict(), **self.extra}
        if self.order is not None:
            # a row read back keeps its file's keys in their order; of the keys its file lacks,
            # only what a decision taken since set (a closed bracket's acceptance) comes last
            gained = {k: row[k] for k in DECISION_KEYS if k not in self.order and row.get(k) is not None}
            row = {**{k: row[k] for k in self.order if k in row}, **gained}
        return as_json(row)

    def flat(self) -> dict[str, Any]:
        """The trial's row of ``iterations.csv``: the checks as ``check_<name>`` columns."""
        row = self.to_dict()
        checks = row.pop("checks", {})
        row.update({f"check_{k}": v for k, v in checks.items()})
        return row

    @classmethod
    def from_dict(cls, row: Mapping[str, Any]) -> Trial:
        """A trial from its row (``trial.json``, a trial of ``result.json``, or :meth:`to_dict`)."""
        # the row's own values: ROW's plain keys, but for the two read with a default or a type
        plain = {k: row.get(k) for k in cls.ROW if isinstance(k, str) and k not in ("overfull_m", "checks")}
        trial = cls(
            **plain,
            forces=WallForces.from_row(dict(row)),
            plate=PlateStage.from_row(row),
            forces_after=WallForces.from_row(dict(row), "_after"),
            check_numbers=CheckNumbers.from_dict(dict(row)),
            checks=Checks(**{f.name: (row.get("checks") or {}).get(f.name) for f in fields(Checks)}),
            decision=Decision.from_row(row),
            overfull_m=row.get("overfull_m") or 0.0,
            failure=StageFailure.from_row(row),
            porosity=PorosityNumbers.from_row(dict(row)),
        )
        modelled = Record.to_dict(trial)
        trial.extra = {k: v for k, v in row.items() if k not in modelled}
        checks = row.get("checks")
        if isinstance(checks, Mapping) and list(checks) != list(trial.checks.to_dict()):
            trial.extra["checks"] = checks  # checks this version does not know: kept as they were
        trial.order = tuple(row)
        return trial


__all__ = ["Decision", "PlateStage", "StageFailure", "Trial", "trial_name"]
