"""The frictionless jamming fraction phi_J of a set of disks: an independent dense-end reference.

Why
---
Multilayer compaction with frictionless preparation should reach, near its dense end, about
the solid fraction at which frictionless disks of the same grading jam. This module finds
that fraction by a different method, in different code: it imports nothing from the DEM
engine (:mod:`poro2d.dem`) or the compaction (:mod:`poro2d.specimen.compaction`); only the
drawing of radii from a grading curve (:mod:`poro2d.grading`) may be shared.

Model
-----
A periodic square cell of side ``L`` (no walls, no gravity) holds frictionless soft disks
with a harmonic repulsion

    U = (k / 2) * sum over pairs of overlap_ij^2,     overlap_ij = r_i + r_j - |x_j - x_i|,

for overlapping pairs (the nearest periodic image only). Lengths are measured in the
number-mean diameter of the disks and ``k = 1``, so ``U / N`` is dimensionless; for equal
disks this is exactly O'Hern's ``(eps / 2) (1 - r / sigma)^2`` with ``eps = k sigma^2``. The
constant-``k`` form (rather than O'Hern's ``1 / sigma_ij^2`` weights) is chosen because all
pairs then have the same stiffness, so one time step suits wide gradings too. The jamming
point itself does not depend on this choice in the limit of vanishing overlap.

Minimisation: FIRE
------------------
The energy is minimised with FIRE (Bitzek et al. 2006, PRL 97, 170201) in the form of
Guenole et al. 2020, Comput. Mater. Sci. 175, 109584 (semi-implicit Euler, half a step back
on an uphill move). One compiled call runs a whole minimisation over struct-of-arrays
(positions ``(n, 2)``, radii ``(n,)``) with a Verlet list (skin) built from a cell list and
rebuilt when a disk has moved more than half the skin. Each disk gets the mass
``(r_i + r_min) / (2 r_min)``: its number of contacts can grow like that (a large disk
touches many small ones), so every disk has about the same highest frequency and one time
step is efficient for wide gradings too.

FIRE was preferred over L-BFGS (:func:`scipy.optimize.minimize`, ``L-BFGS-B``, with the same
compiled energy and gradient) after a comparison on N = 1000 bidisperse disks 1e-4 and 1e-3
above their phi_J: both reach the same energy (to 4 digits) and a largest force ~1e-10, and
L-BFGS needs about half as many gradient evaluations (2486 against 4268 FIRE steps; 4479
against 8317), but it took 3.7 s and 14.7 s against FIRE's 0.12 s and 0.25 s, its time
going into the work per iteration outside compiled code. 1e-4 and 1e-3 below phi_J both
reach zero energy at once (L-BFGS in 46 and 20 evaluations, FIRE in 168 and 93 steps,
< 0.02 s). FIRE also keeps a whole minimisation, list rebuilds included, in one compiled
call. A minimisation ends when

- the energy per disk is below ``e_zero`` (default 1e-16, O'Hern's threshold): *unjammed*;
- or the largest net force on a disk is below ``f_rel`` times the mean contact force (or
  below an absolute floor ``F_ABS``): a local minimum, *jammed* if its energy is above
  ``e_zero``;
- or ``max_steps`` steps were taken: the state is judged by its energy and the result is
  marked not converged.

Protocol (O'Hern, Silbert, Liu & Nagel 2003, PRE 68, 011306)
-----------------------------------------------------------
Disks start at random positions at a low packing fraction (``phi_start``) and are minimised.
The cell is then compressed (positions and side scaled, radii fixed) by ``dphi`` and
minimised again, step after step. When a minimised state is jammed (energy per disk above
``e_zero``) the direction turns to expansion, and every turn halves the step. The search
stops when the step falls below ``tol``; ``phi_J`` is the packing fraction of the last jammed
state (where the energy has just become nonzero), which lies within ``2 tol`` of the last
unjammed one.

Literature
----------
- 50:50 bidisperse disks of diameter ratio 1.4: phi_J = 0.842 for large N (O'Hern et al.
  2003), about 0.84 for N ~ 1000 (smaller cells jam a little lower on average and their
  packings spread more from seed to seed).
- Polydisperse disks: phi_J grows with the size span: about 0.84-0.85 for mild
  polydispersity, higher for wide gradings (Voivret et al. 2007; Meer et al. 2024).

At the jamming point the disks that are not rattlers (fewer than 3 contacts, removed
repeatedly) have on average 4 contacts (isostatic in 2D); :class:`JammingResult` reports it
as a check.
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numba import njit

from poro2d.errors import InputError, as_float_array, check_int, check_range
from poro2d.grading import GradingCurve, draw_disks

__all__ = [
    "E_ZERO",
    "FireResult",
    "JammingReference",
    "JammingResult",
    "energy_and_forces",
    "fire_minimise",
    "jamming_fraction",
    "jamming_reference",
]

#: Energy per disk below which a minimised state counts as unjammed (O'Hern et al. 2003).
E_ZERO = 1e-16
#: Absolute floor of the force tolerance: below it, forces are rounding noise of positions ~ L.
F_ABS = 1e-13
#: Verlet skin, in mean diameters (lengths are in mean diameters inside the protocol).
SKIN = 0.3
#: The largest packing fraction the protocol compresses to (no disk set jams above it).
PHI_MAX = 0.97

# FIRE constants (Bitzek et al. 2006): steps of downhill motion before dt grows, growth and
# cut of dt, starting mixing and its decay.
_N_MIN = 5
_F_INC = 1.1
_F_DEC = 0.5
_ALPHA0 = 0.1
_F_ALPHA = 0.99
# time steps in units of sqrt(m_min / k): stable explicit steps are below ~0.5 with the masses
# used here, FIRE may go above briefly and backs off
_DT0 = 0.05
_DT_MAX = 0.5
_DT_MIN = 1e-4

# status codes of a minimisation
ZERO_ENERGY, FORCE_BALANCE, MAX_STEPS = 0, 1, 2
_STATUS_NAMES = ("zero_energy", "force_balance", "max_steps")


# ----------------------------------------------------------------------------- compiled kernels
@njit(inline="always", cache=True)
def _nearest_image(pos, i, j, lx, ly):
    """The separation from disk i to the nearest periodic image of disk j."""
    dx = pos[j, 0] - pos[i, 0]
    dy = pos[j, 1] - pos[i, 1]
    return dx - lx * np.rint(dx / lx), dy - ly * np.rint(dy / ly)


@njit(cache=True)
def _cell_index(x: float, length: float, ncell: int) -> int:
    """The cell of coordinate ``x`` in a periodic row of ``ncell`` cells of total ``length``."""
    w = x - length * math.floor(x / length)  # wrapped into [0, length)
    c = int(w / length * ncell)
    # rounding can give ncell for w just below length
    return min(max(c, 0), ncell - 1)


@njit(cache=True)
def _sort_into_cells(pos, lx, ly, nx, ny):
    """Counting sort of disks into cells: ``order[start[c]:start[c + 1]]`` are cell c's disks."""
    n = pos.shape[0]
    cell = np.empty(n, np.int64)
    start = np.zeros(nx * ny + 1, np.int64)
    for i in range(n):
        c = _cell_index(pos[i, 1], ly, ny) * nx + _cell_index(pos[i, 0], lx, nx)
        cell[i] = c
        start[c + 1] += 1
    for c in range(nx * ny):
        start[c + 1] += start[c]
    cursor = start[:-1].copy()
    order = np.empty(n, np.int64)
    for i in range(n):  # disks in index order within a cell: the list is deterministic
        order[cursor[cell[i]]] = i
        cursor[cell[i]] += 1
    return cell, start, order


