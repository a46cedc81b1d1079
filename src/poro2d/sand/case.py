"""A user's soil as one value: its laboratory description and how ``poro2d sand`` runs it.

A sand config is a criterion config (``[grading]``, ``[specimen]``, ``[criterion]``) with
three tables of its own::

    [soil]                 # who the soil is: printed and written with every result
    name = "Toyoura sand"
    reference = "Verdugo & Ishihara (1996)"
    [lab]                  # the laboratory description (poro2d.lab_state)
    e_max = 0.977          # or n_max / n_min
    e_min = 0.597
    dr = 0.5               # or e, n, or dry_density with solid_density
    [sand]                 # how to run it (all optional)
    seeds = 3              # specimens at full size
    replacements = 3       # seeds not accepted at full size replaced by the next ones, at most
    calibration_seeds = 2  # specimens per friction in the calibration
    calibration_disks = 1500
    mu_prep = [0.0, 0.05, 0.1, 0.2, 0.5, 1.0]

:func:`load_sand_case` turns it into a :class:`SandCase` once; nothing below reads the
TOML again.
"""

from __future__ import annotations

import copy
import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar

from poro2d.config import check_keys
from poro2d.criterion.density import DEFAULT_MUS, check_mus
from poro2d.critical_state.state_table import StateRequest, state_request
from poro2d.errors import InputError, check_int, check_range
from poro2d.grading import GradingCurve
from poro2d.lab_state import LabState, lab_state_from_table
from poro2d.specimen.compaction import SpecimenSpec, time_step
from poro2d.sweep.criterion_base import CriterionBase
from poro2d.sweep.density import DEFAULT_SEEDS, with_density_defaults
from poro2d.typed_result import TypedResult

#: the tables a sand config adds to a criterion config
SAND_TABLES = ("soil", "lab", "sand", "state")
SOIL_KEYS = {"name", "reference"}
SAND_KEYS = {"seeds", "replacements", "calibration_seeds", "calibration_disks", "mu_prep"}
#: disks in the calibration box unless ``[sand] calibration_disks`` says otherwise: the dense and
#: loose ends of the paper grading moved by less than their seed spread between this box and the
#: full one (docs/sand.md)
CALIBRATION_DISKS = 1500
#: specimens per friction in the calibration unless ``[sand] calibration_seeds`` says otherwise:
#: a third seed moved the friction by 0.0004 (Toyoura sand) and 0.0035 (the paper's sand), the
#: answer by under a tenth of its seed spread (docs/sand.md)
CALIBRATION_SEEDS = 2
#: seeds refused at full size replaced by the next unused ones, at most, unless ``[sand]
#: replacements`` says otherwise: a seed refused at a threshold is one sample of a chaotic
#: packing, and the answer is asked of ``seeds`` specimens
REPLACEMENTS = 3

ConfigLike = dict | str | os.PathLike


@dataclass(eq=False)
class SoilRecord(TypedResult):
    """The soil as every result file names it (``soil`` in ``preflight.json``, ``sand.json`` and
    each kept specimen's ``soil.json``): who it is, its ``[grading]`` table, the grading's source
    and up-scaling, and its laboratory description (:meth:`poro2d.lab_state.LabState.to_dict`)."""

    name: str
    reference: str
    grading: dict[str, Any]
    grading_source: str
    upscale: float
    lab: LabState

    #: the laboratory state, as its class reads it
    PARTS: ClassVar[dict[str, type]] = {"lab": LabState}


@dataclass(frozen=True)
class SandCase:
    """Everything ``poro2d sand`` needs, checked: the soil, its state, the specimens' config.

    ``config`` is the criterion config of the full-size specimens as a value (density mode's
    defaults filled in, ``criterion.n_lab`` the laboratory state), which the calibration and
    the specimens vary; ``base_dir`` the folder its relative paths start from; ``spec`` and
    ``grading`` are built from it.
    """

    name: str
    reference: str
    lab: LabState
    config: CriterionBase = field(repr=False)
    base_dir: Path | None
    spec: SpecimenSpec
    grading: GradingCurve
    seeds: int = DEFAULT_SEEDS
    calibration_disks: int = CALIBRATION_DISKS
    mus: tuple[float, ...] = DEFAULT_MUS
    calibration_seeds: int = CALIBRATION_SEEDS
    state: StateRequest | None = None
    #: the run time the pre-flight measures its estimate against (minutes; None: none)
    budget_minutes: float | None = None
    replacements: int = REPLACEMENTS

    @property
    def n_max(self) -> float:
        assert self.lab.n_max is not None
        return self.lab.n_max

    @property
    def n_min(self) -> float:
        assert self.lab.n_min is not None
        return self.lab.n_min

    def soil_record(self) -> SoilRecord:
        """The soil as every result file names it."""
        return SoilRecord(
            name=self.name,
            reference=self.reference,
            grading=self.config.table("grading"),
            grading_source=self.grading.source,
            upscale=self.grading.upscale,
            lab=self.lab,
        )


