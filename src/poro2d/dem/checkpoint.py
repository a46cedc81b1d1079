"""Save and load the complete engine state, contact history and walls included.

A run continued from a checkpoint gives the same numbers as an uninterrupted run:
the neighbour lists, their shear histories and the rebuild bookkeeping are stored
as they are, not rebuilt.

Rolling resistance (``mu_r`` of disks and walls, the contacts' rolling moments) is
stored only when some disk has a rolling friction: a checkpoint without it, and every
checkpoint written before it existed, loads with zeros, and a state without rolling
resistance keeps its file contents and its :func:`state_digest`.
"""

from __future__ import annotations

import copy
import hashlib
import json
import os
import zipfile
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from poro2d.dem import kernels as K
from poro2d.dem.model import ContactModel
from poro2d.dem.simulation import Simulation
from poro2d.dem.state import PARTICLE_FIELDS, SERVO_COLUMNS, Particles, Walls
from poro2d.errors import InputError
from poro2d.io_utils import CHECKPOINT_FILE_LIMIT, Provenance, atomic_path, check_input_file

FORMAT = "poro2d-checkpoint-1"

_WALL_FIELDS = ("p0", "p1", "kn", "ks", "mu", "vel", "mode", "servo_dir", "servo")
# The simulation's arrays by their names in the file ("sim.<name>", the names of the first
# format, kept so that every checkpoint loads) and where they live: (store, field), the
# store an attribute of the Simulation or None for the Simulation's own field.
_SIM_ARRAYS = {
    "force": (None, "force"), "moment": (None, "moment"), "wall_force_vec": (None, "wall_force_vec"),
    "_wstat": ("work", "wall_stat"), "_pos_build": ("work", "pos_build"),
    "_wall_build": ("work", "wall_build"),
    "_nb_start": ("pairs", "start"), "_nb_j": ("pairs", "other"), "_nb_fs": ("pairs", "fs"),
    "_nb_fn": ("pairs", "fn"), "_nb_ov": ("pairs", "ov"), "_nb_nx": ("pairs", "nx"),
    "_nb_ny": ("pairs", "ny"),
    "_wb_start": ("wall_pairs", "start"), "_wb_w": ("wall_pairs", "other"), "_wb_fs": ("wall_pairs", "fs"),
    "_wb_fn": ("wall_pairs", "fn"), "_wb_ov": ("wall_pairs", "ov"), "_wb_nx": ("wall_pairs", "nx"),
    "_wb_ny": ("wall_pairs", "ny"),
    "_iprm": ("kernel_params", "iprm"),
}  # fmt: skip
# the simulation's settings in the file's metadata after its contact model and gravity, by name
_SETTINGS = (
    "local_damping restitution dt fixed_dt dt_safety density_scale skin threads partitions step_count time"
)
# the contacts' rolling moments, stored only with rolling resistance (module doc)
_ROLLING_ARRAYS = {"_nb_mr": "pairs", "_wb_mr": "wall_pairs"}


def _key(name: str) -> str:
    """The file key of one of the simulation's arrays."""
    return f"sim.{name}"


# every particle field but mu_r, which is stored only with rolling resistance (module doc)
_CORE_PARTICLE_FIELDS = tuple(f for f in PARTICLE_FIELDS if f != "mu_r")


def save(sim: Simulation, path: str | os.PathLike, extra: dict | None = None) -> Path:
    """Write ``sim`` to ``path`` (.npz), atomically. ``extra`` is stored as JSON metadata."""
    path = Path(path)
    sim.sync_walls()  # walls added since the last run: their rows in the per-wall arrays
    arrays: dict[str, np.ndarray] = {}
    for f in _CORE_PARTICLE_FIELDS:
        arrays[f"particles.{f}"] = getattr(sim.particles, f)
    for f in _WALL_FIELDS:
        arrays[f"walls.{f}"] = getattr(sim.walls, f)
    for name, (store, field) in _SIM_ARRAYS.items():
        arrays[_key(name)] = getattr(_holder(sim, store), field)
    if K.rolling_active(sim.particles.mu_r):
        arrays["particles.mu_r"] = sim.particles.mu_r
        arrays["walls.mu_r"] = sim.walls.rolling_friction()
        for name, store in _ROLLING_ARRAYS.items():
            arrays[_key(name)] = getattr(sim, store).mr
    meta = {
        "format": FORMAT,
        "provenance": Provenance.now().to_dict(),
        "thickness": sim.particles.thickness,
        "wall_names": sim.walls.names,
        "settings": {
            "contact": sim.contact.to_dict(),
            "gravity": list(sim.gravity),
            **{name: getattr(sim, name) for name in _SETTINGS.split()},
            # only when set: checkpoints of runs with true masses keep their keys
            **({} if sim.mass_scaling_dt is None else {"mass_scaling_dt": sim.mass_scaling_dt}),
            **({} if sim.sort_every is None else {"sort_every": sim.sort_every}),
        },
        "extra": extra or {},
    }
    arrays["meta"] = np.frombuffer(json.dumps(meta).encode(), dtype=np.uint8)
    with atomic_path(path, suffix=".npz") as tmp:
        with open(tmp, "wb") as fh:
            np.savez(fh, **arrays)
    return path


