"""The direct shear test as a protocol that drives the engine.

One test, at one normal stress sigma_n:

1. load the specimen checkpoint and build the split box around it
   (:func:`poro2d.shear.box.build_split_box`);
2. consolidate: servo the top plate to ``sigma_n W t`` until the specimen is in
   equilibrium (maximum unbalanced-force ratio below ``consolidation_ratio``) and
   the plate's stress is within ``stress_tolerance`` of the target, the servo on;
3. shear: the lower half moves at ``velocity`` in +x, the upper half is fixed, the
   plate servo stays on; every ``record_interval`` of shear displacement one row
   is recorded (see :data:`CURVE_COLUMNS`), and every ``checkpoint_interval`` the
   whole state is saved so that a killed run continues from there.

Shear stress is the horizontal force of the disks on the upper half (upper walls,
upper lip and the top plate's friction) over the nominal area ``W t``. The peak
strength is the maximum of the curve smoothed by a centred moving average over
``peak_window`` of shear displacement.
"""

from __future__ import annotations

import hashlib
import json
import math
import time
from collections import deque
from collections.abc import Callable
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from poro2d.config import check_finite
from poro2d.dem import Simulation, checkpoint
from poro2d.dem.measure import coordination_number
from poro2d.errors import InputError, check_range
from poro2d.io_utils import provenance, write_csv, write_json
from poro2d.shear.box import LOWER, SplitBox, build_split_box
from poro2d.shear.fit import peak, smooth

CURVE_COLUMNS = [
    "step", "shear_displacement_mm", "shear_stress_kpa", "normal_stress_kpa", "plate_displacement_mm",
    "coordination_number", "lower_half_stress_kpa", "plane_stress_kpa", "upper_unbalanced_kpa",
    "plate_friction_kpa", "contacts_across_plane", "max_unbalanced_ratio", "inertial_number",
]  # fmt: skip


@dataclass
class ShearSettings:
    """Settings of a direct shear test (SI units; the box walls default to Table 1).

    velocity (m/s) and max_displacement (m) of the lower half; record_interval and
    checkpoint_interval (m of shear displacement); consolidation_ratio and
    consolidation_max_steps for the consolidation stage; servo_gain, servo_integral
    (per step; it keeps the stress on target while the specimen dilates) and
    servo_max_speed (m/s) of the top plate; kn_wall, ks_wall (N/m), friction_wall and
    gap (m) of the box; particle_friction replaces the specimen's when given;
    local_damping likewise (None: the specimen's); density_scale >= 1 scales the
    inertial masses; dt_safety the automatic time step; peak_window (m) the
    smoothing of the peak; shear_zone_factor k in gamma_dot = v / (k d_mean);
    inertial_limit and stress_tolerance the quasi-static and servo checks.
    """

    velocity: float = 0.025
    max_displacement: float = 0.02
    record_interval: float = 5e-5
    checkpoint_interval: float = 1e-3
    consolidation_ratio: float = 1e-3
    consolidation_max_steps: int = 300_000
    servo_gain: float = 0.5
    servo_integral: float = 1e-3
    servo_max_speed: float = 0.05
    kn_wall: float = 1e7
    ks_wall: float = 1e7
    friction_wall: float = 1.5
    gap: float = 0.0
    particle_friction: float | None = None
    local_damping: float | None = None
    density_scale: float = 1.0
    dt_safety: float = 0.8
    peak_window: float = 2e-3
    shear_zone_factor: float = 10.0
    inertial_limit: float = 1e-3
    stress_tolerance: float = 0.02

    def __post_init__(self) -> None:
        check_range("velocity", self.velocity, 0.0, 10.0, lo_open=True)
        check_range("max_displacement", self.max_displacement, 0.0, None, lo_open=True)
        check_range("record_interval", self.record_interval, 0.0, None, lo_open=True)
        check_range("checkpoint_interval", self.checkpoint_interval, 0.0, None, lo_open=True)
        check_range("consolidation_ratio", self.consolidation_ratio, 0.0, 1.0, lo_open=True)
        if not (isinstance(self.consolidation_max_steps, int) and self.consolidation_max_steps >= 1000):
            raise InputError("consolidation_max_steps", self.consolidation_max_steps, "an integer >= 1000")
        check_range("servo_gain", self.servo_gain, 0.0, 1.0, lo_open=True)
        check_range("servo_integral", self.servo_integral, 0.0, 0.1)
        check_range("servo_max_speed", self.servo_max_speed, 0.0, 10.0, lo_open=True)
        check_range("kn_wall", self.kn_wall, 0.0, None, lo_open=True)
        check_range("ks_wall", self.ks_wall, 0.0, None)
        check_range("friction_wall", self.friction_wall, 0.0, None)
        check_range("gap", self.gap, 0.0, None)
        if self.particle_friction is not None:
            check_range("particle_friction", self.particle_friction, 0.0, None)
        if self.local_damping is not None:
            check_range("local_damping", self.local_damping, 0.0, 1.0, hi_open=True)
        check_range("density_scale", self.density_scale, 1.0, None)
        check_range("dt_safety", self.dt_safety, 0.0, 1.0, lo_open=True)
        check_range("peak_window", self.peak_window, 0.0, None)
        check_range("shear_zone_factor", self.shear_zone_factor, 0.0, None, lo_open=True)
        check_range("inertial_limit", self.inertial_limit, 0.0, None, lo_open=True)
        check_range("stress_tolerance", self.stress_tolerance, 0.0, 1.0, lo_open=True)
        if self.record_interval > self.max_displacement:
            raise InputError("record_interval", self.record_interval, f"(0, {self.max_displacement}] m")

    def to_dict(self) -> dict:
        return asdict(self)


