"""The report of ``poro2d paper``: poro2d's numbers beside the paper's, with every figure.

The report is made from the results themselves, never from files: the case study's
summary (a ``PaperSummary``), the criterion's results (a
:class:`~poro2d.criterion.result.CriterionOutputs`), the shear figures the run wrote, and a
calibration or a sensitivity study when there is one. The command that resumes a finished
run reads them through their result classes. The report layer sits below the criterion (the
criterion draws its force chains here), so it reads those objects by their fields and
imports none of their classes.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

from poro2d.report.document import Block, write_report
from poro2d.report.paper_fabric import fabric_blocks

#: where ``poro2d calibrate --out`` puts a calibration the paper report shows (``paper-out/calibration``)
CALIBRATION_FOLDER = "calibration"
#: the shear figures of the report, by the name the case study gives them, with their captions
SHEAR_FIGURES = {
    "curves_replicates": "Fig. 8(a): shear stress against shear displacement, mean and +- sd band over the "
    "specimens",
    "peaks_replicates": "Fig. 8(b): peak strength against normal stress over the specimens, with the fitted "
    "lines",
    "curves_first": "The first specimen's curves with the plate displacement",
}
#: the conversion figures, by file name, with their captions
CONVERSION_FIGURES = {
    "fig1_relations.png": "Fig. 1: 2D porosity against laboratory porosity, all methods",
    "fig2_lim_parabola.png": "Fig. 2: LIM 2D-Lab, LIM 2D-3D and the parabola of Eq. 12",
}


def build_blocks(
    out: Path,
    summary,
    criterion,
    *,
    shear_figures: dict[str, Path] | None = None,
    calibration: Any = None,
    sensitivity: Any = None,
    shear_series: dict | None = None,
) -> list[Block]:
    """The report's blocks: summary, inputs, conversions, criterion, sensitivity, shear, fabric,
    provenance.

    ``summary``: the case study's ``PaperSummary``; ``criterion``: its criterion's results
    (a ``CriterionOutputs``); ``shear_figures``: the shear figures written, by a name of
    :data:`SHEAR_FIGURES`; ``calibration``: a ``CalibrationResult`` kept in
    ``out/calibration``; ``sensitivity``: a ``SensitivityResult`` to explain the paper's value;
    ``shear_series``: each specimen's ``ShearSeriesResult`` with its curves, by label, the first
    specimen first (their fabric's section; its figures among ``shear_figures``).
    """
    crit = criterion.result
    b = _intro_blocks(summary, crit)
    b += _inputs_blocks(summary, crit)
    b += _conversion_blocks(out, summary.conversions)
    b += _criterion_blocks(criterion, summary.paper.criterion, _measured_angle(summary.shear))
    if sensitivity is not None:  # why the paper gets what it gets, when the run holds a sensitivity study
        from poro2d.report.sensitivity_report import report_blocks

        b += report_blocks(sensitivity)
    if summary.shear:
        b += _shear_blocks(summary.shear, shear_figures or {})
        b += fabric_blocks(shear_series or {}, shear_figures or {})
    b += _calibration_blocks(calibration, out / CALIBRATION_FOLDER)
    b += _provenance_blocks(summary, crit)
    return b


def _calibration_blocks(calibration: Any, folder: Path) -> list[Block]:
    """The calibration's section, when ``poro2d calibrate --out <paper-out>/calibration`` has run."""
    if calibration is None:
        return []
    from poro2d.report.calibration_report import calibration_blocks

    return calibration_blocks(calibration, folder)


def _intro_blocks(summary, crit) -> list[Block]:
    """The title, the paper's case in one paragraph, and the summary table beside the paper."""
    paper = summary.paper
    pc = paper.criterion
    its = [r.to_dict() for r in crit.iterations or []]  # each trial's row (its keys are not its fields)
    shear = summary.shear
    b: list[Block] = [("h1", "poro2d: the paper's case study"), ("note", PAPER_MODE_CAVEAT)]
    b.append((
        "p",
        "Wang, Jacobs and Ziegler, 'A new suggestion for determining 2D porosities in DEM studies': "
        f"laboratory porosity nLab = {paper.n_lab} (dry density {paper.dry_density_kg_m3:.0f} "
        f"kg/m3, solid density {paper.solid_density_kg_m3:.0f} kg/m3), nLab,max = {paper.n_max}, "
        f"nLab,min = {paper.n_min}."
        + (" Quick mode: a reduced specimen, not the paper's box." if summary.quick else ""),
    ))  # fmt: skip
    b.append(("h2", "Summary"))
    rows = [["accepted 2D porosity", crit.final_porosity, pc.accepted_porosity]]
    if crit.interior_porosity is not None:
        rows.append(["box porosity n' of the accepted specimen (gap under the plate included)",
                     crit.box_porosity, "-"])  # fmt: skip
        inner = f"{crit.interior_porosity:.4f} +- {crit.interior_porosity_std:.4f}"
        rows.append(["interior porosity of the accepted specimen (the packing's own)", inner, "-"])
    if its:
        rows.append(["first trial porosity (Eq. 12, rounded)", its[0]["trial_porosity"], pc.trials[0]])
        rows.append(["number of trials", len(its), len(pc.trials)])
    reps = summary.replicate_specimens or []
    if reps:
        n2d = [r.final_porosity for r in reps if r.converged]
        rows.append([
            "accepted n2D of the replicate seeds", ", ".join(f"{v:.2f}" for v in n2d) or "none accepted", "-",
        ])  # fmt: skip
    if shear:
        fit = getattr(shear.replicates, "fit", None)
        ci = fit.friction_angle_ci_deg if fit is not None else None
        phi = shear.friction_angle_deg
        if phi is not None and ci:
            phi = f"{phi:.1f} ({fit.level:.0%} interval {ci[0]:.1f} to {ci[1]:.1f})"
        scale = shear.extra.get("box_scale")  # the shear package's BoxScale: box-scale angles are labelled
        label = f" ({scale.label()})" if scale is not None and scale.label() else ""
        rows.append([f"friction angle from peak strengths{label} (deg)", phi, "not stated"])
    b.append(("table", ["quantity", "poro2d", "paper"], rows))
    b.append(("note", crit.message if crit.message is not None else "criterion not run"))
    return b + _specimen_blocks(summary)


def _specimen_blocks(summary) -> list[Block]:
    """How many of the specimens asked for were sheared, and the seeds refused (a summary of an
    earlier poro2d did not record it: nothing)."""
    asked, seeds = getattr(summary, "specimens_asked", None), getattr(summary, "specimen_seeds", None)
    if asked is None or seeds is None:
        return []
    refused = [
        f"replicate seed {r.seed} not accepted ({r.reason}): "
        + ("no seed left to replace it" if r.replaced_by is None else f"replaced by seed {r.replaced_by}")
        for r in summary.seeds_replaced or []
    ]
    text = f"Specimens sheared: {len(seeds)} of the {asked} asked for (seeds {', '.join(map(str, seeds))})."
    if len(seeds) < asked:
        text += " The direct shear results below are over fewer specimens than asked for."
    return [("note" if len(seeds) < asked else "p", text), *([("ul", refused)] if refused else [])]


#: what paper mode is and is not, said before any number (the report's first note)
PAPER_MODE_CAVEAT = (
    "Paper mode reproduces the paper's procedure, not a soil at its laboratory density: it ignores "
    "the dry density below except to state nLab, starts from the 2D porosity of Eq. 12 (the "
    "parabola of nLab) and keeps the porosity the criterion accepts, so the accepted 2D porosity "
    "is Eq. 12's and the criterion's, whatever density the laboratory specimen had. For a soil at a "
    "laboratory state (its grading, density and strength), run `poro2d sand` (docs/sand.md); "
    "`poro2d criterion` in density mode targets a laboratory density (docs/criterion.md)."
)


def _inputs_blocks(summary, crit) -> list[Block]:
    """What is reconstructed or assumed where the paper is silent."""
    spec, pc = crit.specimen, summary.paper.criterion
    pairs = enumerate(zip(pc.particle_counts, pc.trials, strict=True))
    counts = ", ".join(f"{n} disks at {t:g}" if i == 0 else f"{n} at {t:g}" for i, (n, t) in pairs)
    quick = [
        f"Quick mode: a {spec.width} m x {spec.height} m box in {spec.layers} "
        "layers, the criterion's force window widened to "
        f"{crit.settings.force_fraction:.0%} of G (in so small a box 1 % "
        "of G is about two disks' weight), shear to 4 mm: a first look, not the paper's case.",
    ] if summary.quick else []  # fmt: skip
    return [("h2", "Inputs the paper does not give"), ("ul", [
        "Grading curve: a reconstruction of the paper's Fig. 4 (a medium sand, up-scaled x10), matched "
        f"to the paper's particle counts ({counts}); see docs/grading.md. The "
        "real curve can replace it ([grading] csv = ...).",
        f"Local damping {spec.local_damping} (PFC 4.0's default; the paper does not state it).",
        "Contact properties combined PFC 4.0 style (springs in series, smaller friction), as Table 1 lists "
        "them per body.",
        f"Disk thickness {spec.thickness} m (the paper's 8 mm); forces per metre of thickness.",
        "Multilayer compaction by radius expansion inside each band under a temporary lid "
        f"({spec.layers} layers), equilibrium at a maximum unbalanced-force ratio of "
        f"{spec.ratio}.",
        *quick,
        "Direct shear: the shear velocity is far above the laboratory rate of 0.384 mm/min "
        f"(the quasi-static checks are in the direct shear section); {_lab_text(summary)} A test "
        "ends once its smoothed peak lies stop_after_peak (5 mm by default) behind, or at "
        "max_displacement (20 mm); each test's "
        "result.json says which (ended_by).",
    ])]  # fmt: skip


def _lab_text(summary) -> str:
    """Where the laboratory shear data of Fig. 8 come from in this run, if from anywhere."""
    lab = summary.lab
    if not lab:
        return (
            "no laboratory curves are built in (Fig. 8's data are not published as numbers): "
            "pass them with --lab."
        )
    peaks = len(lab.peaks or [])
    what = f"laboratory {lab.kind or 'data'} from {lab.source} ({peaks} peak(s))"
    if not summary.shear:
        return f"{what} were given, but no test ran to compare them with."
    return f"{what} are drawn beside the DEM's in Fig. 8."


def _conversion_blocks(out: Path, conv) -> list[Block]:
    """The table of Eqs. 1-12 and Figs. 1-2 (the figures the conversions stage lists)."""
    cdir = out / "conversions"
    figures = [("img", cdir / name, CONVERSION_FIGURES[name]) for name in conv.figures or []
               if name in CONVERSION_FIGURES]  # fmt: skip
    return [
        ("h2", "3D-to-2D conversions (Eqs. 1-12)"),
        ("table", ["method", "equation", "n2D", "flags"],
         [[m.method, m.equation, m.n2d, m.flags] for m in conv.methods]),
        *figures,
    ]  # fmt: skip


#: the criterion's figures in the report, by file name, with their captions
CRITERION_CAPTIONS = {
    "fig5_forces_initial_trial.png": "Fig. 5: contact forces at the initial trial porosity, top plate at H",
    "fig6_forces_after_plate.png": "Fig. 6: contact forces after the top plate moved",
    "fig7_forces_accepted.png": "Fig. 7: contact forces at the accepted porosity",
}


#: the rows of the trials' table: a label and the key of a trial's row (None: a trial without it)
TRIAL_ROWS = (
    ("trial n2D", "trial_porosity"),
    ("disks", "particle_count"),
    ("F_top at H (N/m)", "f_top_n_per_m"),
    ("F_bottom at H (N/m)", "f_bottom_n_per_m"),
    ("G = rho_s (1-n) W H g (N/m)", "self_weight_n_per_m"),
    ("top plate moved", "plate_moved"),
    ("plate displacement (mm)", "plate_displacement_mm"),
    ("F_top after (N/m)", "f_top_after_n_per_m"),
    ("F_bottom after (N/m)", "f_bottom_after_n_per_m"),
    ("n'", "new_porosity"),
    ("|n' - n2D|", "porosity_change"),
    ("interior porosity", "interior_porosity"),
    ("mean gap under the plate (d50)", "surface_gap_mean_d50"),
    ("accepted", "accepted"),
)


def _shown(trial: dict) -> dict:
    """A trial's row as its table shows it: the plate's displacement in mm, the verdict in words."""
    accepted = "yes" if trial["accepted"] else "no"
    return dict(trial, plate_displacement_mm=1e3 * trial["plate_displacement_m"], accepted=accepted)


def _measured_angle(shear) -> float | None:
    """The friction angle this run measured: the Mohr-Coulomb fit of the direct shear peaks (deg)."""
    return getattr(shear, "friction_angle_deg", None) if shear else None


def _criterion_blocks(criterion, pc, phi: float | None = None) -> list[Block]:
    """poro2d's trials beside the paper's, the discussion, Figs. 5-7 and the specimen's state."""
    b: list[Block] = [("h2", "The criterion (Fig. 3)")]
    its = [r.to_dict() for r in criterion.result.iterations or []]  # each trial's row
    if its:
        rows = [[label, *[_shown(r).get(key) for r in its]] for label, key in TRIAL_ROWS]
        b.append(("table", ["", *[f"trial {r['iteration']}" for r in its]], rows))
        b.append(("p", "The paper's run, for comparison:"))
        b.append((
            "table",
            ["", "trial 1", "trial 2"],
            [
                ["trial n2D", *pc.trials],
                ["disks", *pc.particle_counts],
                ["F_top at H (N/m)", 1e3 * pc.f_top_first_trial_kn_per_m, pc.f_top_accepted_n_per_m],
                ["F_bottom at H (N/m)", 1e3 * pc.f_bottom_first_trial_kn_per_m, pc.f_bottom_accepted_n_per_m],
                ["G (N/m)", pc.self_weight_first_trial_n_per_m, pc.self_weight_accepted_n_per_m],
                ["|n' - n2D|", pc.porosity_change_first_trial, "-"],
                ["accepted", "no", "yes"],
            ],
        ))  # fmt: skip
        b.extend(_criterion_discussion(its, pc))
    for name, cap in CRITERION_CAPTIONS.items():
        if name in criterion.figures:
            b.append(("img", criterion.figures[name], cap))
    return b + _state_blocks(criterion, phi) + _porosity_blocks(criterion)


def _provenance_blocks(summary, crit) -> list[Block]:
    """Version, machine, seed, timings and the settings of the run."""
    return [
        ("h2", "Provenance"),
        ("table", ["item", "value"], [[k, str(v)] for k, v in _as_dict(summary.provenance).items()]
         + [["seed", summary.seed]]
         + [[f"time: {k}", v] for k, v in _as_dict(summary.timings).items()]),
        ("code", json.dumps({"specimen": _as_dict(crit.specimen), "criterion": _as_dict(crit.settings)},
                            indent=1)),
    ]  # fmt: skip


def _as_dict(part) -> dict:
    """A typed part as the dict of its file (empty when missing)."""
    return part.to_dict() if part is not None else {}


def _criterion_discussion(its: list[dict], pc) -> list[Block]:
    first = its[0]
    out: list[Block] = [("h3", "Where poro2d differs from the paper")]
    notes = []
    ratio = first["f_top_n_per_m"] / (1e3 * pc.f_top_first_trial_kn_per_m)
    notes.append(
        f"At the first trial the top plate carries {first['f_top_n_per_m']:.4g} N/m, "
        f"{ratio:.2g} times the paper's {pc.f_top_first_trial_kn_per_m:g} kN/m; both are far above the "
        "self weight, so the "
        "branch taken is the same (the plate moves up)."
    )
    if first.get("plate_moved") == "up":
        notes.append(
            f"After the plate moved, n' = {first['new_porosity']:.4f} "
            f"(change {first['porosity_change']:.4f}; "
            f"paper: {pc.trials[0] + pc.porosity_change_first_trial:.3f}, change "
            f"{pc.porosity_change_first_trial:g}). The reconstructed grading is narrow (Cu about 1.7): "
            "disks of similar size leave larger voids than a well-graded sand, so the specimen relaxes to a "
            "looser state than the paper's. The accepted porosity follows from the grading; with the real "
            "Fig. 4 curve the result may differ."
        )
    notes.append(
        f"The paper's F_bottom ({pc.f_bottom_accepted_n_per_m:g} N/m) is close to G "
        f"({pc.self_weight_accepted_n_per_m:g} N/m). poro2d reports F_bottom and the vertical "
        "friction of the side walls separately: their sum balances the weight plus F_top."
    )
    out.append(("ul", notes))
    return out


def _state_blocks(criterion, phi: float | None = None) -> list[Block]:
    """Homogeneity and stress state of the accepted specimen, when the criterion wrote them, and its
    K0 beside Jaky's for the friction angle ``phi`` (deg) the run measured."""
    st = criterion.state
    if st is None:
        return []
    k0 = st.k0_mean
    ratio = st.sigma_v_bottom_over_geostatic
    b: list[Block] = [("h3", "The accepted specimen: homogeneity and stress state")]
    b.append((
        "p",
        f"Porosity in {len(st.bands)} horizontal bands: mean {st.porosity_mean:.4f}, sd "
        f"{st.porosity_sd:.4f}, range {st.porosity_range:.4f} (disks clipped at the band edges). "
        + (f"K0 = sigma_h / sigma_v averages {k0:.2f} over the bands; " if k0 is not None else "")
        + (f"in the bottom band sigma_v is {ratio:.2f} x the geostatic stress "
           "(F_top / W plus the weight above; the side walls carry the rest by friction)." if ratio else ""),
    ))  # fmt: skip
    if k0 is not None:
        b += k0_blocks(k0, st.k0_sd, phi)
    if "specimen_state.png" in criterion.figures:
        cap = "Porosity and stresses of the accepted specimen, by height"
        b.append(("img", criterion.figures["specimen_state.png"], cap))
    return b


def jaky_k0(phi_deg: float) -> float:
    """Jaky's coefficient of earth pressure at rest, K0 = 1 - sin(phi') (Jaky 1944, Journal of the
    Society of Hungarian Architects and Engineers 78(22), 355-358), for ``phi_deg`` in degrees."""
    return 1.0 - math.sin(math.radians(phi_deg))


def k0_blocks(k0: float, k0_sd: float | None, phi: float | None) -> list[Block]:
    """The accepted specimen's K0 beside Jaky's 1 - sin(phi) for the angle the run measured, and why
    they differ."""
    sd = f" (sd {k0_sd:.2f} over the bands)" if k0_sd is not None else ""
    rows = [["K0 = sigma_h / sigma_v of the accepted specimen (Love-Weber stress of its disks, mean over "
             "the bands)", f"{k0:.2f}{sd}"]]  # fmt: skip
    if phi is not None:
        jaky = jaky_k0(phi)
        rows.append([f"Jaky (1944): K0 = 1 - sin phi, phi = {phi:.1f} deg (this run's direct shear peaks)",
                     f"{jaky:.2f}"])  # fmt: skip
        rows.append(["ratio of the two", f"{k0 / jaky:.2f}"])
    return [("table", ["K0", "value"], rows), ("p", k0_note(k0, None if phi is None else jaky_k0(phi)))]


#: K0 of the paper's accepted specimen (seed 0, f_p 3.0) under one-dimensional loading (d sigma_h /
#: d sigma_v from 100 to 200 kPa) and unloaded to 50 kPa (benchmarks/k0_one_dimensional.py;
#: docs/criterion.md, "K0")
K0_LOADING = 0.40
K0_UNLOADED = 0.76
#: the relative difference within which a K0 is said to agree with Jaky's
K0_AGREEMENT = 0.15


def k0_note(k0: float, jaky: float | None = None) -> str:
    """Why the prepared specimen's K0 is or is not Jaky's, with the numbers that say so (``jaky``:
    Jaky's K0 for the angle the run measured; None: the range for sands)."""
    if jaky is not None and abs(k0 / jaky - 1.0) <= K0_AGREEMENT:
        return (
            f"K0 {k0:.2f} is within {K0_AGREEMENT:.0%} of Jaky's 1 - sin phi ({jaky:.2f} for the angle "
            "this run measured), the K0 of a normally consolidated soil."
        )
    reference = "about 0.4-0.5 for sands" if jaky is None else f"{jaky:.2f} for the angle this run measured"
    return (
        f"K0 {k0:.2f} is not Jaky's 1 - sin phi ({reference}): that is the K0 of a soil "
        "loaded one-dimensionally from a loose deposit, while this specimen was built by growing its "
        "disks in layers under a lid, which presses them in every direction and locks in a lateral "
        "stress near the vertical one, as in an overconsolidated soil; under self-weight alone "
        "nothing has loaded it since. Loaded one-dimensionally (side walls held, up to 200 kPa), the "
        f"paper's specimen gives K0 = {K0_LOADING:.2f} (Jaky's value for phi near 37 deg) and "
        f"{K0_UNLOADED:.2f} once unloaded to a quarter of that stress: a K0 near 1 says how the "
        'specimen was made, not what the disks are (docs/criterion.md, "K0").'
    )


#: what the box and the interior porosity each say
POROSITY_NOTE = (
    "The paper's n' counts the gap between the plate and the rough surface of the specimen; the "
    "interior porosity is the packing's own and does not depend on the box's size. To build this "
    "specimen in another code, take the interior porosity (docs/porosity.md)."
)


def _porosity_blocks(criterion) -> list[Block]:
    """Box against interior porosity of the accepted specimen, the plate's surface, the local map."""
    m = criterion.porosity
    if m is None or m.interior_porosity is None:
        return []
    b: list[Block] = [("h3", "The accepted specimen: box porosity and the specimen's own porosity")]
    regions = f"{m.interior_regions} circles, {m.margin_d50:g} d50 clear of walls and surface"
    gap = f"{1e3 * m.surface_gap_mean_m:.2f} mm = {m.surface_gap_mean_d50:.2f} d50"
    contact = f"{100 * m.plate_contact_fraction:.1f} % ({m.plate_touching_disks} disks)"
    rows = [
        ["box porosity n' (the paper's: W x plate height)", m.box_porosity],
        [f"interior porosity ({regions})",
         f"{m.interior_porosity:.4f} +- {m.interior_porosity_std:.4f}"],
        ["interior rectangle / Laguerre cells",
         f"{m.interior_rect_porosity:.4f} / {m.laguerre_interior_porosity:.4f}"],
        ["mean gap under the plate", gap],
        ["plate width in contact", contact],
    ]  # fmt: skip
    b.append(("table", ["measure", "value"], rows))
    b.append(("p", POROSITY_NOTE))
    if "local_porosity.png" in criterion.figures:
        cap = "Local porosity of the accepted specimen (Laguerre cells)"
        b.append(("img", criterion.figures["local_porosity.png"], cap))
    return b


def _shear_blocks(shear, figures: dict[str, Path]) -> list[Block]:
    """Fig. 8 over the replicate specimens: peaks mean +- sd, the pooled fit with its intervals."""
    b: list[Block] = [("h2", "Direct shear tests (Fig. 8)")]
    rep = shear.replicates  # None in a summary without replicates: no rows, no fits
    rows = getattr(rep, "per_normal_stress", None) or []
    n = len(getattr(rep, "specimens", None) or [])
    if rows:
        b.append((
            "p",
            f"The same tests on {n} specimen(s), one per seed, each accepted by the criterion itself: a "
            "peak from one specimen is one sample of a chaotic packing, so the peaks are given as mean "
            "+- sd over the specimens and the Mohr-Coulomb line is fitted to every specimen's peaks.",
        ))  # fmt: skip
        b.append((
            "table",
            ["normal stress (kPa)", "peak mean (kPa)", "peak sd (kPa)", "specimens", "peaks (kPa)"],
            [[r.normal_stress_kpa, r.peak_mean_kpa, r.peak_sd_kpa, r.n,
              ", ".join(f"{v:.1f}" for v in r.peaks_kpa)] for r in rows],
        ))  # fmt: skip
    fits = []
    for key, name in (("fit", "least squares"), ("fit_through_origin", "through the origin (c = 0)")):
        f = getattr(rep, key, None)
        if f is None:
            continue
        ci, cci = f.friction_angle_ci_deg, f.cohesion_ci_kpa
        fits.append(
            f"{name}: phi = {f.friction_angle_deg:.1f} deg"
            + (f" ({f.level:.0%} interval {ci[0]:.1f} to {ci[1]:.1f})" if ci else " (too few points)")
            + (f", c = {f.cohesion_kpa:.1f} kPa ({cci[0]:.1f} to {cci[1]:.1f})" if cci else "")
        )  # fmt: skip
    per = getattr(rep, "friction_angle_per_specimen_deg", None) or []
    if per:
        fits.append("phi of each specimen alone: " + ", ".join(f"{v:.1f}" for v in per) + " deg")
    if fits:
        b.append(("ul", fits))
    elif shear.friction_angle_deg is not None:
        b.append(("p", f"Mohr-Coulomb fit of the peaks: friction angle {shear.friction_angle_deg:.3g} deg."))
    scale = shear.extra.get("box_scale")
    if scale is not None:
        b.append(("note", scale.note() + ("" if scale.warning() is None else f"; {scale.warning()}")))
    for name, cap in SHEAR_FIGURES.items():
        if name in figures:
            b.append(("img", figures[name], cap))
    return b + quasi_static_blocks(shear)


#: the columns of the quasi-static checks' table, one row per test
CHECK_COLUMNS = [
    "normal stress (kPa)", "max inertial number I", "I below the limit",
    "upper half against shear plane (mean abs. difference / tau)",
    "largest normal stress error after consolidation",
    "coordination number at the end", "ended by",
]  # fmt: skip


def quasi_static_blocks(shear) -> list[Block]:
    """The quasi-static checks each direct shear test recorded: its largest inertial number against
    the limit, the force balance of the upper half against the shear plane, the servo's normal
    stress error, and the coordination number at the end of the test."""
    tests = getattr(shear, "tests", None) or []  # the first specimen's (the summary keeps those)
    if not tests:
        return []
    qs = getattr(shear, "quasi_static", None)
    b: list[Block] = [("h3", "Quasi-static checks (the first specimen's tests)")]
    if qs is not None:
        verdict = "every test below it" if qs.inertial_number_ok else "NOT every test below it"
        b.append((
            "p",
            "Inertial number I (largest over the tests of the first specimen: "
            f"{_num(qs.max_inertial_number)}; limit {qs.inertial_limit:g}, {verdict}): "
            f"{qs.inertial_number_definition}. "
            "The shear force carried by the upper half should equal the force across the shear plane; "
            "their mean difference over the test, relative to the shear force, says how far the box "
            "is from equilibrium while it is sheared. The kinetic energy is not recorded by the "
            "direct shear test: the inertial number and this balance are its checks.",
        ))  # fmt: skip
    b.append(("table", CHECK_COLUMNS, [_check_row(t) for t in tests]))
    return b


def _check_row(t) -> list:
    """One test's row of the quasi-static checks."""
    balance = getattr(t.force_balance, "mean_abs_upper_minus_plane_rel", None)
    end = getattr(t.end, "coordination_number", None)
    return [
        t.normal_stress_kpa, _num(t.max_inertial_number), "yes" if t.inertial_number_ok else "no",
        _percent(balance), _percent(t.normal_stress_max_error_after_consolidation),
        _num(end, ".2f"), t.ended_by or "-",
    ]  # fmt: skip


def _num(value, fmt: str = ".2e") -> str:
    return "-" if value is None else format(value, fmt)


def _percent(value) -> str:
    return "-" if value is None else f"{100 * value:.1f} %"


def write_paper_report(out: str | Path, summary, criterion, **parts) -> list[Path]:
    """report.md and report.html in ``out``; ``parts``: the keywords of :func:`build_blocks`."""
    out = Path(out)
    blocks = build_blocks(out, summary, criterion, **parts)
    return write_report(blocks, out, "report", "poro2d: the paper's case study")