def _soil(table: dict) -> tuple[str, str]:
    check_keys("soil", table, SOIL_KEYS)
    for key in SOIL_KEYS:
        if key in table and not isinstance(table[key], str):
            raise InputError(f"soil.{key}", table[key], "a string")
    return table.get("name", "unnamed soil"), table.get("reference", "")


def _lab(table) -> LabState:
    if table is None:
        raise InputError(
            "lab",
            None,
            "a [lab] table: e_max and e_min (or n_max and n_min) and the state "
            "(e, n, dr, or dry_density with solid_density)",
        )
    if not isinstance(table, dict):
        raise InputError("lab", table, "a table of key = value pairs")
    lab = lab_state_from_table(table)
    if lab.n_max is None or lab.n_min is None:
        raise InputError(
            "lab.e_max/e_min",
            None,
            "both laboratory extremes (e_max and e_min, or n_max and n_min)",
            "the density-aware answer maps the state between them; without them use "
            "poro2d criterion (the paper's mode)",
        )
    return lab


def _criterion_config(cfg: dict, lab: LabState, base_dir: Path | None) -> CriterionBase:
    """The criterion config of the full-size specimens: the state's nLab, density mode's defaults.

    ``cfg``: the sand config as read (its criterion tables beside ``[soil]``, ``[lab]``, ``[sand]``).
    """
    if "density" in cfg:
        raise InputError(
            "density",
            cfg["density"],
            "no [density] table in a sand config",
            "the laboratory extremes go in [lab], seeds and frictions in [sand]",
        )
    crit = {k: copy.deepcopy(v) for k, v in cfg.items() if k not in SAND_TABLES}
    table = dict(crit.get("criterion") or {})
    given = table.get("n_lab")
    if given is not None and not math.isclose(
        check_range("criterion.n_lab", given, 0.0, 1.0, hi_open=True), lab.n_lab, abs_tol=5e-5
    ):
        raise InputError("criterion.n_lab", given, f"unset or the [lab] state's n = {lab.n_lab:.4f}")
    table["n_lab"] = round(lab.n_lab, 6)
    crit["criterion"] = table
    return with_density_defaults(CriterionBase(crit, base_dir))


#: step budgets (setting: the paper's default) that bound a stage in simulated time; they were
#: set for the paper grading's time step, so a grading whose finest disks set a smaller step gets
#: them in proportion (the lid of a frictional preparation on a fine sand did not settle within
#: 600 000 steps at 0.53 of the paper's step, i.e. half the simulated time)
STEP_BUDGETS = {
    ("criterion", "max_plate_steps"): 600_000,
    ("specimen", "max_steps_per_stage"): 400_000,
    ("specimen", "fallback_steps"): 200_000,
    ("specimen", "calm_steps"): 50_000,
}


def with_step_budgets(config: CriterionBase, spec: SpecimenSpec, grading: GradingCurve) -> CriterionBase:
    """``config`` with every step budget it leaves unset scaled to the grading's time step.

    The factor is the paper grading's step over this one's (at least 1): the same simulated
    time for the lid to settle and the layers to come to rest. The paper's grading keeps the
    defaults exactly.
    """
    from poro2d.grading import paper_grading

    slow = time_step(spec, paper_grading().d_min_m) / time_step(spec, grading.d_min_m)
    if slow <= 1.0 + 1e-9:
        return config
    tables = {name: config.table(name) for name in dict.fromkeys(table for table, _ in STEP_BUDGETS)}
    for (table, key), default in STEP_BUDGETS.items():
        if key not in tables[table]:
            tables[table][key] = _scaled_budget(config, grading, key, default, slow)
    return config.with_tables(**tables)


