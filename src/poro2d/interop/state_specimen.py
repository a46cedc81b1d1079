"""A specimen by its laboratory state: the accepted specimen of one state and seed of a run.

Three folders hold specimens by laboratory state:

* a relation folder (``poro2d relation``): ``relation.json`` lists the states (``points``:
  ``n_lab``, ``relative_density``). In density mode the cases of the states are the sweep in
  ``states/`` (one per state and seed, the state's ``criterion.n_lab`` and the ``seed`` among
  the parameters each case's ``result.json`` records); a state's case that the calibration had
  already run (its twin, at the same friction and seed) is not run again and is read from the
  calibration's cases (``sweeps.calibration.cases``). In paper mode the cases are the sweep in
  the folder itself, one per state, each at the config's seed;
* a density-mode criterion folder (``poro2d criterion --mode density``): ``density.json``
  is one state of the same layout as a density-mode relation;
* a sand folder (``poro2d sand``): ``sand.json`` lists ``states``, each a dict with
  ``n_lab``, ``relative_density``, ``seed`` and ``specimen``, the path (relative to the sand
  folder) of the accepted criterion folder holding ``specimen.npz``.

The cases are found by what their files say (the sweep's ``sweep.json`` lists them; each
case's ``result.json`` gives its parameters, the criterion's ``result.json`` in its ``run``
folder its seed and whether it converged), never by a folder name made up from a state.
:func:`find_state_specimen` returns the criterion folder holding the specimen;
:func:`state_specimen` the same with the state it belongs to (for the export's provenance).
Everything refused is one :class:`~poro2d.errors.InputError` naming the option, its value
and the states and seeds there are.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path

from poro2d.errors import InputError, check_int, check_range
from poro2d.io_utils import check_input_file
from poro2d.store import Store

#: the record files of a folder of specimens by state, in the order they are looked for
STATE_RECORDS = ("sand.json", "relation.json", "density.json")
#: how close ``--n-lab`` must be to a state's laboratory porosity (states are kept to 4 decimals)
N_LAB_TOLERANCE = 5e-5
#: how close ``--dr`` must be to a state's relative density
DR_TOLERANCE = 5e-4
#: the folder holding a sweep case's criterion outputs (:mod:`poro2d.sweep.runner`)
CASE_RUN = "run"


@dataclass(frozen=True)
class KnownState:
    """The laboratory state a specimen belongs to, as far as its records say (None: not said).

    ``record``: the state folder's record it was read from (``sand.json``, ``relation.json``,
    ``density.json``), None when the specimen's own ``soil.json`` says it.
    """

    mode: str | None
    n_lab: float | None
    relative_density: float | None
    seed: int | None
    record: str | None = None


@dataclass(frozen=True)
class StateCase:
    """One specimen of a state: its seed, the criterion folder, accepted or why not."""

    n_lab: float
    seed: int | None
    folder: Path | None
    why_not: str = ""  # empty: accepted

    @property
    def accepted(self) -> bool:
        return not self.why_not


@dataclass(frozen=True)
class StateSpecimen:
    """The accepted specimen of one state and seed, and where the state was read.

    ``folder``: the criterion folder holding ``specimen.npz``; ``record``: the state
    folder's ``sand.json``, ``relation.json`` or ``density.json``; ``mode``: ``density`` or
    ``paper`` (None when the record does not say).
    """

    folder: Path
    record: Path
    mode: str | None
    n_lab: float
    relative_density: float | None
    seed: int

    def known(self) -> KnownState:
        """The state as the export's provenance lines name it (:func:`poro2d.interop.origin.origin_lines`)."""
        return KnownState(self.mode, self.n_lab, self.relative_density, self.seed, record=str(self.record))


@dataclass
class StateIndex:
    """What a state folder holds: its record, mode, states (n_lab, Dr) and their cases."""

    record: Path
    mode: str | None
    states: list[tuple[float, float | None]]
    cases: list[StateCase]

    def cases_of(self, n_lab: float) -> list[StateCase]:
        return sorted(
            (c for c in self.cases if _same(c.n_lab, n_lab)), key=lambda c: (c.seed is None, c.seed or 0)
        )

    def listing(self) -> str:
        """The states and their accepted seeds, as a refusal lists them."""
        parts = []
        for n_lab, dr in self.states:
            cases = self.cases_of(n_lab)
            ok = [str(c.seed) for c in cases if c.accepted]
            bad = [str(c.seed) for c in cases if not c.accepted]
            text = f"n_lab {n_lab:g} (Dr {_dr_text(dr)}): "
            text += f"seed{'s' if len(ok) != 1 else ''} {', '.join(ok)}" if ok else "no accepted seed"
            if bad:
                text += f" (not accepted: {', '.join(bad)})"
            parts.append(text)
        return "; ".join(parts) if parts else "none"


