"""LAMMPS: a data file of the disks and an input script of the same model.

Translation of poro2d's model into LAMMPS (``units si``, ``dimension 2``, GRANULAR package):

* ``atom_style sphere``: LAMMPS sets ``mass = 4/3 pi r^3 density`` even in 2D, so each
  atom gets the density ``3 rho t / (4 r)`` (:func:`lammps_density`), which gives the
  disk mass ``rho pi r^2 t``; ``fix nve/sphere disc`` uses the disk inertia ``m r^2 / 2``.
* Hookean styles take plain springs in N/m, as PFC does: the per-body values of PFC 4.0 are
  mixed beforehand (:meth:`poro2d.dem.model.ContactModel.pair`). The classic form's gamma_n is a
  negligible positive value (:data:`GAMMA_TINY`): the model has no viscous damping, and with a
  normal damping of exactly 0 LAMMPS gives NaN at the first wall contact.
* walls: one ``fix wall/gran`` plane per wall with the disk-wall contact's values, the plate a
  plane fixed at its height.
* rolling resistance (``granular`` law only): ``rolling sds k_roll 0 mu_roll`` with ``k_roll``
  the contact's ks and ``mu_roll`` its mu_r is poro2d's rolling spring ``kr = ks R^2`` capped at
  ``mu_r R Fn``, LAMMPS applying its rolling force at the lever arm ``R_eff`` (docs/export.md).
* local damping: ``fix damping/cundall a a``, PFC's local damping, after ``fix gravity`` so
  that the weight is part of the damped unbalanced force, as in PFC and poro2d; ``fix
  store/force`` just before it keeps the undamped unbalanced force for the stop test.

The stop test of the exported script is PFC's ratio: the largest unbalanced force over the
largest contact force (for disk-disk contacts the normal force stands for the magnitude,
since LAMMPS reduces one column at a time), checked every ``check_every`` steps by
``fix halt``.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from poro2d import __version__
from poro2d.dem.state import BOX_WALLS
from poro2d.errors import InputError
from poro2d.interop.csv_table import read_number
from poro2d.interop.specimen_data import SpecimenData, WallData, exact
from poro2d.interop.validate import LIMITS, Limit, check_value, text_of
from poro2d.io_utils import write_texts

# positive stand-in for "no normal dashpot" (1/s, times the effective mass)
GAMMA_TINY = 1e-9

#: files the exported script reads and writes, in its folder
DATA_FILE = "specimen.data"
INPUT_FILE = "in.specimen"
FINAL_DISKS = "final_disks.dump"
FINAL_CONTACTS = "final_contacts.dump"

#: quantities the script prints on its last line, ``poro2d-result key value ...``
RESULT_KEYS = ("ratio", "f_top", "f_bottom", "side_friction_up", "f_left", "f_right", "coordination")

#: wall fix of each box wall: (plane style, which side is given)
_PLANES = {"bottom": ("yplane", 0), "top": ("yplane", 1), "left": ("xplane", 0), "right": ("xplane", 1)}


def disk_mass(radius, density, thickness: float) -> np.ndarray:
    """Mass of disks of thickness ``t``: ``rho pi r^2 t``."""
    r = np.asarray(radius, dtype=float)
    return np.asarray(density, dtype=float) * math.pi * r * r * thickness


def lammps_density(radius, density, thickness: float) -> np.ndarray:
    """Per-atom density that makes LAMMPS' ``4/3 pi r^3 density`` the disk mass ``rho pi r^2 t``."""
    return 3.0 * np.asarray(density, dtype=float) * thickness / (4.0 * np.asarray(radius, dtype=float))


def critical_dt(radius, density: float, thickness: float, kn_max: float, factor: float = 0.2) -> float:
    """Time step ``factor * sqrt(m_min / kn_max)``."""
    m_min = float(disk_mass(np.min(radius), density, thickness))
    return factor * math.sqrt(m_min / kn_max)


# ------------------------------------------------------------------ data file


