"""A specimen by its laboratory state: the accepted specimen of one state and seed of a run.

Three folders hold specimens by laboratory state (docs/export.md):

* a relation (``relation.json`` lists the ``points``): in density mode the cases are the sweep
  in ``states/``, one per state and seed, and a state's twin that the calibration had already
  run is read from the calibration's cases (``sweeps.calibration.cases``); in paper mode the
  cases are the sweep in the folder itself, each at the config's seed;
* a density-mode criterion (``density.json``): one state of the same layout;
* a sand run (``sand.json`` lists ``states``, each naming its accepted criterion folder).

The cases are found by what their files say (``sweep.json``, each case's ``result.json``, the
criterion's ``result.json`` in its ``run`` folder), never by a folder name made up from a state.
Everything refused is one :class:`~poro2d.errors.InputError` naming the option, its value and
the states and seeds there are.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TypeVar

from poro2d.errors import InputError, check_int, check_range
from poro2d.interop.run_records import (
    CaseParams,
    CaseRow,
    SandRecord,
    StatesRecord,
    SweepListing,
)
from poro2d.io_utils import check_input_file
from poro2d.specimen.accepted import CriterionOutcome
from poro2d.store import Store

#: the record files of a folder of specimens by state, in the order they are looked for
STATE_RECORDS = ("sand.json", "relation.json", "density.json")
#: how close ``--n-lab`` must be to a state's laboratory porosity (states are kept to 4 decimals)
N_LAB_TOLERANCE = 5e-5
#: how close ``--dr`` must be to a state's relative density
DR_TOLERANCE = 5e-4
#: the folder holding a sweep case's criterion outputs (:mod:`poro2d.sweep.runner`)
CASE_RUN = "run"

R = TypeVar("R")  # a record read from a JSON file


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
    record: str | Path | None = None


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


@dataclass(frozen=True, kw_only=True)
class StateSpecimen(KnownState):
    """The accepted specimen of one state and seed: the state, read from its state folder's
    ``record``, and the criterion ``folder`` holding ``specimen.npz``."""

    folder: Path


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
            text = f"n_lab {n_lab:g} (Dr {dr_text(dr)}): "
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


def state_specimen(
    folder: str | os.PathLike | Store, n_lab: float | None = None, dr: float | None = None, seed: int = 0
) -> StateSpecimen:
    """The accepted specimen of one state and seed, with the state it belongs to.

    ``folder``: a relation, a density-mode criterion or a sand run (its store or folder); the
    state by its laboratory porosity ``n_lab`` or its relative density ``dr`` (one of the
    two), ``seed`` the specimen among the state's. Refused (InputError naming ``--n-lab``,
    ``--dr`` or ``--seed``, with the states and accepted seeds there are) when the state or
    seed is not there or its criterion did not accept a specimen.
    """
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
        check_range("--dr", dr, 0, 1)
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
    folder = accepted[0].folder
    return StateSpecimen(
        mode=index.mode, n_lab=state[0], relative_density=state[1], seed=seed, record=record, folder=folder
    )


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
    if record.name == "sand.json":
        return _sand_index(record, _read(record, "SPECIMEN", lambda d: SandRecord.from_json(d, record)))
    data = _read(
        record, "SPECIMEN", lambda d: StatesRecord.from_json(d, one_state=record.name == "density.json")
    )
    pairs = [(p.n_lab, p.relative_density) for p in data.points if p.n_lab is not None]
    if not pairs:
        raise InputError(
            "SPECIMEN", str(record.parent), f"a folder whose {record.name} lists laboratory states"
        )
    folder = record.parent
    # paper mode runs its sweep in the folder itself (a relation of before "mode" was recorded too)
    if data.mode == "paper" or (data.mode is None and (folder / "sweep.json").is_file()):
        cases = _sweep_cases(folder, relation_seed=data.config_seed)
    else:
        cases = _sweep_cases(folder / "states") if (folder / "states" / "sweep.json").is_file() else []
        cases += _calibration_twins(record, data, cases)
    return StateIndex(record, data.mode, pairs, cases)


def _sand_index(record: Path, data: SandRecord) -> StateIndex:
    """``sand.json``: ``states``, each with n_lab, relative_density, seed and specimen."""
    states: dict[float, float | None] = {}
    cases = []
    for k, row in enumerate(data.states):
        key = next((n for n in states if _same(n, row.n_lab)), row.n_lab)
        dr = row.relative_density
        states[key] = dr if dr is not None else states.get(key)
        where = f"{record} states[{k}]"
        if row.specimen is None:
            cases.append(StateCase(key, row.seed, None, f"{where} names no specimen folder"))
            continue
        folder = inside(record.parent, row.specimen, f"{where} specimen")
        why = row.refusal or _not_accepted(folder) or _other_seed(folder, row.seed, where)
        cases.append(StateCase(key, row.seed, folder, why))
    return StateIndex(record, data.mode, sorted(states.items(), key=lambda s: -s[0]), cases)


def inside(root: Path, name: str, where: str) -> Path:
    """``root / name``, refused (InputError naming ``where``) when it resolves outside ``root``:
    an edited record must not send an export to the files of another folder."""
    path = root / name
    if not path.resolve().is_relative_to(root.resolve()):
        raise InputError(where, name, f"a path inside {root}", "this one leaves it")
    return path


def _other_seed(folder: Path, seed: int | None, where: str) -> str:
    """Why a specimen is not the seed its record labels it ('' when its criterion's ``result.json``
    records that seed, or none): a specimen is never written out under another seed's label."""
    crit = _read(folder / "result.json", "SPECIMEN", CriterionOutcome.from_json)
    if not crit.names_seed or crit.seed == seed:
        return ""
    return f"{folder / 'result.json'} records seed {crit.seed}, not the seed {seed} of {where}"