def _store(folder: str | os.PathLike | Store) -> Store:
    """The finished run a state is read from: a store, or the folder the user named."""
    return folder if isinstance(folder, Store) else Store(folder, parameter="SPECIMEN")


def state_record(folder: str | os.PathLike | Store) -> Path | None:
    """The record file of a folder of specimens by state, None for any other folder or a file."""
    store = _store(folder)
    if not store.exists():
        return None
    return next((store.root / name for name in STATE_RECORDS if store.has(name)), None)


def find_state_specimen(
    folder: str | os.PathLike | Store, n_lab: float | None = None, dr: float | None = None, seed: int = 0
) -> Path:
    """The criterion folder holding the accepted ``specimen.npz`` of one state and seed.

    ``folder``: a relation, a density-mode criterion or a sand run (its store or folder); the
    state by its laboratory porosity ``n_lab`` or its relative density ``dr`` (one of the
    two), ``seed`` the specimen among the state's. Refused (InputError naming ``--n-lab``,
    ``--dr`` or ``--seed``, with the states and accepted seeds there are) when the state or
    seed is not there or its criterion did not accept a specimen.
    """
    return state_specimen(folder, n_lab=n_lab, dr=dr, seed=seed).folder


def state_specimen(
    folder: str | os.PathLike | Store, n_lab: float | None = None, dr: float | None = None, seed: int = 0
) -> StateSpecimen:
    """:func:`find_state_specimen` with the state it belongs to (mode, n_lab, Dr, seed)."""
    store = _store(folder)
    record = state_record(store)
    if record is None:
        raise InputError(
            "SPECIMEN",
            str(store.root),
            "a folder holding " + ", ".join(STATE_RECORDS) + " (a folder of states)",
        )
    if n_lab is not None and dr is not None:
        raise InputError("--n-lab/--dr", (n_lab, dr), "one of the two, not both")
    if n_lab is not None:
        check_range("--n-lab", n_lab, 0.0, 1.0, lo_open=True, hi_open=True)
    if dr is not None:
        check_range("--dr", dr)
    seed = check_int("--seed", seed, 0)
    index = read_state_index(record)
    if n_lab is None and dr is None:
        raise InputError("--n-lab/--dr", None, f"one of the states of {record}: {index.listing()}")
    state = _pick_state(index, n_lab, dr)
    cases = [c for c in index.cases_of(state[0]) if c.seed == seed]
    if not cases:
        raise InputError(
            "--seed", seed, f"a seed of the state n_lab {state[0]:g} in {record}: {index.listing()}"
        )
    accepted = [c for c in cases if c.accepted]
    if not accepted:
        allowed = f"a seed whose specimen the criterion accepted; states of {record}: {index.listing()}"
        raise InputError("--seed", seed, allowed, f"n_lab {state[0]:g} seed {seed}: {cases[0].why_not}")
    if len(accepted) > 1:
        where = ", ".join(str(c.folder) for c in accepted)
        raise InputError(
            "--seed", seed, f"one specimen of n_lab {state[0]:g} and this seed", f"{where} both are"
        )
    return StateSpecimen(accepted[0].folder, record, index.mode, state[0], state[1], seed)


def _pick_state(index: StateIndex, n_lab: float | None, dr: float | None) -> tuple[float, float | None]:
    if n_lab is not None:
        hits = [s for s in index.states if abs(s[0] - n_lab) <= N_LAB_TOLERANCE]
        option, value = "--n-lab", n_lab
    else:
        hits = [s for s in index.states if s[1] is not None and abs(s[1] - dr) <= DR_TOLERANCE]
        option, value = "--dr", dr
    if len(hits) != 1:
        tol = N_LAB_TOLERANCE if option == "--n-lab" else DR_TOLERANCE
        what = "none" if not hits else f"{len(hits)} states"
        raise InputError(
            option,
            value,
            f"one of the states of {index.record} (within {tol:g}): {index.listing()}",
            f"{what} within {tol:g}" if hits else "",
        )
    return hits[0]