def data_text(
    x, y, radius, density, thickness: float, box, margin: float, title: str = "poro2d disks",
    comments: list[str] | None = None,
) -> str:  # fmt: skip
    """The text of a LAMMPS data file (``atom_style sphere``) of disks of thickness ``thickness``.

    ``box`` is (xlo, xhi, ylo, yhi); the simulation box is larger by ``margin`` on each
    side, and spans ``-t/2 .. t/2`` in z. ``comments`` are written below the title as
    ``#`` lines. Every number is written with ``repr``: it reads back to the same float.
    """
    x, y, radius = (np.asarray(a, dtype=float) for a in (x, y, radius))
    dens = lammps_density(radius, density, thickness)
    xlo, xhi, ylo, yhi = map(float, box)
    zt = 0.5 * thickness
    lines = [title, *(comments or []), ""]
    lines += [f"{x.size} atoms", "1 atom types", ""]
    lines += [
        f"{xlo - margin!r} {xhi + margin!r} xlo xhi",
        f"{ylo - margin!r} {yhi + margin!r} ylo yhi",
        f"{-zt!r} {zt!r} zlo zhi",
        "",
        "Atoms # sphere",
        "",
    ]
    body = [
        f"{i + 1} 1 {2.0 * float(radius[i])!r} {float(dens[i])!r} {float(x[i])!r} {float(y[i])!r} 0"
        for i in range(x.size)
    ]
    return "\n".join(lines + body) + "\n"


@dataclass
class DataFile:
    """What a LAMMPS data file of disks holds: centres, radii, masses, box, and poro2d's notes.

    ``notes``: each ``# poro2d`` note's line and words by its key (``wall NAME`` per wall), in file
    order; ``atom_lines`` the line of each atom (in id order), ``box_line`` those of the ``xlo xhi``
    and ``ylo yhi`` header lines: where a value came from, for the checks.
    """

    x: np.ndarray
    y: np.ndarray
    radius: np.ndarray
    mass: np.ndarray
    box: tuple[float, float, float, float]
    zspan: float
    notes: dict[str, tuple[int, list[str]]]
    atom_lines: np.ndarray
    box_line: dict


#: section titles of a LAMMPS data file (any other line that starts with a letter is malformed)
SECTIONS = {
    "Atoms", "Velocities", "Masses", "Ellipsoids", "Lines", "Triangles", "Bodies", "Bonds", "Angles",
    "Dihedrals", "Impropers", "Pair", "PairIJ", "Bond", "Angle", "Dihedral", "Improper", "BondBond",
    "BondAngle", "MiddleBondTorsion", "EndBondTorsion", "AngleTorsion", "AngleAngleTorsion",
    "BondBond13", "AngleAngle",
}  # fmt: skip
#: what an atom's type may be: the disks of a specimen share one set of properties, and a
#: second type's (its mass, its pair coefficients) would be read as the first's
ONE_TYPE = "1: one atom type (a second type's properties are not read)"
#: a z spread larger than this fraction of the smallest radius makes a file 3D
Z_TOLERANCE = 1e-3


