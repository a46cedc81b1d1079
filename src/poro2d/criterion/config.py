"""Config files for the criterion: ``[specimen]``, ``[grading]``, ``[criterion]``, ``seed``.

Example (every key optional; the defaults are the paper preset)::

    seed = 1
    [specimen]          # SpecimenSpec: box, Table 1 properties, layers, damping
    width = 0.305
    layers = 4
    [grading]           # preset = "paper" | csv = "curve.csv" | sizes_mm + percent_passing
    preset = "paper"
    [criterion]         # CriterionSettings: n_lab, thresholds, resolution, servo
    n_lab = 0.3434
"""

from __future__ import annotations

import copy
import math
import os
from collections.abc import Mapping
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, Self

from poro2d.config import check_keys, dataclass_from_table, load_toml
from poro2d.criterion.protocol import CriterionSettings
from poro2d.errors import InputError, check_int
from poro2d.grading import GradingCurve, paper_grading
from poro2d.paper_data import QUICK_CRITERION, QUICK_SPECIMEN
from poro2d.porosity import PAPER_N_LAB
from poro2d.specimen.compaction import SpecimenSpec, wide_grading_spec

TOP_KEYS = {"seed", "specimen", "grading", "criterion", "shear", "title", "density"}


@dataclass(frozen=True)
class CriterionConfig:
    """A criterion config's tables (``seed``, ``specimen``, ``grading``, ``criterion``, ...) as a value.

    Read once, at the edge (a command, a preset, the one call of a study); every variation
    (another seed, a smaller box, a friction) is a new value, so nothing below re-reads the
    file or edits another's dict. ``config``: the tables in the order given, never changed in
    place: result files record them as given, and case ids hash them; ``base_dir``: the folder
    a grading file's relative path starts from.
    """

    config: Mapping[str, Any]
    base_dir: Path | None = None

    def table(self, name: str) -> dict[str, Any]:
        """A copy of the table ``name`` as given (empty when the config has none)."""
        return copy.deepcopy(dict(self.config.get(name) or {}))

    def with_tables(self, **tables: Mapping[str, Any]) -> Self:
        """This config with ``tables`` in place of its own (where they stood; new ones at the end)."""
        return replace(self, config={**self.config, **{k: dict(v) for k, v in tables.items()}})

    def with_defaults(self, defaults: Mapping[str, Mapping[str, Any]]) -> Self:
        """This config with ``defaults`` filled in where its tables are silent (its own values win)."""
        return self.with_tables(**{name: {**values, **self.table(name)} for name, values in defaults.items()})

    def with_seed(self, seed: int) -> Self:
        """This config with another seed (where ``seed`` stood; at the end when it had none)."""
        return replace(self, config={**self.config, "seed": seed})

    def without(self, *names: str) -> Self:
        """This config without the top-level keys ``names``."""
        return replace(self, config={k: v for k, v in self.config.items() if k not in names})

    def with_params(self, params: Mapping[str, Any]) -> Self:
        """This config with a case's parameters set, in their order: a dotted name
        (``specimen.kn_particle``) sets a key of its table, a bare one (``seed``) a top-level key."""
        config = dict(self.config)
        for name, value in params.items():
            if "." in name:
                table, key = name.split(".", 1)
                config[table] = {**(config.get(table) or {}), key: value}
            else:
                config[name] = value
        return replace(self, config=config)

    def with_grading_file_absolute(self) -> Self:
        """This config with its grading file's path made absolute (from ``base_dir``): a case
        run in another folder, or recorded, names the same file."""
        g = self.config.get("grading")
        if not (isinstance(g, Mapping) and isinstance(g.get("csv"), str) and self.base_dir is not None):
            return self
        path = Path(g["csv"])
        if path.is_absolute():
            return self
        return self.with_tables(grading=dict(g, csv=str((self.base_dir / path).resolve())))

    def as_config(self) -> dict[str, Any]:
        """The tables as the files record them (a deep copy: a record may keep it)."""
        return copy.deepcopy(dict(self.config))

    def build(self, **overrides):
        """(SpecimenSpec, GradingCurve, CriterionSettings, seed) of this config, every value checked."""
        return build(self.as_config(), self.base_dir, **overrides)


def paper_preset() -> CriterionConfig:
    """The paper's case (Table 1, nLab = 0.3434, reconstructed grading)."""
    tables = {"seed": 0, "specimen": {}, "grading": {"preset": "paper"}, "criterion": {"n_lab": PAPER_N_LAB}}
    return CriterionConfig(tables)


def paper_config(quick: bool, seed: int) -> CriterionConfig:
    """The paper's case with ``seed`` (``quick``: the small box and the widened force window)."""
    cfg = paper_preset().with_seed(seed)
    if quick:
        quick_criterion = {**cfg.table("criterion"), **QUICK_CRITERION}
        cfg = cfg.with_tables(specimen=QUICK_SPECIMEN, criterion=quick_criterion)
    return cfg


