"""The calibration section of a report: ``calibration.md`` and ``calibration.html`` beside result.json."""

from __future__ import annotations

from pathlib import Path

from poro2d.calibration.outputs import FIT_PNG, POSTERIOR_PNG
from poro2d.report.document import write_report

#: every parameter a calibration may calibrate: its key in the result, its symbol and its name
PARAMETERS = (
    ("particle_friction", "f_p", "particle friction"),
    ("rolling_friction", "mu_r", "rolling friction"),
    ("particle_kn", "kn", "disk normal stiffness (N/m)"),
    ("particle_ks", "ks", "disk shear stiffness (N/m)"),
)


def calibrated(result) -> list[tuple[str, str, str]]:
    """The parameters ``result`` calibrated (:data:`PARAMETERS` whose range it holds)."""
    return [p for p in PARAMETERS if getattr(result.ranges, p[0]) is not None]


def interval_text(result, name: str) -> str:
    best, interval = getattr(result.best, name), getattr(result.intervals, name)
    if interval is None:  # a design that cannot estimate its noise (``unidentified``)
        return f"{best:.3g} at the posterior maximum; {result.level:.0%} interval unknown"
    lo, hi = interval
    median = getattr(result.posterior.median, name)
    return (
        f"{best:.3g} at the posterior maximum; marginal median {median:.3g},"
        f" {result.level:.0%} interval {lo:.3g} to {hi:.3g}"
    )


def identifiability_note(result) -> str:
    """What the posterior says about identifiability, in words."""
    if result.unidentified:
        return f"Not identified: {result.unidentified}."
    flags = result.posterior.wide.to_dict()  # one per calibrated parameter
    wide = [n for n, w in flags.items() if w]
    corr = result.posterior.correlation
    text = f"The posterior correlation of log(f_p) and mu_r is {corr:+.2f}."
    if abs(corr) > 0.7:
        text += (
            " The laboratory values fix a combination of the two frictions (a ridge in the posterior"
            " figure) better than either one."
        )
    if wide:
        symbols = {key: symbol for key, symbol, _ in PARAMETERS}
        listed = [symbols[n] for n in wide]
        names = " and ".join(listed) if len(listed) < 3 else ", ".join(listed[:-1]) + " and " + listed[-1]
        one = len(wide) == 1
        subject = f"The interval of {names} spans" if one else f"The intervals of {names} span"
        text += (
            f" {subject} more than half the search range: these data do not identify"
            f" {'it' if one else 'them'} well."
            " Peak strengths alone often cannot separate sliding from rolling resistance;"
            + (
                " the volumetric strain, readings along the curves (--stations), more confining stresses"
                " or more replicate specimens narrow it."
                if result.test == "biaxial"
                else " whole curves that soften (the end stress) or that carry the plate's rise (the"
                " dilation), readings along them (--stations), more normal stresses or more replicate"
                " specimens narrow it."
            )
        )
        if any(n in ("particle_kn", "particle_ks") for n in wide):
            text += (
                " The disks' stiffness shows in a curve's first slope more than in its peak or end: readings"
                " early along the curves (--stations) are what see it."
            )
    else:
        text += (
            " Both intervals are narrower than half their search ranges."
            if len(flags) == 2
            else " Every interval is narrower than half its search range."
        )
    return text


def box_note(result) -> str | None:
    """The box the frictions were fitted in, in one line (None for a file written before boxes were
    recorded): parameters fitted to a box-scale box carry its biases (docs/shear.md)."""
    scale = result.box_scale
    if scale is None:  # the shear package's BoxScale (a result read back through its class)
        return None
    fitted = "fitted to a box-scale box: they carry its biases" if scale.box_scale else "fitted"
    warning = f" Warning: {scale.warning()}." if scale.warning() else ""
    return f"{scale.note()}; the frictions are {fitted}.{warning}"


def box_dominated_note(result) -> str | None:
    """How many design points were left out as box-dominated, in one line (None for a biaxial
    calibration or a file written before they were)."""
    left = result.box_dominated
    return None if left is None else f"{left.note[:1].upper()}{left.note[1:]}."


def repeats_note(result) -> str | None:
    """The laboratory repeats fitted as their mean, in one line (None for a single series)."""
    post = result.posterior
    count = post.lab_repeats
    if not count:
        return None
    ratio = post.lab_scatter_ratio
    scaled = "" if ratio is None or ratio <= 1.0 else f", so their share was scaled up by {ratio:.2f}"
    return (
        f"{count} laboratory repeats fitted as their mean; their scatter is {ratio:.2f} times a simulated "
        f"specimen's{scaled}; the laboratory's share of the noise is {max(1.0, ratio or 1.0) / count:.2f}"
        " of one specimen's."
    )