def read_meta(path: str | os.PathLike) -> dict:
    p = _existing(path)
    try:
        with np.load(p) as z:
            return json.loads(bytes(z["meta"]).decode())
    except _UNREADABLE as exc:
        raise _damaged(p, exc) from None


def state_digest(path: str | os.PathLike) -> str:
    """SHA-256 (hex) of the state saved at ``path``: equal for equal states, wherever saved.

    The file's bytes would not do: the archive and the metadata carry the time of
    writing. Left out as well are the thread count and the step budget of the last
    run (in the kernel's integer settings, ``kernel_params.iprm``), which change how a
    continued run is computed, not its numbers. So a specimen rebuilt from the same config
    and seed has the same digest, and a specimen moved or copied keeps it.

    A content hash, not a run identity (:mod:`poro2d.identity`): it says what a file holds,
    whichever run wrote it, since a shear test depends on the state it starts from, not on
    how that state was made. It enters run descriptions as a value.
    """
    with np.load(_existing(path)) as z:
        return content_digest(json.loads(bytes(z["meta"]).decode()), z)


def content_digest(meta: dict, arrays: Mapping[str, np.ndarray]) -> str:
    """:func:`state_digest` of a checkpoint's content already read (:func:`read`); ``meta`` is not changed."""
    h = hashlib.sha256()
    for name in sorted(k for k in arrays if k != "meta"):
        a = np.ascontiguousarray(arrays[name])
        if name == _key("_iprm"):
            a = a.copy()
            a[[i for i in (K.NSTEPS, K.CHECK_EVERY, K.THREADS) if i < a.size]] = 0
        h.update(f"{name}:{a.dtype.str}:{a.shape}\n".encode())
        h.update(a.tobytes())
    meta = copy.deepcopy(meta)
    meta.pop("provenance", None)
    meta.get("settings", {}).pop("threads", None)
    h.update(json.dumps(meta, sort_keys=True, separators=(",", ":")).encode())
    return h.hexdigest()


def _existing(path) -> Path:
    p = Path(path)
    if not p.is_file():
        raise InputError("checkpoint", str(p), "an existing .npz file written by poro2d")
    return check_input_file("checkpoint", p, CHECKPOINT_FILE_LIMIT)


# what NumPy, zipfile and json raise on a truncated, corrupted or foreign file
_UNREADABLE = (OSError, ValueError, EOFError, KeyError, TypeError, zipfile.BadZipFile)


def _damaged(path: Path, exc: BaseException) -> InputError:
    if isinstance(exc, ValueError) and "pickle" in str(exc):
        reason = "not an .npz archive"  # NumPy's guess for a file of neither format
    else:
        reason = (str(exc).splitlines() or [type(exc).__name__])[0][:80]
    return InputError(
        "checkpoint", str(path), "a complete .npz file written by poro2d",
        f"it cannot be read: {reason}; truncated, or not a poro2d checkpoint",
    )  # fmt: skip


def read(path: str | os.PathLike) -> tuple[dict, dict[str, np.ndarray]]:
    """(metadata, arrays) of the checkpoint at ``path``; every array is read in full.

    Reading everything checks the whole file (each member's CRC), so a damaged checkpoint
    is refused with one InputError naming it, before anything is built from it.
    """
    p = _existing(path)
    try:
        with np.load(p) as z:
            meta = json.loads(bytes(z["meta"]).decode())
            arrays = {k: z[k].copy() for k in z.files if k != "meta"}
    except _UNREADABLE as exc:
        raise _damaged(p, exc) from None
    if not isinstance(meta, dict) or meta.get("format") != FORMAT:
        raise InputError("checkpoint format", meta.get("format") if isinstance(meta, dict) else None, FORMAT)
    needed = [f"particles.{f}" for f in _CORE_PARTICLE_FIELDS] + [f"walls.{f}" for f in _WALL_FIELDS]
    needed += [_key(f) for f in _SIM_ARRAYS]
    missing = [k for k in needed if k not in arrays]
    if missing or not isinstance(meta.get("settings"), dict):
        raise _damaged(p, KeyError(f"missing {missing[0] if missing else 'settings'}"))
    return meta, arrays


