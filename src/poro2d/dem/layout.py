"""Checks of where disks start: none on top of another, on a wall or outside the walls.

The engine would run such a state without a word and produce nonsense: two disks at one
point have no contact normal, a disk centred on a wall is pushed to whichever side round-off
picks, and a disk outside a closed box falls away or is shot through a wall. So
:class:`poro2d.dem.Simulation` refuses them when it is built and when disks are added.

Every check is vectorised over the disks (Python loops run over walls and over a handful
of cell offsets only): a million disks take one or two seconds, the paper's 2600 a few ms.
"""

from __future__ import annotations

import numpy as np

from poro2d.dem.state import Walls
from poro2d.errors import InputError

#: Two disks whose centres are closer than this fraction of the smaller radius coincide.
COINCIDENT = 0.01
#: A disk whose centre is closer to a wall than this fraction of its radius sits on it.
ON_WALL = 0.01


class MisplacedDisk(InputError):
    """A disk on top of another, on a wall or outside the walls: bad input where the disks come
    from the user; where a protocol drew and placed them, an event of its run (a layer compacted
    denser than its grading packs throws disks out), which the protocol names as such."""


def check_layout(pos: np.ndarray, radius: np.ndarray, walls: Walls) -> None:
    """Raise :class:`MisplacedDisk` naming the first disk that coincides with another, sits on
    a wall or lies outside the box the walls close."""
    if pos.shape[0] == 0:
        return
    for disk, allowed, why in _misplaced(pos, radius, walls):  # the first one found is refused
        raise MisplacedDisk(f"disk {disk} position", _xy(pos[disk]), allowed, why)


def _misplaced(pos: np.ndarray, radius: np.ndarray, walls: Walls):
    """Each check's first misplaced disk, as (disk, where its centre must be, why it is not),
    check by check: a generator, so that a later (costlier) check runs only when needed."""
    pair = coincident_pair(pos, radius)
    if pair is not None:
        i, j, d = pair
        why = f"disks {i} and {j} are {d:.3g} m apart, less than {COINCIDENT:g} of the smaller radius"
        yield j, f"a centre apart from that of disk {i}", why
    if walls.n == 0:
        return
    hit = on_wall(pos, radius, walls)
    if hit is not None:
        i, w, d = hit
        yield (
            i,
            f"a centre off wall {walls.names[w]!r}",
            f"it lies {d:.3g} m from the wall, radius {radius[i]:.3g} m",
        )
    out = outside(pos, walls)
    if out is not None:
        i, w = out
        yield (
            i,
            "a centre inside the walls",
            f"it lies beyond wall {walls.names[w]!r}, outside the box the walls close",
        )


def _xy(p: np.ndarray) -> tuple[float, float]:
    return (float(f"{p[0]:.6g}"), float(f"{p[1]:.6g}"))


# ------------------------------------------------------------------ coincident disks
def coincident_pair(pos: np.ndarray, radius: np.ndarray) -> tuple[int, int, float] | None:
    """The first pair (i < j, by i then j) closer than ``COINCIDENT`` times the smaller radius.

    Centres are binned in square cells at least that threshold wide, so a close pair lies
    in one cell or in two neighbouring ones; each disk is compared with the disks of its
    own cell that come after it and of four neighbouring cells (the other four are covered
    from the other side).
    """
    n = pos.shape[0]
    if n < 2:
        return None
    lo = pos.min(axis=0)
    extent = float((pos.max(axis=0) - lo).max())
    # at most 2^30 cells a side, so the cell keys below fit in int64
    h = max(COINCIDENT * float(radius.max()), extent / 2**30, np.finfo(float).tiny)
    cell = np.floor((pos - lo) / h).astype(np.int64) + 1  # +1: neighbours at -1 stay >= 0
    ny = int(cell[:, 1].max()) + 2
    key = cell[:, 0] * ny + cell[:, 1]
    order = np.argsort(key, kind="stable")
    sk = key[order]  # work in sorted order: the searches below then read memory in sequence
    ranks = np.arange(n)
    candidates_i = []
    candidates_j = []
    for dx, dy in ((0, 0), (1, -1), (1, 0), (1, 1), (0, 1)):
        target = sk + (dx * ny + dy)
        # in its own cell a disk meets only those after it; in the others, all
        start = ranks + 1 if dx == dy == 0 else np.searchsorted(sk, target, side="left")
        stop = np.searchsorted(sk, target, side="right")
        k, slot = _expand(start, stop)
        candidates_i.append(order[k])
        candidates_j.append(order[slot])
    i = np.concatenate(candidates_i)
    j = np.concatenate(candidates_j)
    if i.size == 0:
        return None
    d = np.hypot(pos[i, 0] - pos[j, 0], pos[i, 1] - pos[j, 1])
    close = d < COINCIDENT * np.minimum(radius[i], radius[j])
    if not close.any():
        return None
    a = np.minimum(i[close], j[close])
    b = np.maximum(i[close], j[close])
    k = int(np.lexsort((b, a))[0])
    return int(a[k]), int(b[k]), float(d[close][k])


