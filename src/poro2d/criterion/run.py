"""``run_criterion``: the criterion of ``poro2d criterion`` as one Python call.

The command only parses its options and prints; everything it computes is here, so a
script gets the same checks, files and resuming.
"""

from __future__ import annotations

import copy
import os
from pathlib import Path
from typing import Any

from poro2d.locks import holds_output

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
            from poro2d.errors import InputError

            raise InputError("config/preset", f"a dict and {preset}", "one of the two, not both")
        from poro2d.criterion.config import check_tables

        check_tables(config)
        return copy.deepcopy(config), None
    return load_config(config, preset, extra_tables=extra_tables)


DENSITY_KEYS = {"mode", "n_max", "n_min", "mu_prep", "seeds"}


def density_settings(cfg: dict, mode, n_max, n_min, seeds, *, preset: bool) -> dict:
    """Mode and density-mode settings from ``[density]`` and the options (options win)."""
    from poro2d import porosity as P
    from poro2d.config import check_keys
    from poro2d.errors import InputError, check_int, check_range
    from poro2d.sweep.density import check_mus

    check_keys("density", cfg.get("density") or {}, DENSITY_KEYS)
    t = dict(cfg.get("density") or {})
    mode = mode if mode is not None else t.get("mode", "paper")
    if mode not in ("paper", "density"):
        raise InputError("mode", mode, "paper or density")
    if mode == "paper":
        # the paper's protocol prepares at friction_prep and uses no laboratory extremes: an
        # option of density mode given with it would be ignored, so it is refused instead
        for option, value in (("--n-max", n_max), ("--n-min", n_min), ("--seeds", seeds)):
            if value is not None:
                raise InputError(option, value, "only with --mode density (paper mode: the paper's protocol)")
        return {"mode": mode, "mu_prep": None}
    mus = t.get("mu_prep")
    out = {"mode": mode, "mu_prep": None if mus is None else check_mus(mus, "density.mu_prep")}
    hi = n_max if n_max is not None else t.get("n_max", P.PAPER_N_MAX if preset else None)
    lo = n_min if n_min is not None else t.get("n_min", P.PAPER_N_MIN if preset else None)
    if hi is None or lo is None:
        raise InputError("density.n_max/n_min", (hi, lo), "both laboratory extremes",
                         "set them in [density] or with --n-max/--n-min")  # fmt: skip
    out["n_max"] = check_range("n_max", hi, 0.0, 1.0, lo_open=True, hi_open=True)
    out["n_min"] = check_range("n_min", lo, 0.0, 1.0, lo_open=True, hi_open=True)
    out["seeds"] = check_int("seeds", seeds if seeds is not None else t.get("seeds", 3), 1, 50)
    return out


@holds_output("out")
def run_criterion(
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
) -> Any:
    """The criterion of Fig. 3 for a config (a dict, a TOML file, or the paper preset when None).

    Paper mode (the default, or ``[density] mode``) runs it once, as the paper does, and
    returns the :class:`~poro2d.criterion.result.CriterionResult` written to
    ``out/result.json``. Density mode calibrates the grading (cached), sets the preparation
    friction from the laboratory relative density between ``n_max`` and ``n_min`` and runs
    the criterion over ``seeds``; it returns the dict written to ``out/density.json``.
    The keyword options override the config as the command's options do. Bad input
    raises :class:`~poro2d.errors.InputError` before anything is written.
    """
    from poro2d.criterion.config import build
    from poro2d.criterion.protocol import PorosityCriterion
    from poro2d.errors import check_int
    from poro2d.io_utils import check_output_dir
    from poro2d.specimen.compaction import check_feasible

    out = Path(out)
    check_output_dir("--out", out)
    cfg, base = load(config, preset)
    if seed is not None:
        cfg["seed"] = check_int("--seed", seed, 0)
    dens = density_settings(cfg, mode, n_max, n_min, seeds, preset=config is None)
    spec, grading, settings, sd = build(
        cfg, base, n_lab=n_lab, trial_porosity=trial_porosity, threads=threads
    )
    check_feasible(spec, grading, settings.initial_trial())
    if dens["mode"] == "density":
        from poro2d.errors import InputError
        from poro2d.sweep.density import run_density_state

        # density mode runs seeds 0 .. seeds-1, each from its state's 2D target: a seed or a
        # first trial of its own would be ignored, so they are refused
        for option, value in (("--seed", seed), ("--trial-porosity", trial_porosity)):
            if value is not None:
                raise InputError(option, value, "only in paper mode (density: --seeds and the 2D target)")
        rest = {k: v for k, v in cfg.items() if k != "density"}
        if threads is not None:
            rest["specimen"] = dict(rest.get("specimen") or {}, threads=spec.threads)
        return run_density_state(rest, base, settings.n_lab, dens["n_max"], dens["n_min"], out,
                                 seeds=dens["seeds"], mus=dens["mu_prep"], progress=progress)  # fmt: skip
    return PorosityCriterion(spec, grading, settings, seed=sd, out=out, progress=progress, config=cfg).run()


__all__ = ["run_criterion"]
