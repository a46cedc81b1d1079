"""A slow, direct NumPy implementation of one DEM step, used only by the tests.

It shares no code with the compiled engine (``kernels.py``, ``neighbors.py``,
``contact_law.py``): every disk pair and every disk-wall pair is tested directly
(no neighbour list, no cells, no skin), and the contact history is a plain dict
keyed by ``(i, j)`` for disk pairs (``i < j``) and ``(i, "wall", w)`` for disk-wall
pairs. The physics is the documented one:

* normal ``n`` from disk ``i`` to body ``j`` (for a wall: to the closest point of the
  segment), tangent ``t = (-n_y, n_x)``, overlap ``ov``, lever arm ``r - ov / 2``;
* ``Fn = max(0, kn ov + cn vn)`` with ``cn = 2 beta sqrt(kn m_eff)`` (``beta = 0``: no
  dashpot), ``Fs = Fs_old + ks vt dt`` capped at ``mu Fn``; the history ends when the
  bodies separate;
* force on ``i``: ``-Fn n + Fs t``, moment ``(r_i - ov / 2) Fs`` on both disks;
* rolling resistance: ``Mr = Mr_old - kr (omega_i - omega_j) dt`` (``omega_j = 0`` for a
  wall) capped at ``mu_r R Fn``, ``kr = ks R^2``, ``R = r_i r_j / (r_i + r_j)`` (a wall:
  ``r_i``), ``mu_r`` the smaller of the two bodies'; ``Mr`` on ``i``, ``-Mr`` on ``j``,
  each added to the contact's shear moment before that reaches the disk's sum; its
  history is a second dict;
* gravity on the true mass, local damping ``F - alpha |F| sign(v)`` per component of
  force and moment, then leapfrog ``v += F / m dt``, ``x += v dt``; walls move with
  their velocity. Prescribed disks keep their velocity and spin.

Servo walls are not modelled (a servo wall is treated as moving with its current
velocity).
"""

from __future__ import annotations

from typing import Any

import numpy as np

FREE = 0


def _series(ka: np.ndarray, kb: np.ndarray) -> np.ndarray:
    s = ka + kb
    out = np.zeros(np.broadcast(ka, kb).shape)
    ok = s > 0.0
    ka_b = np.broadcast_to(ka, out.shape)
    kb_b = np.broadcast_to(kb, out.shape)
    s_b = np.broadcast_to(s, out.shape)
    out[ok] = ka_b[ok] * kb_b[ok] / s_b[ok]
    eq = ka_b == kb_b  # as the kernel: equal springs give exactly half
    out[eq] = 0.5 * ka_b[eq]
    return out


def _rolling_moments(mr_old, kr, dtheta, cap):
    """Vectorised elastic-plastic rolling spring: the moments on the first bodies."""
    mr = mr_old - kr * dtheta
    return np.where(mr > cap, cap, np.where(mr < -cap, -cap, mr))


def _contact_forces(ov, vn, vt, fs_old, kn, ks, mu, cn, dt):
    """Vectorised linear law: (fn, fs, sliding) for touching contacts."""
    fn = kn * ov + cn * vn
    fn = np.where(fn < 0.0, 0.0, fn)
    fs = fs_old + ks * vt * dt
    cap = mu * fn
    hi = fs > cap
    lo = fs < -cap
    fs = np.where(hi, cap, np.where(lo, -cap, fs))
    return fn, fs, hi | lo