@njit(cache=True)
def _scan_pairs(pos, rad, lx, ly, skin, nx, ny, cell, start, order, pi, pj, fill):
    """Count (``fill`` False) or store the pairs ``i < j`` closer than ``r_i + r_j + skin``."""
    n = pos.shape[0]
    reach = 1 if (nx >= 3 and ny >= 3) else 0  # one cell (all pairs) when the grid is too coarse
    count = 0
    for i in range(n):
        cx = cell[i] % nx
        cy = cell[i] // nx
        for oy in range(-reach, reach + 1):
            for ox in range(-reach, reach + 1):
                c = ((cy + oy) % ny) * nx + (cx + ox) % nx
                for k in range(start[c], start[c + 1]):
                    j = order[k]
                    if j <= i:
                        continue
                    dx, dy = _nearest_image(pos, i, j, lx, ly)
                    cut = rad[i] + rad[j] + skin
                    if dx * dx + dy * dy < cut * cut:
                        if fill:
                            pi[count] = i
                            pj[count] = j
                        count += 1
    return count


@njit(cache=True)
def _build_pairs(pos, rad, lx, ly, skin):
    """Verlet list (half: ``i < j``) of the pairs within ``r_i + r_j + skin``, via a cell list."""
    cut = 2.0 * rad.max() + skin
    nx = max(int(lx // cut), 1)
    ny = max(int(ly // cut), 1)
    if nx < 3 or ny < 3:  # neighbouring cells would repeat: one cell holding all disks instead
        nx, ny = 1, 1
    cell, start, order = _sort_into_cells(pos, lx, ly, nx, ny)
    dummy = np.empty(0, np.int64)
    npair = _scan_pairs(pos, rad, lx, ly, skin, nx, ny, cell, start, order, dummy, dummy, False)
    pi = np.empty(npair, np.int64)
    pj = np.empty(npair, np.int64)
    _scan_pairs(pos, rad, lx, ly, skin, nx, ny, cell, start, order, pi, pj, True)
    return pi, pj


@njit(cache=True)
def _pair_offset(pos, rad, lx, ly, pi, pj, k):
    """Pair ``k``'s disks i and j, the nearest image's offset (dx, dy) from i to j and their radii's sum."""
    i = pi[k]
    j = pj[k]
    dx, dy = _nearest_image(pos, i, j, lx, ly)
    return i, j, dx, dy, rad[i] + rad[j]


@njit(cache=True)
def _forces(pos, rad, lx, ly, pi, pj, force, stats):
    """Harmonic energy; net forces into ``force``; ``stats`` = (sum of overlaps, contacts, virial)."""
    force[:, :] = 0.0
    energy = 0.0
    sum_overlap = 0.0
    contacts = 0
    virial = 0.0
    for k in range(pi.shape[0]):
        i, j, dx, dy, s = _pair_offset(pos, rad, lx, ly, pi, pj, k)
        r2 = dx * dx + dy * dy
        if r2 >= s * s:
            continue
        r = math.sqrt(r2)
        overlap = s - r
        if r > 0.0:
            ux = dx / r
            uy = dy / r
        else:  # coincident centres (a random start can do it): push apart along x
            ux = 1.0
            uy = 0.0
        energy += 0.5 * overlap * overlap
        sum_overlap += overlap
        contacts += 1
        virial += overlap * r  # f_ij . r_ij with f = k * overlap along the centre line
        force[j, 0] += overlap * ux
        force[j, 1] += overlap * uy
        force[i, 0] -= overlap * ux
        force[i, 1] -= overlap * uy
    stats[0] = sum_overlap
    stats[1] = contacts
    stats[2] = virial
    return energy


@njit(cache=True)
def _max_force(force):
    worst = 0.0
    for i in range(force.shape[0]):
        worst = max(worst, force[i, 0] * force[i, 0] + force[i, 1] * force[i, 1])
    return math.sqrt(worst)


@njit(cache=True)
def _moved_beyond(pos, ref, limit):
    """True when some disk has moved more than ``limit`` since ``ref`` (the last list build)."""
    lim2 = limit * limit
    for i in range(pos.shape[0]):
        dx = pos[i, 0] - ref[i, 0]
        dy = pos[i, 1] - ref[i, 1]
        if dx * dx + dy * dy > lim2:
            return True
    return False


@njit(cache=True)
def _converged(energy, fmax, stats, n, e_zero, f_rel, f_abs):
    """Status of the current state: ZERO_ENERGY, FORCE_BALANCE, or -1 (go on)."""
    if energy < e_zero * n:
        return ZERO_ENERGY
    mean_force = stats[0] / stats[1] if stats[1] > 0 else 0.0  # k = 1: force = overlap
    if fmax <= f_abs or fmax <= f_rel * mean_force:
        return FORCE_BALANCE
    return -1


@njit(nogil=True, cache=True)
def _fire(pos, rad, mass, lx, ly, skin, e_zero, f_rel, f_abs, max_steps, out):
    """FIRE minimisation of ``pos`` in place; ``out`` = (energy, max force, steps, status, rebuilds)."""
    n = pos.shape[0]
    vel = np.zeros((n, 2))
    force = np.empty((n, 2))
    stats = np.zeros(3)
    pi, pj = _build_pairs(pos, rad, lx, ly, skin)
    ref = pos.copy()
    rebuilds = 1
    energy = _forces(pos, rad, lx, ly, pi, pj, force, stats)
    dt = _DT0
    alpha = _ALPHA0
    downhill = 0
    step = 0
    status = MAX_STEPS
    while True:
        fmax = _max_force(force)
        s = _converged(energy, fmax, stats, n, e_zero, f_rel, f_abs)
        if s >= 0:
            status = s
            break
        if step >= max_steps:
            break
        power = 0.0
        for i in range(n):
            power += force[i, 0] * vel[i, 0] + force[i, 1] * vel[i, 1]
        if power > 0.0:
            downhill += 1
            if downhill > _N_MIN:
                dt = min(dt * _F_INC, _DT_MAX)
                alpha *= _F_ALPHA
        else:
            # uphill: step half of the last move back, stop, and restart cautiously
            for i in range(n):
                pos[i, 0] -= 0.5 * dt * vel[i, 0]
                pos[i, 1] -= 0.5 * dt * vel[i, 1]
            vel[:, :] = 0.0
            downhill = 0
            dt = max(dt * _F_DEC, _DT_MIN)
            alpha = _ALPHA0
        # semi-implicit Euler: velocity first, then the FIRE mixing towards the force
        vnorm2 = 0.0
        fnorm2 = 0.0
        for i in range(n):
            vel[i, 0] += dt * force[i, 0] / mass[i]
            vel[i, 1] += dt * force[i, 1] / mass[i]
            vnorm2 += vel[i, 0] * vel[i, 0] + vel[i, 1] * vel[i, 1]
            fnorm2 += force[i, 0] * force[i, 0] + force[i, 1] * force[i, 1]
        mix = alpha * math.sqrt(vnorm2 / fnorm2) if fnorm2 > 0.0 else 0.0
        for i in range(n):
            vel[i, 0] = (1.0 - alpha) * vel[i, 0] + mix * force[i, 0]
            vel[i, 1] = (1.0 - alpha) * vel[i, 1] + mix * force[i, 1]
            pos[i, 0] += dt * vel[i, 0]
            pos[i, 1] += dt * vel[i, 1]
        if _moved_beyond(pos, ref, 0.5 * skin):
            pi, pj = _build_pairs(pos, rad, lx, ly, skin)
            ref[:, :] = pos
            rebuilds += 1
        energy = _forces(pos, rad, lx, ly, pi, pj, force, stats)
        step += 1
    out[0] = energy
    out[1] = _max_force(force)
    out[2] = step
    out[3] = status
    out[4] = rebuilds


@njit(cache=True)
def _contact_counts(pos, rad, lx, ly):
    """Contacts per disk, the contact pairs, and the virial sum of f . r (k = 1)."""
    pi, pj = _build_pairs(pos, rad, lx, ly, 0.0)
    z = np.zeros(pos.shape[0], np.int64)
    keep = np.zeros(pi.shape[0], np.bool_)
    virial = 0.0
    for k in range(pi.shape[0]):
        i, j, dx, dy, s = _pair_offset(pos, rad, lx, ly, pi, pj, k)
        r = math.sqrt(dx * dx + dy * dy)
        if r < s:
            z[i] += 1
            z[j] += 1
            keep[k] = True
            virial += (s - r) * r
    return z, pi[keep], pj[keep], virial


@njit(cache=True)
def _strip_rattlers(z, pi, pj, z_min):
    """Remove disks with fewer than ``z_min`` contacts, repeatedly; True marks a rattler."""
    z = z.copy()
    rattler = np.zeros(z.shape[0], np.bool_)
    alive = np.ones(pi.shape[0], np.bool_)
    changed = True
    while changed:
        changed = False
        for i in range(z.shape[0]):
            if not rattler[i] and z[i] < z_min:
                rattler[i] = True
                changed = True
        for k in range(pi.shape[0]):
            if alive[k] and (rattler[pi[k]] or rattler[pj[k]]):
                alive[k] = False
                z[pi[k]] -= 1
                z[pj[k]] -= 1
    return rattler, int(alive.sum())


# ----------------------------------------------------------------------------- checks
def _check_radii(radii) -> np.ndarray:
    r = as_float_array("radii", radii)
    if r.ndim != 1 or r.size < 2:
        raise InputError("radii", _shape_of(radii), "a flat array of at least 2 radii")
    if not np.all(np.isfinite(r)) or np.any(r <= 0.0):
        raise InputError("radii", "array with a non-finite or non-positive radius", "finite radii > 0")
    return np.ascontiguousarray(r)


def _shape_of(values) -> str:
    return f"array of shape {np.shape(values)}"


def _check_box(box) -> tuple[float, float]:
    if isinstance(box, Sequence | np.ndarray) and len(box) == 2:
        lx = check_range("box[0]", box[0], 0.0, None, lo_open=True)
        ly = check_range("box[1]", box[1], 0.0, None, lo_open=True)
    else:
        lx = ly = check_range("box", box, 0.0, None, lo_open=True)
    if not (math.isfinite(lx) and math.isfinite(ly)):
        raise InputError("box", box, "finite cell sides > 0")
    return lx, ly


def _check_positions(positions, n: int) -> np.ndarray:
    p = as_float_array("positions", positions)
    if p.shape != (n, 2):
        raise InputError("positions", _shape_of(positions), f"an array of shape ({n}, 2), one row per radius")
    if not np.all(np.isfinite(p)):
        raise InputError("positions", "array with a non-finite value", "finite coordinates")
    return np.array(p, dtype=np.float64, order="C")  # a copy: minimisation works in place


def _check_min_image(r: np.ndarray, side: float, parameter: str, value) -> None:
    """Refuse cells in which one disk could overlap two images of another."""
    two = np.sort(r)[-2:].sum()
    if two >= 0.5 * side:
        raise InputError(
            parameter,
            value,
            "a periodic cell at least 2 x (sum of the two largest radii) wide",
            f"the two largest radii sum to {two:.4g} against half the side {0.5 * side:.4g}; "
            "use more disks (or a narrower grading)",
        )


def _seed_rng(seed) -> np.random.Generator:
    if isinstance(seed, np.random.Generator):
        return seed
    return np.random.default_rng(check_int("seed", seed, 0, None))


def _masses(r: np.ndarray) -> np.ndarray:
    """FIRE masses ``(r + r_min) / (2 r_min)``: about the contacts a disk can have, see module doc."""
    r_min = r.min()
    return (r + r_min) / (2.0 * r_min)


# ----------------------------------------------------------------------------- public helpers
def energy_and_forces(positions, radii, box) -> tuple[float, np.ndarray]:
    """Energy ``U = (1/2) sum overlap^2`` (``k = 1``) and net forces ``-dU/dx`` of disks in a periodic cell.

    ``box`` is the side of a square cell or ``(Lx, Ly)``. Units are those of the input
    (energy in length^2, forces in length, times k).
    """
    r = _check_radii(radii)
    pos = _check_positions(positions, r.size)
    lx, ly = _check_box(box)
    _check_min_image(r, min(lx, ly), "box", box)
    pi, pj = _build_pairs(pos, r, lx, ly, 0.0)
    force = np.empty_like(pos)
    energy = _forces(pos, r, lx, ly, pi, pj, force, np.zeros(3))
    return float(energy), force


@dataclass(frozen=True)
class FireResult:
    """One FIRE minimisation: final positions (wrapped into the cell), energy, largest net force."""

    positions: np.ndarray
    energy: float
    max_force: float
    steps: int
    status: str  # "zero_energy", "force_balance" or "max_steps"
    rebuilds: int

    @property
    def converged(self) -> bool:
        return self.status != "max_steps"


def fire_minimise(
    positions,
    radii,
    box,
    *,
    e_zero: float = E_ZERO,
    f_rel: float = 1e-6,
    max_steps: int = 200_000,
    skin: float | None = None,
) -> FireResult:
    """Minimise the harmonic energy of disks in a periodic cell with FIRE (compiled, one core).

    Stops when the energy per disk is below ``e_zero`` (``status="zero_energy"``), when the
    largest net force is below ``f_rel`` times the mean contact force or below ``F_ABS``
    (``"force_balance"``), or after ``max_steps`` steps. ``skin`` defaults to 0.3 mean
    diameters. Units are those of the input (time steps assume ``k = 1`` and lengths of
    order the disk sizes: pass radii of order 0.5 for best speed).
    """
    r = _check_radii(radii)
    pos = _check_positions(positions, r.size)
    lx, ly = _check_box(box)
    _check_min_image(r, min(lx, ly), "box", box)
    e_zero = check_range("e_zero", e_zero, 0.0, None, lo_open=True)
    f_rel = check_range("f_rel", f_rel, 0.0, 1.0, lo_open=True)
    max_steps = check_int("max_steps", max_steps, 0, None)
    if skin is None:
        skin = SKIN * 2.0 * float(r.mean())
    skin = check_range("skin", skin, 0.0, None, lo_open=True)
    return _minimise(pos, r, _masses(r), lx, ly, skin, e_zero, f_rel, max_steps)


def _minimise(pos, r, mass, lx, ly, skin, e_zero, f_rel, max_steps) -> FireResult:
    """FIRE on checked, contiguous arrays (``pos`` is changed in place and wrapped)."""
    out = np.zeros(5)
    _fire(pos, r, mass, lx, ly, skin, e_zero, f_rel, F_ABS, max_steps, out)
    pos[:, 0] -= lx * np.floor(pos[:, 0] / lx)
    pos[:, 1] -= ly * np.floor(pos[:, 1] / ly)
    return FireResult(
        positions=pos,
        energy=float(out[0]),
        max_force=float(out[1]),
        steps=int(out[2]),
        status=_STATUS_NAMES[int(out[3])],
        rebuilds=int(out[4]),
    )


# ----------------------------------------------------------------------------- the protocol
@dataclass(frozen=True)
class JammingResult:
    """phi_J of one packing and the state of its last jammed configuration.

    Lengths of ``positions`` and ``box`` are in the units of the radii given; ``pressure``
    and ``energy_per_disk`` are dimensionless (``k = 1``, lengths in mean diameters).
    ``contact_number`` is the mean number of contacts of the disks that are not rattlers
    (4 at isostatic jamming in 2D). ``stalled_minimisations`` counts the minimisations that
    ran out of ``max_steps`` (each was then judged by its energy); ``converged`` needs none.
    """

    phi_j: float
    phi_unjammed: float
    energy_per_disk: float
    pressure: float
    n_disks: int
    n_contacts: int
    n_rattlers: int
    contact_number: float
    minimisations: int
    fire_steps: int
    stalled_minimisations: int
    seconds: float
    converged: bool
    positions: np.ndarray = field(repr=False)
    radii: np.ndarray = field(repr=False)
    box: float

    @property
    def porosity(self) -> float:
        return 1.0 - self.phi_j


@dataclass
class _Search:
    """Where the compress/expand bisection stands."""

    phi: float
    step: float
    direction: int = 1  # +1 compress, -1 expand
    jammed_phi: float = math.nan
    unjammed_phi: float = math.nan
    seen_jammed: bool = False


def _next_phi(search: _Search, jammed: bool) -> None:
    """O'Hern's rule: compress while unjammed, expand while jammed, halve the step at every turn."""
    if jammed:
        search.jammed_phi = search.phi
        search.seen_jammed = True
    else:
        search.unjammed_phi = search.phi
    if (jammed and search.direction > 0) or (not jammed and search.direction < 0):
        search.direction = -search.direction
        search.step *= 0.5
    search.phi += search.direction * search.step


def _rescale(pos: np.ndarray, side: float, phi_old: float, phi_new: float) -> float:
    """Affine compression (or expansion) of positions and cell to ``phi_new``; returns the new side."""
    factor = math.sqrt(phi_old / phi_new)
    pos *= factor
    return side * factor


def jamming_fraction(
    radii,
    seed: int | np.random.Generator,
    *,
    tol: float = 1e-5,
    phi_start: float = 0.5,
    dphi: float = 2e-3,
    e_zero: float = E_ZERO,
    f_rel: float = 1e-6,
    max_steps: int = 500_000,
    max_minimisations: int = 2_000,
) -> JammingResult:
    """phi_J of the disks ``radii`` from random positions drawn with ``seed`` (O'Hern protocol).

    Starts at packing fraction ``phi_start``, compresses in steps ``dphi``, turns and halves
    the step at every change between jammed and unjammed until the step is below ``tol``.
    ``max_steps`` bounds each FIRE minimisation and ``max_minimisations`` the whole search;
    ``converged`` is False if either bound was hit (or no jammed state was found below
    ``PHI_MAX``, then ``phi_j`` is NaN). The same radii and seed give the same
    result bit for bit (one thread, fixed summation order).
    """
    t0 = time.perf_counter()
    r_in = _check_radii(radii)
    rng = _seed_rng(seed)
    tol = check_range("tol", tol, 1e-9, 1e-2)
    phi_start = check_range("phi_start", phi_start, 0.05, 0.8)
    dphi = check_range("dphi", dphi, tol, 0.1)
    e_zero = check_range("e_zero", e_zero, 0.0, None, lo_open=True)
    f_rel = check_range("f_rel", f_rel, 0.0, 1.0, lo_open=True)
    max_steps = check_int("max_steps", max_steps, 100, None)
    max_minimisations = check_int("max_minimisations", max_minimisations, 1, None)

    unit = 2.0 * float(r_in.mean())  # lengths in mean diameters from here on
    r = r_in / unit
    solid = float(np.pi * np.sum(r * r))
    _check_min_image(r, math.sqrt(solid / PHI_MAX), "radii", f"{r_in.size} radii")
    mass = _masses(r)
    skin = SKIN
    side = math.sqrt(solid / phi_start)
    pos = rng.random((r.size, 2)) * side

    search = _Search(phi=phi_start, step=dphi)
    tally = _Tally()
    while tally.minimisations < max_minimisations:
        res = _minimise(pos, r, mass, side, side, skin, e_zero, f_rel, max_steps)
        jammed = res.energy >= e_zero * r.size
        tally.add(res, pos, side, jammed)
        phi = search.phi
        _next_phi(search, jammed)
        if search.seen_jammed and search.step < tol and not math.isnan(search.unjammed_phi):
            break
        if search.phi > PHI_MAX:  # never jammed: phi_J is NaN and the result not converged
            break
        side = _rescale(pos, side, phi, search.phi)
    done = search.step < tol and tally.best is not None
    return _result(tally, search, r, unit, done, time.perf_counter() - t0)


@dataclass
class _Tally:
    """What the minimisations of one search did, and the last jammed state (positions, side, result)."""

    minimisations: int = 0
    fire_steps: int = 0
    stalled: int = 0
    best: tuple[np.ndarray, float, FireResult] | None = None

    def add(self, res: FireResult, pos: np.ndarray, side: float, jammed: bool) -> None:
        self.minimisations += 1
        self.fire_steps += res.steps
        self.stalled += not res.converged
        if jammed:
            self.best = (pos.copy(), side, res)


def _result(tally: _Tally, search: _Search, r, unit, done, seconds) -> JammingResult:
    """Describe the last jammed state: contacts, rattlers, pressure."""
    common = dict(
        phi_unjammed=float(search.unjammed_phi),
        n_disks=int(r.size),
        minimisations=tally.minimisations,
        fire_steps=tally.fire_steps,
        stalled_minimisations=tally.stalled,
        seconds=seconds,
        converged=bool(done and tally.stalled == 0),
        radii=r * unit,
    )
    if tally.best is None:  # never jammed below PHI_MAX (or stopped too early)
        nan = math.nan
        return JammingResult(
            phi_j=nan, energy_per_disk=nan, pressure=nan, n_contacts=0, n_rattlers=0,
            contact_number=nan, positions=np.empty((0, 2)), box=nan, **common,
        )  # fmt: skip
    pos, side, res = tally.best
    z, pi, pj, virial = _contact_counts(pos, r, side, side)
    rattler, n_contacts = _strip_rattlers(z, pi, pj, 3)
    n_rigid = int(r.size - rattler.sum())
    return JammingResult(
        phi_j=float(search.jammed_phi),
        energy_per_disk=res.energy / r.size,
        pressure=float(virial / (2.0 * side * side)),  # 2D virial: p = sum f.r / (d A)
        n_contacts=int(n_contacts),
        n_rattlers=int(rattler.sum()),
        contact_number=2.0 * n_contacts / n_rigid if n_rigid else math.nan,
        positions=pos * unit,
        box=side * unit,
        **common,
    )


# ----------------------------------------------------------------------------- a grading's reference
@dataclass(frozen=True)
class JammingReference:
    """phi_J of a grading over several seeds; ``std`` is the sample standard deviation (0 for one seed)."""

    seeds: tuple[int, ...]
    phi_j: tuple[float, ...]
    n_disks: tuple[int, ...]
    mean: float
    std: float
    seconds: float
    results: tuple[JammingResult, ...] = field(repr=False)

    @property
    def porosity_mean(self) -> float:
        return 1.0 - self.mean

    @property
    def porosity_std(self) -> float:
        return self.std

    @property
    def converged(self) -> bool:
        return all(res.converged for res in self.results)


def jamming_reference(
    grading: GradingCurve,
    n_disks: int = 1500,
    seeds: Sequence[int] = (0, 1, 2),
    *,
    within_class: str = "uniform",
    **options,
) -> JammingReference:
    """phi_J of ``grading`` for each seed, with about ``n_disks`` disks; mean and spread.

    Radii come from :func:`poro2d.grading.draw_disks` with a solid area of
    ``n_disks`` mean disk areas; each seed is split into two independent streams, one for the
    radii and one for the start positions. ``options`` go to :func:`jamming_fraction`.
    """
    if not isinstance(grading, GradingCurve):
        raise InputError("grading", type(grading).__name__, "a GradingCurve")
    n_disks = check_int("n_disks", n_disks, 16, 200_000)
    if isinstance(seeds, str | bytes) or not isinstance(seeds, Sequence) or len(seeds) == 0:
        raise InputError("seeds", seeds, "a non-empty sequence of integers >= 0")
    seeds = tuple(check_int("seeds", s, 0, None) for s in seeds)
    t0 = time.perf_counter()
    results = []
    for s in seeds:
        radii_rng, position_rng = (np.random.default_rng(c) for c in np.random.SeedSequence(s).spawn(2))
        area = n_disks * grading.mean_disk_area(within_class)
        radii = draw_disks(grading, area, radii_rng, within_class=within_class)
        results.append(jamming_fraction(radii, position_rng, **options))
    phi = np.array([res.phi_j for res in results])
    return JammingReference(
        seeds=seeds,
        phi_j=tuple(float(v) for v in phi),
        n_disks=tuple(res.n_disks for res in results),
        mean=float(phi.mean()),
        std=float(phi.std(ddof=1)) if phi.size > 1 else 0.0,
        seconds=time.perf_counter() - t0,
        results=tuple(results),
    )