def inertial_number(velocity: float, sigma_pa: float, rho_inertial: float, shear_zone_factor: float) -> float:
    """I = gamma_dot d_mean sqrt(rho / sigma_n) with gamma_dot = v / (k d_mean).

    The shear zone of a direct shear test is about 10 to 20 mean diameters thick;
    taking k = 10 (the thin end) over-estimates the shear rate, so I is on the safe
    side. With this estimate d_mean cancels: I = (v / k) sqrt(rho / sigma_n).
    """
    if not sigma_pa > 0:
        return math.inf
    return velocity / shear_zone_factor * math.sqrt(rho_inertial / sigma_pa)


def resolve_specimen(path: str | Path) -> Path:
    """A checkpoint file, or a criterion output folder holding ``specimen.npz``."""
    p = Path(path)
    if p.is_dir():
        p = p / "specimen.npz"
    if not p.is_file():
        raise InputError(
            "specimen",
            str(path),
            "a specimen checkpoint (.npz) or a criterion output folder with specimen.npz",
        )
    return p


def specimen_box(path: str | Path) -> tuple[float, float]:
    """(W, H) of a specimen checkpoint, from its right wall and top plate, without loading it."""
    with np.load(resolve_specimen(path)) as z:
        meta = json.loads(bytes(z["meta"]).decode())
        names = meta.get("wall_names", [])
        p0 = z["walls.p0"]
    if "right" not in names or "top" not in names:
        raise InputError("specimen walls", names, "walls named bottom, right, top, left (a poro2d specimen)")
    return float(p0[names.index("right"), 0]), float(p0[names.index("top"), 1])


class _Frame:
    """A stored state for force-chain figures (what plot_force_chains reads of a simulation)."""

    def __init__(self, data: dict) -> None:
        from types import SimpleNamespace

        from poro2d.dem.measure import ContactSet

        self.data = data
        self.particles = SimpleNamespace(
            pos=data["pos"], radius=data["radius"], thickness=float(data["thickness"])
        )
        self.walls = SimpleNamespace(p0=data["wall_p0"], p1=data["wall_p1"], n=int(data["wall_p0"].shape[0]))
        self._contacts = ContactSet(**{k: data["c_" + k] for k in ("i", "j", "kind", "point", "normal", "fn",
                                                                   "fs", "force", "branch")})  # fmt: skip

    @classmethod
    def capture(cls, sim: Simulation, contacts=None, **extra) -> _Frame:
        c = sim.contacts() if contacts is None else contacts
        data = {
            "pos": sim.particles.pos.copy(), "radius": sim.particles.radius.copy(),
            "thickness": np.float64(sim.particles.thickness),
            "wall_p0": sim.walls.p0.copy(), "wall_p1": sim.walls.p1.copy(),
        }  # fmt: skip
        for k in ("i", "j", "kind", "point", "normal", "fn", "fs", "force", "branch"):
            data["c_" + k] = getattr(c, k)
        for k, v in extra.items():
            data[k] = np.float64(v)
        return cls(data)

    def contacts(self):
        return self._contacts

    def save(self, path: Path) -> None:
        from poro2d.io_utils import atomic_path

        with atomic_path(path, suffix=".npz") as tmp, open(tmp, "wb") as fh:
            np.savez(fh, **self.data)

    @classmethod
    def load(cls, path: Path) -> _Frame:
        with np.load(path) as z:
            return cls({k: z[k].copy() for k in z.files})


ProgressFn = Callable[[str, float], None]


