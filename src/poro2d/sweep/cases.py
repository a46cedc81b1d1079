"""Sweep configs, case ids and the registry of case kinds.

A sweep config is a criterion config (``seed``, ``[specimen]``, ``[grading]``,
``[criterion]``) plus a ``[sweep]`` table::

    [sweep]
    kind = "criterion"                       # a key of KINDS
    n_lab = [0.33, 0.36, 0.39]               # grid axes: every combination is a case
    specimen.friction_particle = [1.0, 3.0]

or, instead of grid axes, an explicit list of cases::

    [[sweep.cases]]
    n_lab = 0.33
    specimen.kn_particle = 2e5

A parameter is a dotted path into the base config (``specimen.kn_particle``,
``criterion.n_lab``, ``grading.upscale``, ``seed``) or a bare field name of
:class:`SpecimenSpec` or :class:`CriterionSettings` (``n_lab`` means
``criterion.n_lab``). Names are resolved once, so ``n_lab`` and
``criterion.n_lab`` give the same case and the same id.

The TOML is read once, at the edge (:func:`parse_sweep`); a study that builds its cases
itself (the relation, the calibration) hands :func:`make_sweep` its base config and the
parameters of every case. A :class:`Case` is a value: its id is the digest of its kind
and merged config, fixed when it is made.

A case kind is a callable ``run(config, store)`` that returns the case's table cells, a
dict of scalars or a typed record of them (``store``: the case's
:class:`~poro2d.store.Store`, where it keeps what it writes); it is
registered in :data:`KINDS` (and optionally a ``validate(config, base_dir)`` in
:data:`VALIDATORS`, run before anything is submitted, that raises
:class:`InputError` on bad input). New kinds (direct shear, ...) only add an entry.
"""

from __future__ import annotations

import copy
import dataclasses
import itertools
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from poro2d.config import check_finite, check_keys
from poro2d.criterion.config import CriterionConfig, build
from poro2d.criterion.settings import CriterionSettings
from poro2d.errors import InputError, check_int
from poro2d.identity import identity_digest
from poro2d.specimen.compaction import SpecimenSpec, check_feasible
from poro2d.sweep.records import CriterionCaseResults

if TYPE_CHECKING:
    from poro2d.store import Store

#: kind -> run(config, store) -> the case's scalar results (a dict or a typed record)
KINDS: dict[str, Callable[[dict, Store], Mapping[str, Any]]] = {}
#: kind -> validate(config, base_dir); raises InputError before any case runs
VALIDATORS: dict[str, Callable[[dict, Path | None], None]] = {}
#: tables whose dataclass field names may be used without the table prefix
BARE_NAME_TABLES: dict[str, type] = {"specimen": SpecimenSpec, "criterion": CriterionSettings}

#: keys of ``[sweep]`` that are options, not grid axes
SWEEP_OPTIONS = {"kind", "cases", "figures", "retries", "title"}
#: top-level tables of a sweep config
TOP_KEYS = {"seed", "specimen", "grading", "criterion", "shear", "title", "sweep", "relation"}
#: the tables a case parameter may point into
CASE_TABLES = {"specimen", "grading", "criterion", "shear"}


def register_kind(
    name: str,
    run: Callable[[dict, Store], Mapping[str, Any]],
    validate: Callable[[dict, Path | None], None] | None = None,
    tables: tuple[str, ...] = (),
) -> None:
    """Add (or replace) a case kind; ``tables``: extra config tables its parameters live in."""
    KINDS[name] = run
    CASE_TABLES.update(tables)
    TOP_KEYS.update(tables)
    if validate is not None:
        VALIDATORS[name] = validate
    else:
        VALIDATORS.pop(name, None)


# --------------------------------------------------------------------------- criterion kind
def criterion_objects(config: dict, base_dir: Path | None = None):
    """(spec, grading, settings, seed) of a criterion case's config, checked feasible (the criterion
    kind's validator)."""
    cfg = {k: v for k, v in config.items() if k in ("seed", "specimen", "grading", "criterion")}
    spec, grading, settings, seed = build(copy.deepcopy(cfg), base_dir)
    check_feasible(spec, grading, settings.initial_trial())
    return spec, grading, settings, seed


def criterion_case(config: dict, store: Store) -> CriterionCaseResults:
    """The criterion of Fig. 3 for one case; scalars of its result, of its first and of its accepted trial.

    ``config``: the case's merged config as its ``params.json`` records it.
    """
    from poro2d.criterion.protocol import PorosityCriterion
    from poro2d.store import Store

    spec, grading, settings, seed = criterion_objects(config)
    # a [sweep] figures = true is drawn by the command once the sweep ends (its sweep_options
    # stay in the case's config: they are part of its identity)
    crit = PorosityCriterion(spec, grading, settings, seed=seed, store=Store(store.root), progress=False,
                             config=config)  # fmt: skip
    return CriterionCaseResults.of(crit.run())