def read_data(path: str | os.PathLike) -> DataFile:
    """Read a LAMMPS data file of ``atom_style sphere`` (id type diameter density x y z [images]).

    Any other section (Velocities, ...) is skipped. Lines written by :func:`write_specimen` as
    ``# poro2d <key> <values>`` are returned in ``notes`` (the first of a key). A malformed line is
    an InputError naming the file, the line and the column: ids and types must be whole numbers
    (ids >= 1, none twice), the atoms must lie in one plane (z constant) and in the box's
    own image (image flags 0 in x and y), and their count must be the header's.
    """
    p = Path(path)
    lines = text_of(p, "LAMMPS data file").splitlines()
    notes: dict[str, tuple[int, list[str]]] = {}
    header: dict = {}
    atoms: list[tuple[int, list[float]]] = []
    section = None
    for k, raw in enumerate(lines[1:], start=2):
        if raw.startswith("# poro2d "):
            key, *vals = raw[len("# poro2d ") :].split() or [""]
            _add_note(p, k, f"wall {vals[0]}" if key == "wall" and vals else key, vals, notes)
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        words = line.split()
        if words[0] in SECTIONS:
            section = words[0]
            if section == "Atoms":
                _atom_style(p, k, raw)
            continue
        if section is None:
            _header_line(p, k, words, header)
        elif section == "Atoms":
            atoms.append((k, _numbers(p, k, words, 7, 10)))
    needed = (("atoms", "N atoms"), ("xlo", "xlo xhi"), ("ylo", "ylo yhi"))
    missing = next((what for key, what in needed if key not in header), None)
    if missing:
        allowed = "a LAMMPS data file with 'N atoms', 'xlo xhi' and 'ylo yhi' lines"
        raise InputError(f"{p} header", f"no '{missing}' line", allowed)
    n, n_line = header["atoms"]
    if len(atoms) != n:
        where = f"{p} Atoms section (lines {atoms[0][0]}-{atoms[-1][0]})" if atoms else f"{p} Atoms section"
        raise InputError(where, f"{len(atoms)} atoms", f"{n} atoms, as line {n_line} says")
    a = np.array([v[:7] for _, v in atoms])
    order = np.argsort(a[:, 0], kind="stable")
    a = a[order]
    atom_lines = np.array([atoms[i][0] for i in order])
    diam, dens = a[:, 2], a[:, 3]
    # a diameter is checked here, before a mass is made of it: a huge one would overflow
    radius = LIMITS["radius"]
    diameter = Limit(2.0 * radius.lo, 2.0 * radius.hi, "m")
    checks = (
        (3, "diameter", diameter.holding(diam), f"a diameter in {diameter.text}"),
        (4, "density", (dens > 0.0) & np.isfinite(dens), "a positive density"),
    )
    for col, name, ok, allowed in checks:
        bad = np.flatnonzero(~ok)
        if bad.size:
            k = atom_lines[bad[0]]
            raise InputError(f"{p} line {k} column {col} ({name})", float(a[bad[0], col - 1]), allowed)
    _check_atoms(p, atoms, np.array([v[:7] for _, v in atoms]))
    r = 0.5 * diam
    zlo, zhi = header.get("zlo", ((-0.5, 0.5), 0))[0]
    with np.errstate(over="ignore"):  # a mass too large for a float is refused by its density later
        mass = 4.0 / 3.0 * math.pi * r**3 * dens
    return DataFile(
        x=a[:, 4].copy(), y=a[:, 5].copy(), radius=r, mass=mass,
        box=(*header["xlo"][0], *header["ylo"][0]), zspan=zhi - zlo, notes=notes, atom_lines=atom_lines,
        box_line={"x": header["xlo"][1], "y": header["ylo"][1]},
    )  # fmt: skip


#: the ``# poro2d`` notes the reader takes, each once (a wall's once per name)
NOTE_KEYS = ("thickness", "disk_properties", "settings", "window", "rolling_friction", "wall")


def _add_note(p: Path, k: int, label: str, vals: list[str], notes: dict) -> None:
    """Keep a note's line and words; a second note of the same key (or wall) is refused, since
    only one of the two could be read and the other would be dropped without a word."""
    if label in notes and label.split()[0] in NOTE_KEYS:
        where = f"{p} line {k}"
        raise InputError(where, f"# poro2d {label}", f"one such line (line {notes[label][0]} has it)")
    notes.setdefault(label, (k, vals))


def _atom_style(p: Path, k: int, raw: str) -> None:
    """``Atoms`` or ``Atoms # sphere``: the columns read are those of atom_style sphere."""
    style = raw.split("#", 1)[1].strip() if "#" in raw else "sphere"
    if style not in ("sphere", ""):
        raise InputError(f"{p} line {k}", raw.strip(), "'Atoms # sphere' (id type diameter density x y z)")


def _check_atoms(p: Path, atoms: list[tuple[int, list[float]]], a: np.ndarray) -> None:
    """Whole ids (>= 1, unique), atom type 1, one plane in z, image flags 0 in x and y."""
    seen: dict[float, int] = {}
    for k, v in atoms:
        if v[0] != int(v[0]) or v[0] < 1:
            raise InputError(f"{p} line {k} column 1 (id)", v[0], "a whole number >= 1")
        if v[1] != 1:
            raise InputError(
                f"{p} line {k} column 2 (type)", int(v[1]) if v[1] == int(v[1]) else v[1], ONE_TYPE
            )
        if v[0] in seen:
            raise InputError(
                f"{p} line {k} column 1 (id)", int(v[0]), f"an id of its own (line {seen[v[0]]} has it)"
            )
        seen[v[0]] = k
        for c in (8, 9):
            if len(v) >= c and v[c - 1] != 0.0:
                raise InputError(
                    f"{p} line {k} column {c} (image flag {'xy'[c - 8]})", v[c - 1],
                    "0: the atom in the box itself (the criterion's box is closed, not periodic)",
                )  # fmt: skip
    z = a[:, 6]
    tolerance = Z_TOLERANCE * 0.5 * float(a[:, 2].min())
    off = np.flatnonzero(np.abs(z - z[0]) > tolerance)
    if off.size:
        k = atoms[off[0]][0]
        raise InputError(
            f"{p} line {k} column 7 (z)", float(z[off[0]]),
            f"{float(z[0])!r} within {tolerance:.3g} m, as line {atoms[0][0]}: a 2D file has every atom "
            f"in one plane (z spread here {np.ptp(z):.4g} m)",
        )  # fmt: skip


