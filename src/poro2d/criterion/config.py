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

import os
from pathlib import Path

from poro2d.config import check_keys, dataclass_from_table, load_toml
from poro2d.criterion.protocol import CriterionSettings
from poro2d.errors import InputError, check_int
from poro2d.porosity import PAPER_N_LAB
from poro2d.specimen.compaction import SpecimenSpec
from poro2d.specimen.grading import GradingCurve, paper_grading

TOP_KEYS = {"seed", "specimen", "grading", "criterion", "shear", "title", "density"}


def paper_preset() -> dict:
    """The paper's case as a config dict (Table 1, nLab = 0.3434, reconstructed grading)."""
    return {"seed": 0, "specimen": {}, "grading": {"preset": "paper"}, "criterion": {"n_lab": PAPER_N_LAB}}


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
        return paper_preset(), None
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


def build(cfg: dict, base_dir: Path | None = None, **overrides):
    """(SpecimenSpec, GradingCurve, CriterionSettings, seed) from a config dict."""
    spec_over = {k: overrides.pop(k) for k in ("threads",) if k in overrides}
    spec = dataclass_from_table(SpecimenSpec, "specimen", cfg.get("specimen"), **spec_over)
    g = cfg.get("grading") or {"preset": "paper"}
    if not isinstance(g, dict):
        raise InputError("grading", g, "a table: preset, csv or sizes_mm with percent_passing")
    grading = paper_grading() if g == {"preset": "paper"} else GradingCurve.from_config(g, base_dir=base_dir)
    settings = dataclass_from_table(CriterionSettings, "criterion", cfg.get("criterion"), **overrides)
    seed = check_int("seed", cfg.get("seed", 0), 0)
    if not isinstance(cfg.get("title", ""), str):
        raise InputError("title", cfg["title"], "a string")
    return spec, grading, settings, seed