def _scaled_budget(config: CriterionBase, grading: GradingCurve, key: str, default: int, slow: float) -> int:
    """``default`` steps scaled by ``slow``; refused, naming the grading's key that sets the time
    step, when that is more than a stage may take (the config would be refused for a key the
    user never typed)."""
    from poro2d.criterion.config import CRITERION_BOUNDS, SPECIMEN_BOUNDS

    steps = int(math.ceil(default * slow / 1000.0) * 1000)
    most = {**SPECIMEN_BOUNDS, **CRITERION_BOUNDS}[key][1]
    if steps <= most:
        return steps
    table = config.table("grading")
    name = "grading.upscale" if "upscale" in table else "grading.d_min_mm"
    raise InputError(
        name, table.get(name.split(".")[1]),
        f"a finest disk whose time step is at least {default / most:.3g} of the paper grading's",
        f"the finest disk, {grading.d_min_m * 1e3:.3g} mm in the model, steps at {1 / slow:.3g} of it: "
        f"{key} would be {steps}, above its {most:g}; up-scale more or cut the fines (d_min_mm)",
    )  # fmt: skip


def load_sand_case(
    config: ConfigLike, *, seeds: int | None = None, budget_minutes: float | None = None
) -> SandCase:
    """A :class:`SandCase` from a sand config (a TOML file or a dict), every value checked.

    ``seeds`` overrides ``[sand] seeds``; ``budget_minutes``: the run time the pre-flight's
    estimate is held against (``--budget``). Raises :class:`~poro2d.errors.InputError` naming
    the key, its value and what is allowed.
    """
    from poro2d.criterion.config import check_tables, load_config

    if isinstance(config, dict):
        check_keys("config", config, {"seed", "specimen", "grading", "criterion", "title", *SAND_TABLES})
        check_tables(config)
        cfg, base_dir = copy.deepcopy(config), None
    else:
        cfg, base_dir = load_config(config, extra_tables=SAND_TABLES)
    for name in SAND_TABLES:
        if name in cfg and not isinstance(cfg[name], dict):
            raise InputError(name, cfg[name], "a table of key = value pairs")
    name, reference = _soil(cfg.get("soil") or {})
    lab = _lab(cfg.get("lab"))
    sand = cfg.get("sand") or {}
    check_keys("sand", sand, SAND_KEYS)
    n_seeds = check_int(
        "--seeds" if seeds is not None else "sand.seeds",
        seeds if seeds is not None else sand.get("seeds", DEFAULT_SEEDS),
        1,
        50,
    )
    replacements = check_int("sand.replacements", sand.get("replacements", REPLACEMENTS), 0, 50)
    cal_seeds = check_int("sand.calibration_seeds", sand.get("calibration_seeds", CALIBRATION_SEEDS), 1, 50)
    cal_disks = check_int(
        "sand.calibration_disks", sand.get("calibration_disks", CALIBRATION_DISKS), 200, 50_000
    )
    mus = tuple(check_mus(sand["mu_prep"], "sand.mu_prep")) if "mu_prep" in sand else DEFAULT_MUS
    if "grading" not in cfg:
        raise InputError("grading", None, "a [grading] table: csv, sizes_mm with percent_passing, or preset")
    crit = _criterion_config(cfg, lab, base_dir)
    spec, grading, _settings, _seed = crit.build()
    crit = with_step_budgets(crit, spec, grading)
    spec, grading, _settings, _seed = crit.build()
    state = state_request(
        cfg.get("state"), lab, base_dir, spec.friction_particle, spec.rolling_friction, grading
    )
    if budget_minutes is not None:
        check_range("--budget", budget_minutes, 0.0, 7 * 24 * 60.0, lo_open=True)
    return SandCase(
        name, reference, lab, crit, base_dir, spec, grading, n_seeds, cal_disks, mus, cal_seeds, state,
        budget_minutes, replacements,
    )  # fmt: skip


__all__ = [
    "CALIBRATION_DISKS",
    "CALIBRATION_SEEDS",
    "REPLACEMENTS",
    "SandCase",
    "SoilRecord",
    "load_sand_case",
]
