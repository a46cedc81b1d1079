"""The criterion's density mode as one Python call, and the dispatch of ``poro2d criterion``.

Density mode runs its calibration and its seeds as sweeps, so it lives on the sweep layer;
the criterion layer checks both modes' inputs (:func:`poro2d.criterion.run.criterion_inputs`)
and runs paper mode. :func:`run_criterion_modes` is the command's one call: it checks the
inputs once and runs the mode they ask for.

:func:`run_density_state` runs one laboratory state on the relation's sweeps
(:func:`poro2d.sweep.relation.density_relation`); it sits here, above both the relation and
the calibration (:mod:`poro2d.sweep.density`), so that neither imports the other back.
"""

from __future__ import annotations

from poro2d.criterion.density import lab_relative_density
from poro2d.criterion.result import CriterionResult
from poro2d.criterion.run import ConfigLike, CriterionInputs, criterion_inputs, run_paper_mode
from poro2d.errors import InputError
from poro2d.execute.options import RunOptions
from poro2d.io_utils import Provenance, check_output_dir
from poro2d.store import Store
from poro2d.sweep.criterion_base import CriterionBase
from poro2d.sweep.density import DEFAULT_SEEDS
from poro2d.sweep.output import held
from poro2d.sweep.relation import RelationSettings, density_relation
from poro2d.sweep.results import DensityStateResult


def run_density_state(
    base: CriterionBase,
    n_lab: float,
    n_max: float,
    n_min: float,
    store: Store,
    *,
    seeds: int = DEFAULT_SEEDS,
    mus=None,
    use_cache: bool = True,
    options: RunOptions = RunOptions(),
) -> DensityStateResult:
    """The density-controlled criterion for one laboratory state, over seeds.

    Calibrates (or reads the cached calibration), maps ``n_lab`` to its 2D target and
    preparation friction, runs the criterion with them for every seed and writes
    ``density.json`` to ``store``: the accepted n2D (mean, sd, per seed), the target, mu_prep
    and Dr, returned as a :class:`~poro2d.sweep.results.DensityStateResult`. ``options``: where the
    jobs run and whether bars show (:class:`~poro2d.execute.options.RunOptions`).
    """
    lab_relative_density(n_lab, n_max, n_min)  # nLab outside [n_min, n_max]: refused before any run
    settings = RelationSettings(n_max, n_min, (round(float(n_lab), 4),))
    rel, sweeps = density_relation(base, settings, store, seeds=seeds, mus=mus, use_cache=use_cache,
                                   options=options)  # fmt: skip
    (point,) = rel.points
    record = {
        "mode": "density",
        "n_lab": point.n_lab,
        "relative_density": point.relative_density,
        "n2d_target": point.n2d_target,
        "mu_prep": point.mu_prep,
        "final_porosity_mean": point.n2d_dem,
        "final_porosity_sd": point.n2d_sd,
        "final_porosity_per_seed": point.n2d_seeds,
        "measured_porosity_mean": point.n2d_measured,
        "interior_porosity_mean": point.n2d_interior,
        "interior_porosity_sd": point.n2d_interior_sd,
        "interior_porosity_per_seed": point.n2d_interior_seeds,
        "seeds": point.seeds,
        "seeds_converged": point.seeds_converged,
        "converged": point.seeds_converged == point.seeds,
        "n2d_min": rel.n2d_min,
        "n2d_max": rel.n2d_max,
        "calibration": rel.calibration,
        "sweeps": sweeps,
        "config": base.as_config(),
        "provenance": Provenance.now().to_dict(),
    }
    result = DensityStateResult.from_dict(record)
    store.write_result("density.json", result)
    return result