class DirectShearTest:
    """One direct shear test at ``normal_stress_kpa`` on the specimen at ``specimen``.

    With ``out`` every stage is written there as it finishes (``consolidated.npz``,
    ``consolidation.json``, ``shear_checkpoint.npz`` during shearing, ``curve.csv``,
    ``result.json``, ``forces_peak.png``); a rerun skips what is done and continues a
    shear stage from its last checkpoint. ``progress(phase, fraction)`` is called
    between blocks of steps.
    """

    def __init__(
        self,
        specimen: str | Path,
        normal_stress_kpa: float,
        settings: ShearSettings | None = None,
        out: str | Path | None = None,
        progress: ProgressFn | None = None,
        figures: bool = True,
        threads: int = 1,
    ) -> None:
        self.specimen = resolve_specimen(specimen)
        self.sigma_kpa = check_range("normal stress (kPa)", normal_stress_kpa, 0.0, None, lo_open=True)
        self.settings = settings if settings is not None else ShearSettings()
        check_finite("shear", self.settings.to_dict())  # open ranges let an infinity through
        W, _ = specimen_box(self.specimen)
        if self.settings.max_displacement > W / 2:
            raise InputError(
                "max_displacement", self.settings.max_displacement, f"(0, {W / 2:.4g}] m (half the box width)"
            )
        self.out = Path(out) if out is not None else None
        self.progress = progress
        self.figures = figures
        self.threads = threads
        self.box: SplitBox | None = None
        self._digest: str | None = None

    # ------------------------------------------------------------ bookkeeping
    def _report(self, phase: str, fraction: float) -> None:
        if self.progress is not None:
            self.progress(phase, fraction)

    def _path(self, name: str) -> Path | None:
        return None if self.out is None else self.out / name

    @property
    def specimen_digest(self) -> str:
        """Digest of the specimen's state (:func:`poro2d.dem.checkpoint.state_digest`)."""
        if self._digest is None:
            self._digest = checkpoint.state_digest(self.specimen)
        return self._digest

    def _record(self) -> dict:
        """What a stored test must share with this one to be reused: content, never paths."""
        return {
            "specimen_digest": self.specimen_digest,
            "normal_stress_kpa": self.sigma_kpa,
            "settings": self.settings.to_dict(),
        }

    def _work_started(self) -> bool:
        """True once the folder holds more than the test's record (a stage has begun)."""
        assert self.out is not None
        return self.out.is_dir() and any(p.name != "test.json" for p in self.out.iterdir())

    def _stale_reason(self) -> str | None:
        """Why the work in ``out`` belongs to another test, or None if it is this test's (or none)."""
        assert self.out is not None
        p = self.out / "test.json"
        if not self._work_started():
            return None
        if not p.is_file():
            return "no record of its specimen and settings"
        old = json.loads(p.read_text()).get("run") or {}
        rec = self._record()
        if "specimen_digest" not in old:
            return "no content key of its specimen (written by an older poro2d)"
        if old["specimen_digest"] != rec["specimen_digest"]:
            return "another specimen (the content of the specimen file differs)"
        if old.get("normal_stress_kpa") != rec["normal_stress_kpa"]:
            return f"another normal stress ({old.get('normal_stress_kpa')} kPa)"
        settings = old.get("settings") or {}
        now = rec["settings"]
        changed = sorted(k for k in set(settings) | set(now) if settings.get(k) != now.get(k))
        if changed:
            return "other settings (" + ", ".join(changed) + ")"
        return None

    def check_reusable(self) -> None:
        """Refuse an ``out`` that holds work of another specimen, normal stress or settings.

        Stale tests are not recomputed: their folder may hold hours of work the user
        still wants (a mistyped --specimen, say), so the choice of a new folder is left
        to the user.
        """
        assert self.out is not None
        reason = self._stale_reason()
        if reason is not None:
            raise InputError(
                "out", str(self.out), "an empty folder or one holding the same test",
                f"it holds a test of {reason}; use a new --out",
            )  # fmt: skip

    def bind(self) -> None:
        """Record this test in ``out/test.json`` (unless that folder already holds its work)."""
        assert self.out is not None
        if self._work_started() and (self.out / "test.json").is_file():
            return
        self.out.mkdir(parents=True, exist_ok=True)
        run = self._record()
        key = hashlib.sha256(json.dumps(run, sort_keys=True, separators=(",", ":")).encode()).hexdigest()
        record = {"key": key, "run": run, "specimen": str(self.specimen), "provenance": provenance()}
        write_json(self.out / "test.json", record, config=True)

    def _check_resume(self) -> None:
        assert self.out is not None
        self.check_reusable()
        self.bind()

    # ----------------------------------------------------------------- stages
    def consolidate(self) -> tuple[Simulation, dict]:
        """Build the split box and servo the top plate to the normal stress until equilibrium."""
        s = self.settings
        cpath, jpath = self._path("consolidated.npz"), self._path("consolidation.json")
        if cpath is not None and jpath is not None and cpath.is_file() and jpath.is_file():
            info = json.loads(jpath.read_text())
            self.box = SplitBox(**info["box"])
            return checkpoint.load(cpath, threads=self.threads), info
        t0 = time.perf_counter()
        spec = checkpoint.load(self.specimen, threads=self.threads)
        sim, box = build_split_box(
            spec, s.max_displacement, s.kn_wall, s.ks_wall, s.friction_wall, s.gap,
            s.particle_friction, s.density_scale, s.dt_safety, self.threads,
        )  # fmt: skip
        if s.local_damping is not None:
            sim.set_local_damping(float(s.local_damping))
        self.box = box
        target = self.sigma_kpa * 1e3 * box.width * box.thickness
        sim.set_wall_servo("top", target, (0.0, -1.0), s.servo_max_speed, s.servo_gain, s.servo_integral)
        y0 = box.plate_height(sim)
        check = 500
        state = {"ratio": math.inf, "err": math.inf}

        def settled(sm: Simulation) -> bool:
            rmax, _ = sm.unbalanced_ratios()
            err = abs(box.plate_force(sm) / target - 1.0)
            state.update(ratio=rmax, err=err)
            self._report("consolidating", min(sm.step_count / s.consolidation_max_steps, 1.0))
            return rmax < s.consolidation_ratio and err < s.stress_tolerance

        sim.reset_clock()
        res = sim.run(s.consolidation_max_steps, every=check, callback=settled)
        converged = state["ratio"] < s.consolidation_ratio and state["err"] < s.stress_tolerance
        if not converged:
            raise RuntimeError(
                f"consolidation at {self.sigma_kpa:g} kPa did not reach equilibrium within "
                f"{s.consolidation_max_steps} steps (ratio {state['ratio']:.2e}, "
                f"stress error {state['err']:.2%})"
            )
        info = {
            "normal_stress_kpa": self.sigma_kpa,
            "target_force_n": target,
            "steps": res.steps,
            "max_unbalanced_ratio": state["ratio"],
            "normal_stress_measured_kpa": box.plate_force(sim) / (box.width * box.thickness) / 1e3,
            "normal_stress_error": state["err"],
            "plate_height_before_m": y0,
            "plate_height_m": box.plate_height(sim),
            "plate_settlement_m": y0 - box.plate_height(sim),
            "coordination_number": coordination_number(sim),
            "wall_time_s": time.perf_counter() - t0,
            "box": box.to_dict(),
            "engine": sim.summary(),
        }
        if cpath is not None and jpath is not None:
            checkpoint.save(sim, cpath, extra={"stage": "consolidated", "normal_stress_kpa": self.sigma_kpa})
            write_json(jpath, info)
        return sim, info

    def _row(self, sim: Simulation, y_plate0: float, step0: int, rho: float) -> dict:
        box = self.box
        assert box is not None
        s = self.settings
        area = box.width * box.thickness
        fu = box.upper_force(sim)
        fl = box.lower_force(sim)
        c = sim.contacts()
        pl = box.plane_force(sim, c)
        sigma = box.plate_force(sim) / area
        self._contacts = c
        return {
            "step": sim.step_count - step0,
            "shear_displacement_mm": 1e3 * box.shear_displacement(sim),
            "shear_stress_kpa": fu[0] / area / 1e3,
            "normal_stress_kpa": sigma / 1e3,
            "plate_displacement_mm": 1e3 * (box.plate_height(sim) - y_plate0),
            "coordination_number": float(2 * np.count_nonzero(c.kind == 0) + np.count_nonzero(c.kind == 1))
            / sim.particles.n,
            "lower_half_stress_kpa": -fl[0] / area / 1e3,
            "plane_stress_kpa": pl["across"][0] / area / 1e3,
            "upper_unbalanced_kpa": pl["unbalanced"][0] / area / 1e3,
            "plate_friction_kpa": sim.wall_force("top")[0] / area / 1e3,
            "contacts_across_plane": pl["contacts_across"],
            "max_unbalanced_ratio": sim.unbalanced_ratios()[0],
            "inertial_number": inertial_number(s.velocity, sigma, rho, s.shear_zone_factor),
        }

    def shear(self, sim: Simulation, info: dict) -> dict:
        """Shear the consolidated specimen to ``max_displacement``; returns the test result."""
        s = self.settings
        box = self.box
        assert box is not None
        t0 = time.perf_counter()
        ck = self._path("shear_checkpoint.npz")
        fpath = self._path("peak_frame.npz")
        rows: list[dict] = []
        y_plate0 = info["plate_height_m"]
        if ck is not None and ck.is_file():
            sim = checkpoint.load(ck, threads=self.threads)
            meta = checkpoint.read_meta(ck)["extra"]
            rows = meta["rows"]
            step0 = meta["step0"]
            wall_before = meta.get("wall_time_s", 0.0)
        else:
            step0 = sim.step_count
            wall_before = 0.0
            for name in LOWER:
                sim.set_wall_velocity(name, (s.velocity, 0.0))
        dx_step = s.velocity * sim.dt
        every = max(1, int(round(s.record_interval / dx_step)))
        total = int(math.ceil(s.max_displacement / dx_step / every)) * every
        ck_every = max(1, int(round(s.checkpoint_interval / (every * dx_step))))
        rho = float(np.mean(sim.particles.density)) * sim.density_scale
        window = s.peak_window
        # the peak's force-chain frame: frames wait in a queue until their smoothed value is final
        pending: deque[tuple[int, _Frame]] = deque()
        best: dict = {"value": -math.inf, "index": -1}
        self._peak_frame: _Frame | None = None
        if fpath is not None and fpath.is_file() and rows:
            fr = _Frame.load(fpath)
            self._peak_frame = fr
            best["index"] = int(fr.data["record"])
            xs = np.array([r["shear_displacement_mm"] for r in rows]) * 1e-3
            ys = np.array([r["shear_stress_kpa"] for r in rows])
            best["value"] = float(smooth(xs, ys, window)[best["index"]])

        def finalize(upto: float | None) -> None:
            xs = np.array([r["shear_displacement_mm"] for r in rows]) * 1e-3
            ys = np.array([r["shear_stress_kpa"] for r in rows])
            while pending and (upto is None or xs[pending[0][0]] + 0.5 * window <= upto):
                k, fr = pending.popleft()
                lo = np.searchsorted(xs, xs[k] - 0.5 * window, side="left")
                hi = np.searchsorted(xs, xs[k] + 0.5 * window, side="right")
                v = float(ys[lo:hi].mean())
                if v > best["value"]:
                    best.update(value=v, index=k, saved=False)
                    self._peak_frame = fr

        def record(sm: Simulation) -> bool:
            rows.append(self._row(sm, y_plate0, step0, rho))
            if self.figures:
                pending.append(
                    (
                        len(rows) - 1,
                        _Frame.capture(
                            sm,
                            self._contacts,
                            record=len(rows) - 1,
                            displacement_mm=rows[-1]["shear_displacement_mm"],
                        ),
                    )
                )
            finalize(rows[-1]["shear_displacement_mm"] * 1e-3)
            done = sm.step_count - step0
            self._report("shearing", done / total)
            if ck is not None and len(rows) % ck_every == 0 and done < total:
                if fpath is not None and self._peak_frame is not None and not best.get("saved", True):
                    self._peak_frame.save(fpath)  # a resumed run still draws the peak's forces
                    best["saved"] = True
                checkpoint.save(
                    sm, ck, extra={"stage": "shear", "rows": rows, "step0": step0,
                                   "wall_time_s": wall_before + time.perf_counter() - t0},
                )  # fmt: skip
            return False

        remaining = total - (sim.step_count - step0)
        if remaining > 0:
            sim.run(remaining, every=every, callback=record)
        finalize(None)
        wall = wall_before + time.perf_counter() - t0
        result = self._result(rows, info, sim, wall)
        if self.out is not None:
            write_csv(self.out / "curve.csv", rows, header=CURVE_COLUMNS)
            if self.figures:
                self._figure(result)
            write_json(self.out / "result.json", result)
            for f in (ck, fpath):
                if f is not None and f.is_file():
                    f.unlink()
        return result

    def _figure(self, result: dict) -> None:
        from poro2d.report.force_chains import plot_force_chains

        assert self.out is not None and self.box is not None
        fr = self._peak_frame
        if fr is None:
            return
        b = self.box
        d = float(fr.data["displacement_mm"])
        plot_force_chains(
            fr, self.out / "forces_peak.png",
            title=f"direct shear at {self.sigma_kpa:g} kPa, at the peak: d = {d:.2f} mm",
            box=(-0.02 * b.width, 0.0, b.width + b.max_displacement, b.height),
            notes=[f"tau_peak = {result['peak_shear_stress_kpa']:.1f} kPa (smoothed over "
                   f"{1e3 * self.settings.peak_window:g} mm)"],
        )  # fmt: skip

    def _result(self, rows: list[dict], info: dict, sim: Simulation, wall: float) -> dict:
        s = self.settings
        x = np.array([r["shear_displacement_mm"] for r in rows]) * 1e-3
        col = {k: np.array([r[k] for r in rows], float) for k in CURVE_COLUMNS}
        k, xp, tp = peak(x, col["shear_stress_kpa"], s.peak_window)
        end = {}
        for name in ("shear_stress_kpa", "normal_stress_kpa", "plate_displacement_mm", "coordination_number"):
            end[name] = float(smooth(x, col[name], s.peak_window)[-1])
        tau = col["shear_stress_kpa"]
        sig_err = np.abs(col["normal_stress_kpa"] / self.sigma_kpa - 1.0)
        late = x >= min(s.peak_window, 0.5 * x[-1])  # leave out the first moments of shearing
        ref = float(np.mean(np.abs(tau[late])))
        balance = {
            "mean_abs_upper_minus_plane_rel": _rel(tau, col["plane_stress_kpa"], late, ref),
            "mean_abs_upper_minus_lower_rel": _rel(tau, col["lower_half_stress_kpa"], late, ref),
            "mean_upper_kpa": float(np.mean(tau[late])),
            "mean_plane_kpa": float(np.mean(col["plane_stress_kpa"][late])),
            "mean_lower_kpa": float(np.mean(col["lower_half_stress_kpa"][late])),
            "note": "upper = force on the upper half walls; plane = contact forces across y = H/2; "
            "lower = force on the lower half walls; all over W t, means over the test after the "
            "first peak_window of displacement",
        }  # fmt: skip
        inertial = col["inertial_number"]
        i_target = inertial_number(
            s.velocity, self.sigma_kpa * 1e3, float(np.mean(sim.particles.density)) * sim.density_scale,
            s.shear_zone_factor,
        )  # fmt: skip
        return {
            "normal_stress_kpa": self.sigma_kpa,
            "peak_shear_stress_kpa": tp,
            "shear_displacement_at_peak_m": xp,
            "peak_stress_ratio": tp / self.sigma_kpa,
            "peak_shear_stress_raw_kpa": float(np.max(tau)),
            "peak_window_m": s.peak_window,
            "normal_stress_at_peak_kpa": float(smooth(x, col["normal_stress_kpa"], s.peak_window)[k]),
            "plate_displacement_at_peak_mm": float(col["plate_displacement_mm"][k]),
            "end": end,
            "end_shear_displacement_m": float(x[-1]),
            "max_inertial_number": float(np.max(inertial)),
            "inertial_number_at_target_stress": i_target,
            "inertial_number_ok": bool(np.max(inertial) < s.inertial_limit),
            "normal_stress_max_error_after_consolidation": float(np.max(sig_err)),
            "normal_stress_mean_error": float(np.mean(sig_err)),
            "consolidation": {k2: v for k2, v in info.items() if k2 not in ("engine",)},
            "force_balance": balance,
            "velocity_m_per_s": s.velocity,
            "density_scale": sim.density_scale,
            "local_damping": sim.local_damping,
            "dt_s": sim.dt,
            "d_mean_m": float(2.0 * np.mean(sim.particles.radius)),
            "shear_steps": int(rows[-1]["step"]) if rows else 0,
            "records": len(rows),
            "wall_time_shear_s": wall,
            "wall_time_s": wall + float(info.get("wall_time_s", 0.0)),
            "settings": s.to_dict(),
            "specimen": str(self.specimen),
            "engine": sim.summary(),
            "provenance": provenance(),
        }

    def run(self) -> dict:
        """Consolidate (or reuse the consolidated state), shear, write and return the result."""
        if self.out is not None:
            self.check_reusable()  # before a stored result is trusted
            done = self.out / "result.json"
            if done.is_file():
                return json.loads(done.read_text())
            self.bind()
        sim, info = self.consolidate()
        return self.shear(sim, info)