def _header_line(p: Path, k: int, words: list[str], header: dict) -> None:
    """One line of the header: ``N atoms``, ``lo hi xlo xhi``, ...; other keywords are ignored."""
    if words[-2:] in (["xlo", "xhi"], ["ylo", "yhi"], ["zlo", "zhi"]):
        lo, hi = _numbers(p, k, words[:2], 2, 2)
        for c, v in ((1, lo), (2, hi)):
            check_value(f"{p} line {k} column {c} ({words[1 + c]})", v, LIMITS["coordinate"])
        if not lo < hi:
            raise InputError(f"{p} line {k} column 2 ({words[3]})", hi, f"above {words[2]} = {lo!r}")
        header[words[-2]] = ((lo, hi), k)
    elif words[1:] == ["atom", "types"] and words[0] != "1":
        raise InputError(f"{p} line {k} column 1 (atom types)", words[0], ONE_TYPE)
    elif words[-1] == "atoms" and len(words) == 2:
        v = _numbers(p, k, words[:1], 1, 1)[0]
        if v != int(v) or v < 1:
            raise InputError(f"{p} line {k} column 1", words[0], "a positive whole number of atoms")
        header["atoms"] = (int(v), k)


def _numbers(p: Path, k: int, words: list[str], lo: int, hi: int) -> list[float]:
    if not lo <= len(words) <= hi:
        column, found = (len(words) + 1, "the end of the line") if len(words) < lo else (hi + 1, words[hi])
        raise InputError(
            f"{p} line {k} column {column}", found, f"{lo} to {hi} numbers" if lo != hi else f"{lo} numbers"
        )
    return [read_number(p, k, c, w) for c, w in enumerate(words, start=1)]


# ------------------------------------------------------------------ input script


@dataclass
class WallFix:
    """One ``fix wall/gran`` plane: its fix id, ``xplane``/``yplane``, lo and hi (None: NULL)."""

    fix_id: str
    style: str
    lo: float | None
    hi: float | None
    kn: float
    kt: float
    mu: float
    contacts: bool = True
    mu_r: float = 0.0  # rolling friction of the disk-wall contacts

    def command(self, law: str = "granular") -> str:
        lo = "NULL" if self.lo is None else repr(float(self.lo))
        hi = "NULL" if self.hi is None else repr(float(self.hi))
        model = contact_law(law, self.kn, self.kt, self.mu, self.mu_r)
        tail = " contacts" if self.contacts else ""
        return f"fix             {self.fix_id} all wall/gran {model} {self.style} {lo} {hi}{tail}"


def contact_law(law: str, kn: float, kt: float, mu: float, mu_r: float = 0.0) -> str:
    """The arguments of a linear spring-slider contact for ``pair_coeff``/``fix wall/gran``.

    ``granular``: the sub-model syntax (``hooke kn 0 tangential linear_history kt 0 mu
    damping mass_velocity``), without viscous damping; its shear spring is rotated with
    the contact and keeps its length, as poro2d's shear force does. ``classic``: the
    older ``hooke/history`` form (a vector projected on the contact plane, not rescaled),
    with a negligible normal dashpot. ``mu_r > 0`` adds the rolling spring (``granular``
    only; see the module's doc for the mapping).
    """
    if law == "granular":
        rolling = f" rolling sds {float(kt)!r} 0 {float(mu_r)!r}" if mu_r > 0.0 else ""
        return (f"granular hooke {float(kn)!r} 0 tangential linear_history {float(kt)!r} 0 {float(mu)!r} "
                f"damping mass_velocity{rolling}")  # fmt: skip
    if mu_r > 0.0:
        raise InputError("LAMMPS contact law", law, "'granular' (the only one with rolling resistance)")
    return f"hooke/history {float(kn)!r} {float(kt)!r} {GAMMA_TINY!r} {GAMMA_TINY!r} {float(mu)!r} 0"