def load(path: str | os.PathLike, threads: int | None = None) -> Simulation:
    """Rebuild the :class:`Simulation` saved at ``path``, ready to continue."""
    meta, a = read(path)
    try:
        return _build(meta, a, threads)
    except (KeyError, TypeError, IndexError, ValueError) as exc:
        if isinstance(exc, InputError):
            raise
        raise _damaged(Path(path), exc) from None


def from_content(meta: dict, arrays: Mapping[str, np.ndarray], threads: int | None = None) -> Simulation:
    """The :class:`Simulation` of a checkpoint's content already read (:func:`read`).

    The arrays are copied: the content stays as read, so it can start several runs.
    """
    return _build(meta, {k: np.array(v, copy=True) for k, v in arrays.items()}, threads)


def _build(meta: dict, a: dict[str, np.ndarray], threads: int | None) -> Simulation:
    """The Simulation of a checkpoint's metadata and arrays."""
    s = meta["settings"]
    particles = Particles(
        **{f: a[f"particles.{f}"] for f in _CORE_PARTICLE_FIELDS},
        thickness=meta["thickness"],
        mu_r=a.get("particles.mu_r"),
    )
    walls = Walls()
    for f in _WALL_FIELDS:
        setattr(walls, f, np.ascontiguousarray(a[f"walls.{f}"]))
    if walls.servo.shape[1] < SERVO_COLUMNS:  # written before the servo had an integral term
        pad = np.zeros((walls.n, SERVO_COLUMNS - walls.servo.shape[1]))
        walls.servo = np.ascontiguousarray(np.hstack([walls.servo.reshape(walls.n, -1), pad]))
    walls.names = list(meta["wall_names"])
    walls.mu_r = np.ascontiguousarray(a.get("walls.mu_r", np.zeros(walls.n)), dtype=float)
    c = s["contact"]
    contact = ContactModel(
        c["convention"],
        tuple(c["pp"]) if c["pp"] is not None else None,
        tuple(c["pw"]) if c["pw"] is not None else None,
    )
    sim = Simulation(
        particles, walls, contact, gravity=tuple(s["gravity"]), local_damping=s["local_damping"],
        restitution=s["restitution"], dt=s["fixed_dt"], dt_safety=s["dt_safety"],
        density_scale=s["density_scale"], mass_scaling_dt=s.get("mass_scaling_dt"), skin=s["skin"],
        threads=threads if threads is not None else min(s["threads"], _max_threads()),
        partitions=s.get("partitions", 2),
    )  # fmt: skip
    sim.dt = s["dt"]  # exactly as saved, whatever the rule that produced it
    sim.set_sorting(s.get("sort_every"))
    sim.step_count = s["step_count"]
    sim.time = s["time"]
    for name, (store, field) in _SIM_ARRAYS.items():
        setattr(_holder(sim, store), field, np.ascontiguousarray(a[_key(name)]))
    # integer settings added by later versions start at zero (their defaults)
    params = sim.kernel_params
    iprm = np.zeros(K.N_IPRM, dtype=np.int64)
    iprm[: min(len(params.iprm), K.N_IPRM)] = params.iprm[: K.N_IPRM]
    params.iprm = iprm
    # the rolling moments: zero for a checkpoint without rolling resistance
    for name, store_name in _ROLLING_ARRAYS.items():
        store = getattr(sim, store_name)
        store.mr = np.ascontiguousarray(a.get(_key(name), np.zeros(store.capacity)), dtype=float)
        if store.mr.shape != store.other.shape:
            raise ValueError("rolling moments of another length than the contact lists")
        store.renew_scratch()  # as long as the lists just read
    return sim


def _holder(sim: Simulation, store: str | None):
    """The object that holds a stored array: the Simulation or one of its stores."""
    return sim if store is None else getattr(sim, store)


def _max_threads() -> int:
    import numba

    return int(numba.config.NUMBA_NUM_THREADS)
