"""YADE: a Python script that builds the same disks and walls with the same contact law.

YADE is 3D. The choices made here:

* each disk is a sphere of the disk's radius centred in the plane z = 0, its motion locked
  to the plane (``blockedDOFs = 'zXY'``), its mass the disk mass ``rho pi r^2 t`` and its
  inertia the disk's ``m r^2 / 2``;
* each sphere gets its own ``FrictMat`` with ``young = kn / (2 r)``, which YADE's
  ``Ip2_FrictMat_FrictMat_FrictPhys`` combines into kn_a kn_b / (kn_a + kn_b), PFC 4.0's
  springs in series; ``poisson`` holds ks/kn (exact when every body has the same ks/kn, as
  in the paper's Table 1); the friction angle is ``atan(mu)``, the smaller one taken;
* walls are fixed boxes whose face lies on the poro2d segment, away from the specimen. YADE's
  stiffness of a box contact depends on the sphere's radius, so a ``PyRunner`` sets kn, ks and
  the friction of every disk-wall contact to the PFC 4.0 values;
* Cundall's local damping and gravity are ``NewtonIntegrator``'s; the time step is poro2d's;
* rolling friction (a rolled specimen only): no per-body material of YADE gives poro2d's
  rolling spring (kr = ks R^2, cap mu_r R Fn) for every pair of radii, so the materials give
  kr = 0 and a ``PyRunner`` sets each new contact's ``kr`` and ``maxRollPl`` for
  ``Law2_ScGeom6D_CohFrictPhys_CohesionMoment`` (the script's own comment says how).

The numbers are literals at the top of the script (``SETTINGS``, ``DISKS``, ``WALLS``, and
for a rolled specimen ``DISK_ROLLING`` and ``WALL_ROLLING``), written with ``repr`` so that
they read back exactly.
"""

from __future__ import annotations

import os
from pathlib import Path

from poro2d.errors import InputError
from poro2d.interop.specimen_data import SpecimenData, exact
from poro2d.io_utils import write_texts

SCRIPT_FILE = "specimen_yade.py"

_BODY = '''

import math
import sys

from yade import O, utils
from yade.wrapper import (
    Bo1_Box_Aabb, Bo1_Sphere_Aabb, ForceResetter, FrictMat, Ig2_Box_Sphere_ScGeom,
    Ig2_Sphere_Sphere_ScGeom, InsertionSortCollider, InteractionLoop, Ip2_FrictMat_FrictMat_FrictPhys,
    Law2_ScGeom_FrictPhys_CundallStrack, NewtonIntegrator, PyRunner,
)

try:  # YADE 2020 and later ship minieigen as yade.minieigenHP
    from yade.minieigenHP import Vector3
except ImportError:  # older YADE used the separate minieigen package
    from minieigen import Vector3

# the run settings may be overridden on the command line: yade -n -x THIS_FILE ratio=1e-6 max_steps=100000
for arg in sys.argv[1:]:
    key, _, value = arg.partition("=")
    if key not in ("ratio", "max_steps", "check_every"):
        raise SystemExit(f"unknown setting {arg!r}: use ratio=R, max_steps=N or check_every=N")
    SETTINGS[key] = float(value) if key == "ratio" else int(value)


def series(a, b):
    return a * b / (a + b)


T = SETTINGS["thickness"]
RMAX = max(d[2] for d in DISKS)

disk_ids = []
for x, y, r, rho, kn, ks, mu in DISKS:
    mat = O.materials.append(
        FrictMat(young=kn / (2.0 * r), poisson=ks / kn, frictionAngle=math.atan(mu), density=rho)
    )
    b = utils.sphere((x, y, 0.0), r, material=mat)
    m = rho * math.pi * r * r * T  # the disk mass, not the sphere's
    b.state.mass = m
    b.state.inertia = Vector3(0.5 * m * r * r, 0.5 * m * r * r, 0.5 * m * r * r)
    b.state.blockedDOFs = "zXY"
    disk_ids.append(O.bodies.append(b))
disk_props = {i: (kn, ks, mu) for i, (_, _, _, _, kn, ks, mu) in zip(disk_ids, DISKS)}

wall_ids = {}
wall_props = {}
for name, x0, y0, x1, y1, kn, ks, mu in WALLS:
    length = math.hypot(x1 - x0, y1 - y0)
    nx, ny = -(y1 - y0) / length, (x1 - x0) / length  # towards the specimen
    h = RMAX  # half thickness of the wall box, behind the segment
    cx, cy = 0.5 * (x0 + x1) - h * nx, 0.5 * (y0 + y1) - h * ny
    if abs(nx) < 0.5:  # horizontal
        extents = (0.5 * length, h, 2.0 * RMAX)
    else:
        extents = (h, 0.5 * length, 2.0 * RMAX)
    mat = O.materials.append(FrictMat(young=kn / (2.0 * RMAX), poisson=ks / kn, frictionAngle=math.atan(mu)))
    wid = O.bodies.append(utils.box((cx, cy, 0.0), extents, fixed=True, material=mat))
    wall_ids[name] = wid
    wall_props[wid] = (kn, ks, mu)


def wall_contacts():
    """PFC 4.0 properties on every disk-wall contact: springs in series, the smaller friction."""
    for wid, (kw, sw, mw) in wall_props.items():
        for i in O.interactions.withBody(wid):
            if not i.isReal:
                continue
            d = i.id2 if i.id1 == wid else i.id1
            kd, sd, md = disk_props[d]
            i.phys.kn = series(kd, kw)
            i.phys.ks = series(sd, sw)
            i.phys.tangensOfFrictionAngle = min(md, mw)


def report():
    """Wall forces per metre of disk thickness (N/m), as poro2d reports them."""
    f = {name: O.forces.f(wid) for name, wid in wall_ids.items()}
    out = {
        "f_top_n_per_m": f["top"][1] / T if "top" in f else float("nan"),
        "f_bottom_n_per_m": -f["bottom"][1] / T if "bottom" in f else float("nan"),
        "side_friction_up_n_per_m": -(f["left"][1] + f["right"][1]) / T if "left" in f else float("nan"),
        "unbalanced_force": utils.unbalancedForce(),
        "steps": O.iter,
    }
    print("poro2d-result", " ".join(f"{k} {v!r}" for k, v in out.items()))


def stop_at_rest():
    # YADE's unbalancedForce() is the mean unbalanced force over the mean contact force
    if O.iter > 100 and utils.unbalancedForce() < SETTINGS["ratio"]:
        O.pause()


O.engines = [
    ForceResetter(),
    InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Box_Aabb()]),
    InteractionLoop(
        [Ig2_Sphere_Sphere_ScGeom(), Ig2_Box_Sphere_ScGeom()],
        [Ip2_FrictMat_FrictMat_FrictPhys()],
        [Law2_ScGeom_FrictPhys_CundallStrack()],
    ),
    PyRunner(command="wall_contacts()", iterPeriod=1),
    NewtonIntegrator(damping=SETTINGS["damping"], gravity=(*SETTINGS["gravity"], 0.0)),
    PyRunner(command="stop_at_rest()", iterPeriod=SETTINGS["check_every"]),
]
O.dt = SETTINGS["dt"]
'''

