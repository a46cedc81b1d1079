"""Verlet lists with a skin, built from a cell grid in O(N).

Disk-disk candidates are kept as a half list in CSR form (row ``i`` lists the
partners ``j > i``); disk-wall candidates as a CSR list of wall indices per disk.
A pair is a candidate while the gap between the two surfaces is below ``skin``;
the lists stay valid until a disk or a wall has moved more than ``skin / 2``.

On a rebuild the history of every pair that survives (its shear force and its
rolling moment) is copied across by matching ``(i, j)`` in the old row of ``i``. The capacity of the pair
arrays is fixed by the caller: when it is too small the build reports how much
it needs and changes nothing, so the caller can grow the arrays and retry.

A build is a sequence of phases (grid, count rows, prefix sums, fill rows, copy
back). The phases over rows take a disk range ``[lo, hi)`` and write only their own
rows, so the engine's workers run them side by side between barriers
(:func:`poro2d.dem.kernels.step_block`); :func:`build_pairs` and
:func:`build_wall_pairs` run them one after the other. Either way the lists are the
same, slot for slot.

Scratch storage (all preallocated by the caller, see :func:`grid_scratch`):
``cell`` and ``members`` (n), ``cstart`` and ``cfill`` (:func:`max_cells` + 1),
``ginfo`` (float64, the grid: :data:`G_NCX` ... :data:`G_REACH`) and ``cand`` (n x
:data:`CAND_SLOTS`, or empty).

The counting scan keeps a row's partners in ``cand`` when they are fewer than
:data:`CAND_SLOTS`, so that filling copies them instead of scanning the nine cells again; a
row with more partners is scanned again. Either way a row's partners
are written in the scan's order: the lists are the same, slot for slot.

For wide size ratios the disk-disk rows are built from grids by size level instead
(:func:`level_grid`, :func:`count_level_rows`, :func:`fill_level_rows`; storage in
:func:`level_scratch`): the same candidates, found without crowding a coarse disk's cells
with fines (see the section at the end of the module).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from poro2d.dem.contact_law import segment_closest


@njit(cache=True)
def max_cells(n):
    """Most cells the grid may use for ``n`` disks (a runaway disk cannot make it huge)."""
    return 4 * n + 16


# entries of ``ginfo`` (float64): cells along x and y, the grid's origin, the inverse of a
# cell's side, and the largest radius plus the skin (a row's reach beyond its own radius)
G_NCX, G_NCY, G_X0, G_Y0, G_INV, G_REACH = range(6)
G_SIZE = 6
#: a row's cell range is widened by this fraction of a cell: rounding may not narrow it
_GRID_PAD = 1e-9

#: slots per disk for the partners the counting scan keeps for the filling: all but the last,
#: which takes the candidates past them (paper grading: 2.4 partners on average)
CAND_SLOTS = 8


class GridScratch(NamedTuple):
    """The cell grid's storage (int64): see the module doc."""

    cell: np.ndarray  # (n) cell of each disk
    members: np.ndarray  # (n) disks ordered by cell
    cstart: np.ndarray  # (max_cells + 1) first member of each cell
    cfill: np.ndarray  # (max_cells + 1) fill counters
    ginfo: np.ndarray  # (G_SIZE) float64: the grid's cell counts, origin, inverse side, reach
    cand: np.ndarray  # (n * CAND_SLOTS) the partners the counting scan found, row by row


def grid_scratch(n: int) -> GridScratch:
    """The grid storage for ``n`` disks."""
    nc = max_cells(n) + 1
    i8 = np.int64
    return GridScratch(
        np.zeros(n, i8), np.zeros(n, i8), np.zeros(nc, i8), np.zeros(nc, i8), np.zeros(G_SIZE),
        np.zeros(n * CAND_SLOTS, i8),
    )  # fmt: skip