def _rel(a: np.ndarray, b: np.ndarray, mask: np.ndarray, ref: float) -> float:
    return float(np.mean(np.abs(a - b)[mask]) / ref) if ref > 0 else math.nan


# ---------------------------------------------------------------------- series
def _run_job(job: dict, queue=None) -> dict:
    """Run one test (in a worker process); progress goes to ``queue`` as (key, phase, fraction)."""
    last = [0.0, ""]

    def report(phase: str, fraction: float) -> None:
        now = time.monotonic()
        if queue is not None and (now - last[0] > 0.5 or phase != last[1] or fraction >= 1.0):
            last[0], last[1] = now, phase
            queue.put((job["key"], phase, fraction))

    test = DirectShearTest(
        job["specimen"], job["sigma"], ShearSettings(**job["settings"]), out=job["out"],
        progress=report, figures=job.get("figures", True), threads=1,
    )  # fmt: skip
    res = test.run()
    if queue is not None:
        queue.put((job["key"], "done", 1.0))
    return res


def folder_name(sigma_kpa: float) -> str:
    return f"sn{sigma_kpa:g}kPa"


def job_label(job: dict) -> str:
    """How a test is named in progress lines and errors: its normal stress, (v/2) for a rate check."""
    prefix = f"{job['series']}: " if job.get("series") else ""
    return prefix + f"{job['sigma']:g} kPa" + (" (v/2)" if "rate" in job["key"] else "")


