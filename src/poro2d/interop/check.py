"""The criterion's check on a specimen brought in from elsewhere, as it stands.

The specimen (a CSV pair, a LAMMPS data file or a poro2d checkpoint) is put in the paper's box
(:func:`poro2d.specimen.compaction.make_walls`, moved so that the box starts at the origin),
at rest with no contact history, and cycled to equilibrium with the plate fixed; then the
window of Fig. 3 is tested on the wall forces: 0 < F_top < 1 % of the self weight G. For a
specimen that fails it, the criterion's own plate servo finds where the plate would settle,
and so the porosity n' the box would have there.
"""

from __future__ import annotations

import os
import time
from dataclasses import asdict
from pathlib import Path

import numpy as np

from poro2d.criterion.protocol import CriterionSettings, wall_forces
from poro2d.criterion.servo import PlateServo, in_window
from poro2d.dem import ContactModel, Particles, Simulation
from poro2d.dem.state import BOX_WALLS
from poro2d.errors import InputError
from poro2d.interop import csv_table
from poro2d.interop import lammps as lmp
from poro2d.interop.specimen_data import SpecimenData, from_checkpoint
from poro2d.interop.validate import check_imported
from poro2d.measure.porosity import box_porosity
from poro2d.specimen.compaction import SpecimenSpec, make_walls

#: the values a file may not say (a LAMMPS data file of another origin), by their SpecimenSpec names
DEFAULT_FIELDS = ("thickness", "solid_density", "kn_particle", "ks_particle", "friction_particle")
DEFAULT_FIELDS += ("kn_wall", "ks_wall", "friction_wall", "gravity", "local_damping")
#: what those values are when neither the file nor an option says them: the prepared specimen's (Table 1's)
DEFAULTS = {name: getattr(SpecimenSpec(), name) for name in DEFAULT_FIELDS}


def read_specimen(path: str | os.PathLike, defaults: dict | None = None) -> SpecimenData:
    """A specimen from a CSV table (``disks.csv`` or its folder), a LAMMPS data file or a checkpoint.

    Every value is checked before any work (:func:`poro2d.interop.validate.check_imported`):
    a refusal names the file, line and column it was read from.
    """
    spec = _read(Path(path), dict(DEFAULTS, **(defaults or {})))
    locate = spec.locate or (
        lambda quantity, i=None: f"{spec.source} ({quantity}{'' if i is None else f' of disk {i}'})"
    )
    check_imported(spec, locate)
    return spec


def _read(p: Path, d: dict) -> SpecimenData:
    if not p.exists():
        raise InputError("FILE", str(p), "an existing disks.csv, LAMMPS data file, checkpoint or folder")
    if p.is_dir():
        if (p / csv_table.DISKS_FILE).is_file():
            return csv_table.read_specimen(p, d)
        if (p / lmp.DATA_FILE).is_file():
            return lmp.read_specimen(p / lmp.DATA_FILE, d)
        if not (p / "specimen.npz").is_file():
            raise InputError(
                "FILE", str(p), f"a folder holding {csv_table.DISKS_FILE}, {lmp.DATA_FILE} or specimen.npz"
            )
        return from_checkpoint(p)
    if p.suffix == ".csv":
        return csv_table.read_specimen(p, d)
    if p.suffix == ".npz":
        return from_checkpoint(p)
    return lmp.read_specimen(p, d)


def box_spec(spec: SpecimenData, ratio: float) -> SpecimenSpec:
    """The SpecimenSpec of the imported box: its size, the disks' and walls' properties."""
    xlo, xhi, ylo, yhi = spec.box()
    walls = {w.name: w for w in spec.walls}
    props = {(w.kn, w.ks, w.mu) for name, w in walls.items() if name in BOX_WALLS}
    if len(props) != 1:
        raise InputError("walls", sorted(props), "one set of (kn, ks, mu) for the four box walls")
    kw, sw, mw = props.pop()
    return SpecimenSpec(
        width=xhi - xlo, height=yhi - ylo, thickness=spec.thickness,
        solid_density=float(np.sum(spec.density * spec.radius**2) / np.sum(spec.radius**2)),
        kn_particle=float(spec.kn.max()), ks_particle=float(spec.ks.max()), kn_wall=kw, ks_wall=sw,
        friction_wall=mw, friction_particle=float(spec.mu.max()), ratio=ratio,
        local_damping=spec.local_damping, gravity=float(np.hypot(*spec.gravity)),
    )  # fmt: skip