_MAIN = """
if __name__ == "__main__":
    O.run(SETTINGS["max_steps"], True)
    report()
"""

_ROLLING = '''

# Rolling resistance, poro2d's rolling spring on every contact: the moment on the first body
# grows by -kr (w1 - w2) dt each step and is capped at mu_r R Fn, with kr = ks R^2 (ks of the
# contact), R = r1 r2 / (r1 + r2) (a disk's own radius against a wall) and mu_r the smaller
# of the two bodies' values. YADE's Law2_ScGeom6D_CohFrictPhys_CohesionMoment in its
# incremental form runs this spring on a contact's kr and maxRollPl (cap maxRollPl Fn), but
# its Ip2 derives them from the materials (kr = alphaKr ks r1 r2, maxRollPl = min(etaRoll1 r1,
# etaRoll2 r2)), which no per-body alphaKr and etaRoll turn into ks R^2 and mu_r R for every
# pair. So the materials give kr = 0 and rolling_contacts() sets kr and maxRollPl on each
# contact in the step it forms, and applies that step's moment itself.
from yade.wrapper import (
    CohFrictMat, Ig2_Box_Sphere_ScGeom6D, Ig2_Sphere_Sphere_ScGeom6D,
    Ip2_CohFrictMat_CohFrictMat_CohFrictPhys, Law2_ScGeom6D_CohFrictPhys_CohesionMoment,
)

disk_radius = {i: d[2] for i, d in zip(disk_ids, DISKS)}
rolling_friction = dict(zip(disk_ids, DISK_ROLLING))
rolling_friction.update({wid: WALL_ROLLING[name] for name, wid in wall_ids.items()})
shear_stiffness = {i: p[1] for i, p in {**disk_props, **wall_props}.items()}


def with_moments(mat):
    """The body's FrictMat as a CohFrictMat: moments on, never cohesive, kr = 0 until set per contact."""
    new = CohFrictMat(
        young=mat.young, poisson=mat.poisson, frictionAngle=mat.frictionAngle, density=mat.density,
        isCohesive=False, momentRotationLaw=True, alphaKr=0.0, alphaKtw=0.0, etaRoll=-1.0, etaTwist=-1.0,
    )
    return O.materials[O.materials.append(new)]


for body in O.bodies:
    body.material = with_moments(body.material)


def rolling_spring(i):
    """(kr, mu_r R): poro2d's rolling stiffness and moment cap per unit normal force of a contact."""
    a, b = i.id1, i.id2
    if a in disk_radius and b in disk_radius:
        r = disk_radius[a] * disk_radius[b] / (disk_radius[a] + disk_radius[b])
    else:
        r = disk_radius.get(a, disk_radius.get(b))
    ks = series(shear_stiffness[a], shear_stiffness[b])
    return ks * r * r, min(rolling_friction[a], rolling_friction[b]) * r


def rolling_contacts():
    """poro2d's rolling spring on every contact that formed in this step, and this step's moment."""
    for i in O.interactions:
        if i.iterMadeReal != O.iter:
            continue
        kr, limit = rolling_spring(i)
        i.phys.kr, i.phys.maxRollPl = kr, limit
        w = O.bodies[i.id2].state.angVel[2] - O.bodies[i.id1].state.angVel[2]
        cap = limit * i.phys.normalForce.norm()
        m = min(max(-kr * w * O.dt, -cap), cap)
        i.phys.moment_bending = Vector3(0.0, 0.0, m)
        O.forces.addT(i.id1, Vector3(0.0, 0.0, -m))
        O.forces.addT(i.id2, Vector3(0.0, 0.0, m))


O.engines = [
    *O.engines[:2],
    InteractionLoop(
        [Ig2_Sphere_Sphere_ScGeom6D(), Ig2_Box_Sphere_ScGeom6D()],
        [Ip2_CohFrictMat_CohFrictMat_CohFrictPhys()],
        [Law2_ScGeom6D_CohFrictPhys_CohesionMoment(useIncrementalForm=True, always_use_moment_law=True)],
    ),
    PyRunner(command="rolling_contacts()", iterPeriod=1, initRun=True),
    *O.engines[3:],
]

'''