def execute_jobs(jobs: list[dict], processes: int, progress: bool) -> dict:
    """Run the tests of ``jobs`` (finished ones are read back) in up to ``processes`` processes.

    Returns ``{job["key"]: result}``; the slow (half velocity) tests start first so the pool
    ends together. An input error of a test is raised as it is; other failures together.
    """
    results: dict = {}
    errors: dict = {}
    todo = []
    for job in jobs:  # finished tests are read here, without starting a process
        done = Path(job["out"]) / "result.json"
        if done.is_file():
            results[job["key"]] = json.loads(done.read_text())
        else:
            todo.append(job)
    if not todo:
        return results
    n = min(processes, len(todo))
    labels = {j["key"]: job_label(j) for j in todo}
    bar = _Bars(labels) if progress else None
    try:
        if n <= 1:
            for job in todo:
                q = _DirectQueue(bar)
                try:
                    results[job["key"]] = _run_job(job, q)
                except Exception as exc:  # noqa: BLE001 - reported with the test it belongs to
                    errors[job["key"]] = exc
        else:
            import multiprocessing as mp
            from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait

            ctx = mp.get_context("spawn")
            with ctx.Manager() as manager, ProcessPoolExecutor(max_workers=n, mp_context=ctx) as pool:
                queue = manager.Queue()
                # the slow (half velocity) tests first, so the pool ends together
                order = sorted(todo, key=lambda j: ("rate" not in j["key"], -j["sigma"]))
                futs = {pool.submit(_run_job, job, queue): job["key"] for job in order}
                pending = set(futs)
                while pending:
                    finished, pending = wait(pending, timeout=0.25, return_when=FIRST_COMPLETED)
                    _drain(queue, bar)
                    for f in finished:
                        try:
                            results[futs[f]] = f.result()
                        except Exception as exc:  # noqa: BLE001
                            errors[futs[f]] = exc
                _drain(queue, bar)
    finally:
        if bar is not None:
            bar.stop()
    if errors:
        key, exc = next(iter(errors.items()))
        if isinstance(exc, InputError):
            raise exc
        msgs = "; ".join(f"{labels[k]}: {e}" for k, e in errors.items())
        raise RuntimeError(f"{len(errors)} direct shear test(s) failed: {msgs}")
    return results


