"""The criterion's density mode as one Python call, and the dispatch of ``poro2d criterion``.

Density mode runs its calibration and its seeds as sweeps, so it lives on the sweep layer;
the criterion layer makes both modes' case (:class:`poro2d.criterion.run.CriterionCase`,
every input checked) and runs paper mode. :func:`run_criterion_modes` is the command's one
call: it runs the mode the case asks for.

:func:`run_density_criterion` runs one laboratory state on the relation's sweeps
(:func:`poro2d.sweep.relation.density_relation`); it sits here, above both the relation and
the calibration (:mod:`poro2d.sweep.density`), so that neither imports the other back.
"""

from __future__ import annotations

from poro2d.console import OutputConsole, shown
from poro2d.criterion.result import CriterionResult
from poro2d.criterion.run import KIND, CriterionCase, run_criterion
from poro2d.errors import InputError
from poro2d.execute.options import RunOptions
from poro2d.io_utils import Provenance
from poro2d.store import Store
from poro2d.sweep.criterion_base import CriterionBase
from poro2d.sweep.output import held
from poro2d.sweep.records import DensitySweeps
from poro2d.sweep.relation import RelationSettings, density_relation
from poro2d.sweep.results import DensityStateResult, RelationResult

console = OutputConsole()


def run_density_criterion(
    case: CriterionCase, store: Store | None = None, *, options: RunOptions = RunOptions()
) -> DensityStateResult:
    """``poro2d criterion --mode density`` as one call: the criterion for one laboratory state.

    ``case``: a density-mode :class:`~poro2d.criterion.run.CriterionCase` (its ``[density]``
    table or ``from_config(..., mode="density", n_max=..., n_min=...)``). Calibrates the
    grading (cached), maps the case's ``n_lab`` between the laboratory extremes to its 2D target
    and preparation friction, runs the criterion with them for every seed (a seed not accepted
    replaced by the next unused one, ``[density] replacements`` at most, each said on the console) and writes
    ``density.json`` to ``store`` (None: nothing kept but the calibration cache): the accepted
    n2D (mean, sd, per seed), the target, mu_prep and Dr, returned as a
    :class:`~poro2d.sweep.results.DensityStateResult`. ``options``: where the jobs run and
    whether bars show (:class:`~poro2d.execute.options.RunOptions`).
    """
    dens = case.density
    if dens.mode != "density":
        raise InputError("mode", dens.mode, "density here (paper mode: poro2d.criterion.run_criterion)")
    rest = {k: v for k, v in case.config.items() if k != "density"}
    if dens.threads is not None:  # the option's thread count, as the specimen was built with it
        rest["specimen"] = dict(rest.get("specimen") or {}, threads=dens.threads)
    base = CriterionBase(rest, case.base)
    settings = RelationSettings(dens.n_max, dens.n_min, (round(float(case.settings.n_lab), 4),))
    with held(store, kind=KIND) as kept:
        spare = {"replacements": dens.replacements, "announce": _say}
        rel, sweeps = density_relation(base, settings, kept, seeds=dens.seeds, mus=dens.mu_prep,
                                       options=options, **spare)  # fmt: skip
        result = DensityStateResult.from_dict(_state_record(rel, sweeps, base, dens.seeds))
        kept.write_result("density.json", result)
    return result


def _say(text: str) -> None:
    """A line of the run (a seed replaced, with why) printed as text: a reason may hold brackets."""
    console.print(shown(text), soft_wrap=True)


def _state_record(rel: RelationResult, sweeps: DensitySweeps, base: CriterionBase, requested: int) -> dict:
    """density.json's keys: the one state's point of the relation, its extremes and calibration
    (converged: ``requested`` seeds accepted, replacements counted)."""
    (point,) = rel.points
    return {
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
        "converged": point.seeds_converged >= requested,
        "n2d_min": rel.n2d_min,
        "n2d_max": rel.n2d_max,
        "calibration": rel.calibration,
        "sweeps": sweeps,
        "config": base.as_config(),
        "provenance": Provenance.now().to_dict(),
    }


def run_criterion_modes(
    case: CriterionCase, store: Store | None = None, *, options: RunOptions = RunOptions()
) -> CriterionResult | DensityStateResult:
    """``poro2d criterion``: the ``case``'s mode (:meth:`~poro2d.criterion.run.CriterionCase.from_config`).

    Paper mode returns the :class:`~poro2d.criterion.result.CriterionResult` of
    :func:`poro2d.criterion.run_criterion`, density mode the
    :class:`~poro2d.sweep.results.DensityStateResult` of :func:`run_density_criterion`.
    ``store``: where the run is kept (None: nothing is kept); ``options``: where the jobs run and
    whether bars show (:class:`~poro2d.execute.options.RunOptions`).
    """
    run = run_criterion if case.mode == "paper" else run_density_criterion
    return run(case, store, options=options)


__all__ = ["run_criterion_modes", "run_density_criterion"]
