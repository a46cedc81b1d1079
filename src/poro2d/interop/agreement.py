"""The same specimen in LAMMPS and in poro2d: do the two engines agree at rest?

Both start from the exported centres and radii, at rest, with no contact history (LAMMPS cannot
import poro2d's stored shear forces, so poro2d drops them too), and the same masses, contact law,
walls (the plate fixed), time step, gravity and damping; each cycles until its largest
unbalanced-force ratio is below the case's ``ratio``, then both measure the wall forces per
metre, the mean contact force and the coordination number.

Known differences, both small at rest: LAMMPS' Hookean styles take a contact's lever arm as
the full radius, poro2d as the radius less half the overlap, and LAMMPS stores the shear
displacement as a vector projected on the contact plane each step, poro2d the shear force as a
component along the contact tangent.
"""

from __future__ import annotations

import os
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from poro2d.criterion.protocol import wall_forces
from poro2d.dem.state import BOX_WALLS
from poro2d.interop import lammps as lmp
from poro2d.interop.lammps_run import LammpsError, execute_script, parse_thermo, read_dump, version_from_log
from poro2d.interop.settled import RestCase, SettledRun, result_numbers
from poro2d.measure.coordination import coordination_number
from poro2d.typed_result import TypedResult

#: quantities compared, as (key, label) pairs
QUANTITIES = (
    ("f_top_n_per_m", "F_top (N/m)"),
    ("f_bottom_n_per_m", "F_bottom (N/m)"),
    ("side_friction_up_n_per_m", "side-wall friction up (N/m)"),
    ("mean_contact_force_n", "mean contact force (N)"),
    ("coordination_number", "coordination number"),
)


@dataclass(eq=False, kw_only=True)
class Agreement(TypedResult):
    """Both engines' runs of one specimen to rest and how far apart they are (``--json`` of the benchmark).

    ``disks`` and the self weight ``weight_n_per_m`` (G) of the specimen, the stop ``ratio``
    of both; ``poro2d`` and ``lammps``: each engine's :class:`SettledRun`; ``rel_diff`` and
    ``rel_to_weight``: the differences by quantity key (see :func:`compare`).
    """

    disks: int
    weight_n_per_m: float
    ratio: float
    poro2d: SettledRun
    lammps: SettledRun
    rel_diff: dict[str, float]
    rel_to_weight: dict[str, float]


def settle_poro2d(case: RestCase) -> SettledRun:
    """poro2d from the exported state: disks at rest, no history; cycled until ``case.ratio``."""
    spec = case.spec
    sim = spec.to_simulation(dt=spec.dt)
    t0 = time.perf_counter()
    res = sim.solve(case.ratio, case.max_steps)
    mags = sim.contacts().magnitude
    forces = wall_forces(sim)
    return SettledRun(
        f_top_n_per_m=float(forces.f_top_n_per_m),
        f_bottom_n_per_m=float(forces.f_bottom_n_per_m),
        side_friction_up_n_per_m=float(forces.side_friction_up_n_per_m),
        mean_contact_force_n=float(mags.mean()) if mags.size else 0.0,
        coordination_number=coordination_number(sim),
        contacts=int(mags.size),
        steps=res.steps,
        converged=res.converged,
        max_ratio=res.max_ratio,
        seconds=time.perf_counter() - t0,
    )


def settle_lammps(case: RestCase, workdir: str | os.PathLike) -> SettledRun:
    """LAMMPS on the exported files in ``workdir``, run as written but for the stop ratio and step cap."""
    wd = Path(workdir)
    lmp.write_specimen(case.spec, wd, ratio=case.ratio, max_steps=case.max_steps)
    t0 = time.perf_counter()
    log = execute_script(wd, lmp.INPUT_FILE)
    seconds = time.perf_counter() - t0
    res = result_numbers(log, LammpsError, "the LAMMPS log")
    pairs = read_dump(wd / lmp.FINAL_CONTACTS)
    fn, ft = pairs.column("c_pl[1]"), pairs.column("c_pl[2]")
    touching = fn > 0.0
    mags = [np.hypot(fn[touching], ft[touching])]
    disks = read_dump(wd / lmp.FINAL_DISKS)
    for w in BOX_WALLS:
        on = disks.column(f"f_w_{w}[1]") > 0.0
        mags.append(np.hypot(disks.column(f"f_w_{w}[2]")[on], disks.column(f"f_w_{w}[3]")[on]))
    allm = np.concatenate(mags)
    head, rows = parse_thermo(log)[-1]
    return SettledRun(
        f_top_n_per_m=res["f_top"],
        f_bottom_n_per_m=res["f_bottom"],
        side_friction_up_n_per_m=res["side_friction_up"],
        mean_contact_force_n=float(allm.mean()) if allm.size else 0.0,
        coordination_number=res["coordination"],
        contacts=int(allm.size),
        steps=int(rows[-1][head.index("Step")]),
        converged=res["ratio"] < case.ratio,
        max_ratio=res["ratio"],
        seconds=seconds,
        lammps_version=version_from_log(log),
    )


def compare(case: RestCase, workdir: str | os.PathLike | None = None) -> Agreement:
    """Run both engines from the same state; their results and relative differences.

    ``rel_diff[key]`` is |LAMMPS - poro2d| / |poro2d|; for the wall forces also
    ``rel_to_weight[key]``, the difference over the self weight G (F_top of an accepted
    specimen is below 1 % of G, so its own relative difference is a small number over
    a small number). LAMMPS' files are kept in ``workdir`` (None: a temporary folder).
    """
    if workdir is None:
        with tempfile.TemporaryDirectory(prefix="poro2d_lmp_") as tmp:
            return compare(case, tmp)
    ours = settle_poro2d(case)
    theirs = settle_lammps(case, workdir)
    weight = case.spec.weight_per_thickness()
    rel, relg = {}, {}
    for key, _ in QUANTITIES:
        a, b = getattr(theirs, key), getattr(ours, key)
        rel[key] = abs(a - b) / abs(b) if b != 0.0 else (0.0 if a == 0.0 else float("inf"))
        if key.endswith("_n_per_m"):
            relg[key] = abs(a - b) / weight
    return Agreement(
        disks=case.spec.n, weight_n_per_m=weight, ratio=case.ratio, poro2d=ours, lammps=theirs,
        rel_diff=rel, rel_to_weight=relg,
    )  # fmt: skip