@njit(cache=True)
def cell_grid(pos, radius, skin, cell, members, cstart, cfill, ginfo):
    """Bin the disks into square cells of side 2 r_max + skin (members in index order)."""
    n = pos.shape[0]
    if n == 0:
        ginfo[G_NCX] = 1
        ginfo[G_NCY] = 1
        cstart[0] = 0
        cstart[1] = 0
        return
    xmin = pos[0, 0]
    xmax = pos[0, 0]
    ymin = pos[0, 1]
    ymax = pos[0, 1]
    rmax = radius[0]
    for i in range(1, n):
        x = pos[i, 0]
        y = pos[i, 1]
        if x < xmin:
            xmin = x
        if x > xmax:
            xmax = x
        if y < ymin:
            ymin = y
        if y > ymax:
            ymax = y
        if radius[i] > rmax:
            rmax = radius[i]
    size = 2.0 * rmax + skin
    # A runaway disk must not make the grid huge: cap the cell count near 4N.
    while ((xmax - xmin) / size + 1.0) * ((ymax - ymin) / size + 1.0) > max_cells(n):
        size *= 1.5
    ncx = int((xmax - xmin) / size) + 1
    ncy = int((ymax - ymin) / size) + 1
    ncell = ncx * ncy
    for c in range(ncell + 1):
        cstart[c] = 0
    for i in range(n):
        cx = int((pos[i, 0] - xmin) / size)
        cy = int((pos[i, 1] - ymin) / size)
        if cx >= ncx:
            cx = ncx - 1
        if cy >= ncy:
            cy = ncy - 1
        c = cy * ncx + cx
        cell[i] = c
        cstart[c + 1] += 1
    _members_by_cell(n, ncell, cell, members, cstart, cfill)
    ginfo[G_NCX] = ncx
    ginfo[G_NCY] = ncy
    ginfo[G_X0] = xmin
    ginfo[G_Y0] = ymin
    ginfo[G_INV] = 1.0 / size
    ginfo[G_REACH] = rmax + skin


@njit(cache=True)
def _members_by_cell(n, ncell, cell, members, cstart, cfill):
    """The disks ordered by cell: ``cstart[c + 1]`` holds cell c's count on entry, its end on
    exit; members of a cell stay in index order."""
    for c in range(ncell):
        cstart[c + 1] += cstart[c]
        cfill[c] = cstart[c]
    for i in range(n):
        c = cell[i]
        members[cfill[c]] = i
        cfill[c] += 1


@njit(inline="always", cache=True)
def _cell_span(c, ncell, v, reach, origin, inv):
    """The cells, among c - 1 .. c + 1 of a grid of ``ncell``, that the interval v +- reach
    touches (widened by :data:`_GRID_PAD` of a cell); c itself always."""
    lo = int((v - reach - origin) * inv - _GRID_PAD)  # truncation: 0 for anything below
    hi = int((v + reach - origin) * inv + _GRID_PAD)
    return max(c - 1, min(c, lo), 0), min(c + 1, max(c, hi), ncell - 1)


@njit(inline="always", cache=True)
def _grid(ginfo):
    """The grid's entries as scalars, read once per call: (ncx, ncy, x0, y0, inv, reach
    beyond a disk's radius). Read from the array in every row, they made the scan a third
    slower (the candidates' writes could change them, as far as the compiler knows)."""
    return (int(ginfo[G_NCX]), int(ginfo[G_NCY]), ginfo[G_X0], ginfo[G_Y0], ginfo[G_INV], ginfo[G_REACH])