def read_state_index(record: Path) -> StateIndex:
    """The states of a state folder and their cases, read from its files."""
    data = _json(record, "SPECIMEN")
    if record.name == "sand.json":
        return _sand_index(record, data)
    mode = data.get("mode") if isinstance(data.get("mode"), str) else None
    if record.name == "density.json":
        states = [data]
    else:
        states = [p for p in data.get("points") or [] if isinstance(p, dict)]
    pairs = [(_number(p.get("n_lab")), _number(p.get("relative_density"))) for p in states]
    pairs = [(n, d) for n, d in pairs if n is not None]
    if not pairs:
        raise InputError(
            "SPECIMEN", str(record.parent), f"a folder whose {record.name} lists laboratory states"
        )
    folder = record.parent
    # paper mode runs its sweep in the folder itself (a relation of before "mode" was recorded too)
    if mode == "paper" or (mode is None and (folder / "sweep.json").is_file()):
        cases = _sweep_cases(folder, relation_seed=_config_seed(data))
    else:
        cases = _sweep_cases(folder / "states") if (folder / "states" / "sweep.json").is_file() else []
        cases += _calibration_twins(record, data, states, cases)
    return StateIndex(record, mode, pairs, cases)


def _sand_index(record: Path, data: dict) -> StateIndex:
    """``sand.json``: ``states``, each with n_lab, relative_density, seed and specimen."""
    rows = data.get("states")
    if not isinstance(rows, list):
        raise InputError("SPECIMEN", str(record.parent), f"a folder whose {record.name} has a list 'states'")
    mode = data.get("mode") if isinstance(data.get("mode"), str) else None
    states: dict[float, float | None] = {}
    cases = []
    for k, row in enumerate(rows):
        n_lab = _number(row.get("n_lab")) if isinstance(row, dict) else None
        if n_lab is None:
            raise InputError(f"{record} states[{k}]", row, "a dict with a number n_lab")
        key = next((n for n in states if _same(n, n_lab)), n_lab)
        dr = _number(row.get("relative_density"))
        states[key] = dr if dr is not None else states.get(key)
        seed = row.get("seed")
        seed = seed if isinstance(seed, int) and not isinstance(seed, bool) else None
        spec = row.get("specimen")
        folder = record.parent / spec if isinstance(spec, str) and spec else None
        why = "" if folder is not None else f"{record} states[{k}] names no specimen folder"
        if not why:
            why = _refused_by_row(row) or _not_accepted(folder)
        cases.append(StateCase(key, seed, folder, why))
    return StateIndex(record, mode, sorted(states.items(), key=lambda s: -s[0]), cases)


def _refused_by_row(row: dict) -> str:
    for key in ("accepted", "converged"):
        if key in row and row[key] is not True:
            return f"sand.json says {key} = {row[key]}"
    return ""


def _sweep_cases(sweep: Path, relation_seed: int | None = None) -> list[StateCase]:
    """Every case of the sweep in ``sweep`` (its ``sweep.json``), with n_lab, seed and folder."""
    record = _json(sweep / "sweep.json", "SPECIMEN")
    out = []
    for case in record.get("cases") or []:
        cid = case.get("id") if isinstance(case, dict) else None
        if not isinstance(cid, str) or not cid or Path(cid).name != cid:
            continue
        out.append(_case(sweep / "cases" / cid, _dict(case.get("params")), relation_seed))
    return out


def _case(case_dir: Path, params: dict, relation_seed: int | None, n_lab: float | None = None) -> StateCase:
    """A sweep case: its parameters and status from ``result.json`` (``error.json`` if it failed),
    its seed and acceptance from the criterion's ``run/result.json``."""
    row = _json(case_dir / "result.json", "SPECIMEN") if (case_dir / "result.json").is_file() else None
    if row is None and (case_dir / "error.json").is_file():
        row = _json(case_dir / "error.json", "SPECIMEN")
    params = {**params, **_dict((row or {}).get("params"))}
    run = case_dir / CASE_RUN
    crit = _json(run / "result.json", "SPECIMEN") if (run / "result.json").is_file() else {}
    if n_lab is None:
        n_lab = _number(params.get("criterion.n_lab"))
        n_lab = n_lab if n_lab is not None else _number(((row or {}).get("results") or {}).get("n_lab"))
    seed = crit.get("seed", params.get("seed", relation_seed))
    seed = seed if isinstance(seed, int) and not isinstance(seed, bool) else None
    if row is None:
        why = f"case {case_dir} has not finished"
    elif row.get("status") != "done":
        why = f"case {case_dir} failed: {row.get('error')}"
    else:
        why = _not_accepted(run)
    return StateCase(n_lab if n_lab is not None else math.nan, seed, run, why)


