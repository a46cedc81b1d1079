"""``run_criterion``: the criterion of ``poro2d criterion`` (paper mode) as one Python call.

The command only parses its options and prints; the case of both modes, every input checked
when it is made (:meth:`CriterionCase.from_config`), and the paper mode's run are here, so a
script gets the same checks, files and resuming. Density mode runs its specimens on the sweep layer
(:mod:`poro2d.sweep.density_criterion`, which also dispatches the command's two modes).
"""

from __future__ import annotations

import copy
import os
from dataclasses import dataclass, replace
from pathlib import Path

from poro2d.criterion.protocol import CriterionSettings, PorosityCriterion
from poro2d.criterion.replicates import MAX_REPLACEMENTS, REPLACEMENTS
from poro2d.criterion.result import CriterionResult
from poro2d.errors import InputError, check_int, check_range
from poro2d.execute.options import RunOptions
from poro2d.grading import GradingCurve
from poro2d.specimen.compaction import SpecimenSpec
from poro2d.store import Store, claimed

#: the kind of run an output folder of this command belongs to (poro2d.locks.KIND_SIGNS)
KIND = "criterion"

ConfigLike = dict | str | os.PathLike | None


def load(
    config: ConfigLike, preset: str | None = None, extra_tables: tuple[str, ...] = ()
) -> tuple[dict, Path | None]:
    """(config dict, folder its relative paths start from): a dict as given, a TOML file, or the preset.

    ``extra_tables``: top-level tables a command reads besides the criterion's own.
    """
    from poro2d.criterion.config import load_config

    if isinstance(config, dict):
        if preset is not None:
            raise InputError("config/preset", f"a dict and {preset}", "one of the two, not both")
        from poro2d.criterion.config import check_tables

        check_tables(config)
        return copy.deepcopy(config), None
    return load_config(config, preset, extra_tables=extra_tables)


DENSITY_KEYS = {"mode", "n_max", "n_min", "mu_prep", "seeds", "replacements"}


@dataclass(frozen=True)
class DensitySettings:
    """The mode of ``poro2d criterion`` and, in density mode, its settings.

    ``mu_prep``: the calibration's preparation frictions (None: the defaults); ``n_max``,
    ``n_min``: the laboratory extremes; ``seeds``: specimens per state; ``threads``: the DEM
    threads the option gave the states' specimens (None: the config's); ``replacements``: seeds
    not accepted replaced by the next unused ones, at most (density mode only).
    """

    mode: str
    mu_prep: list[float] | None = None
    n_max: float | None = None
    n_min: float | None = None
    seeds: int | None = None
    threads: int | None = None
    replacements: int = REPLACEMENTS


def density_settings(cfg: dict, mode, n_max, n_min, seeds, *, preset: bool) -> DensitySettings:
    """Mode and density-mode settings from ``[density]`` and the options (options win).

    With no mode given, density mode when both laboratory extremes are (``[density]`` or the
    options), else paper mode.
    """
    from poro2d.config import check_keys
    from poro2d.criterion.density import check_mus

    check_keys("density", cfg.get("density") or {}, DENSITY_KEYS)
    t = dict(cfg.get("density") or {})
    if mode is None and "mode" not in t:
        # density-aware by default: a config or options that give both laboratory extremes ask
        # for the answer at the laboratory density, which paper mode cannot give
        both = all((opt if opt is not None else t.get(key)) is not None
                   for opt, key in ((n_max, "n_max"), (n_min, "n_min")))  # fmt: skip
        mode = "density" if both else "paper"
    mode = mode if mode is not None else t.get("mode", "paper")
    if mode not in ("paper", "density"):
        raise InputError("mode", mode, "paper or density")
    if mode == "paper":
        # the paper's protocol prepares at friction_prep and uses no laboratory extremes: an
        # option of density mode given with it would be ignored, so it is refused instead
        for option, value in (("--n-max", n_max), ("--n-min", n_min), ("--seeds", seeds)):
            if value is not None:
                raise InputError(option, value, "only with --mode density (paper mode: the paper's protocol)")
        return DensitySettings(mode)
    mus = t.get("mu_prep")
    mu_prep = None if mus is None else check_mus(mus, "density.mu_prep")
    hi, lo = lab_extremes(
        "density", t, n_max, n_min, preset=preset, hint="set them in [density] or with --n-max/--n-min"
    )
    if seeds is None:
        seeds = check_int("density.seeds", t.get("seeds", 3), 1, 50)
    seeds = check_int("--seeds", seeds, 1, 50)
    spare = check_int("density.replacements", t.get("replacements", REPLACEMENTS), 0, MAX_REPLACEMENTS)
    return DensitySettings(mode, mu_prep, n_max=hi, n_min=lo, seeds=seeds, replacements=spare)


