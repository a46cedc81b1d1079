"""The criterion's density mode as one Python call, and the dispatch of ``poro2d criterion``.

Density mode runs its calibration and its seeds as sweeps, so it lives on the sweep layer;
the criterion layer checks both modes' inputs (:func:`poro2d.criterion.run.criterion_inputs`)
and runs paper mode. :func:`run_criterion_modes` is the command's one call: it checks the
inputs once and runs the mode they ask for.
"""

from __future__ import annotations

import os
from pathlib import Path

from poro2d.criterion.result import CriterionResult
from poro2d.criterion.run import ConfigLike, CriterionInputs, criterion_inputs, run_paper_mode
from poro2d.errors import InputError
from poro2d.io_utils import check_output_dir
from poro2d.locks import holds_output
from poro2d.sweep.density import run_density_state
from poro2d.sweep.results import DensityStateResult


def _run_density_mode(inputs: CriterionInputs, out: Path, *, threads: int | None,
                      progress: bool) -> DensityStateResult:  # fmt: skip
    """Calibration (cached), the state's friction and first trial, the criterion over seeds."""
    rest = {k: v for k, v in inputs.config.items() if k != "density"}
    if threads is not None:  # the option's thread count, as the specimen was built with it
        rest["specimen"] = dict(rest.get("specimen") or {}, threads=inputs.spec.threads)
    dens = inputs.density
    return run_density_state(rest, inputs.base, inputs.settings.n_lab, dens["n_max"], dens["n_min"], out,
                             seeds=dens["seeds"], mus=dens["mu_prep"], progress=progress)  # fmt: skip


def _refuse_paper_options(seed: int | None, trial_porosity: float | None) -> None:
    # density mode runs seeds 0 .. seeds-1, each from its state's 2D target: a seed or a
    # first trial of its own would be ignored, so they are refused
    for option, value in (("--seed", seed), ("--trial-porosity", trial_porosity)):
        if value is not None:
            raise InputError(option, value, "only in paper mode (density: --seeds and the 2D target)")


@holds_output("out")
def run_density_criterion(
    config: ConfigLike = None,
    *,
    preset: str | None = None,
    out: str | os.PathLike = "criterion-out",
    n_lab: float | None = None,
    threads: int | None = None,
    n_max: float | None = None,
    n_min: float | None = None,
    seeds: int | None = None,
    progress: bool = True,
) -> DensityStateResult:
    """``poro2d criterion --mode density`` as one call: the criterion for one laboratory state.

    Calibrates the grading (cached), sets the preparation friction from the laboratory
    relative density between ``n_max`` and ``n_min`` and runs the criterion over ``seeds``;
    returns the :class:`~poro2d.sweep.results.DensityStateResult` written to
    ``out/density.json``. ``config`` as for :func:`poro2d.criterion.run_criterion`, whose
    ``[density]`` table the options override. Bad input raises
    :class:`~poro2d.errors.InputError` before anything is written.
    """
    return run_criterion_modes(config, preset=preset, out=out, n_lab=n_lab, threads=threads, mode="density",
                               n_max=n_max, n_min=n_min, seeds=seeds, progress=progress)  # fmt: skip


@holds_output("out")
def run_criterion_modes(
    config: ConfigLike = None,
    *,
    preset: str | None = None,
    out: str | os.PathLike = "criterion-out",
    seed: int | None = None,
    n_lab: float | None = None,
    trial_porosity: float | None = None,
    threads: int | None = None,
    mode: str | None = None,
    n_max: float | None = None,
    n_min: float | None = None,
    seeds: int | None = None,
    progress: bool = True,
) -> CriterionResult | DensityStateResult:
    """``poro2d criterion``: the mode the options or ``[density] mode`` ask for (paper by default).

    Paper mode returns the :class:`~poro2d.criterion.result.CriterionResult` of
    :func:`poro2d.criterion.run_criterion`, density mode the
    :class:`~poro2d.sweep.results.DensityStateResult` of :func:`run_density_criterion`.
    """
    out = Path(out)
    check_output_dir("--out", out)
    inputs = criterion_inputs(config, preset=preset, seed=seed, n_lab=n_lab, trial_porosity=trial_porosity,
                              threads=threads, mode=mode, n_max=n_max, n_min=n_min, seeds=seeds)  # fmt: skip
    if inputs.mode == "paper":
        return run_paper_mode(inputs, out, progress=progress)
    _refuse_paper_options(seed, trial_porosity)
    return _run_density_mode(inputs, out, threads=threads, progress=progress)


__all__ = ["run_criterion_modes", "run_density_criterion"]