def build_simulation(spec: SpecimenData, box: SpecimenSpec, threads: int = 1) -> Simulation:
    """The disks at rest, no contact history, in the paper's box moved to the origin.

    The disks keep their rolling friction, the box's walls that of the specimen's walls of
    the same name (0 for a wall the specimen does not have).
    """
    xlo, _, ylo, _ = spec.box()

    def simulation(dt: float | None) -> Simulation:
        p = Particles(
            np.column_stack([spec.x - xlo, spec.y - ylo]), spec.radius, spec.density, spec.thickness,
            spec.kn, spec.ks, spec.mu, mu_r=spec.mu_r,
        )  # fmt: skip
        walls = make_walls(box, box.height)
        # the box's walls keep the rolling friction of the specimen's walls of the same name
        wall_mu_r = {w.name: w.mu_r for w in spec.walls}
        walls.rolling_friction()[:] = [wall_mu_r.get(name, 0.0) for name in walls.names]
        return Simulation(
            p, walls, ContactModel("per_body"), gravity=(0.0, -box.gravity),
            local_damping=box.local_damping, dt=dt, threads=threads,
        )  # fmt: skip

    sim = simulation(None)
    if spec.dt is None:
        return sim
    # a given step must be stable for this packing: at most the critical step the engine computes
    if not spec.dt <= sim.dt_critical:
        where = spec.locate("dt") if spec.locate else "dt"
        raise InputError(where, spec.dt, f"(0, {sim.dt_critical:.4g}] s, the critical step of these disks")
    return simulation(spec.dt)


def check_specimen(
    spec: SpecimenData, settings: CriterionSettings | None = None, ratio: float = 1e-3,
    max_steps: int = 400_000, threads: int = 1, progress: bool = False, at_equilibrium=None,
) -> tuple[Simulation, dict]:  # fmt: skip
    """Cycle ``spec`` to equilibrium with the plate fixed and test the window of Fig. 3.

    Returns the simulation (at equilibrium, or after the plate servo for a specimen
    that fails) and the report: the wall forces (N/m), G, whether it passes, and for a
    failing specimen where the plate settles and the porosity n' of that box.
    ``at_equilibrium(sim, report)``, if given, is called before the plate moves (to
    save the state as it stood).
    """
    settings = settings or CriterionSettings()
    box = box_spec(spec, ratio)
    xlo, _, ylo, _ = spec.box()
    sim = build_simulation(spec, box, threads)
    t0 = time.perf_counter()
    res = sim.solve(ratio, max_steps, progress="equilibrium" if progress else False)
    n_box = box_porosity(sim.particles.area(), box.width, box.height)
    weight = box.self_weight(n_box)
    forces = wall_forces(sim).to_dict()
    passes = bool(res.converged and in_window(forces["f_top_n_per_m"], weight, settings.force_fraction))
    report = {
        "source": spec.source,
        "disks": spec.n,
        "box_m": {"width": box.width, "height": box.height, "moved_by": [0.0 - xlo, 0.0 - ylo]},
        "box_porosity": n_box,
        "self_weight_n_per_m": weight,
        "force_limit_n_per_m": settings.force_fraction * weight,
        **forces,
        "equilibrium": {"steps": res.steps, "max_ratio": res.max_ratio, "converged": res.converged},
        "passes": passes,
        "time_s": time.perf_counter() - t0,
        "specimen": box.to_dict(),
        "criterion_settings": asdict(settings),
    }
    if at_equilibrium is not None:
        at_equilibrium(sim, report)
    if passes or not res.converged:
        return sim, report
    # the criterion's plate servo, with the imported box's height and equilibrium ratio
    servo = PlateServo(settings, box.ratio, box.equilibrium, box.height, progress=progress)
    plate = servo.settle(sim, weight)
    after = wall_forces(sim)
    report["plate"] = {
        **plate.to_dict(),
        "moved": "down" if forces["f_top_n_per_m"] <= 0.0 else "up",
        "new_porosity": box_porosity(sim.particles.area(), box.width, plate.height_m),
        "f_top_after_n_per_m": after.f_top_n_per_m,
        "f_bottom_after_n_per_m": after.f_bottom_n_per_m,
    }
    return sim, report