def lab_extremes(table: str, t: dict, n_max, n_min, *, preset: bool, hint: str) -> tuple[float, float]:
    """The laboratory extremes (n_max, n_min): the options, else ``table``'s ``t``, else (the
    preset) the paper's; both checked in (0, 1). ``hint``: where a user sets them."""
    from poro2d import porosity as P

    hi = n_max if n_max is not None else t.get("n_max", P.PAPER_N_MAX if preset else None)
    lo = n_min if n_min is not None else t.get("n_min", P.PAPER_N_MIN if preset else None)
    if hi is None or lo is None:
        raise InputError(f"{table}.n_max/n_min", (hi, lo), "both laboratory extremes", hint)
    # each named as the user gave it: the argument (the command names its option), else the table's key
    hi_name = "n_max" if n_max is not None else f"{table}.n_max"
    lo_name = "n_min" if n_min is not None else f"{table}.n_min"
    return (check_range(hi_name, hi, 0.0, 1.0, lo_open=True, hi_open=True),
            check_range(lo_name, lo, 0.0, 1.0, lo_open=True, hi_open=True))  # fmt: skip


@dataclass(frozen=True)
class CriterionCase:
    """A criterion config checked and built, before anything runs (both modes start here).

    ``config``: the config as loaded, with the seed option applied; ``base``: the folder its
    relative paths start from; ``density``: the mode and, in density mode, its settings
    (:func:`density_settings`); ``spec``, ``grading``, ``settings``, ``seed``: the objects
    the criterion runs on. Made by :meth:`from_config`.
    """

    config: dict
    base: Path | None
    density: DensitySettings
    spec: SpecimenSpec
    grading: GradingCurve
    settings: CriterionSettings
    seed: int

    @property
    def mode(self) -> str:
        return self.density.mode

    @classmethod
    def from_config(cls, config: ConfigLike = None, *, preset: str | None = None, seed: int | None = None,
                    n_lab: float | None = None, trial_porosity: float | None = None,
                    threads: int | None = None, mode: str | None = None, n_max: float | None = None,
                    n_min: float | None = None, seeds: int | None = None,
                    vtk_every: int | None = None) -> CriterionCase:  # fmt: skip
        """The case of ``poro2d criterion``: ``config`` (a dict, a TOML file, or the paper preset
        when None) with the command's options applied, every input checked, the specimen's
        feasibility too (InputError if not); ``vtk_every``: the criterion table's, each trial's
        plate stage as a ParaView series."""
        from poro2d.criterion.config import build
        from poro2d.criterion.density import lab_relative_density
        from poro2d.specimen.compaction import check_feasible

        # a [relation] table is the relation's: one config serves both commands
        cfg, base = load(config, preset, extra_tables=("relation",))
        if seed is not None:
            cfg["seed"] = check_int("--seed", seed, 0)
        if vtk_every is not None:
            cfg["criterion"] = {**cfg.get("criterion", {}), "vtk_every": vtk_every}
        dens = density_settings(cfg, mode, n_max, n_min, seeds, preset=config is None)
        spec, grading, settings, sd = build(
            cfg, base, n_lab=n_lab, trial_porosity=trial_porosity, threads=threads
        )
        check_feasible(spec, grading, settings.initial_trial())
        if dens.mode == "density":
            _refuse_paper_options(seed, trial_porosity)
            # a state outside [n_min, n_max] has no relative density: refused before any run
            lab_relative_density(settings.n_lab, dens.n_max, dens.n_min)
            # the option's thread count goes to the density runs' specimens, as this one was built
            dens = replace(dens, threads=None if threads is None else spec.threads)
        return cls(cfg, base, dens, spec, grading, settings, sd)


def _refuse_paper_options(seed: int | None, trial_porosity: float | None) -> None:
    # density mode runs seeds 0 .. seeds-1, each from its state's 2D target: a seed or a
    # first trial of its own would be ignored, so they are refused
    for option, value in (("--seed", seed), ("--trial-porosity", trial_porosity)):
        if value is not None:
            raise InputError(option, value, "only in paper mode (density: --seeds and the 2D target)")


def run_criterion(
    case: CriterionCase, store: Store | None = None, *, options: RunOptions = RunOptions()
) -> CriterionResult:
    """The criterion of Fig. 3 for a paper-mode ``case`` (:meth:`CriterionCase.from_config`).

    Runs it once, as the paper does, and returns the
    :class:`~poro2d.criterion.result.CriterionResult` kept as ``result.json`` in ``store``
    (held for the call, resumable; None: nothing is kept). ``options``: whether bars show
    (:class:`~poro2d.execute.options.RunOptions`; the criterion runs in this process).
    A density-mode case runs on the sweep layer:
    :func:`poro2d.sweep.density_criterion.run_density_criterion` is its call, and it is
    refused here before anything is written.
    """
    if case.mode == "density":
        raise InputError("density.mode", "density", "paper here (density mode: "
                         "poro2d.sweep.density_criterion.run_density_criterion)")  # fmt: skip
    with claimed(store, KIND):
        return PorosityCriterion(case.spec, case.grading, case.settings, seed=case.seed, store=store,
                                 progress=options.progress, config=case.config).run()  # fmt: skip


__all__ = ["CriterionCase", "DensitySettings", "lab_extremes", "run_criterion"]
