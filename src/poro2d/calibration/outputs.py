"""What a calibration writes: result.json, the fit and posterior figures, a ready config, a report."""

from __future__ import annotations

import math

from poro2d.calibration.evaluations import DesignPoint
from poro2d.calibration.specimens import replicate_unit
from poro2d.calibration.units import CACHE, unit_curve
from poro2d.specimen.specimen_set import SpecimenSet
from poro2d.store import Store

FIT_PNG = "calibration_fit.png"
POSTERIOR_PNG = "calibration_posterior.png"
CONFIG_TOML = "calibrated.toml"


def write_outputs(store: Store, result, post, surrogates, lab, specimens: SpecimenSet, base) -> None:
    """Figures, config and report first; ``result.json`` last (its presence says: finished)."""
    from poro2d.report.calibration_figures import plot_calibration_fit, plot_calibration_posterior

    curves, nearest = _best_curves(result, lab, specimens, base, store.child(CACHE))
    plot_calibration_fit(result, lab, curves, nearest, store.path(FIT_PNG))
    plot_calibration_posterior(result, post, store.path(POSTERIOR_PNG))
    store.write_text(CONFIG_TOML, _config(result, lab))
    from poro2d.report.calibration_report import write_calibration_report

    write_calibration_report(store.root, result)
    store.write_result("result.json", result)


def _best_curves(
    result, lab, specimens: SpecimenSet, base, cache: Store
) -> tuple[dict[float, list], DesignPoint]:
    """The curves of the design point nearest the best parameters, per normal stress (all
    specimens), and that design point: what the fit figure draws."""
    best = result.best
    nearest = min(
        result.evaluations,
        key=lambda e: (
            (math.log(e.particle_friction / best["particle_friction"])) ** 2
            + (e.rolling_friction - best["rolling_friction"]) ** 2
        ),
    )
    curves: dict[float, list] = {}
    for s in lab.normal_stresses():
        for label in specimens:
            unit = replicate_unit(
                specimens, label, s, base, nearest.particle_friction, nearest.rolling_friction
            )
            curve = unit_curve(unit, cache)
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


def _config(result, lab) -> str:
    """The text of a config with the calibrated values: ``[shear]`` for ``poro2d shear --config``,
    ``[specimen]``
    for a new specimen (``poro2d criterion``) to export with ``poro2d export``."""
    b = result.best
    shear = {k: v for k, v in result.settings.items() if v is not None}
    shear.update(
        particle_friction=b["particle_friction"],
        rolling_friction=b["rolling_friction"],
        normal_stress_kpa=lab.normal_stresses(),
    )
    if result.unidentified is None:
        fp_lo, fp_hi = result.intervals["particle_friction"]
        mr_lo, mr_hi = result.intervals["rolling_friction"]
        known = (
            f"{result.level:.0%} intervals: f_p {fp_lo:.3g} to {fp_hi:.3g}, mu_r {mr_lo:.3g} to {mr_hi:.3g}"
        )
    else:
        known = f"NOT IDENTIFIED, intervals unknown: {result.unidentified}"
    lines = [
        "# poro2d calibrate: the posterior maximum of particle and rolling friction",
        f"# ({known}); see result.json and calibration.md before using them",
        "",
        "[specimen]",
        f"friction_particle = {_toml_value(b['particle_friction'])}",
        f"rolling_friction = {_toml_value(b['rolling_friction'])}",
        "",
        "[shear]",
    ] + [f"{k} = {_toml_value(v)}" for k, v in shear.items()]
    return "\n".join(lines) + "\n"


__all__ = ["CONFIG_TOML", "FIT_PNG", "POSTERIOR_PNG", "write_outputs"]