def _run_density_mode(inputs: CriterionInputs, store: Store, *, threads: int | None,
                      options: RunOptions) -> DensityStateResult:  # fmt: skip
    """Calibration (cached), the state's friction and first trial, the criterion over seeds."""
    rest = {k: v for k, v in inputs.config.items() if k != "density"}
    if threads is not None:  # the option's thread count, as the specimen was built with it
        rest["specimen"] = dict(rest.get("specimen") or {}, threads=inputs.spec.threads)
    dens = inputs.density
    base = CriterionBase(rest, inputs.base)
    return run_density_state(base, inputs.settings.n_lab, dens.n_max, dens.n_min, store,
                             seeds=dens.seeds, mus=dens.mu_prep, options=options)  # fmt: skip


def _refuse_paper_options(seed: int | None, trial_porosity: float | None) -> None:
    # density mode runs seeds 0 .. seeds-1, each from its state's 2D target: a seed or a
    # first trial of its own would be ignored, so they are refused
    for option, value in (("--seed", seed), ("--trial-porosity", trial_porosity)):
        if value is not None:
            raise InputError(option, value, "only in paper mode (density: --seeds and the 2D target)")


def run_density_criterion(
    config: ConfigLike = None,
    *,
    preset: str | None = None,
    store: Store | None = None,
    n_lab: float | None = None,
    threads: int | None = None,
    n_max: float | None = None,
    n_min: float | None = None,
    seeds: int | None = None,
    options: RunOptions = RunOptions(),
) -> DensityStateResult:
    """``poro2d criterion --mode density`` as one call: the criterion for one laboratory state.

    Calibrates the grading (cached), sets the preparation friction from the laboratory
    relative density between ``n_max`` and ``n_min`` and runs the criterion over ``seeds``;
    returns the :class:`~poro2d.sweep.results.DensityStateResult` written to
    ``density.json`` in ``store`` (None: nothing kept but the calibration cache). ``config`` as
    for :func:`poro2d.criterion.run_criterion`, whose ``[density]`` table the options override.
    ``options``: where the jobs run and whether bars show (:class:`~poro2d.execute.options.RunOptions`).
    Bad input raises :class:`~poro2d.errors.InputError` before anything is written.
    """
    return run_criterion_modes(config, preset=preset, store=store, n_lab=n_lab, threads=threads,
                               mode="density", n_max=n_max, n_min=n_min, seeds=seeds,
                               options=options)  # fmt: skip


def run_criterion_modes(
    config: ConfigLike = None,
    *,
    preset: str | None = None,
    store: Store | None = None,
    seed: int | None = None,
    n_lab: float | None = None,
    trial_porosity: float | None = None,
    threads: int | None = None,
    mode: str | None = None,
    n_max: float | None = None,
    n_min: float | None = None,
    seeds: int | None = None,
    options: RunOptions = RunOptions(),
) -> CriterionResult | DensityStateResult:
    """``poro2d criterion``: the mode the options or ``[density] mode`` ask for (paper by default).

    Paper mode returns the :class:`~poro2d.criterion.result.CriterionResult` of
    :func:`poro2d.criterion.run_criterion`, density mode the
    :class:`~poro2d.sweep.results.DensityStateResult` of :func:`run_density_criterion`.
    ``store``: where the run is kept (None: nothing is kept); ``options``: where the jobs run and
    whether bars show (:class:`~poro2d.execute.options.RunOptions`).
    """
    if store is not None:
        check_output_dir(store.parameter, store.root)
    with held(store, kind="criterion") as kept:
        inputs = criterion_inputs(config, preset=preset, seed=seed, n_lab=n_lab,
                                  trial_porosity=trial_porosity, threads=threads, mode=mode, n_max=n_max,
                                  n_min=n_min, seeds=seeds)  # fmt: skip
        if inputs.mode == "paper":
            return run_paper_mode(inputs, kept, options=options)
        _refuse_paper_options(seed, trial_porosity)
        return _run_density_mode(inputs, kept, threads=threads, options=options)


__all__ = ["run_criterion_modes", "run_density_criterion", "run_density_state"]