class ReferenceDEM:
    """Copies of a simulation's state, advanced one step at a time by direct NumPy code.

    Build it with :meth:`from_simulation`; :meth:`step` advances the copy. After a step,
    ``force``/``moment`` hold the unbalanced force and moment of that step (before
    damping), ``wall_force`` the force the disks exert on each wall, ``contacts`` a
    dict of the touching contacts ``key -> (fn, fs, sliding)``.
    """

    def __init__(
        self,
        *,
        pos,
        vel,
        theta,
        omega,
        radius,
        mass,
        inv_mass,
        inv_inertia,
        mode,
        pkn,
        pks,
        pmu,
        wp0,
        wp1,
        wvel,
        wkn,
        wks,
        wmu,
        gravity: tuple[float, float],
        damping: float,
        beta: float,
        dt: float,
        per_body: bool = True,
        pp: tuple[float, float, float] | None = None,
        pw: tuple[float, float, float] | None = None,
        history: dict[Any, float] | None = None,
        pmu_r=None,
        wmu_r=None,
        rolling: dict[Any, float] | None = None,
    ) -> None:
        c = np.array
        self.pos = c(pos, dtype=float)
        self.vel = c(vel, dtype=float)
        self.theta = c(theta, dtype=float)
        self.omega = c(omega, dtype=float)
        self.radius = c(radius, dtype=float)
        self.mass = c(mass, dtype=float)
        self.inv_mass = c(inv_mass, dtype=float)
        self.inv_inertia = c(inv_inertia, dtype=float)
        self.mode = c(mode, dtype=np.int64)
        self.pkn, self.pks, self.pmu = c(pkn, dtype=float), c(pks, dtype=float), c(pmu, dtype=float)
        self.wp0 = c(wp0, dtype=float).reshape(-1, 2)
        self.wp1 = c(wp1, dtype=float).reshape(-1, 2)
        self.wvel = c(wvel, dtype=float).reshape(-1, 2)
        self.wkn, self.wks, self.wmu = c(wkn, dtype=float), c(wks, dtype=float), c(wmu, dtype=float)
        self.gravity = (float(gravity[0]), float(gravity[1]))
        self.damping = float(damping)
        self.beta = float(beta)
        self.dt = float(dt)
        self.per_body = bool(per_body)
        self.pp = pp
        self.pw = pw
        self.history: dict[Any, float] = dict(history or {})
        n, nw = self.pos.shape[0], self.wp0.shape[0]
        self.pmu_r = np.zeros(n) if pmu_r is None else c(pmu_r, dtype=float)
        self.wmu_r = np.zeros(nw) if wmu_r is None else c(wmu_r, dtype=float)
        self.rolling: dict[Any, float] = dict(rolling or {})  # rolling moment on the first body
        self.force = np.zeros((n, 2))
        self.moment = np.zeros(n)
        self.wall_force = np.zeros((nw, 2))
        self.contacts: dict[Any, tuple[float, float, bool]] = {}
        self.time = 0.0

    @classmethod
    def from_simulation(cls, sim) -> ReferenceDEM:
        """Copy the state of a :class:`~poro2d.dem.simulation.Simulation` (history included)."""
        p, w = sim.particles, sim.walls
        history: dict[Any, float] = {}
        rolling: dict[Any, float] = {}
        nb, wb = sim.pairs, sim.wall_pairs
        rows = nb.rows()
        for k in nb.touching():
            history[(int(rows[k]), int(nb.other[k]))] = float(nb.fs[k])
            rolling[(int(rows[k]), int(nb.other[k]))] = float(nb.mr[k])
        wrows = wb.rows()
        for k in wb.touching():
            history[(int(wrows[k]), "wall", int(wb.other[k]))] = float(wb.fs[k])
            rolling[(int(wrows[k]), "wall", int(wb.other[k]))] = float(wb.mr[k])
        conv = sim.contact.convention
        m = sim.masses
        return cls(
            pos=p.pos, vel=p.vel, theta=p.theta, omega=p.omega, radius=p.radius,
            mass=m.mass, inv_mass=m.inv_mass, inv_inertia=m.inv_inertia, mode=p.mode,
            pkn=p.kn, pks=p.ks, pmu=p.mu, wp0=w.p0, wp1=w.p1, wvel=w.vel, wkn=w.kn, wks=w.ks,
            wmu=w.mu, gravity=sim.gravity, damping=sim.local_damping, beta=sim.beta, dt=sim.dt,
            per_body=conv == "per_body", pp=sim.contact.pp, pw=sim.contact.pw, history=history,
            pmu_r=p.mu_r, wmu_r=w.rolling_friction(), rolling=rolling,
        )  # fmt: skip

    def follow(self, sim) -> None:
        """Take the engine's motion (positions, speeds, spins, angles, walls, clock), keep
        the reference's own contact history: the next :meth:`step` starts where the engine's
        does, and the histories it carries are its own, from its own contacts."""
        p, w = sim.particles, sim.walls
        self.pos[:], self.vel[:], self.theta[:], self.omega[:] = p.pos, p.vel, p.theta, p.omega
        self.wp0[:], self.wp1[:], self.wvel[:] = w.p0, w.p1, w.vel
        self.time = sim.time

    # ------------------------------------------------------------------ step
    def _disk_pairs(self):
        pos, r = self.pos, self.radius
        n = pos.shape[0]
        i, j = np.triu_indices(n, 1)
        dx = pos[j, 0] - pos[i, 0]
        dy = pos[j, 1] - pos[i, 1]
        d = np.sqrt(dx * dx + dy * dy)
        ov = r[i] + r[j] - d
        t = ov > 0.0
        return i[t], j[t], dx[t], dy[t], d[t], ov[t]

    def _wall_pairs(self):
        pos, r = self.pos, self.radius
        n, nw = pos.shape[0], self.wp0.shape[0]
        if nw == 0 or n == 0:
            e = np.zeros(0)
            return np.zeros(0, np.int64), np.zeros(0, np.int64), e, e, e, e
        i = np.repeat(np.arange(n), nw)  # disk-major: i ascending, then w ascending
        w = np.tile(np.arange(nw), n)
        px, py = pos[i, 0], pos[i, 1]
        ax, ay = self.wp0[w, 0], self.wp0[w, 1]
        bx, by = self.wp1[w, 0], self.wp1[w, 1]
        sx = bx - ax
        sy = by - ay
        s = ((px - ax) * sx + (py - ay) * sy) / (sx * sx + sy * sy)
        s = np.clip(s, 0.0, 1.0)
        cx = ax + s * sx
        cy = ay + s * sy
        dx = cx - px
        dy = cy - py
        d = np.sqrt(dx * dx + dy * dy)
        ov = r[i] - d
        t = ov > 0.0
        return i[t], w[t], dx[t], dy[t], d[t], ov[t]

    def step(
        self,
        pair_order: np.ndarray | None = None,
        partitions: np.ndarray | None = None,
    ) -> None:
        """Advance the copy by one time step.

        The contributions to each disk's force are summed disk-pair by disk-pair in
        ascending ``(i, j)`` order, unless ``pair_order`` lists pairs (``(m, 2)``) in the order
        to sum them (e.g. the slots of the engine's neighbour list, :func:`engine_pair_order`):
        then in that order, pairs it does not list last. With ``partitions`` (the engine's
        partition boundaries, :func:`engine_partitions`) the sums follow the engine's
        partitioned order: a pair whose disks lie in different partitions reaches its
        second disk last, and wall resultants are summed partition by partition. Only
        the order of the sums changes (round-off); which pairs touch is always decided
        here, directly.
        """
        pos, vel, omega, r, m = self.pos, self.vel, self.omega, self.radius, self.mass
        dt = self.dt
        n = pos.shape[0]
        nw = self.wp0.shape[0]
        new_hist: dict[Any, float] = {}
        new_rolling: dict[Any, float] = {}
        rolls = bool(n and self.pmu_r.max() > 0.0)
        contacts: dict[Any, tuple[float, float, bool]] = {}

        # disk-disk
        i, j, dx, dy, d, ov = self._disk_pairs()
        if pair_order is not None and len(i):
            o = np.argsort(_ranks(pair_order, i, j), kind="stable")
            i, j, dx, dy, d, ov = i[o], j[o], dx[o], dy[o], d[o], ov[o]
        with np.errstate(invalid="ignore", divide="ignore"):
            inv = 1.0 / d  # as the kernel: one division, two products
            nx = np.where(d > 0.0, dx * inv, 1.0)
            ny = np.where(d > 0.0, dy * inv, 0.0)
        tx, ty = -ny, nx
        dvx = vel[j, 0] - vel[i, 0]
        dvy = vel[j, 1] - vel[i, 1]
        vn = -(dvx * nx + dvy * ny)
        vt = dvx * tx + dvy * ty - (r[i] - 0.5 * ov) * omega[i] - (r[j] - 0.5 * ov) * omega[j]
        kn, ks, mu = self._law(i, (self.pkn, self.pks, self.pmu), j, self.pp)
        m_eff = m[i] * m[j] / (m[i] + m[j])
        pairs = list(zip(i.tolist(), j.tolist(), strict=True))
        fn, fs = self._forces(pairs, ov, vn, vt, kn, ks, mu, m_eff, new_hist, contacts)
        cfx = -fn * nx - fs * ny  # force on i
        cfy = -fn * ny + fs * nx
        mr = np.zeros(len(i))
        if rolls:
            reff = r[i] * r[j] / (r[i] + r[j])
            mr_old = np.array([self.rolling.get(pair, 0.0) for pair in pairs])
            mur = np.minimum(self.pmu_r[i], self.pmu_r[j])
            mr = _rolling_moments(mr_old, ks * reff * reff, (omega[i] - omega[j]) * dt, mur * reff * fn)
            for k, pair in enumerate(pairs):
                new_rolling[pair] = float(mr[k])

        # disk-wall
        wi, ww, wdx, wdy, wd, wov = self._wall_pairs()
        if len(wi):
            sx = self.wp1[ww, 0] - self.wp0[ww, 0]
            sy = self.wp1[ww, 1] - self.wp0[ww, 1]
            sl_ = np.sqrt(sx * sx + sy * sy)
            with np.errstate(invalid="ignore", divide="ignore"):
                wnx = np.where(wd > 0.0, wdx / wd, sy / sl_)
                wny = np.where(wd > 0.0, wdy / wd, -sx / sl_)
        else:
            wnx = wny = np.zeros(0)
        wtx, wty = -wny, wnx
        wdvx = self.wvel[ww, 0] - vel[wi, 0]
        wdvy = self.wvel[ww, 1] - vel[wi, 1]
        wvn = -(wdvx * wnx + wdvy * wny)
        wvt = wdvx * wtx + wdvy * wty - (r[wi] - 0.5 * wov) * omega[wi]
        wkn, wks, wmu = self._law(wi, (self.wkn, self.wks, self.wmu), ww, self.pw)
        keys = [(a, "wall", b) for a, b in zip(wi.tolist(), ww.tolist(), strict=True)]
        wfn, wfs = self._forces(keys, wov, wvn, wvt, wkn, wks, wmu, m[wi], new_hist, contacts)
        wcfx = -wfn * wnx - wfs * wny
        wcfy = -wfn * wny + wfs * wnx
        wmr = np.zeros(len(wi))
        if rolls:
            wmr_old = np.array([self.rolling.get(key, 0.0) for key in keys])
            wmur = np.minimum(self.pmu_r[wi], self.wmu_r[ww])
            wmr = _rolling_moments(wmr_old, wks * r[wi] * r[wi], omega[wi] * dt, wmur * r[wi] * wfn)
            for k, key in enumerate(keys):
                new_rolling[key] = float(wmr[k])

        # unbalanced force and moment
        force = np.empty((n, 2))
        force[:, 0] = m * self.gravity[0]
        force[:, 1] = m * self.gravity[1]
        moment = np.zeros(n)
        # the engine's order: for each disk, its partners j < i of the same partition, its
        # own row, its walls, then its partners j < i from earlier partitions
        if partitions is None:
            part_of = np.zeros(n, dtype=np.int64)
            bounds = np.array([0, n])
        else:
            bounds = np.asarray(partitions)
            part_of = np.searchsorted(bounds, np.arange(n), side="right") - 1
        cross = part_of[j] != part_of[i]
        mj = (r[j] - 0.5 * ov) * fs
        mi = (r[i] - 0.5 * ov) * fs
        mw = (r[wi] - 0.5 * wov) * wfs
        if rolls:  # one term per contact and disk: shear moment and rolling moment together
            mi = mi + mr
            mj = mj - mr
            mw = mw + wmr
        for sel in (~cross, None, cross):
            if sel is None:  # own rows, then walls
                np.add.at(force[:, 0], i, cfx)
                np.add.at(force[:, 1], i, cfy)
                np.add.at(moment, i, mi)
                np.add.at(force[:, 0], wi, wcfx)
                np.add.at(force[:, 1], wi, wcfy)
                np.add.at(moment, wi, mw)
            else:
                np.add.at(force[:, 0], j[sel], -cfx[sel])
                np.add.at(force[:, 1], j[sel], -cfy[sel])
                np.add.at(moment, j[sel], mj[sel])
        wall_force = np.zeros((nw, 2))
        for k in range(len(bounds) - 1):
            sel = part_of[wi] == k
            partial = np.zeros((nw, 2))
            np.add.at(partial[:, 0], ww[sel], -wcfx[sel])
            np.add.at(partial[:, 1], ww[sel], -wcfy[sel])
            wall_force += partial

        # damping and leapfrog integration
        free = self.mode == FREE
        fx, fy, mz = force[:, 0].copy(), force[:, 1].copy(), moment.copy()
        a = self.damping
        if a > 0.0:
            fx = fx - a * np.abs(fx) * np.sign(vel[:, 0])
            fy = fy - a * np.abs(fy) * np.sign(vel[:, 1])
            mz = mz - a * np.abs(mz) * np.sign(omega)
        vel[free, 0] += fx[free] * self.inv_mass[free] * dt
        vel[free, 1] += fy[free] * self.inv_mass[free] * dt
        omega[free] += mz[free] * self.inv_inertia[free] * dt
        pos += vel * dt
        self.theta += omega * dt
        self.wp0 += self.wvel * dt
        self.wp1 += self.wvel * dt
        self.time += dt

        self.force, self.moment, self.wall_force = force, moment, wall_force
        self.history = new_hist
        self.rolling = new_rolling
        self.contacts = contacts

    def _law(self, i, other: tuple, j, constants: tuple | None) -> tuple:
        """The contacts' (kn, ks, mu): disk ``i``'s values mixed with ``other``'s at ``j`` (per
        body: springs in series, the smaller friction), or the pair type's ``constants``."""
        if self.per_body:
            kn, ks, mu = other
            return _series(self.pkn[i], kn[j]), _series(self.pks[i], ks[j]), np.minimum(self.pmu[i], mu[j])
        assert constants is not None
        return tuple(np.full(len(i), float(v)) for v in constants[:3])

    def _forces(self, keys, ov, vn, vt, kn, ks, mu, m_eff, new_hist, contacts) -> tuple:
        """(fn, fs) of the touching contacts ``keys``, their shear history and contacts recorded."""
        cn = 2.0 * self.beta * np.sqrt(kn * m_eff) if self.beta > 0.0 else np.zeros(len(keys))
        fs_old = np.array([self.history.get(key, 0.0) for key in keys])
        fn, fs, sl = _contact_forces(ov, vn, vt, fs_old, kn, ks, mu, cn, self.dt)
        for k, key in enumerate(keys):
            new_hist[key] = float(fs[k])
            contacts[key] = (float(fn[k]), float(fs[k]), bool(sl[k]))
        return fn, fs

    def run(self, steps: int) -> None:
        for _ in range(steps):
            self.step()

    # ------------------------------------------------------------ measures
    def n_sliding(self) -> int:
        return sum(1 for _fn, _fs, s in self.contacts.values() if s)

    def kinetic_energy(self) -> float:
        m = self.mass
        inertia = 0.5 * m * self.radius**2
        return float(0.5 * np.sum(m * np.sum(self.vel**2, axis=1)) + 0.5 * np.sum(inertia * self.omega**2))