def model_commands(
    data: str, pp: tuple[float, float, float], walls: list[WallFix], dt: float, skin: float,
    gravity: tuple[float, float], damping: float, processors: str | None = None, store_force: bool = False,
    law: str = "granular", pp_mu_r: float = 0.0,
) -> str:  # fmt: skip
    """The model part of a script: settings, disks, contact law, walls, gravity, damping, integration.

    ``pp`` is the disk-disk (kn, kt, mu) at contact level, ``pp_mu_r`` its rolling friction;
    ``gravity`` the (gx, gy) vector.
    With ``store_force`` the undamped unbalanced force is kept in ``f_unbal``.
    """
    g = math.hypot(*gravity)
    gvec = (gravity[0] / g, gravity[1] / g) if g > 0 else (0.0, -1.0)
    if law == "granular":
        pair_style, pair_coeff = "granular", contact_law(law, *pp, pp_mu_r).split(" ", 1)[1]
    else:
        pair_style, pair_coeff = "gran/" + contact_law(law, *pp), ""
    s = [
        "units           si",
        "dimension       2",
        "boundary        f f p",
        "atom_style      sphere",
        "atom_modify     map array",
        "comm_modify     vel yes",
        "newton          off",
    ]
    if processors:
        s.append(f"processors      {processors}")
    s += [
        f"read_data       {data}",
        "",
        f"neighbor        {float(skin)!r} bin",
        "neigh_modify    delay 0 every 1 check yes",
        "",
        f"pair_style      {pair_style}",
        f"pair_coeff      * * {pair_coeff}".rstrip(),
        "",
        f"timestep        {float(dt)!r}",
        "",
        "fix             integ all nve/sphere disc",
        *(w.command(law) for w in walls),
        f"fix             grav all gravity {g!r} vector {gvec[0]!r} {gvec[1]!r} 0",
        "fix             e2d all enforce2d",
    ]
    if store_force:
        s.append("fix             unbal all store/force")
    if damping > 0:
        s.append(f"fix             damp all damping/cundall {float(damping)!r} {float(damping)!r}")
    return "\n".join(s) + "\n"


def box_wall_fixes(spec: SpecimenData) -> list[WallFix]:
    """One plane per box wall, at its face, with that wall's disk-wall contact properties."""
    box = spec.box()
    params = spec.contact_parameters()
    faces = {"left": box[0], "right": box[1], "bottom": box[2], "top": box[3]}
    extra = [w.name for w in spec.walls if w.name not in BOX_WALLS]
    if extra:
        raise InputError("walls", [w.name for w in spec.walls], "the four walls of a box (LAMMPS planes)")
    fixes = []
    for name in BOX_WALLS:
        style, side = _PLANES[name]
        lo, hi = (faces[name], None) if side == 0 else (None, faces[name])
        kn, kt, mu, mu_r = params.walls[name]
        fixes.append(WallFix(f"w_{name}", style, lo, hi, kn, kt, mu, mu_r=mu_r))
    return fixes


