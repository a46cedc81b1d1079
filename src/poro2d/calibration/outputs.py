"""What a calibration writes: result.json and a ready config; what its figures are drawn from."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from poro2d.calibration.evaluations import DesignPoint
from poro2d.calibration.units import CACHE
from poro2d.specimen.specimen_set import SpecimenSet
from poro2d.store import Store

FIT_PNG = "calibration_fit.png"
POSTERIOR_PNG = "calibration_posterior.png"
CONFIG_TOML = "calibrated.toml"


@dataclass(frozen=True)
class FitDrawing:
    """What a calibration's figures are drawn from besides its result: the posterior (``post``,
    its grid or chain), the laboratory values fitted (``lab``), and the curves of the design
    point nearest the best parameters (``curves`` per normal or confining stress, ``nearest``)."""

    post: Any
    lab: Any
    curves: dict[float, list]
    nearest: DesignPoint


def write_outputs(store: Store, result, post, lab, specimens: SpecimenSet, make, stresses) -> FitDrawing:
    """The ready config, then ``result.json`` (its presence says: finished); what the figures and
    the report are drawn from (``draw_calibration`` (``report/calibration_figures.py``)).

    ``make(specimens, label, sigma, fp=, mu_r=)``: the unit of one test (shear or biaxial, its base
    settings bound); ``stresses``: the laboratory's normal (or confining) stresses."""
    curves, nearest = _best_curves(result, stresses, specimens, make, store.child(CACHE))
    store.write_text(CONFIG_TOML, _config(result, stresses))
    store.write_result("result.json", result)
    return FitDrawing(post, lab, curves, nearest)


def _best_curves(
    result, stresses, specimens: SpecimenSet, make, cache: Store
) -> tuple[dict[float, list], DesignPoint]:
    """The curves of the design point nearest the best parameters, per normal stress (all
    specimens), and that design point: what the fit figure draws. Near in log f_p and mu_r (the
    two-parameter rule), and in log kn and log ks over their decades when they are calibrated."""
    best = result.best
    stiffness = [k for k in ("particle_kn", "particle_ks") if getattr(best, k) is not None]

    def distance(e: DesignPoint) -> float:
        d = (math.log(e.particle_friction / best.particle_friction)) ** 2
        d += (e.rolling_friction - best.rolling_friction) ** 2
        for k in stiffness:
            lo, hi = getattr(result.ranges, k)
            d += (math.log(getattr(e, k) / getattr(best, k)) / math.log(hi / lo)) ** 2
        return d

    nearest = min(result.evaluations, key=distance)
    given = {k.removeprefix("particle_"): getattr(nearest, k) for k in stiffness}
    curves: dict[float, list] = {}
    for s in stresses:
        for label in specimens:
            unit = make(
                specimens, label, s, fp=nearest.particle_friction, mu_r=nearest.rolling_friction, **given
            )
            curve = unit.curve(cache)
            if curve is not None:
                curves.setdefault(s, []).append(curve)
    return curves, nearest


def _toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int | float):
        return repr(float(v)) if isinstance(v, float) else str(v)
    if isinstance(v, list | tuple):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    return '"' + str(v).replace("\\", "\\\\").replace('"', '\\"') + '"'


def _known(result) -> str:
    """The intervals in a line of the config's header, or why they are unknown."""
    if result.unidentified is not None:
        return f"NOT IDENTIFIED, intervals unknown: {result.unidentified}"
    names = {"particle_friction": "f_p", "rolling_friction": "mu_r", "particle_kn": "kn", "particle_ks": "ks"}
    spans = [
        f"{names[k]} {lo:.3g} to {hi:.3g}" + (" N/m" if k in _STIFFNESS else "")
        for k, (lo, hi) in result.intervals.to_dict().items()
        if k in names
    ]
    return f"{result.level:.0%} intervals: " + ", ".join(spans)


#: the calibrated stiffnesses: their key in a result and in a ``[specimen]`` table
_STIFFNESS = {"particle_kn": "kn_particle", "particle_ks": "ks_particle"}


def _specimen_lines(best) -> list[str]:
    """The ``[specimen]`` table's calibrated values: both frictions, and kn, ks where calibrated."""
    lines = [
        f"friction_particle = {_toml_value(best.particle_friction)}",
        f"rolling_friction = {_toml_value(best.rolling_friction)}",
    ]
    given = [(name, getattr(best, k)) for k, name in _STIFFNESS.items()]
    return lines + [f"{name} = {_toml_value(v)}" for name, v in given if v is not None]


def _config(result, stresses) -> str:
    """The text of a config with the calibrated values: ``[specimen]`` for a new specimen (``poro2d
    criterion``) to export with ``poro2d export``, and ``[shear]`` for ``poro2d shear --config`` (or
    ``[biaxial]`` for ``poro2d biaxial --config``): the settings used, the calibrated values and
    the laboratory's normal (or confining) stresses."""
    b = result.best
    table = {k: v for k, v in result.settings.to_dict().items() if v is not None}
    table.update(particle_friction=b.particle_friction, rolling_friction=b.rolling_friction)
    if result.biaxial:
        table.update(confining_kpa=list(stresses))
        head = ["# poro2d calibrate (biaxial laboratory tests):", "# the posterior maximum of particle and "
                "rolling friction"]  # fmt: skip
        return _config_text(head, result, "biaxial", table)
    table.update({k: getattr(b, k) for k in _STIFFNESS if getattr(b, k) is not None})
    table.update(normal_stress_kpa=list(stresses))
    what = "particle and rolling friction" + (
        " and the disks' stiffness" if any(getattr(b, k) is not None for k in _STIFFNESS) else ""
    )
    return _config_text([f"# poro2d calibrate: the posterior maximum of {what}"], result, "shear", table)


def _config_text(head: list[str], result, name: str, table: dict) -> str:
    """``head`` comments, the calibrated ``[specimen]`` lines, then the table ``[name]``."""
    lines = [*head, f"# ({_known(result)}); see result.json and calibration.md before using them", "",
             "[specimen]", *_specimen_lines(result.best), "", f"[{name}]"]  # fmt: skip
    return "\n".join(lines + [f"{k} = {_toml_value(v)}" for k, v in table.items()]) + "\n"


__all__ = ["CONFIG_TOML", "FIT_PNG", "POSTERIOR_PNG", "FitDrawing", "write_outputs"]
