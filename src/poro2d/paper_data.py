"""The paper's facts in one place: its sand, its criterion run, its quick-look settings.

Numbers the paper states (Wang, Jacobs and Ziegler, sections 2.2, 3 and 4, Table 1); the
porosities and densities are :mod:`poro2d.porosity`'s constants. Held below every layer
that quotes them (the case study, its report, the sensitivity study), so none of those
reaches up into another to read them. Table 1's per-body properties are ``TABLE_1``: the
defaults of :class:`poro2d.specimen.compaction.SpecimenSpec`, of the shear box's walls and of
an imported file that does not state them.
"""

from __future__ import annotations

from dataclasses import dataclass

from poro2d import porosity as P


@dataclass(frozen=True)
class Table1:
    """Table 1: the per-body properties of the disks and the box walls (PFC 4.0; SI units).

    A contact combines its two bodies' stiffnesses as springs in series and takes the
    smaller friction (docs/engine.md).
    """

    solid_density: float = P.PAPER_SOLID_DENSITY  # kg/m3
    kn_particle: float = 4e5  # N/m
    ks_particle: float = 4e5  # N/m
    friction_particle: float = 3.0  # after preparation
    kn_wall: float = 1e7  # N/m
    ks_wall: float = 1e7  # N/m
    friction_wall: float = 1.5


TABLE_1 = Table1()

PAPER = {
    "n_lab": P.PAPER_N_LAB,
    "n_max": P.PAPER_N_MAX,
    "n_min": P.PAPER_N_MIN,
    "dry_density_kg_m3": P.PAPER_DRY_DENSITY,
    "solid_density_kg_m3": P.PAPER_SOLID_DENSITY,
    # numbers the paper reports for its criterion run (section 3)
    "criterion": {
        "trials": [0.14, 0.15],
        "particle_counts": [2591, 2552],
        "porosity_change_first_trial": 0.008,
        "f_top_first_trial_kn_per_m": 3854.0,
        "f_bottom_first_trial_kn_per_m": 3855.0,
        "self_weight_first_trial_n_per_m": 846.0,
        "f_top_accepted_n_per_m": 2.7,
        "f_bottom_accepted_n_per_m": 809.0,
        "self_weight_accepted_n_per_m": 836.0,
        "accepted_porosity": 0.15,
    },
}

#: ``--quick``: a small box of two layers
QUICK_SPECIMEN = {"width": 0.08, "height": 0.04, "layers": 2}
#: a small specimen's 1 % of G is the weight of about two disks: granular noise, so the
#: quick look uses a wider window (stated in its report), and the paper's plate: the fill
#: acceptance's lid needs a window of many grain weights (docs/criterion.md)
QUICK_CRITERION = {"force_fraction": 0.05, "acceptance": "plate"}
#: the quick look's direct shear (and the quick calibration's): sheared to 4 mm
QUICK_SHEAR = {"max_displacement": 0.004}
#: where the quick box reads soil-like strength, measured (docs/shear.md, "Box-dominated tests"): on
#: two quick specimens sheared 16 mm at 50-200 kPa, at least one test of each three at f_p 0.7 or 1
#: (any mu_r) and in 3 of 4 cases at mu_r 0.2 was box-dominated (poro2d.shear.box_dominated); at
#: f_p <= 0.5 and mu_r <= 0.1, 15 of 90 tests (a grid's 24 and a calibration's 66): the fraction
#: below. Sheared 4 mm, the quick calibration's travel, no test peaked
QUICK_BOX_SOIL_LIKE = {
    "particle_friction": 0.5, "rolling_friction": 0.1, "max_displacement": 0.016,
    "box_dominated_fraction": 0.17,
}  # fmt: skip

__all__ = [
    "PAPER",
    "QUICK_BOX_SOIL_LIKE",
    "QUICK_CRITERION",
    "QUICK_SHEAR",
    "QUICK_SPECIMEN",
    "TABLE_1",
    "Table1",
]