def input_script(
    spec: SpecimenData, ratio: float = 1e-3, max_steps: int = 2_000_000, check_every: int = 500
) -> str:
    """The exported script: the specimen at rest, the plate fixed, cycled until the ratio is met.

    Prints the unbalanced-force ratio, the wall forces per metre of thickness and the
    coordination number as it runs, and writes the final disks and contacts.
    """
    if spec.dt is None:
        raise InputError("time step", None, "the time step of the specimen (a poro2d checkpoint has one)")
    t = spec.thickness
    pp = spec.contact_parameters().disks
    model = model_commands(
        DATA_FILE, pp[:3], box_wall_fixes(spec), spec.dt, 0.5 * float(spec.radius.min()), spec.gravity,
        spec.local_damping, store_force=True, pp_mu_r=pp.mu_r,
    )  # fmt: skip
    head = "\n".join(spec.header("#")) + "\n"
    head += f"""# written by poro2d export --to lammps; run: lmp -in {INPUT_FILE}
# disks start at rest with no shear force stored; the four walls are fixed planes, the
# top plate at its height. The run stops when the ratio below is met (fix halt) or
# after max_steps; override on the command line: lmp -in {INPUT_FILE} -var ratio_target 1e-5

variable        ratio_target index {ratio!r}
variable        max_steps index {int(max_steps)}
variable        check_every index {int(check_every)}
variable        thickness equal {t!r}

"""
    meas = f"""
# ---- measurements (forces per metre of disk thickness, N/m, the paper's unit)
compute         pl all pair/local force p4
compute         cmax_pp all reduce max c_pl[1] inputs local
variable        fu atom sqrt(f_unbal[1]^2+f_unbal[2]^2)
compute         fumax all reduce max v_fu
{_wall_sums()}
variable        cmax equal {_largest(["c_cmax_pp", *(f"c_cmax_w_{w}" for w in BOX_WALLS)])}
variable        ratio equal c_fumax/(v_cmax+1e-300)
variable        f_top equal -c_fy_w_top/v_thickness
variable        f_bottom equal c_fy_w_bottom/v_thickness
variable        side_friction_up equal (c_fy_w_left+c_fy_w_right)/v_thickness
variable        f_left equal c_fx_w_left/v_thickness
variable        f_right equal -c_fx_w_right/v_thickness
compute         zpp all contact/atom
compute         zsum all reduce sum c_zpp
variable        coordination equal (c_zsum+c_n_w_bottom+c_n_w_top+c_n_w_left+c_n_w_right)/atoms

thermo_style    custom step time ke v_ratio v_f_top v_f_bottom v_side_friction_up v_coordination
thermo_modify   norm no flush yes format float %.10g
thermo          ${{check_every}}

fix             stop all halt ${{check_every}} v_ratio < ${{ratio_target}} error continue
run             ${{max_steps}}

print           "poro2d-result {" ".join(f"{k} ${{{k}}}" for k in RESULT_KEYS)}"
write_dump      all custom {FINAL_DISKS} id x y radius vx vy omegaz {_wall_columns()} &
                modify sort id format float %.17g
write_dump      all local {FINAL_CONTACTS} c_pl[1] c_pl[2] modify format float %.17g
"""
    return head + model + meas


def _wall_columns() -> str:
    """Dump columns of every wall's contact on a disk: in contact (1/0), force x, force y."""
    return " ".join(f"f_w_{w}[{c}]" for w in BOX_WALLS for c in (1, 2, 3))


def _largest(terms: list[str]) -> str:
    """A LAMMPS formula for the largest of ``terms`` (its max() only takes vectors)."""
    if len(terms) == 1:
        return terms[0]
    rest = _largest(terms[1:])
    return f"ternary({terms[0]}>({rest}),{terms[0]},{rest})"


def _wall_sums() -> str:
    """Per wall: summed x and y force on the disks, contact count, largest contact force."""
    out = []
    for name in BOX_WALLS:
        f = f"w_{name}"
        out += [
            f"variable        fx_{f} atom f_{f}[2]",
            f"variable        fy_{f} atom f_{f}[3]",
            f"variable        fm_{f} atom sqrt(f_{f}[2]^2+f_{f}[3]^2)",
            f"variable        in_{f} atom f_{f}[1]",
            f"compute         fx_{f} all reduce sum v_fx_{f}",
            f"compute         fy_{f} all reduce sum v_fy_{f}",
            f"compute         n_{f} all reduce sum v_in_{f}",
            f"compute         cmax_{f} all reduce max v_fm_{f}",
        ]
    return "\n".join(out)


def export_files(
    spec: SpecimenData, ratio: float = 1e-3, max_steps: int = 2_000_000, check_every: int = 500
) -> list[tuple[str, str]]:
    """(name, text) of ``specimen.data`` and ``in.specimen``.

    The data file's comment lines record the thickness, the per-body properties of the
    disks and every wall (``# poro2d ...``), so that ``poro2d import`` reads the
    specimen back whole.
    """
    spec.refuse_dashpot("LAMMPS")
    params = spec.contact_parameters()  # refuses disks of differing properties first
    box = spec.box()
    script = input_script(spec, ratio, max_steps, check_every)
    notes = [
        *spec.header("#"),
        f"# poro2d thickness {spec.thickness!r}",
        f"# poro2d disk_properties {exact(a[0] for a in (spec.density, spec.kn, spec.ks, spec.mu))}",
        f"# poro2d settings {spec.gravity[0]!r} {spec.gravity[1]!r} {spec.local_damping!r} {spec.dt!r}",
        *(f"# poro2d wall {w.name} {exact(w.numbers)}" for w in spec.walls),
        *([f"# poro2d window {spec.force_fraction!r}"] if spec.force_fraction is not None else []),
        f"# pair contact kn ks mu: {params.disks.kn!r} {params.disks.ks!r} {params.disks.mu!r}",
    ]
    if params.disks.mu_r > 0.0:  # the disks', then each wall's, in wall-line order
        values = [params.disks.mu_r, *(w.mu_r for w in spec.walls)]
        notes.append("# poro2d rolling_friction " + exact(values))
    data = data_text(
        spec.x, spec.y, spec.radius, spec.density, spec.thickness, box, margin=float(spec.radius.max()),
        title=f"poro2d {__version__} specimen (atom_style sphere)", comments=notes,
    )  # fmt: skip
    return [(DATA_FILE, data), (INPUT_FILE, script)]