def _sweep_cases(sweep: Path, relation_seed: int | None = None) -> list[StateCase]:
    """Every case of the sweep in ``sweep`` (its ``sweep.json``), with n_lab, seed and folder."""
    listing = _read(sweep / "sweep.json", "SPECIMEN", SweepListing.from_json)
    where = f"{sweep / 'sweep.json'} case id"
    return [
        _case(inside(sweep / "cases", cid, where), params, relation_seed) for cid, params in listing.cases
    ]


def _case(
    case_dir: Path, params: CaseParams, relation_seed: int | None, n_lab: float | None = None
) -> StateCase:
    """A sweep case: its parameters and status from ``result.json`` (``error.json`` if it failed),
    its seed and acceptance from the criterion's ``run/result.json``."""
    row = None
    for name in ("result.json", "error.json"):
        if row is None and (case_dir / name).is_file():
            row = _read(case_dir / name, "SPECIMEN", CaseRow.from_json)
    if row is not None:
        params = params.then(row.params)
    run = case_dir / CASE_RUN
    crit = (
        _read(run / "result.json", "SPECIMEN", CriterionOutcome.from_json)
        if (run / "result.json").is_file()
        else None
    )
    if n_lab is None:
        n_lab = params.n_lab if params.n_lab is not None else (row.result_n_lab if row is not None else None)
    if crit is not None and crit.names_seed:
        seed = crit.seed
    else:
        seed = params.seed if "seed" in params.given else relation_seed
        seed = seed if isinstance(seed, int) and not isinstance(seed, bool) else None
    if row is None:
        why = f"case {case_dir} has not finished"
    elif row.failure is not None:
        why = f"case {case_dir} failed: {row.failure}"
    else:
        why = _not_accepted(run)
    return StateCase(n_lab if n_lab is not None else math.nan, seed, run, why)


def _not_accepted(folder: Path) -> str:
    """Why the criterion folder holds no accepted specimen ('' when it holds one)."""
    result = folder / "result.json"
    if not result.is_file():
        return f"{result} is missing"
    crit = _read(result, "SPECIMEN", CriterionOutcome.from_json)
    if not crit.converged.true:
        return f"{result} says converged = {crit.converged.said}: {crit.message}"
    if not crit.accepted_trial:
        return f"{result} lists no accepted trial"
    if not (folder / "specimen.npz").is_file():
        return f"{folder / 'specimen.npz'} is missing"
    return ""


def _calibration_twins(record: Path, data: StatesRecord, found: list[StateCase]) -> list[StateCase]:
    """The seeds of density states that the state sweep did not run: the calibration ran them.

    A state's check at a calibration friction (the densest or the loosest state) is the same
    criterion run as the calibration case of that friction and seed, which the relation reads
    back instead of running it again (:func:`poro2d.sweep.density.calibration_twins`). Such a
    seed is found among the calibration's cases by its friction and seed; the calibration's
    folder is where ``sweeps.calibration.cases`` says (the cache), else ``calibration/``.
    """
    out = []
    cal_cases: list[tuple[CaseParams, Path]] | None = None
    for state in data.points:
        n_lab, mu, count = state.n_lab, state.mu_prep, state.seeds
        if n_lab is None or count is None:
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
                if mu is not None and _same(p.friction_prep, round(mu, 6)) and p.seed == seed
            ]
            if len(hits) == 1:
                case = _case(hits[0], CaseParams(frozenset()), None, n_lab=n_lab)
                out.append(StateCase(n_lab, seed, case.folder, case.why_not))
            else:
                why = f"no case of this seed in {record.parent / 'states'} nor among the calibration's cases"
                out.append(StateCase(n_lab, seed, None, why))
    return out


def _calibration_cases(record: Path, data: StatesRecord) -> list[tuple[CaseParams, Path]]:
    """(parameters, case folder) of every case in the state's calibration folder.

    Each case's ``params.json`` says what it ran: a cached calibration serves every run of its
    grading and settings, and its ``sweep.json`` lists only the last run's cases.
    """
    places = [Path(data.calibration_cases)] if data.calibration_cases is not None else []
    places.append(record.parent / "calibration")
    for place in places:
        if (place / "sweep.json").is_file() and (place / "cases").is_dir():
            out = []
            for params_file in sorted((place / "cases").glob("*/params.json")):
                params = _read(params_file, "SPECIMEN", lambda d: CaseParams.from_json(d.get("params")))
                out.append((params, params_file.parent))
            return out
    return []


def _read(path: Path, parameter: str, parse: Callable[[dict], R]) -> R:
    """The record at ``path`` the user pointed at, read by ``parse`` from its JSON object (checked
    as every input file is; ``parse`` keeps what it needs)."""
    check_input_file(parameter, path)
    data = Store(path.parent, parameter=parameter).read_json(path.name)
    if data is None:
        raise InputError(parameter, str(path), "a readable JSON file", "it cannot be read or parsed")
    if not isinstance(data, dict):
        raise InputError(parameter, str(path), "a JSON file holding an object")
    return parse(data)


def _same(a: float | None, b: float | None) -> bool:
    return a is not None and b is not None and abs(a - b) <= 1e-9


def dr_text(dr: float | None) -> str:
    """A relative density as the messages and provenance lines write it."""
    return "unknown" if dr is None else f"{dr:.4f}"


__all__ = [
    "STATE_RECORDS",
    "KnownState",
    "StateSpecimen",
    "dr_text",
    "read_state_index",
    "state_record",
    "state_specimen",
]