# --------------------------------------------------------------------------------- cases
@dataclass(frozen=True)
class Case:
    """One case, a value: its kind, the parameters that differ from the base, the merged config.

    ``id`` is fixed when the case is made (:func:`case_id` of kind and config), so a case
    built again from the same values names the same folder. Its fields, in their order, are
    what its ``params.json`` records (``dataclasses.asdict``).
    """

    id: str = field(default="", kw_only=True)
    kind: str
    params: dict[str, Any]
    config: dict

    def __post_init__(self) -> None:
        if not self.id:
            object.__setattr__(self, "id", case_id(self.kind, self.config))


@dataclass(frozen=True)
class SweepConfig:
    """A sweep: its cases and options, plus its config as given (written to ``sweep.json``)."""

    kind: str
    cases: list[Case]
    raw: dict
    base_dir: Path | None = None
    retries: int = 2
    figures: bool = False
    title: str = ""
    axes: list[str] = field(default_factory=list)


def config_tables(prefix: str = "") -> dict[str, type]:
    """The dataclass each table of a case's config stands for, keyed ``prefix`` + table name (a
    registry: which tables there are depends on the kinds registered).

    Their fields marked as not changing results (:mod:`poro2d.identity`: the thread count)
    are left out of a case's identity.
    """
    return {f"{prefix}{table}": cls for table, cls in BARE_NAME_TABLES.items()}


def case_id(kind: str, config: dict) -> str:
    """A stable id: the first 12 hex digits of the run digest of the kind and merged config.

    The identity rule (:func:`poro2d.identity.identity_digest`) leaves out the settings that
    change no result, so a rerun with another thread count finds the finished cases; a grading
    curve file counts by its content (:func:`grading_by_content`), so a config moved with its
    csv to another folder finds them too (the merged config holds the file's absolute path).
    """
    view = {"kind": kind, "config": config_by_content(config)}
    return identity_digest(view, tables=config_tables("config."), length=12)


def grading_by_content(grading: Any, base_dir: Path | None = None) -> Any:
    """A grading table as identities see it: a curve file named by its content (its SHA-256),
    not by its path, so the same curve read from another folder, or given by another path, is
    the same input. A file that cannot be read keeps its path (the run then refuses it)."""
    from poro2d.store.digests import file_digest

    csv = grading.get("csv") if isinstance(grading, dict) else None
    if not isinstance(csv, str):
        return grading
    path = Path(csv) if base_dir is None or Path(csv).is_absolute() else base_dir / csv
    try:
        digest = file_digest(path)
    except OSError:
        return grading
    return {**{k: v for k, v in grading.items() if k != "csv"}, "csv_sha256": digest}


def case_record(case: dict) -> dict:
    """A case as its folder records it (``params.json``): with its grading curve file's SHA-256
    beside the file's path when it has one, so that the folder is bound to the curve, not to
    where the file lay."""
    config = case.get("config")
    by_content = grading_by_content(config.get("grading")) if isinstance(config, dict) else None
    if not isinstance(by_content, dict) or "csv_sha256" not in by_content:
        return case
    return {**case, "grading_csv_sha256": by_content["csv_sha256"]}


def config_by_content(config: dict) -> dict:
    """A case's merged config with its grading by content (:func:`grading_by_content`)."""
    if "grading" not in config:
        return config
    return {**config, "grading": grading_by_content(config["grading"])}


def _field_names(cls: type) -> set[str]:
    return {f.name for f in dataclasses.fields(cls)}


def resolve_name(name: str) -> str:
    """``n_lab`` -> ``criterion.n_lab``; dotted names are checked against the case tables."""
    parts = name.split(".")
    if len(parts) == 1:
        if name == "seed":
            return name
        owners = [t for t, cls in BARE_NAME_TABLES.items() if name in _field_names(cls)]
        if len(owners) == 1:
            return f"{owners[0]}.{name}"
        known = sorted({f"{t}.{n}" for t, c in BARE_NAME_TABLES.items() for n in _field_names(c)})
        if len(owners) > 1:
            raise InputError(f"sweep.{name}", name, f"one of {', '.join(owners)} prefixed", "ambiguous name")
        raise InputError(
            f"sweep.{name}",
            name,
            "seed or a field of " + ", ".join(sorted(BARE_NAME_TABLES)),
            f"or a dotted path such as {known[0]}",
        )
    table, key = parts[0], ".".join(parts[1:])
    if table not in CASE_TABLES or len(parts) != 2:
        raise InputError(f"sweep.{name}", name, f"seed or <table>.<key> with table in {sorted(CASE_TABLES)}")
    cls = BARE_NAME_TABLES.get(table)
    if cls is not None and key not in _field_names(cls):
        check_keys(table, {key: None}, _field_names(cls))
    return f"{table}.{key}"


def _flatten(prefix: str, table: dict) -> dict[str, Any]:
    """Nested TOML tables (``specimen.kn = ...`` inside ``[sweep]``) to dotted keys: a table as
    read, at the edge, before its names are resolved."""
    out: dict[str, Any] = {}
    for k, v in table.items():
        name = f"{prefix}.{k}" if prefix else str(k)
        if isinstance(v, dict):
            out.update(_flatten(name, v))
        else:
            out[name] = v
    return out