@njit(inline="always", cache=True)
def _scan_row(i, pos, radius, skin, cell, members, cstart, grid, out_j, k0, last, exact):
    """Count the partners j > i of disk i in the cells around it, writing them to out_j.

    Of the nine cells around disk i's only those its reach (its radius, the largest radius
    and the skin) touches are read: a small disk's reach, narrower than a cell, misses a row
    or a column of them (about a fifth of the candidates on the paper grading). A cell's
    members are in index order, so those j <= i are stepped over from the cell's end
    before the scan (about half the candidates, no distance taken). With ``exact`` the
    partners alone are written, at k0, k0 + 1, ... (the rare rows scanned again). Otherwise
    every candidate is written, at k0 + min(k, last) with k the partners so far: one that
    fails is overwritten by the next, and slot k0 + last takes all past the first ``last``
    partners. Writing whatever the verdict keeps a branch off it (see :func:`_take`), and the
    clamp keeps the writes in the row without testing k against the row's end: tested, the
    scan took 3.5 times as long (1.15 ms against 0.32 on the paper packing).
    """
    ncx, ncy, x0, y0, inv, beyond = grid
    c = cell[i]
    xi = pos[i, 0]
    yi = pos[i, 1]
    ri = radius[i]
    reach = ri + beyond
    xa, xb = _cell_span(c % ncx, ncx, xi, reach, x0, inv)
    ya, yb = _cell_span(c // ncx, ncy, yi, reach, y0, inv)
    k = 0
    for ny_ in range(ya, yb + 1):
        for nx_ in range(xa, xb + 1):
            cc = ny_ * ncx + nx_
            first = cstart[cc]
            end = cstart[cc + 1]
            while end > first and members[end - 1] > i:
                end -= 1
            for m in range(end, cstart[cc + 1]):
                j = members[m]
                hit = _within_reach(j, xi, yi, ri, pos, radius, skin)
                if exact:
                    if hit:
                        out_j[k0 + k] = j
                else:
                    out_j[k0 + min(k, last)] = j
                k += np.int64(hit)
    return k


@njit(inline="always", cache=True)
def _within_reach(j, xi, yi, ri, pos, radius, skin):
    """Whether disk j lies within the reach of disk i (centre xi, yi, radius ri)."""
    dx = pos[j, 0] - xi
    dy = pos[j, 1] - yi
    reach = ri + radius[j] + skin
    return dx * dx + dy * dy < reach * reach


@njit(inline="always", cache=True)
def _take(i, j, xi, yi, ri, pos, radius, skin, out_j, k0, k, write):
    """Count (and write at k0 + k) disk j as a partner of disk i when j > i lies within reach;
    returns the count so far.

    Without a branch on the verdict: a cell's members pass and fail in no order, and how
    numba lays out such branches changes from one compilation to the next (with Python's
    hash seed), which made a list build's scan twice as slow in some compilations as in
    others. So j is written whatever the verdict and the count moves on only when it
    holds: a candidate that fails is overwritten by the next one, or lies past the row.
    """
    hit = (j > i) & _within_reach(j, xi, yi, ri, pos, radius, skin)
    if write:
        out_j[k0 + k] = j
    return k + np.int64(hit)


#: the bounding-box test of a wall widens the reach by this fraction: far above the
#: round-off of the closest point, so the test never refuses a wall within reach
_WALL_BOX_PAD = 1e-9


@njit(inline="always", cache=True)
def _near_wall(px, py, reach, wp0, wp1, w):
    """Whether the point (px, py) lies within ``reach`` of wall segment ``w``.

    A point farther than the reach from the segment's bounding box is refused without the
    closest point (a division): a criterion's lid is dozens of segments, and each disk is
    tested against every wall twice per list build (with 72 walls on the paper packing
    that count took 0.44 ms, twice a build's pair count).
    """
    ax, ay, bx, by = wp0[w, 0], wp0[w, 1], wp1[w, 0], wp1[w, 1]
    far = reach * (1.0 + _WALL_BOX_PAD)
    if px < min(ax, bx) - far or px > max(ax, bx) + far or py < min(ay, by) - far or py > max(ay, by) + far:
        return False
    cx, cy = segment_closest(px, py, ax, ay, bx, by)
    dx = px - cx
    dy = py - cy
    return dx * dx + dy * dy < reach * reach


@njit(cache=True)
def count_pair_rows(lo, hi, pos, radius, skin, cell, members, cstart, ginfo, new_start, cand):
    """Candidate partners of rows lo..hi-1 into ``new_start[i + 1]``; the first
    ``CAND_SLOTS - 1`` of each row into ``cand`` (when it is not empty; its row's last slot
    takes the candidates past them)."""
    slots = cand.shape[0] // max(pos.shape[0], 1)
    sink = cand if slots > 0 else np.empty(1, np.int64)
    last = max(slots - 1, 0)
    grid = _grid(ginfo)
    for i in range(lo, hi):
        new_start[i + 1] = _scan_row(
            i, pos, radius, skin, cell, members, cstart, grid, sink, i * slots, last, False
        )


@njit(cache=True)
def count_wall_rows(lo, hi, pos, radius, skin, wp0, wp1, wnew_start):
    """Candidate walls of disks lo..hi-1 into ``wnew_start[i + 1]``."""
    nw = wp0.shape[0]
    for i in range(lo, hi):
        c = 0
        reach = radius[i] + skin
        for w in range(nw):
            if _near_wall(pos[i, 0], pos[i, 1], reach, wp0, wp1, w):
                c += 1
        wnew_start[i + 1] = c


@njit(cache=True)
def prefix_rows(n, start):
    """Row counts in ``start[1:]`` to CSR offsets; returns the total."""
    start[0] = 0
    for i in range(n):
        start[i + 1] += start[i]
    return start[n]


@njit(cache=True)
def fill_pair_rows(
    lo, hi, pos, radius, skin, cell, members, cstart, ginfo, nb_start, nb_j, nb_fs, new_start, new_j, new_fs,
    nb_mr, new_mr, cand,
):  # fmt: skip
    """Write rows lo..hi-1 of the new disk-disk list, each pair with its old shear force and
    rolling moment (or 0): copied from ``cand`` when the counting scan kept the whole row,
    else scanned again."""
    slots = cand.shape[0] // max(pos.shape[0], 1)
    grid = _grid(ginfo)
    for i in range(lo, hi):
        k0 = new_start[i]
        count = new_start[i + 1] - k0
        if count < slots:
            for k in range(count):
                new_j[k0 + k] = cand[i * slots + k]
        else:
            _scan_row(i, pos, radius, skin, cell, members, cstart, grid, new_j, k0, 0, True)
        o0 = nb_start[i]
        o1 = nb_start[i + 1]
        _carry_history(k0, new_start[i + 1], o0, o1, nb_j, nb_fs, nb_mr, new_j, new_fs, new_mr)


@njit(inline="always", cache=True)
def _carry_history(k0, k1, o0, o1, nb_j, nb_fs, nb_mr, new_j, new_fs, new_mr):
    """Slots k0..k1-1 of a new row take the shear force and rolling moment their pair had in
    the old row's slots o0..o1-1 (0 for a new pair)."""
    for k in range(k0, k1):
        j = new_j[k]
        h = 0.0
        hr = 0.0
        for o in range(o0, o1):
            if nb_j[o] == j:
                h = nb_fs[o]
                hr = nb_mr[o]
                break
        new_fs[k] = h
        new_mr[k] = hr


@njit(cache=True)
def fill_wall_rows(
    lo, hi, pos, radius, skin, wp0, wp1, wb_start, wb_w, wb_fs, wnew_start, wnew_w, wnew_fs, wb_mr, wnew_mr
):
    """Write rows lo..hi-1 of the new disk-wall list, with the old shear forces and rolling moments."""
    nw = wp0.shape[0]
    for i in range(lo, hi):
        k = wnew_start[i]
        reach = radius[i] + skin
        for w in range(nw):
            if _near_wall(pos[i, 0], pos[i, 1], reach, wp0, wp1, w):
                wnew_w[k] = w
                k += 1
        _carry_history(
            wnew_start[i], k, wb_start[i], wb_start[i + 1], wb_w, wb_fs, wb_mr, wnew_w, wnew_fs, wnew_mr
        )


@njit(cache=True)
def copy_rows(lo, hi, new_start, new_j, new_fs, nb_start, nb_j, nb_fs, new_mr, nb_mr):
    """Make rows lo..hi-1 of a new list the current one (once every row is filled)."""
    for k in range(new_start[lo], new_start[hi]):
        nb_j[k] = new_j[k]
        nb_fs[k] = new_fs[k]
        nb_mr[k] = new_mr[k]
    for i in range(lo, hi):
        nb_start[i + 1] = new_start[i + 1]
    if lo == 0:
        nb_start[0] = 0


@njit(cache=True)
def build_pairs(pos, radius, skin, nb_start, nb_j, nb_fs, new_start, new_j, new_fs, levels=None):
    """Rebuild the disk-disk half list in place, keeping shear history: the kernel's phases one
    after the other, from one cell grid or, given ``levels`` (:func:`level_scratch`), the grids
    by size level.

    Returns the number of pairs, or ``-needed`` when the capacity is too small
    (nothing is changed then).
    """
    n = pos.shape[0]
    g_cell = np.empty(n, dtype=np.int64)
    g_members = np.empty(n, dtype=np.int64)
    g_cstart = np.empty(max_cells(n) + 1, dtype=np.int64)
    g_ginfo = np.zeros(G_SIZE)
    if levels is None:
        cell_grid(pos, radius, skin, g_cell, g_members, g_cstart, np.empty_like(g_cstart), g_ginfo)
        no_cand = np.zeros(0, dtype=np.int64)  # this stand-alone build scans twice
        count_pair_rows(0, n, pos, radius, skin, g_cell, g_members, g_cstart, g_ginfo, new_start, no_cand)
    else:
        level_grid(pos, radius, skin, levels)
        count_level_rows(0, n, pos, radius, skin, levels, new_start)
    total = prefix_rows(n, new_start)
    if total > nb_j.shape[0]:
        return -total
    nb_mr = np.zeros(nb_j.shape[0])  # no rolling history in this stand-alone build
    new_mr = np.zeros(nb_j.shape[0])
    if levels is None:
        fill_pair_rows(0, n, pos, radius, skin, g_cell, g_members, g_cstart, g_ginfo, nb_start, nb_j, nb_fs,
                       new_start, new_j, new_fs, nb_mr, new_mr, np.zeros(0, dtype=np.int64))  # fmt: skip
    else:
        fill_level_rows(0, n, pos, radius, skin, levels, nb_start, nb_j, nb_fs, nb_mr, new_start, new_j,
                        new_fs, new_mr)  # fmt: skip
    copy_rows(0, n, new_start, new_j, new_fs, nb_start, nb_j, nb_fs, new_mr, nb_mr)
    return total


@njit(cache=True)
def build_wall_pairs(pos, radius, skin, wp0, wp1, wb_start, wb_w, wb_fs, new_start, new_w, new_fs):
    """Rebuild the disk-wall candidate list in place, keeping shear history.

    Returns the number of pairs or ``-needed`` when the capacity is too small.
    """
    n = pos.shape[0]
    count_wall_rows(0, n, pos, radius, skin, wp0, wp1, new_start)
    total = prefix_rows(n, new_start)
    if total > wb_w.shape[0]:
        return -total
    wb_mr = np.zeros(wb_w.shape[0])  # no rolling history in this stand-alone build
    new_mr = np.zeros(wb_w.shape[0])
    fill_wall_rows(
        0, n, pos, radius, skin, wp0, wp1, wb_start, wb_w, wb_fs, new_start, new_w, new_fs, wb_mr, new_mr
    )
    copy_rows(0, n, new_start, new_w, new_fs, wb_start, wb_w, wb_fs, new_mr, wb_mr)
    return total


def brute_force_pairs(pos: np.ndarray, radius: np.ndarray, skin: float) -> set[tuple[int, int]]:
    """All (i, j), i < j, within reach: the O(N^2) oracle for tests."""
    d = np.hypot(pos[:, None, 0] - pos[None, :, 0], pos[:, None, 1] - pos[None, :, 1])
    reach = radius[:, None] + radius[None, :] + skin
    i, j = np.nonzero(np.triu(d < reach, k=1))
    return set(zip(i.tolist(), j.tolist(), strict=True))


# ------------------------------------------------------------------ cells by size level
#
# One grid of cells 2 r_max + skin wide suits disks of one size. With fines among coarse
# grains (r_max / r_min of 100 and more) its cells hold hundreds of fines, and every fine
# disk would test them all. Cells by size level (as LAMMPS's ``neighbor multi``) bin each
# disk in the grid of its level, whose cells suit the largest disk of that level: a row
# then looks, in every level's grid, only at the cells within reach of its own disk.
# Rows still hold the partners j > i, now ordered by j, and the lists are the candidate
# set of the single grid (tests/dem/test_neighbors_levels.py); the force sums follow
# the slot order, so a run with this search differs from one with the single grid by
# round-off only. The engine uses it only for wide size ratios (Simulation.level_ratio).

#: radii of one size level lie within this factor of each other
LEVEL_FACTOR = 4.0
#: most size levels (the last one takes every radius above LEVEL_FACTOR ** 15 r_min)
MAX_LEVELS = 16
#: cells a level's grid may use per disk of the level (a runaway disk cannot make it huge)
LEVEL_CELLS_PER_DISK = 16
# columns of the level table ``geo`` (float64): cell side and its inverse, grid origin,
# largest radius
LV_SIZE, LV_INV, LV_X0, LV_Y0, LV_RMAX = range(5)
# columns of ``info`` (int64): cells along x and y, first cell of the level, disks in it
LV_NCX, LV_NCY, LV_CELL0, LV_COUNT = range(4)
# margin (times the cell side) that keeps a row's cell range whole despite rounding
_LEVEL_PAD = 1e-9


@njit(cache=True)
def max_level_cells(n):
    """Most cells all levels' grids may use together for ``n`` disks."""
    return LEVEL_CELLS_PER_DISK * n + 16 * MAX_LEVELS


class LevelScratch(NamedTuple):
    """The grids by size level (int64 unless said): see the section's comment."""

    level: np.ndarray  # (n) size level of each disk
    cell: np.ndarray  # (n) cell of each disk, counted over all levels' grids
    members: np.ndarray  # (n) disks ordered by cell
    cstart: np.ndarray  # (max_level_cells + 1) first member of each cell
    cfill: np.ndarray  # (max_level_cells + 1) fill counters
    geo: np.ndarray  # (MAX_LEVELS, 5) float64: LV_SIZE, LV_INV, LV_X0, LV_Y0, LV_RMAX of each level
    info: np.ndarray  # (MAX_LEVELS, 4): LV_NCX, LV_NCY, LV_CELL0, LV_COUNT of each level
    count: np.ndarray  # (1) levels in use


def level_scratch(n: int) -> LevelScratch:
    """The storage of the grids by size level for ``n`` disks."""
    nc = max_level_cells(n) + 1
    i8 = np.int64
    return LevelScratch(
        np.zeros(n, i8), np.zeros(n, i8), np.zeros(n, i8), np.zeros(nc, i8), np.zeros(nc, i8),
        np.zeros((MAX_LEVELS, 5)), np.zeros((MAX_LEVELS, 4), i8), np.zeros(1, i8),
    )  # fmt: skip


@njit(inline="always", cache=True)
def _cell_index(offset, inv, nc):
    """The cell (0 .. nc - 1) of a coordinate ``offset`` from the grid's origin, clamped
    (``inv`` the inverse cell side: a product costs less than a division in the scan)."""
    q = offset * inv
    if not q >= 0.0:  # below the grid (or not a number)
        return 0
    if q >= nc:
        return nc - 1
    return int(q)


@njit(cache=True)
def _level_bounds(pos, radius):
    """(xmin, xmax, ymin, ymax, rmin, rmax) of the disks (n >= 1)."""
    xmin = xmax = pos[0, 0]
    ymin = ymax = pos[0, 1]
    rmin = rmax = radius[0]
    for i in range(1, pos.shape[0]):
        xmin = min(xmin, pos[i, 0])
        xmax = max(xmax, pos[i, 0])
        ymin = min(ymin, pos[i, 1])
        ymax = max(ymax, pos[i, 1])
        rmin = min(rmin, radius[i])
        rmax = max(rmax, radius[i])
    return xmin, xmax, ymin, ymax, rmin, rmax


@njit(cache=True)
def _assign_levels(radius, rmin, rmax, level, geo, info):
    """Each disk's level (radii in [rmin F^b, rmin F^(b+1)) are level b); returns the count."""
    nlev = 1
    while nlev < MAX_LEVELS and rmin * LEVEL_FACTOR**nlev <= rmax:
        nlev += 1
    for b in range(MAX_LEVELS):
        info[b, LV_COUNT] = 0
        geo[b, LV_RMAX] = 0.0
    for i in range(radius.shape[0]):
        b = 0
        edge = rmin * LEVEL_FACTOR
        while b < nlev - 1 and radius[i] >= edge:
            b += 1
            edge *= LEVEL_FACTOR
        level[i] = b
        info[b, LV_COUNT] += 1
        geo[b, LV_RMAX] = max(geo[b, LV_RMAX], radius[i])
    return nlev


@njit(cache=True)
def level_grid(pos, radius, skin, lv):
    """Bin every disk in the grid of its size level (members of a cell in index order).

    A level's cells are 2 r_max(level) + skin wide, at most ``LEVEL_CELLS_PER_DISK`` per
    disk of the level; all grids share the bounding box of the disks and one ``cstart``.
    """
    n = pos.shape[0]
    level, cell, members, cstart, cfill = lv.level, lv.cell, lv.members, lv.cstart, lv.cfill
    geo, info = lv.geo, lv.info
    if n == 0:
        lv.count[0] = 0
        cstart[0] = 0
        return
    xmin, xmax, ymin, ymax, rmin, rmax = _level_bounds(pos, radius)
    nlev = _assign_levels(radius, rmin, rmax, level, geo, info)
    ncell = 0
    for b in range(nlev):
        info[b, LV_CELL0] = ncell
        if info[b, LV_COUNT] == 0:
            info[b, LV_NCX] = 0
            info[b, LV_NCY] = 0
            continue
        size = 2.0 * geo[b, LV_RMAX] + skin
        cap = LEVEL_CELLS_PER_DISK * info[b, LV_COUNT] + 16
        while ((xmax - xmin) / size + 1.0) * ((ymax - ymin) / size + 1.0) > cap:
            size *= 1.5
        info[b, LV_NCX] = int((xmax - xmin) / size) + 1
        info[b, LV_NCY] = int((ymax - ymin) / size) + 1
        geo[b, LV_SIZE] = size
        geo[b, LV_INV] = 1.0 / size
        geo[b, LV_X0] = xmin
        geo[b, LV_Y0] = ymin
        ncell += info[b, LV_NCX] * info[b, LV_NCY]
    for c in range(ncell + 1):
        cstart[c] = 0
    for i in range(n):
        b = level[i]
        inv = geo[b, LV_INV]
        cx = _cell_index(pos[i, 0] - xmin, inv, info[b, LV_NCX])
        cy = _cell_index(pos[i, 1] - ymin, inv, info[b, LV_NCY])
        c = info[b, LV_CELL0] + cy * info[b, LV_NCX] + cx
        cell[i] = c
        cstart[c + 1] += 1
    _members_by_cell(n, ncell, cell, members, cstart, cfill)
    lv.count[0] = nlev


@njit(inline="always", cache=True)
def _scan_level_row(i, pos, radius, skin, members, cstart, geo, info, nlev, out_j, k0, write, limit):
    """Count (or write from k0, the first ``limit``) the partners j > i of disk i, level by level.

    In each level's grid only the cells that a circle of the largest reach to that level
    touches are read: cell rows within reach, and in each row the run of cells that the
    circle crosses (members of consecutive cells are consecutive). A coarse disk thus
    reads the fines around it, not the many cells of fines a square around it would hold.
    """
    xi = pos[i, 0]
    yi = pos[i, 1]
    ri = radius[i]
    k = 0
    for b in range(nlev):
        ncx = info[b, LV_NCX]
        if ncx == 0:
            continue
        ncy = info[b, LV_NCY]
        size = geo[b, LV_SIZE]
        inv = geo[b, LV_INV]
        x0 = geo[b, LV_X0]
        y0 = geo[b, LV_Y0]
        pad = _LEVEL_PAD * size
        reach = ri + geo[b, LV_RMAX] + skin + pad  # no partner of this level lies farther
        for cy in range(_cell_index(yi - reach - y0, inv, ncy), _cell_index(yi + reach - y0, inv, ncy) + 1):
            ylo = y0 + cy * size  # the row's disks lie at least gy away in y
            gy = max(ylo - yi, yi - (ylo + size), 0.0)
            if gy >= reach:
                continue
            half = math.sqrt(reach * reach - gy * gy) + pad
            row = info[b, LV_CELL0] + cy * ncx
            c0 = row + _cell_index(xi - half - x0, inv, ncx)
            c1 = row + _cell_index(xi + half - x0, inv, ncx)
            for m in range(cstart[c0], cstart[c1 + 1]):
                k = _take(i, members[m], xi, yi, ri, pos, radius, skin, out_j, k0, k, write and k < limit)
    return k


@njit(cache=True)
def count_level_rows(lo, hi, pos, radius, skin, lv, new_start):
    """Candidate partners of rows lo..hi-1 into ``new_start[i + 1]`` (grids by size level)."""
    members, cstart, geo, info = lv.members, lv.cstart, lv.geo, lv.info
    nlev = lv.count[0]
    for i in range(lo, hi):
        new_start[i + 1] = _scan_level_row(
            i, pos, radius, skin, members, cstart, geo, info, nlev, new_start, 0, False, 0
        )


@njit(inline="always", cache=True)
def _sort_row(a, k0, k1):
    """Sort a[k0:k1] in place: insertion for the short rows of most disks (no call of a
    library sort per row), the library's sort for a coarse disk's long row."""
    if k1 - k0 > 24:
        a[k0:k1].sort()
        return
    for k in range(k0 + 1, k1):
        v = a[k]
        m = k - 1
        while m >= k0 and a[m] > v:
            a[m + 1] = a[m]
            m -= 1
        a[m + 1] = v


@njit(inline="always", cache=True)
def _ascending(a, k0, k1):
    """Whether a[k0:k1] is in ascending order."""
    for k in range(k0 + 1, k1):
        if a[k] < a[k - 1]:
            return False
    return True


@njit(inline="always", cache=True)
def _merge_history(k0, k1, o0, o1, nb_j, nb_fs, nb_mr, new_j, new_fs, new_mr):
    """As :func:`_carry_history` for a new row and an old row both ascending: one pass."""
    o = o0
    for k in range(k0, k1):
        j = new_j[k]
        while o < o1 and nb_j[o] < j:
            o += 1
        if o < o1 and nb_j[o] == j:
            new_fs[k] = nb_fs[o]
            new_mr[k] = nb_mr[o]
        else:
            new_fs[k] = 0.0
            new_mr[k] = 0.0


@njit(cache=True)
def fill_level_rows(
    lo, hi, pos, radius, skin, lv, nb_start, nb_j, nb_fs, nb_mr, new_start, new_j, new_fs, new_mr
):
    """Write rows lo..hi-1 of the new disk-disk list (grids by size level), each row in
    ascending j, each pair with its old shear force and rolling moment (or 0).

    A coarse disk's row holds hundreds of fines: ascending rows let the history be
    matched in one pass (an old row from elsewhere, e.g. renumbered, is searched).
    """
    members, cstart, geo, info = lv.members, lv.cstart, lv.geo, lv.info
    nlev = lv.count[0]
    for i in range(lo, hi):
        k0 = new_start[i]
        k1 = new_start[i + 1]
        _scan_level_row(i, pos, radius, skin, members, cstart, geo, info, nlev, new_j, k0, True, k1 - k0)
        _sort_row(new_j, k0, k1)
        o0 = nb_start[i]
        o1 = nb_start[i + 1]
        if _ascending(nb_j, o0, o1):
            _merge_history(k0, k1, o0, o1, nb_j, nb_fs, nb_mr, new_j, new_fs, new_mr)
        else:
            _carry_history(k0, k1, o0, o1, nb_j, nb_fs, nb_mr, new_j, new_fs, new_mr)