def script(
    spec: SpecimenData, ratio: float = 1e-3, max_steps: int = 2_000_000, check_every: int = 500
) -> str:
    """The text of the YADE script (run it with ``yade -n -x specimen_yade.py``)."""
    settings = {
        "thickness": float(spec.thickness),
        "gravity": (float(spec.gravity[0]), float(spec.gravity[1])),
        "damping": float(spec.local_damping),
        "dt": float(spec.dt) if spec.dt else 0.0,
        "ratio": float(ratio),
        "max_steps": int(max_steps),
        "check_every": int(check_every),
    }
    disks = zip(spec.x, spec.y, spec.radius, spec.density, spec.kn, spec.ks, spec.mu, strict=True)
    lines = [
        *spec.header("#"),
        f"# written by poro2d export --to yade; run: yade -n -x {SCRIPT_FILE} (no window, exit at the end)",
        f"# other stop settings: yade -n -x {SCRIPT_FILE} ratio=1e-6 max_steps=100000",
        "# 2D in YADE: spheres with their centres in z = 0, motion locked to the plane, disk masses",
        "",
        f"SETTINGS = {settings!r}",
        "",
        "# x, y, radius, density, kn, ks, mu (per body, PFC 4.0)",
        "DISKS = [",
        *(f"    ({exact(d, ', ')})," for d in disks),
        "]",
        "",
        "# name, x0, y0, x1, y1, kn, ks, mu (the specimen lies to the left going from (x0, y0) to (x1, y1))",
        "WALLS = [",
        *(f"    ({w.name!r}, {exact(w.numbers, ', ')})," for w in spec.walls),
        "]",
    ]
    if not spec.rolled:
        return "\n".join(lines) + _BODY + _MAIN
    return "\n".join(lines + _rolling_lines(spec)) + _BODY + _ROLLING + _MAIN


def _rolling_lines(spec: SpecimenData) -> list[str]:
    """The rolling frictions of a rolled specimen, per disk (in DISKS order) and per wall."""
    walls = {w.name: float(w.mu_r) for w in spec.walls}
    return [
        "",
        "# rolling friction mu_r per disk (in DISKS order) and per wall, for poro2d's rolling spring (below)",
        "DISK_ROLLING = [",
        *(f"    {float(v)!r}," for v in spec.rolling_friction),
        "]",
        f"WALL_ROLLING = {walls!r}",
    ]


def export_files(
    spec: SpecimenData, ratio: float = 1e-3, max_steps: int = 2_000_000, check_every: int = 500
) -> list[tuple[str, str]]:
    """(name, text) of ``specimen_yade.py``, stopping at ``ratio`` (YADE's mean ratio)."""
    if not spec.dt:
        raise InputError("time step", spec.dt, "the time step of the specimen (a poro2d checkpoint has one)")
    spec.refuse_dashpot("YADE")
    slanted = [w.name for w in spec.walls if not (w.horizontal or w.vertical)]
    if slanted:
        raise InputError("walls", slanted, "horizontal or vertical walls (written as YADE boxes)")
    return [(SCRIPT_FILE, script(spec, ratio, max_steps, check_every))]


def write_specimen(
    spec: SpecimenData, out: str | os.PathLike, ratio: float = 1e-3, max_steps: int = 2_000_000,
    check_every: int = 500,
) -> list[Path]:  # fmt: skip
    """Write the script of :func:`export_files` into ``out`` (atomically)."""
    return write_texts(out, export_files(spec, ratio, max_steps, check_every))