def discrepancy_note(result) -> str | None:
    """The model-discrepancy term in one line (None without one, or in a file written before it)."""
    term = result.posterior.discrepancy
    if term is None:
        return None
    lo, hi = term.interval
    if lo == hi:
        fixed = term.median
        return f"Model discrepancy fixed at {fixed:.3g} noise sd per observable; the intervals include it."
    text = (
        f"Model discrepancy (what the laboratory may miss the model by, in each observable's noise sd):"
        f" median {term.median:.3g}, {100 * result.level:g} % interval {lo:.3g} to {hi:.3g};"
        " the intervals above include it."
    )
    if term.saturated:
        text += (
            " Its interval reaches the prior's top: the laboratory may lie further from the model than"
            " the term allows, and the intervals may still be too narrow."
        )
    return text


def notes(result) -> list[str]:
    """What the posterior says about identifiability, then the notes of the repeats, the discrepancy,
    the box and the box-dominated points that apply, each a line."""
    found = (repeats_note(result), discrepancy_note(result), box_note(result), box_dominated_note(result))
    return [identifiability_note(result), *(note for note in found if note)]


def fit_table(observables) -> tuple[list[str], list[list]]:
    """The fit table's header and rows: in kPa while every target is a stress; with dilation
    targets (mm) each row names its unit."""
    units = [o.unit for o in observables]
    if all(u == "kPa" for u in units):
        header = ["observable", "normal stress (kPa)", "laboratory (kPa)", "model (kPa)", "noise sd (kPa)"]
        rows = [[o.observable, o.normal_stress_kpa, o.lab, o.model, o.noise_sd] for o in observables]
    else:  # biaxial targets: the stress is sigma_3, every value dimensionless ("1")
        stress = "confining stress (kPa)" if all(u == "ratio" for u in units) else "normal stress (kPa)"
        header = ["observable", stress, "unit", "laboratory", "model", "noise sd"]
        unit = {"ratio": "1"}  # a dimensionless value's unit as the table shows it
        rows = [
            [o.observable, o.normal_stress_kpa, unit.get(o.unit, o.unit), o.lab, o.model, o.noise_sd]
            for o in observables
        ]
    if any(o.stiffness_number is not None for o in observables):
        # how much elastic strain a volumetric observable carries: kappa and the overlap at the peak
        header = [*header, "kappa", "overlap / d at peak"]
        rows = [[*r, o.stiffness_number, o.mean_overlap_ratio_at_peak]
                for r, o in zip(rows, observables, strict=True)]  # fmt: skip
    return header, rows


def _tests(result) -> str:
    """What the calibration ran, as the report names it."""
    return "Biaxial tests" if result.test == "biaxial" else "Shear tests"


def calibration_blocks(result, out: Path) -> list[tuple]:
    """The section's blocks: best values, identifiability, the fit table and the two figures."""
    header, rows = fit_table(result.posterior.observables)
    info, two = result.cluster, len(calibrated(result)) == 2
    posterior = "The posterior over (f_p, mu_r)" if two else "The pairwise marginals of the sampled posterior"
    lab = (
        f"Laboratory data: {result.lab.source} ({result.lab.kind}); "
        f"{len(result.specimens)} replicate specimen(s); {len(result.evaluations)} design points."
    )
    work = (
        f"{_tests(result)}: {info.tests_run} run, {info.tests_reused} reused from the cache, "
        f"{info.tests_failed} failed; wall time {result.timings.wall_time_s:.0f} s."
    )
    values = [f"{name} {symbol} = {interval_text(result, key)}" for key, symbol, name in calibrated(result)]
    return [
        ("h2", "Calibration of particle and rolling friction" + ("" if two else " and stiffness")),
        ("p", lab),
        ("ul", values),
        *(("p", note) for note in notes(result)),
        ("table", header, rows),
        ("img", str(out / FIT_PNG), "The calibrated model beside the laboratory values and curves."),
        ("img", str(out / POSTERIOR_PNG), f"{posterior}, with the evaluated points."),
        ("p", work),
    ]


def write_calibration_report(out: Path, result) -> list[Path]:
    return write_report(calibration_blocks(result, out), out, "calibration", "poro2d calibration")


__all__ = [
    "PARAMETERS",
    "box_note",
    "calibrated",
    "calibration_blocks",
    "fit_table",
    "interval_text",
    "identifiability_note",
    "notes",
    "write_calibration_report",
]