def _expand(start: np.ndarray, stop: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(row, slot) for every slot of the ranges ``[start[row], stop[row])``."""
    count = np.maximum(stop - start, 0)
    total = int(count.sum())
    rows = np.repeat(np.arange(start.shape[0]), count)
    offset = np.arange(total) - np.repeat(np.cumsum(count) - count, count)
    return rows, np.repeat(start, count) + offset


# ------------------------------------------------------------------ walls
def on_wall(pos: np.ndarray, radius: np.ndarray, walls: Walls) -> tuple[int, int, float] | None:
    """(disk, wall, distance) of the lowest-numbered disk centred on a wall segment, or None."""
    found = None
    for w in range(walls.n):
        a, b = walls.p0[w], walls.p1[w]
        ab = b - a
        s = np.clip(((pos - a) @ ab) / float(ab @ ab), 0.0, 1.0)
        d = np.hypot(pos[:, 0] - (a[0] + s * ab[0]), pos[:, 1] - (a[1] + s * ab[1]))
        bad = np.flatnonzero(d < ON_WALL * radius)
        if bad.size and (found is None or bad[0] < found[0]):
            found = (int(bad[0]), w, float(d[bad[0]]))
    return found


def ray_crossings(pos: np.ndarray, walls: Walls) -> np.ndarray:
    """(N, 4) counts of wall segments crossed by rays from each centre along +x, -x, +y, -y.

    A segment is crossed when it straddles the ray's line (half-open at its end points, so
    two segments meeting at a corner count once) and meets it on that side of the centre;
    segments along the ray are not crossed.
    """
    counts = np.zeros((pos.shape[0], 4), dtype=np.int64)
    for w in range(walls.n):
        a, b = walls.p0[w], walls.p1[w]
        for axis in (0, 1):  # rays along x (axis 0) straddle in y, and the other way round
            other = 1 - axis
            if a[other] == b[other]:
                continue  # parallel to the ray
            c = pos[:, other]
            straddle = ((a[other] <= c) & (c < b[other])) | ((b[other] <= c) & (c < a[other]))
            t = (c - a[other]) / (b[other] - a[other])
            meet = a[axis] + t * (b[axis] - a[axis])
            counts[:, 2 * axis] += straddle & (meet > pos[:, axis])
            counts[:, 2 * axis + 1] += straddle & (meet < pos[:, axis])
    return counts


def outside(pos: np.ndarray, walls: Walls) -> tuple[int, int] | None:
    """(disk, wall) of the lowest-numbered disk beyond a wall of a closed box, or None.

    Looking along x (or y), a disk inside a box meets one wall on each side. A disk that
    meets nothing on one side and two or more walls on the other has gone through the
    nearest of those: it lies outside the box. Open arrangements (a floor, a hopper, the
    opening of a split box) meet at most one wall on a side and are never flagged.
    """
    counts = ray_crossings(pos, walls)
    bad = np.zeros(pos.shape[0], dtype=bool)
    for plus, minus in ((0, 1), (2, 3)):
        bad |= (counts[:, plus] == 0) & (counts[:, minus] >= 2)
        bad |= (counts[:, minus] == 0) & (counts[:, plus] >= 2)
    idx = np.flatnonzero(bad)
    if idx.size == 0:
        return None
    i = int(idx[0])
    return i, _nearest_wall_beyond(pos[i], counts[i], walls)


def _nearest_wall_beyond(p: np.ndarray, counts: np.ndarray, walls: Walls) -> int:
    """The first wall that the crowded ray of one flagged disk crosses (the wall it is beyond)."""
    ray = next(
        k
        for k in range(4)
        if counts[k] >= 2 and counts[k ^ 1] == 0  # k ^ 1: the opposite direction
    )
    axis, sign = ray // 2, (1.0 if ray % 2 == 0 else -1.0)
    other = 1 - axis
    best, best_dist = 0, np.inf
    for w in range(walls.n):
        a, b = walls.p0[w], walls.p1[w]
        if a[other] == b[other] or not min(a[other], b[other]) <= p[other] <= max(a[other], b[other]):
            continue
        t = (p[other] - a[other]) / (b[other] - a[other])
        dist = sign * (a[axis] + t * (b[axis] - a[axis]) - p[axis])
        if 0.0 < dist < best_dist:
            best, best_dist = w, dist
    return best


__all__ = ["COINCIDENT", "ON_WALL", "check_layout", "coincident_pair", "on_wall", "outside", "ray_crossings"]
