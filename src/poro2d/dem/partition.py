"""Partitions: contiguous ranges of disks that fix the order of every force sum.

The engine splits the disks into ``P`` contiguous index ranges of about equal work
(disk pairs and wall pairs per row). A disk pair ``(i, j)``, ``i < j``, whose two
disks lie in different partitions is a *cross pair*; its second disk ``j`` is
*deferred*: it is advanced only after every partition has computed its forces.
Everything else in a partition is computed and advanced in one pass.

Each partition is worked on by exactly one thread, and every sum has a fixed order
given by the partitions alone (see :mod:`poro2d.dem.kernels`). So a run gives the
same numbers bit for bit on 1 thread or on up to ``P`` threads; changing ``P``
changes the round-off, as any change of summation order does.

Since the disks of a specimen are numbered strip by strip, a partition boundary
cuts one strip: cross pairs are a thin band (a few per cent of the pairs).
"""

from __future__ import annotations

from numba import njit


@njit(cache=True)
def partition(n, nb_start, nb_j, wb_start, part, xstart, xpair, dlist, dstart):
    """Fill the partition boundaries and the cross-pair lists; returns the number of cross pairs.

    part (P + 1)
        first disk of each partition, ``part[P] = n``;
    xstart (n + 1), xpair
        for each disk j, the cross pairs in which it is the second disk, ascending;
    dlist, dstart (P + 1)
        the deferred disks (those with cross pairs) of each partition, ascending.
    """
    npart = part.shape[0] - 1
    total = 0
    for i in range(n):
        total += 1 + (nb_start[i + 1] - nb_start[i]) + (wb_start[i + 1] - wb_start[i])
    part[0] = 0
    k = 1
    acc = 0
    for i in range(n):
        # the first disk whose preceding work reaches k / P of the total opens partition k
        while k < npart and acc * npart >= k * total:
            part[k] = i
            k += 1
        acc += 1 + (nb_start[i + 1] - nb_start[i]) + (wb_start[i + 1] - wb_start[i])
    while k <= npart:
        part[k] = n
        k += 1

    for j in range(n + 1):
        xstart[j] = 0
    _cross_pairs(npart, part, nb_start, nb_j, xstart, xpair, False)
    for j in range(n):
        xstart[j + 1] += xstart[j]
    # dlist serves as the fill cursor of each disk's cross list before it gets its own content
    for j in range(n):
        dlist[j] = xstart[j]
    _cross_pairs(npart, part, nb_start, nb_j, dlist, xpair, True)
    m = 0
    for q in range(npart):
        dstart[q] = m
        for i in range(part[q], part[q + 1]):
            if xstart[i + 1] > xstart[i]:
                dlist[m] = i
                m += 1
    dstart[npart] = m
    return xstart[n]


@njit(inline="always", cache=True)
def _cross_pairs(npart, part, nb_start, nb_j, slot, xpair, fill):
    """The pairs whose partner j lies in a later partition than their row: counted into
    ``slot[j + 1]``, or, with ``fill``, listed in ``xpair`` at the cursor ``slot[j]``."""
    for q in range(npart):
        end = part[q + 1]
        for i in range(part[q], end):
            for p in range(nb_start[i], nb_start[i + 1]):
                j = nb_j[p]
                if j >= end:
                    if fill:
                        xpair[slot[j]] = p
                        slot[j] += 1
                    else:
                        slot[j + 1] += 1