def _not_accepted(folder: Path) -> str:
    """Why the criterion folder holds no accepted specimen ('' when it holds one)."""
    result = folder / "result.json"
    if not result.is_file():
        return f"{result} is missing"
    crit = _json(result, "SPECIMEN")
    trials = crit.get("iterations") if isinstance(crit.get("iterations"), list) else []
    if crit.get("converged") is not True:
        return f"{result} says converged = {crit.get('converged')}: {crit.get('message')}"
    if not any(isinstance(t, dict) and t.get("accepted") is True for t in trials):
        return f"{result} lists no accepted trial"
    if not (folder / "specimen.npz").is_file():
        return f"{folder / 'specimen.npz'} is missing"
    return ""


def _calibration_twins(
    record: Path, data: dict, states: list[dict], found: list[StateCase]
) -> list[StateCase]:
    """The seeds of density states that the state sweep did not run: the calibration ran them.

    A state's check at a calibration friction (the densest or the loosest state) is the same
    criterion run as the calibration case of that friction and seed, which the relation reads
    back instead of running it again (:func:`poro2d.sweep.density.calibration_twins`). Such a
    seed is found among the calibration's cases by its friction and seed; the calibration's
    folder is where ``sweeps.calibration.cases`` says (the cache), else ``calibration/``.
    """
    out = []
    cal_cases: list[tuple[dict, Path]] | None = None
    for state in states:
        n_lab, mu, count = _number(state.get("n_lab")), _number(state.get("mu_prep")), state.get("seeds")
        if n_lab is None or not isinstance(count, int) or isinstance(count, bool):
            continue
        have = {c.seed for c in found if _same(c.n_lab, n_lab)}
        for seed in range(count):
            if seed in have:
                continue
            if cal_cases is None:
                cal_cases = _calibration_cases(record, data)
            hits = [
                d
                for p, d in cal_cases
                if mu is not None
                and _same(_number(p.get("specimen.friction_prep")), round(mu, 6))
                and p.get("seed") == seed
            ]
            if len(hits) == 1:
                case = _case(hits[0], {}, None, n_lab=n_lab)
                out.append(StateCase(n_lab, seed, case.folder, case.why_not))
            else:
                why = f"no case of this seed in {record.parent / 'states'} nor among the calibration's cases"
                out.append(StateCase(n_lab, seed, None, why))
    return out


def _calibration_cases(record: Path, data: dict) -> list[tuple[dict, Path]]:
    """(parameters, case folder) of every case in the state's calibration folder.

    Each case's ``params.json`` says what it ran: a cached calibration serves every run of its
    grading and settings, and its ``sweep.json`` lists only the last run's cases.
    """
    cal = _dict(_dict(data.get("sweeps")).get("calibration"))
    places = [Path(cal["cases"])] if isinstance(cal.get("cases"), str) else []
    places.append(record.parent / "calibration")
    for place in places:
        if (place / "sweep.json").is_file() and (place / "cases").is_dir():
            out = []
            for params_file in sorted((place / "cases").glob("*/params.json")):
                case = _json(params_file, "SPECIMEN")
                out.append((_dict(case.get("params")), params_file.parent))
            return out
    return []


def _config_seed(data: dict) -> int | None:
    seed = _dict(data.get("config")).get("seed", 0)
    return seed if isinstance(seed, int) and not isinstance(seed, bool) else None


def _json(path: Path, parameter: str) -> dict:
    """The JSON object of a record the user pointed at, as it is (checked as every input file is; its
    keys are checked where read)."""
    check_input_file(parameter, path)
    data = Store(path.parent, parameter=parameter).read_json(path.name)
    if data is None:
        raise InputError(parameter, str(path), "a readable JSON file", "it cannot be read or parsed")
    if not isinstance(data, dict):
        raise InputError(parameter, str(path), "a JSON file holding an object")
    return data


def _dict(value) -> dict:
    """``value`` if it is a dict, else an empty one (a record of another shape names nothing)."""
    return value if isinstance(value, dict) else {}


def _number(value) -> float | None:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        return None
    return float(value)


def _same(a: float | None, b: float | None) -> bool:
    return a is not None and b is not None and abs(a - b) <= 1e-9


def _dr_text(dr: float | None) -> str:
    return "unknown" if dr is None else f"{dr:.4f}"


__all__ = [
    "STATE_RECORDS",
    "KnownState",
    "StateSpecimen",
    "find_state_specimen",
    "read_state_index",
    "state_record",
    "state_specimen",
]