def _check_value(name: str, value: Any) -> Any:
    if isinstance(value, float) and not math.isfinite(value):
        raise InputError(f"sweep.{name}", value, "a finite number")
    if isinstance(value, dict):
        raise InputError(f"sweep.{name}", value, "a value (number, string, bool or list)")
    return value


def grid_cases(grid: Mapping[str, list]) -> list[dict[str, Any]]:
    """Every combination of the grid's values, the first axis slowest (the base case for no axis)."""
    names = list(grid)
    return [dict(zip(names, vals, strict=True)) for vals in itertools.product(*grid.values())] or [{}]


def axes_of(cases: list[dict[str, Any]]) -> list[str]:
    """The parameters the cases set, in the order they first appear: the table's columns."""
    axes: list[str] = []
    for params in cases:
        axes.extend(k for k in params if k not in axes)
    return axes


def parse_sweep(cfg: dict, base_dir: Path | None = None, *, validate: bool = True) -> SweepConfig:
    """Cases of a sweep config dict (a TOML file's, read at the edge); every problem is an InputError."""
    check_keys("config", cfg, TOP_KEYS)
    check_finite("config", cfg)  # nothing non-finite reaches a case id or a stored config
    sw = cfg.get("sweep")
    if not isinstance(sw, dict):
        raise InputError("sweep", sw, "a [sweep] table with kind and grid axes or cases")
    kind = sw.get("kind", "criterion")
    if kind not in KINDS:
        raise InputError("sweep.kind", kind, ", ".join(sorted(KINDS)))
    retries = check_int("sweep.retries", sw.get("retries", 2), 0, 20)
    figures = sw.get("figures", False)
    if not isinstance(figures, bool):
        raise InputError("sweep.figures", figures, "true or false")
    title = str(sw.get("title", cfg.get("title", "")))

    axes_raw = _flatten("", {k: v for k, v in sw.items() if k not in SWEEP_OPTIONS})
    explicit = sw.get("cases")
    if axes_raw and explicit is not None:
        raise InputError("sweep.cases", "cases and grid axes", "either grid axes or a list of cases")
    if explicit is not None:
        if not isinstance(explicit, list) or not explicit or not all(isinstance(c, dict) for c in explicit):
            raise InputError("sweep.cases", explicit, "a non-empty list of tables ([[sweep.cases]])")
        combos = [{resolve_name(k): _check_value(k, v) for k, v in _flatten("", c).items()} for c in explicit]
        axes = axes_of(combos)
    else:
        grid: dict[str, list] = {}
        for name, values in axes_raw.items():
            full = resolve_name(name)
            if full in grid:
                raise InputError(f"sweep.{name}", values, "each parameter once", f"{full} is given twice")
            if not isinstance(values, list) or not values:
                raise InputError(f"sweep.{name}", values, "a non-empty list of values (a grid axis)")
            grid[full] = [_check_value(name, v) for v in values]
        axes = list(grid)
        combos = grid_cases(grid)

    return make_sweep(kind, cfg, combos, axes, base_dir=base_dir, retries=retries, figures=figures,
                      title=title, validate=validate)  # fmt: skip


def make_sweep(
    kind: str,
    raw: Mapping[str, Any],
    combos: list[dict[str, Any]],
    axes: list[str],
    *,
    base_dir: Path | None = None,
    retries: int = 2,
    figures: bool = False,
    title: str = "",
    validate: bool = True,
) -> SweepConfig:
    """The sweep of ``kind`` whose cases set ``combos`` (resolved dotted names) on the base ``raw``.

    ``raw``: the base config as it is recorded in ``sweep.json`` (its ``[sweep]`` table too,
    which no case sees). Two cases with one id, or a case its kind refuses, are an
    :class:`InputError` naming the case.
    """
    check_keys("config", raw, TOP_KEYS)
    check_finite("config", raw)
    # the tables every case starts from: a study's own tables are recorded in sweep.json, not by a case
    base = CriterionConfig(raw, base_dir).without("sweep", "relation", "title").with_grading_file_absolute()
    cases: list[Case] = []
    seen: dict[str, int] = {}
    for i, params in enumerate(combos):
        merged = base.with_params(params).as_config()
        if figures:
            merged["sweep_options"] = {"figures": True}
        case = Case(kind, params, merged)
        if case.id in seen:
            raise InputError(
                "sweep", params, "distinct cases", f"case {i + 1} repeats case {seen[case.id] + 1}"
            )
        seen[case.id] = i
        if validate and kind in VALIDATORS:
            try:
                VALIDATORS[kind](merged, base_dir)
            except InputError as exc:
                where = ", ".join(f"{k} = {v!r}" for k, v in params.items()) or "the base case"
                raise InputError(exc.parameter, exc.value, exc.allowed, f"in the case {where}") from None
        cases.append(case)
    return SweepConfig(kind, cases, dict(raw), base_dir, retries, figures, title, list(axes))


register_kind("criterion", criterion_case, criterion_objects)