def load_config(
    path: str | os.PathLike | None = None, preset: str | None = None, extra_tables: tuple[str, ...] = ()
) -> tuple[dict, Path | None]:
    """(config, folder of the file) from ``--config`` or ``--preset`` (the paper's case by default).

    ``extra_tables``: top-level tables a command reads besides the criterion's own
    (``relation``, ``sensitivity``).
    """
    if path is not None and preset is not None:
        raise InputError("--config/--preset", f"{path} and {preset}", "one of the two, not both")
    if path is None:
        if preset not in (None, "paper"):
            raise InputError("preset", preset, "'paper'")
        return paper_preset().as_config(), None
    cfg = load_toml(path)
    check_keys("config", cfg, TOP_KEYS | set(extra_tables))
    check_tables(cfg)
    return cfg, Path(path).resolve().parent


#: top-level names of a config that hold tables (``[grading]`` is checked with its own words)
TABLES = ("specimen", "criterion", "density", "shear", "relation", "sensitivity", "sweep")


def check_tables(cfg: dict) -> None:
    """Each table of a config is a table (``relation = 5`` is not), and ``title`` is text."""
    for name in TABLES:
        if name in cfg and not isinstance(cfg[name], dict):
            raise InputError(name, cfg[name], "a table of key = value pairs")
    if not isinstance(cfg.get("title", ""), str):
        raise InputError("title", cfg["title"], "a string")


#: upper (and for the solid density lower) bounds of a config's settings, beyond which a value
#: is a typo or a run that cannot end: stiffnesses (N/m) 1e5 times the paper's particles (the
#: time step falls with their square root: 300 times as many steps), friction coefficients of
#: 10 (a contact that never slides), up to 100 g of gravity (a centrifuge's), the solids of
#: ``poro2d convert``, disks up to 1 m thick, boxes up to 10 m (a large-scale laboratory box
#: is 1-2 m), and step budgets of 1e8 (days of one core)
SPECIMEN_BOUNDS: dict[str, tuple[float, float]] = {
    **{k: (0.0, 10.0) for k in ("width", "height")},
    **{k: (0.0, 1e12) for k in ("kn_particle", "ks_particle", "kn_wall", "ks_wall")},
    **{k: (0.0, 10.0) for k in ("friction_prep", "friction_particle", "friction_wall")},
    "gravity": (0.0, 981.0),
    "solid_density": (500.0, 23000.0),
    "thickness": (0.0, 1.0),
    **{k: (1, 100_000_000) for k in ("max_steps_per_stage", "fallback_steps", "calm_steps")},
    "growth_increments": (1, 10_000),
    "growth_steps": (1, 1_000_000),
    "settle_window": (100, 10_000_000),
}
CRITERION_BOUNDS: dict[str, tuple[float, float]] = {
    "max_plate_steps": (1000, 100_000_000),
    "check_every": (1, 1_000_000),
    "window_checks": (1, 1000),
    "settle_checks": (2, 1000),
}


def check_config_bounds(obj, section: str, bounds: dict[str, tuple[float, float]]) -> None:
    """Each bounded setting of ``obj`` (already checked for type and sign) inside its bounds."""
    for key, (lo, hi) in bounds.items():
        value = getattr(obj, key)
        if math.isfinite(value) and not lo <= value <= hi:  # an infinity is refused as such later
            raise InputError(f"{section}.{key}", value, f"[{lo:g}, {hi:g}]")


def check_cut_in_box(d_max_mm: Any, spec: SpecimenSpec) -> None:
    """A ``[grading] d_max_mm`` no larger than the box: a cut above every disk the box could hold
    cuts nothing, and is a slip of units or of the key (the grading checked it is a size)."""
    side = max(spec.width, spec.height)
    if d_max_mm is not None and d_max_mm / 1000.0 > side:
        raise InputError(
            "grading.d_max_mm", d_max_mm, f"at most the box's larger side, {1000 * side:g} mm",
            "the largest disk must fit a layer of the box",
        )  # fmt: skip


def build(cfg: dict, base_dir: Path | None = None, **overrides):
    """(SpecimenSpec, GradingCurve, CriterionSettings, seed) from a config dict."""
    spec_over = {k: overrides.pop(k) for k in ("threads",) if k in overrides}
    spec = dataclass_from_table(SpecimenSpec, "specimen", cfg.get("specimen"), **spec_over)
    g = cfg.get("grading") or {"preset": "paper"}
    if not isinstance(g, dict):
        raise InputError("grading", g, "a table: preset, csv or sizes_mm with percent_passing")
    grading = paper_grading() if g == {"preset": "paper"} else GradingCurve.from_config(g, base_dir=base_dir)
    check_config_bounds(spec, "specimen", SPECIMEN_BOUNDS)
    check_cut_in_box(g.get("d_max_mm"), spec)
    # a wide grading's preparation: the settled test unless the config says otherwise (the
    # paper's grading is not wide: its spec is unchanged)
    spec = wide_grading_spec(spec, grading, cfg.get("specimen"))
    settings = dataclass_from_table(CriterionSettings, "criterion", cfg.get("criterion"), **overrides)
    check_config_bounds(settings, "criterion", CRITERION_BOUNDS)
    seed = check_int("seed", cfg.get("seed", 0), 0)
    if not isinstance(cfg.get("title", ""), str):
        raise InputError("title", cfg["title"], "a string")
    return spec, grading, settings, seed