def write_specimen(spec: SpecimenData, out: str | os.PathLike, ratio: float = 1e-3,
                   max_steps: int = 2_000_000, check_every: int = 500) -> list[Path]:  # fmt: skip
    """Write the files of :func:`export_files` into ``out`` (each atomically); returns their paths."""
    return write_texts(out, export_files(spec, ratio, max_steps, check_every))


def read_specimen(path: str | os.PathLike, defaults: dict) -> SpecimenData:
    """A specimen from a LAMMPS data file, with its box.

    The disks' density, stiffness and friction, the walls and the run settings come from
    the ``# poro2d`` notes of an exported file; a file without them takes ``defaults`` (keyed as
    :data:`poro2d.interop.check.DEFAULTS`), its walls at the faces of its simulation box. Its disk
    masses are the file's (LAMMPS' ``4/3 pi r^3 density``) unless ``defaults`` says ``density_given``.
    The specimen's ``locate`` names the line and column each value was read from.
    """
    d = read_data(path)
    notes, n = d.notes, d.x.size
    t = _note(path, notes, "thickness", 1)[0] if "thickness" in notes else float(defaults["thickness"])
    if "disk_properties" in notes:
        rho, kn, ks, mu = _note(path, notes, "disk_properties", 4)
    else:
        rho = float(defaults["solid_density"]) if defaults.get("density_given") else None
        kn, ks, mu = (float(defaults[k]) for k in ("kn_particle", "ks_particle", "friction_particle"))
    # the file's masses define the density unless it is named (an exported file, or --density)
    density = np.full(n, rho) if rho is not None else d.mass / (math.pi * d.radius**2 * t)
    gravity, damping, dt = (0.0, -float(defaults["gravity"])), float(defaults["local_damping"]), None
    if "settings" in notes:
        gx, gy, damping, dt = _note(path, notes, "settings", 4)
        gravity = (gx, gy)
    window = _note(path, notes, "window", 1)[0] if "window" in notes else None
    walls = _wall_notes(path, notes)
    mu_r = _rolling_note(path, notes, walls) if "rolling_friction" in notes else None
    if not walls:
        xlo, xhi, ylo, yhi = d.box
        kw = tuple(float(defaults[k]) for k in ("kn_wall", "ks_wall", "friction_wall"))
        walls = box_walls(xlo, xhi, ylo, yhi, *kw)
    return SpecimenData(
        x=d.x, y=d.y, radius=d.radius, density=density, kn=np.full(n, kn), ks=np.full(n, ks),
        mu=np.full(n, mu), thickness=t, walls=walls, gravity=gravity, local_damping=damping,
        dt=dt if dt else None, source=str(path), force_fraction=window,
        mu_r=None if mu_r is None else np.full(n, mu_r),
        locate=_locator(Path(path), d, from_masses=rho is None),
    )  # fmt: skip


def _rolling_note(path, notes: dict, walls: list[WallData]) -> float:
    """The disks' rolling friction from ``# poro2d rolling_friction DISKS WALL...``; each wall
    (in the order of the wall lines) takes its own value here."""
    values = _note(path, notes, "rolling_friction", 1 + len(walls))
    for column, v in enumerate(values, start=4):
        if v < 0.0:
            where = f"{path} line {notes['rolling_friction'][0]} '# poro2d rolling_friction' column {column}"
            raise InputError(where, v, "[0, inf)")
    for wall, v in zip(walls, values[1:], strict=True):
        wall.mu_r = v
    return values[0]


