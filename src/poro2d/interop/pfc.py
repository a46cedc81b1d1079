"""PFC2D: a command file for current PFC (5 and later) and one in the PFC 4.0 form.

PFC2D takes a ball as a disk 1 m thick. To keep every mass poro2d's ``rho pi r^2 t``, the
density written is ``rho t``; the stiffnesses are the disks', so the contact forces read in
PFC are poro2d's, in N (divided by ``t``: N/m, the paper's unit).

* ``specimen.p2dat`` (PFC 5+): balls, walls and the linear contact model with contact-level
  values (PFC 5+ does not mix per-body ones), one set for ball-ball and one for ball-facet
  contacts; a specimen with rolling friction gets ``rrlinear``, whose rolling stiffness
  ``ks R^2`` and limit ``rr_fric R Fn`` are poro2d's rolling spring.
* ``specimen_pfc4.dat`` (PFC 4.0, the paper's code): the per-body values of Table 1, walls by
  their nodes as poro2d stores them (the specimen to the left from the first node to the
  second). PFC 4.0 has no rolling resistance: a rolled specimen gets no 4.0 file
  (:func:`pfc4_refusal` says why), never one that silently drops it.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from poro2d.errors import InputError
from poro2d.interop.specimen_data import SpecimenData
from poro2d.io_utils import write_texts

CURRENT_FILE = "specimen.p2dat"
PFC4_FILE = "specimen_pfc4.dat"


def _r(v) -> str:
    return repr(float(v))


def current_commands(spec: SpecimenData, ratio: float = 1e-3) -> str:
    """The PFC 5+ command file (``;`` comments)."""
    params = spec.contact_parameters()  # refuses disks of differing properties
    wall_sets = {params.walls[w.name] for w in spec.walls}
    if len(wall_sets) > 1:
        raise InputError(
            "walls", [w.name for w in spec.walls],
            "walls of one set of properties (one ball-facet contact model in PFC 5+)",
        )  # fmt: skip
    box = _extent(spec)
    t = spec.thickness
    lines = [
        *spec.header(";"),
        "; PFC2D 5+: balls are disks of unit thickness; density below = rho * t so that mass = rho pi r^2 t",
        "model new",
        f"model domain extent {_r(box[0])} {_r(box[1])} {_r(box[2])} {_r(box[3])}",
        f"model gravity {_r(spec.gravity[0])} {_r(spec.gravity[1])}",
    ]
    lines += [
        f"ball create id {i + 1} position ({_r(spec.x[i])},{_r(spec.y[i])}) radius {_r(spec.radius[i])}"
        for i in range(spec.n)
    ]
    lines += [
        f"ball attribute density {_r(spec.density[i] * t)} damp {_r(spec.local_damping)} range id {i + 1}"
        for i in range(spec.n)
    ]
    for k, w in enumerate(spec.walls, start=1):
        lines.append(
            f"wall create vertices {_r(w.x0)} {_r(w.y0)} {_r(w.x1)} {_r(w.y1)} id {k} name '{w.name}'"
        )
    lines.append(_cmat("ball-ball", *params.disks, rolled=spec.rolled))
    if spec.walls:
        name = spec.walls[0].name
        lines.append(_cmat("ball-facet", *params.walls[name], rolled=spec.rolled))
    if spec.dt:
        lines.append(f"model mechanical timestep fix {_r(spec.dt)}")
    lines += [
        "; every wall, the top plate included, stays where it is: cycle to equilibrium",
        f"model solve ratio {_r(ratio)}",
    ]
    return "\n".join(lines) + "\n"


def _cmat(kind: str, kn: float, ks: float, mu: float, mu_r: float, *, rolled: bool) -> str:
    """One default contact model: ``linear``, or ``rrlinear`` with ``rr_fric`` for a rolled specimen."""
    text = f"contact cmat default type '{kind}' model '{'rrlinear' if rolled else 'linear'}' property "
    text += f"kn {_r(kn)} ks {_r(ks)} fric {_r(mu)}"
    return text + (f" rr_fric {_r(mu_r)}" if rolled else "")


def pfc4_refusal(spec: SpecimenData) -> str | None:
    """Why ``spec`` gets no PFC 4.0 file (rolling friction: PFC 4.0 cannot express it); None: it gets one."""
    if not spec.rolled:
        return None
    return (
        f"{PFC4_FILE} not written: PFC 4.0 has no rolling-resistance model and the specimen has "
        f"rolling friction (disks {spec.contact_parameters().disks.mu_r:g}); {CURRENT_FILE} carries it "
        "(rrlinear)"
    )


def pfc4_commands(spec: SpecimenData) -> str:
    """The PFC 4.0 command file: per-body properties, as in the paper's Table 1."""
    reason = pfc4_refusal(spec)
    if reason is not None:
        raise InputError("rolling friction", spec.contact_parameters().disks.mu_r, "0 for PFC 4.0", reason)
    t = spec.thickness
    lines = [
        *spec.header(";"),
        "; PFC2D 4.0: 'set disk on' makes balls disks of unit thickness; density = rho * t",
        "new",
        "set disk on",
        f"set gravity {_r(spec.gravity[0])} {_r(spec.gravity[1])}",
    ]
    lines += [
        f"ball id={i + 1} x={_r(spec.x[i])} y={_r(spec.y[i])} rad={_r(spec.radius[i])}" for i in range(spec.n)
    ]
    lines += [
        f"property density={_r(spec.density[i] * t)} kn={_r(spec.kn[i])} ks={_r(spec.ks[i])} "
        f"friction={_r(spec.mu[i])} range id={i + 1}"
        for i in range(spec.n)
    ]
    lines.append(f"damp local {_r(spec.local_damping)}")
    for k, w in enumerate(spec.walls, start=1):
        lines.append(
            f"wall id={k} kn={_r(w.kn)} ks={_r(w.ks)} friction={_r(w.mu)} "
            f"nodes ({_r(w.x0)},{_r(w.y0)}) ({_r(w.x1)},{_r(w.y1)}) ; {w.name}"
        )
    lines.append("; every wall, the top plate included, stays where it is: cycle to equilibrium")
    lines.append("solve ratio=1e-3")
    return "\n".join(lines) + "\n"


def _extent(spec: SpecimenData) -> tuple[float, float, float, float]:
    """A model domain holding every disk and wall, with a margin of a largest diameter."""
    xs = np.concatenate([spec.x - spec.radius, spec.x + spec.radius, *[[w.x0, w.x1] for w in spec.walls]])
    ys = np.concatenate([spec.y - spec.radius, spec.y + spec.radius, *[[w.y0, w.y1] for w in spec.walls]])
    m = 2.0 * float(spec.radius.max())
    return float(xs.min()) - m, float(xs.max()) + m, float(ys.min()) - m, float(ys.max()) + m


def export_files(spec: SpecimenData) -> list[tuple[str, str]]:
    """(name, text) of ``specimen.p2dat`` and ``specimen_pfc4.dat``; a specimen with rolling
    friction gets the PFC 5+ file only (see :func:`pfc4_refusal`)."""
    spec.refuse_dashpot("PFC2D")
    files = [(CURRENT_FILE, current_commands(spec))]
    if pfc4_refusal(spec) is None:
        files.append((PFC4_FILE, pfc4_commands(spec)))
    return files


def write_specimen(spec: SpecimenData, out: str | os.PathLike) -> list[Path]:
    """Write the files of :func:`export_files` into ``out`` (atomically)."""
    return write_texts(out, export_files(spec))