def engine_partitions(sim) -> np.ndarray:
    """The partition boundaries of a simulation's last step (its sum order across partitions)."""
    return sim.work.part.copy()


def engine_pair_order(sim) -> np.ndarray:
    """The disk pairs of a simulation's current neighbour list, ``(m, 2)``, in their slots' order
    (the engine's sum order)."""
    nb = sim.pairs
    return np.column_stack((nb.rows(), nb.other[: nb.used])).astype(np.int64)


def _ranks(pairs: np.ndarray, i: np.ndarray, j: np.ndarray) -> np.ndarray:
    """The row of each pair ``(i[k], j[k])`` in ``pairs`` (the last one when a pair is listed
    twice); ``len(pairs) + 1`` for a pair not listed."""
    missing = len(pairs) + 1
    if not len(pairs) or not len(i):
        return np.full(len(i), missing)
    span = int(max(pairs.max(), i.max(), j.max())) + 1  # a pair as one integer: i * span + j
    keys = pairs[:, 0].astype(np.int64) * span + pairs[:, 1]
    order = np.argsort(keys, kind="stable")
    listed = keys[order]
    asked = i.astype(np.int64) * span + j
    at = np.maximum(np.searchsorted(listed, asked, side="right") - 1, 0)
    return np.where(listed[at] == asked, order[at], missing)