#: where each value sits: an Atoms column, or a ``# poro2d`` note and its word
_ATOM_COLUMN = {
    "id": (1, "id"),
    "radius": (3, "radius: half the diameter"),
    "density": (4, "density"),
    "x": (5, "x"),
    "y": (6, "y"),
}
_NOTE_WORD = {
    "thickness": ("thickness", 4), "density": ("disk_properties", 4), "kn": ("disk_properties", 5),
    "ks": ("disk_properties", 6), "mu": ("disk_properties", 7), "gravity_x": ("settings", 4),
    "gravity_y": ("settings", 5), "local_damping": ("settings", 6), "dt": ("settings", 7),
    "window": ("window", 4),
}  # fmt: skip
_WALL_WORD = {name: c for c, name in enumerate(("x0", "y0", "x1", "y1", "kn", "ks", "mu"), start=5)}
#: the command-line option behind each value a file of another origin does not hold
_OPTION = {"thickness": "--thickness", "density": "--density", "kn": "--kn", "ks": "--ks", "mu": "--friction"}


def _locator(p: Path, d: DataFile, from_masses: bool):
    """``locate(quantity, atom)``: the line and column of a value, or the option that gave it."""
    lines = {label: k for label, (k, _) in d.notes.items()}

    def locate(quantity: str, i: int | None = None) -> str:
        if quantity == "disk":
            return f"{p} line {d.atom_lines[i]}"
        if quantity in _ATOM_COLUMN and (quantity != "density" or from_masses):
            column, name = _ATOM_COLUMN[quantity]
            extra = ", the disk density m / (pi r^2 t)" if quantity == "density" else ""
            return f"{p} line {d.atom_lines[i]} column {column} ({name}{extra})"
        if quantity in _NOTE_WORD and _NOTE_WORD[quantity][0] in lines:
            key, word = _NOTE_WORD[quantity]
            return f"{p} line {lines[key]} column {word} ({quantity})"
        if quantity.startswith("wall:"):
            _, wall, field = quantity.split(":")
            if f"wall {wall}" in lines:
                column = _WALL_WORD.get(field, 4)
                return f"{p} line {lines[f'wall {wall}']} column {column} (wall {wall} {field})"
            if field == "mu":
                return "--wall-friction"
            if field in ("kn", "ks"):
                return f"wall {field} (Table 1)"
            axis = "x" if wall in ("left", "right") else "y"
            return f"{p} line {d.box_line[axis]} ({axis}lo {axis}hi, the {wall} wall)"
        if quantity in _OPTION:
            return _OPTION[quantity]
        return f"{p} ({quantity})"

    return locate


def box_walls(xlo, xhi, ylo, yhi, kn, ks, mu) -> list[WallData]:
    """The four walls of a poro2d box (``Walls.box``: sides extended past the corners)."""
    from poro2d.dem import Walls

    w = Walls.box(xlo, ylo, xhi, yhi, kn, ks, mu)
    return [
        WallData(w.names[k], *map(float, (*w.p0[k], *w.p1[k], w.kn[k], w.ks[k], w.mu[k]))) for k in range(w.n)
    ]


def _note(path, notes: dict, key: str, count: int) -> list[float]:
    """The ``count`` numbers of the ``# poro2d KEY ...`` line."""
    line, vals = notes[key]
    return _note_numbers(vals, count, f"{path} line {line} '# poro2d {key}'")


def _note_numbers(vals: list[str], count: int, where: str, first: int = 4) -> list[float]:
    """Numbers of a note line; a bad word is named by its column (``first``: that of vals[0])."""
    if len(vals) != count:
        raise InputError(where, " ".join(vals), f"{count} numbers")
    out = []
    for c, v in enumerate(vals, start=first):
        try:
            x = float(v)
        except ValueError:
            x = math.nan
        if not math.isfinite(x):
            raise InputError(f"{where} column {c}", v, "a finite number")
        out.append(x)
    return out


def _wall_notes(path, notes: dict) -> list[WallData]:
    """The walls of the ``# poro2d wall NAME x0 y0 x1 y1 kn ks mu`` lines, in file order."""
    walls = []
    for label, (line, vals) in notes.items():
        if label == "wall":
            raise InputError(f"{path} '# poro2d wall' line", "", "a name and 7 numbers")
        if label.startswith("wall "):
            where = f"{path} line {line} '# poro2d {label}'"
            walls.append(WallData(vals[0], *_note_numbers(vals[1:], 7, where, first=5)))
    return walls
