"""Verlet lists with a skin, built from a cell grid in O(N).

Disk-disk candidates are kept as a half list in CSR form (row ``i`` lists the
partners ``j > i``); disk-wall candidates as a CSR list of wall indices per disk.
A pair is a candidate while the gap between the two surfaces is below ``skin``;
the lists stay valid until a disk or a wall has moved more than ``skin / 2``.

On a rebuild the shear-force history of every pair that survives is copied
across by matching ``(i, j)`` in the old row of ``i``. The capacity of the pair
arrays is fixed by the caller: when it is too small the build reports how much
it needs and changes nothing, so the caller can grow the arrays and retry.
Every loop writes to its own row, so the result does not depend on threads.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from poro2d.dem.contact_law import segment_closest


@njit(cache=True)
def _cell_grid(pos, radius, skin):
    n = pos.shape[0]
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
    while ((xmax - xmin) / size + 1.0) * ((ymax - ymin) / size + 1.0) > 4.0 * n + 16.0:
        size *= 1.5
    ncx = int((xmax - xmin) / size) + 1
    ncy = int((ymax - ymin) / size) + 1
    cell = np.empty(n, dtype=np.int64)
    count = np.zeros(ncx * ncy + 1, dtype=np.int64)
    for i in range(n):
        cx = int((pos[i, 0] - xmin) / size)
        cy = int((pos[i, 1] - ymin) / size)
        if cx >= ncx:
            cx = ncx - 1
        if cy >= ncy:
            cy = ncy - 1
        c = cy * ncx + cx
        cell[i] = c
        count[c + 1] += 1
    for c in range(ncx * ncy):
        count[c + 1] += count[c]
    start = count.copy()
    members = np.empty(n, dtype=np.int64)
    fill = count[:-1].copy()
    for i in range(n):  # stable: members of a cell stay in index order
        c = cell[i]
        members[fill[c]] = i
        fill[c] += 1
    return cell, start, members, ncx, ncy


@njit(inline="always", cache=True)
def _scan_row(i, pos, radius, skin, cell, start, members, ncx, ncy, out_j, k0, write):
    """Count (or write from k0) the partners j > i of disk i; returns the count."""
    c = cell[i]
    cx = c % ncx
    cy = c // ncx
    xi = pos[i, 0]
    yi = pos[i, 1]
    ri = radius[i]
    k = 0
    for ny_ in range(max(cy - 1, 0), min(cy + 2, ncy)):
        for nx_ in range(max(cx - 1, 0), min(cx + 2, ncx)):
            cc = ny_ * ncx + nx_
            for m in range(start[cc], start[cc + 1]):
                j = members[m]
                if j <= i:
                    continue
                dx = pos[j, 0] - xi
                dy = pos[j, 1] - yi
                reach = ri + radius[j] + skin
                if dx * dx + dy * dy < reach * reach:
                    if write:
                        out_j[k0 + k] = j
                    k += 1
    return k


@njit(parallel=True, cache=True)
def build_pairs(pos, radius, skin, nb_start, nb_j, nb_fs, new_start, new_j, new_fs):
    """Rebuild the disk-disk half list in place, keeping shear history.

    Returns the number of pairs, or ``-needed`` when the capacity is too small
    (nothing is changed then).
    """
    n = pos.shape[0]
    cap = nb_j.shape[0]
    if n == 0:
        nb_start[:] = 0
        return 0
    cell, start, members, ncx, ncy = _cell_grid(pos, radius, skin)
    counts = np.empty(n, dtype=np.int64)
    for i in prange(n):
        counts[i] = _scan_row(i, pos, radius, skin, cell, start, members, ncx, ncy, new_j, 0, False)
    new_start[0] = 0
    for i in range(n):
        new_start[i + 1] = new_start[i] + counts[i]
    total = new_start[n]
    if total > cap:
        return -total
    for i in prange(n):
        k0 = new_start[i]
        _scan_row(i, pos, radius, skin, cell, start, members, ncx, ncy, new_j, k0, True)
        o0 = nb_start[i]
        o1 = nb_start[i + 1]
        for k in range(k0, new_start[i + 1]):
            j = new_j[k]
            h = 0.0
            for o in range(o0, o1):
                if nb_j[o] == j:
                    h = nb_fs[o]
                    break
            new_fs[k] = h
    for i in prange(n + 1):
        nb_start[i] = new_start[i]
    for k in prange(total):
        nb_j[k] = new_j[k]
        nb_fs[k] = new_fs[k]
    return total


@njit(cache=True)
def build_reverse(n, nb_start, nb_j, rev_start, rev_p):
    """For each disk j, the pair indices p in which it is the second member."""
    total = nb_start[n]
    for j in range(n + 1):
        rev_start[j] = 0
    for p in range(total):
        rev_start[nb_j[p] + 1] += 1
    for j in range(n):
        rev_start[j + 1] += rev_start[j]
    fill = rev_start[:n].copy()
    for i in range(n):  # ascending p per j: deterministic gather order
        for p in range(nb_start[i], nb_start[i + 1]):
            j = nb_j[p]
            rev_p[fill[j]] = p
            fill[j] += 1


@njit(inline="always", cache=True)
def _near_wall(px, py, reach, a, b):
    cx, cy = segment_closest(px, py, a[0], a[1], b[0], b[1])
    dx = px - cx
    dy = py - cy
    return dx * dx + dy * dy < reach * reach


@njit(parallel=True, cache=True)
def build_wall_pairs(pos, radius, skin, wp0, wp1, wb_start, wb_w, wb_fs, new_start, new_w, new_fs):
    """Rebuild the disk-wall candidate list in place, keeping shear history.

    Returns the number of pairs or ``-needed`` when the capacity is too small.
    """
    n = pos.shape[0]
    nw = wp0.shape[0]
    cap = wb_w.shape[0]
    counts = np.zeros(n, dtype=np.int64)
    for i in prange(n):
        c = 0
        reach = radius[i] + skin
        for w in range(nw):
            if _near_wall(pos[i, 0], pos[i, 1], reach, wp0[w], wp1[w]):
                c += 1
        counts[i] = c
    new_start[0] = 0
    for i in range(n):
        new_start[i + 1] = new_start[i] + counts[i]
    total = new_start[n]
    if total > cap:
        return -total
    for i in prange(n):
        k = new_start[i]
        reach = radius[i] + skin
        o0 = wb_start[i]
        o1 = wb_start[i + 1]
        for w in range(nw):
            if _near_wall(pos[i, 0], pos[i, 1], reach, wp0[w], wp1[w]):
                new_w[k] = w
                h = 0.0
                for o in range(o0, o1):
                    if wb_w[o] == w:
                        h = wb_fs[o]
                        break
                new_fs[k] = h
                k += 1
    for i in prange(n + 1):
        wb_start[i] = new_start[i]
    for k in prange(total):
        wb_w[k] = new_w[k]
        wb_fs[k] = new_fs[k]
    return total


def brute_force_pairs(pos: np.ndarray, radius: np.ndarray, skin: float) -> set[tuple[int, int]]:
    """All (i, j), i < j, within reach: the O(N^2) oracle for tests."""
    d = np.hypot(pos[:, None, 0] - pos[None, :, 0], pos[:, None, 1] - pos[None, :, 1])
    reach = radius[:, None] + radius[None, :] + skin
    i, j = np.nonzero(np.triu(d < reach, k=1))
    return set(zip(i.tolist(), j.tolist(), strict=True))