class ShearSeries:
    """Direct shear tests at several normal stresses, in parallel processes, with the fit.

    Writes ``out/result.json`` (per test and overall), ``peaks.csv``, ``curves.csv``,
    ``fig8a_shear_curves.png``, ``fig8b_peak_strength.png`` and one folder per test
    (see :class:`DirectShearTest`); with ``rate_check`` every test is repeated at half
    the velocity under ``out/rate_check/`` and the change of the peak is reported.
    Finished tests are skipped on a rerun; a killed test resumes from its checkpoint.
    """

    def __init__(
        self,
        specimen: str | Path,
        normal_stresses_kpa,
        settings: ShearSettings | None = None,
        out: str | Path = "shear-out",
        lab=None,
        rate_check: bool = False,
        rate_tolerance: float = 0.02,
        processes: int | None = None,
        progress: bool = True,
        config: dict | None = None,
        figures: bool = True,
    ) -> None:
        import os

        self.specimen = resolve_specimen(specimen)
        stresses = [
            check_range("normal stress (kPa)", v, 0.0, None, lo_open=True) for v in normal_stresses_kpa
        ]
        if not stresses:
            raise InputError("normal stress", [], "at least one value (kPa)")
        if len(set(stresses)) != len(stresses):
            raise InputError("normal stress", stresses, "different values")
        self.stresses = sorted(stresses)
        self.settings = settings if settings is not None else ShearSettings()
        self.out = Path(out)
        self.lab = lab
        self.rate_check = bool(rate_check)
        self.rate_tolerance = check_range("rate_tolerance", rate_tolerance, 0.0, 1.0, lo_open=True)
        ncpu = os.cpu_count() or 1
        if processes is not None and not (isinstance(processes, int) and 1 <= processes <= 64):
            raise InputError("processes", processes, "an integer in [1, 64]")
        self.progress = progress
        self.config = config or {}
        self.figures = figures
        self.jobs = self._jobs()
        # the tests are about equally long: one process per test (up to twice the cores)
        # leaves no core idle at the end (3 tests on 2 cores take 1.5 test times, not 2)
        self.processes = processes if processes is not None else min(len(self.jobs), 2 * ncpu)
        # validate every test (box size, then what each folder holds) before anything is written
        tests = [
            DirectShearTest(job["specimen"], job["sigma"], ShearSettings(**job["settings"]), out=job["out"])
            for job in self.jobs
        ]
        self.specimen_digest = tests[0].specimen_digest if tests else ""
        for t in tests:
            t._digest = self.specimen_digest  # one specimen: hashed once
            t.check_reusable()
        for t in tests:
            t.bind()

    def _jobs(self) -> list[dict]:
        base = self.settings.to_dict()
        half = dict(base, velocity=0.5 * base["velocity"])
        common = {"specimen": str(self.specimen)}
        jobs = [
            {"key": ("test", sig), "sigma": sig, "settings": base, "figures": self.figures,
             "out": str(self.out / folder_name(sig)), **common}
            for sig in self.stresses
        ]  # fmt: skip
        if self.rate_check:
            jobs += [
                {"key": ("rate", sig), "sigma": sig, "settings": half, "figures": False,
                 "out": str(self.out / "rate_check" / folder_name(sig)), **common}
                for sig in self.stresses
            ]  # fmt: skip
        return jobs

    def _execute(self) -> dict:
        return execute_jobs(self.jobs, self.processes, self.progress)

    def run(self) -> dict:
        t0 = time.perf_counter()
        return self.finish(self._execute(), t0)

    def finish(self, results: dict, t0: float) -> dict:
        """Fit, figures and ``result.json`` from the tests' results (keyed as in :meth:`_jobs`)."""
        from poro2d.shear.fit import mohr_coulomb

        tests = [results[("test", s)] for s in self.stresses]
        sig = np.array([t["normal_stress_kpa"] for t in tests])
        tau = np.array([t["peak_shear_stress_kpa"] for t in tests])
        fit = mohr_coulomb(sig, tau) if len(sig) >= 2 else None
        fit0 = mohr_coulomb(sig, tau, through_origin=True)
        s = self.settings
        summary = []
        for t in tests:
            summary.append({
                k: t[k] for k in (
                    "normal_stress_kpa", "peak_shear_stress_kpa", "shear_displacement_at_peak_m",
                    "peak_stress_ratio", "peak_shear_stress_raw_kpa", "normal_stress_at_peak_kpa",
                    "plate_displacement_at_peak_mm", "end", "end_shear_displacement_m", "max_inertial_number",
                    "inertial_number_ok", "normal_stress_max_error_after_consolidation", "force_balance",
                    "wall_time_s",
                )
            } | {"consolidation_normal_stress_error": t["consolidation"]["normal_stress_error"],
                 "folder": folder_name(t["normal_stress_kpa"])})  # fmt: skip
        # a stored infinity reads back as null (JSON has no infinity): the check failed
        max_i = max(math.inf if t["max_inertial_number"] is None else t["max_inertial_number"] for t in tests)
        result: dict = {
            "normal_stresses_kpa": self.stresses,
            "tests": summary,
            "friction_angle_deg": fit.friction_angle_deg if fit else None,
            "cohesion_kpa": fit.cohesion_kpa if fit else None,
            "r2": fit.r2 if fit else None,
            "fit": fit.to_dict() if fit else None,
            "friction_angle_through_origin_deg": fit0.friction_angle_deg,
            "fit_through_origin": fit0.to_dict(),
            "quasi_static": {
                "max_inertial_number": max_i,
                "inertial_limit": s.inertial_limit,
                "inertial_number_ok": max_i < s.inertial_limit,
                "inertial_number_definition": "I = gamma_dot d_mean sqrt(rho_s density_scale / sigma_n), "
                f"gamma_dot = v / ({s.shear_zone_factor:g} d_mean) (a thin shear zone: conservative), "
                "sigma_n the measured plate stress at each record",
            },
            "peak_definition": f"maximum of the shear stress curve smoothed by a centred moving average over "
            f"{1e3 * s.peak_window:g} mm of shear displacement",
            "shear_stress_definition": "horizontal force of the disks on the upper half (upper walls, upper "
            "lip, top plate friction) / (W t), W the box width (no area correction)",
            "settings": s.to_dict(),
            "velocity_m_per_s": s.velocity,
            "density_scale": s.density_scale,
            "specimen": str(self.specimen),
            "specimen_digest": self.specimen_digest,
            "specimen_meta": checkpoint.read_meta(self.specimen).get("extra", {}),
            "processes": self.processes,
            "config": self.config,
        }
        if self.rate_check:
            rows = []
            for t in tests:
                h = results[("rate", t["normal_stress_kpa"])]
                ch = h["peak_shear_stress_kpa"] / t["peak_shear_stress_kpa"] - 1.0
                pre = self._pre_peak_change(t, h)
                rows.append({
                    "normal_stress_kpa": t["normal_stress_kpa"],
                    "peak_kpa": t["peak_shear_stress_kpa"],
                    "peak_half_velocity_kpa": h["peak_shear_stress_kpa"],
                    "relative_change": ch,
                    "shear_displacement_at_peak_m": t["shear_displacement_at_peak_m"],
                    "shear_displacement_at_peak_half_velocity_m": h["shear_displacement_at_peak_m"],
                    "max_inertial_number_half_velocity": h["max_inertial_number"],
                    "mean_abs_change_before_peak": pre,
                    "wall_time_s": h["wall_time_s"],
                })  # fmt: skip
            worst = max(abs(r["relative_change"]) for r in rows)
            h_tau = [r["peak_half_velocity_kpa"] for r in rows]
            fit_h = mohr_coulomb(sig, h_tau) if len(sig) >= 2 else None
            result["rate_check"] = {
                "velocity_m_per_s": s.velocity,
                "half_velocity_m_per_s": 0.5 * s.velocity,
                "tests": rows,
                "max_abs_relative_change": worst,
                "tolerance": self.rate_tolerance,
                "passed": worst < self.rate_tolerance,
                "friction_angle_half_velocity_deg": fit_h.friction_angle_deg if fit_h else None,
                "friction_angle_change_deg": (fit_h.friction_angle_deg - fit.friction_angle_deg)
                if (fit_h and fit)
                else None,
                "max_mean_abs_change_before_peak": max(r["mean_abs_change_before_peak"] for r in rows),
                "note": "relative_change compares the smoothed peaks; mean_abs_change_before_peak the "
                "smoothed curves from half a window to the earlier of the two peaks, over the peak. "
                "Runs whose state differs only by round-off also differ by a few percent after the "
                "peak forms (the packing's trajectory is chaotic), so a peak change of that size is "
                "not by itself a rate effect; see docs/shear.md",
            }
        if self.lab is not None:
            result["lab"] = self._lab_part(fit)
        result["wall_time_s"] = time.perf_counter() - t0
        result["provenance"] = provenance()
        self._outputs(tests, fit, fit0, result)
        write_json(self.out / "result.json", result)
        return result

    def _pre_peak_change(self, t: dict, h: dict) -> float:
        """Mean |tau_half - tau| / tau_peak of the smoothed curves up to the earlier peak."""
        w = self.settings.peak_window
        a = _read_csv(self.out / folder_name(t["normal_stress_kpa"]) / "curve.csv")
        b = _read_csv(self.out / "rate_check" / folder_name(t["normal_stress_kpa"]) / "curve.csv")
        xa = np.array([r["shear_displacement_mm"] for r in a]) * 1e-3
        xb = np.array([r["shear_displacement_mm"] for r in b]) * 1e-3
        ya = smooth(xa, np.array([r["shear_stress_kpa"] for r in a]), w)
        yb = np.interp(xa, xb, smooth(xb, np.array([r["shear_stress_kpa"] for r in b]), w))
        end = min(t["shear_displacement_at_peak_m"], h["shear_displacement_at_peak_m"])
        m = (xa >= 0.5 * w) & (xa <= end)
        if not m.any():
            return math.nan
        return float(np.mean(np.abs(yb[m] - ya[m])) / t["peak_shear_stress_kpa"])

    def _lab_part(self, fit) -> dict:
        from poro2d.shear.fit import mohr_coulomb

        lab = self.lab
        part = lab.to_dict()
        ls = lab.normal_stresses()
        lab_fit = mohr_coulomb(ls, [lab.peaks[v] for v in ls]) if len(ls) >= 2 else None
        part["fit"] = lab_fit.to_dict() if lab_fit else None
        part["friction_angle_deg"] = lab_fit.friction_angle_deg if lab_fit else None
        part["cohesion_kpa"] = lab_fit.cohesion_kpa if lab_fit else None
        part["friction_angle_difference_deg"] = (
            fit.friction_angle_deg - lab_fit.friction_angle_deg if (fit and lab_fit) else None
        )
        part["fit_through_origin"] = mohr_coulomb(
            ls, [lab.peaks[v] for v in ls], through_origin=True
        ).to_dict()
        return part

    def _outputs(self, tests: list[dict], fit, fit0, result: dict) -> None:
        from poro2d.report.shear_figures import plot_peak_strength, plot_shear_curves
        from poro2d.shear.fit import mohr_coulomb

        curves = {}
        long_rows = []
        for t in tests:
            sigma = t["normal_stress_kpa"]
            rows = _read_csv(self.out / folder_name(sigma) / "curve.csv")
            curves[sigma] = {k: np.array([r[k] for r in rows]) for k in rows[0]} if rows else {}
            for r in rows:
                long_rows.append({"normal_stress_kpa": sigma, **r})
        header = ["normal_stress_kpa"] + CURVE_COLUMNS
        write_csv(self.out / "curves.csv", long_rows, header=header)
        write_csv(self.out / "peaks.csv", [{k: v for k, v in r.items() if not isinstance(v, dict)}
                                           for r in result["tests"]])  # fmt: skip
        if not self.figures:
            return
        peaks = {
            t["normal_stress_kpa"]: (t["shear_displacement_at_peak_m"], t["peak_shear_stress_kpa"])
            for t in tests
        }
        plot_shear_curves(
            curves, self.out / "fig8a_shear_curves.png", lab=self.lab, peaks=peaks,
            smoothing_note=f"v = {1e3 * self.settings.velocity:g} mm/s; peaks (dots) smoothed over "
            f"{1e3 * self.settings.peak_window:g} mm",
        )  # fmt: skip
        lab_fit = None
        if self.lab is not None and len(self.lab.peaks) >= 2:
            ls = self.lab.normal_stresses()
            lab_fit = mohr_coulomb(ls, [self.lab.peaks[v] for v in ls])
        plot_peak_strength(
            [t["normal_stress_kpa"] for t in tests], [t["peak_shear_stress_kpa"] for t in tests], fit,
            self.out / "fig8b_peak_strength.png", fit_origin=fit0, lab=self.lab, lab_fit=lab_fit,
        )  # fmt: skip


def _read_csv(path: Path) -> list[dict]:
    import csv

    with open(path, newline="") as fh:
        return [{k: float(v) for k, v in r.items()} for r in csv.DictReader(fh)]


class _Bars:
    """One rich progress bar per test, with elapsed time and ETA, on a terminal.

    In a log (stderr not a terminal) one plain line for all tests instead, at most every
    ``LINE_INTERVAL_S`` seconds and once at the end, e.g.
    ``direct shear: 50 kPa done; 100 kPa shearing 42 %; 200 kPa consolidating; elapsed 0:03:10``.
    """

    def __init__(self, labels: dict) -> None:
        from rich.progress import (
            BarColumn,
            Progress,
            TaskProgressColumn,
            TextColumn,
            TimeElapsedColumn,
            TimeRemainingColumn,
        )

        from poro2d.progress import ProgressLines, live_console

        self._state = {k: [v, "waiting", 0.0] for k, v in labels.items()}  # label, phase, fraction
        self._t0 = time.perf_counter()
        console = live_console()
        self._lines = ProgressLines() if console is None else None
        if self._lines is not None:
            return
        self._p = Progress(
            TextColumn("[bold]{task.description}"), BarColumn(), TaskProgressColumn(),
            TextColumn("{task.fields[phase]}"), TimeElapsedColumn(), TextColumn("eta"), TimeRemainingColumn(),
            console=console,
        )  # fmt: skip
        self._tasks = {k: self._p.add_task(v, total=1.0, phase="waiting") for k, v in labels.items()}
        self._p.start()

    def update(self, key, phase: str, fraction: float) -> None:
        state = self._state.get(key)
        if state is None:
            return
        state[1] = phase
        if phase in ("shearing", "done"):
            state[2] = 1.0 if phase == "done" else fraction
        if self._lines is not None:
            self._lines.write(self.line(), state=self._news())
        elif phase == "shearing":
            self._p.update(self._tasks[key], completed=fraction, phase=phase)
        elif phase == "done":
            self._p.update(self._tasks[key], completed=1.0, phase="done")
        else:
            self._p.update(self._tasks[key], phase=phase)

    def line(self) -> str:
        """Every test's phase (and how far it has sheared) on one line."""
        from poro2d.progress import clock_text

        tests = "; ".join(
            f"{label} {phase}" + (f" {100.0 * frac:.0f} %" if phase == "shearing" else "")
            for label, phase, frac in self._state.values()
        )
        return f"direct shear: {tests}; elapsed {clock_text(time.perf_counter() - self._t0)}"

    def _news(self) -> tuple:
        """What a line reports, as printed (not the clock)."""
        return tuple((phase, round(100.0 * frac)) for _label, phase, frac in self._state.values())

    def stop(self) -> None:
        if self._lines is not None:
            self._lines.write(self.line(), force=True, state=self._news())
        else:
            self._p.stop()


class _DirectQueue:
    """A stand-in for the process queue when the tests run in this process."""

    def __init__(self, bar: _Bars | None) -> None:
        self.bar = bar

    def put(self, item) -> None:
        if self.bar is not None:
            self.bar.update(*item)


def _drain(queue, bar: _Bars | None) -> None:
    import queue as _q

    while True:
        try:
            item = queue.get_nowait()
        except (_q.Empty, EOFError, OSError):
            return
        if bar is not None:
            bar.update(*item)


__all__ = [
    "CURVE_COLUMNS", "DirectShearTest", "ShearSeries", "ShearSettings", "inertial_number",
    "resolve_specimen", "folder_name",
]  # fmt: skip
