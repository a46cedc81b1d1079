"""What the exporters read from the records a finished run leaves beside its specimens, as values.

A record may come from an earlier poro2d or a hand's edit: each is opened once and handed to a
``from_json`` here, which keeps what the exporters need as typed fields; a value of another shape
reads as not said (None, False), so that the caller refuses it or names it unknown in its own
words. A value that a refusal quotes as the file wrote it (``converged = False``) is kept as text.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from poro2d.errors import InputError
from poro2d.json_fields import int_at, number_at, text_at, value_at

#: a JSON scalar as a record wrote it (compared as it is: a seed of 1.0 equals seed 1, as in JSON)
Scalar = bool | int | float | str | None


@dataclass(frozen=True)
class StatePoint:
    """One laboratory state of a relation's ``points`` (or the one state of ``density.json``):
    n_lab, Dr, the preparation friction and how many seeds it ran (None: not said)."""

    n_lab: float | None
    relative_density: float | None
    mu_prep: float | None
    seeds: int | None

    @classmethod
    def from_json(cls, data: dict) -> StatePoint:
        return cls(
            number_at(data, "n_lab"),
            number_at(data, "relative_density"),
            number_at(data, "mu_prep"),
            int_at(data, "seeds"),
        )


@dataclass(frozen=True)
class StatesRecord:
    """``relation.json`` or ``density.json``: the mode, the states, the seed of the config (0 when
    it gives none, None when it gives one of another kind) and where the calibration's cases are."""

    mode: str | None
    points: tuple[StatePoint, ...]
    config_seed: int | None
    calibration_cases: str | None

    @classmethod
    def from_json(cls, data: dict, one_state: bool = False) -> StatesRecord:
        """``one_state``: the object is itself the state (``density.json``)."""
        points = data.get("points") if isinstance(data.get("points"), list) else []
        rows = [data] if one_state else [p for p in points if isinstance(p, dict)]
        config = data.get("config")
        seed = config.get("seed", 0) if isinstance(config, dict) else 0
        return cls(
            mode=text_at(data, "mode"),
            points=tuple(StatePoint.from_json(p) for p in rows),
            config_seed=seed if isinstance(seed, int) and not isinstance(seed, bool) else None,
            calibration_cases=text_at(data, "sweeps", "calibration", "cases"),
        )


@dataclass(frozen=True)
class SandState:
    """One of ``sand.json``'s ``states``: its n_lab and Dr, seed, the specimen's folder (relative to
    the sand folder; None: none named) and, when the row itself refuses it, why (``refusal``)."""

    n_lab: float
    relative_density: float | None
    seed: int | None
    specimen: str | None
    refusal: str


@dataclass(frozen=True)
class SandRecord:
    """``sand.json``: the mode and the states."""

    mode: str | None
    states: tuple[SandState, ...]

    @classmethod
    def from_json(cls, data: dict, record: Path) -> SandRecord:
        """Refused (InputError naming ``record``) without a list ``states`` or with a state lacking n_lab."""
        rows = data.get("states")
        if not isinstance(rows, list):
            raise InputError(
                "SPECIMEN", str(record.parent), f"a folder whose {record.name} has a list 'states'"
            )
        states = []
        for k, row in enumerate(rows):
            n_lab = number_at(row, "n_lab") if isinstance(row, dict) else None
            if n_lab is None:
                raise InputError(f"{record} states[{k}]", row, "a dict with a number n_lab")
            spec = row.get("specimen")
            states.append(
                SandState(
                    n_lab,
                    number_at(row, "relative_density"),
                    int_at(row, "seed"),
                    spec if isinstance(spec, str) and spec else None,
                    _row_refusal(row),
                )  # fmt: skip
            )
        return cls(text_at(data, "mode"), tuple(states))


def _row_refusal(row: dict) -> str:
    for key in ("accepted", "converged"):
        if key in row and row[key] is not True:
            return f"sand.json says {key} = {row[key]}"
    return ""


@dataclass(frozen=True)
class CaseParams:
    """What a sweep case's parameters say of its state: ``criterion.n_lab``, ``seed`` (as written)
    and ``specimen.friction_prep``; ``given``: the names among these that the case gives at all."""

    given: frozenset[str]
    n_lab: float | None = None
    seed: Scalar = None
    friction_prep: float | None = None

    @classmethod
    def from_json(cls, params) -> CaseParams:
        """The parameters object of a case (anything else gives nothing)."""
        if not isinstance(params, dict):
            return cls(frozenset())
        names = frozenset(k for k in ("criterion.n_lab", "seed", "specimen.friction_prep") if k in params)
        return cls(
            names,
            number_at(params, "criterion.n_lab"),
            value_at(params, "seed"),
            number_at(params, "specimen.friction_prep"),
        )

    def then(self, later: CaseParams) -> CaseParams:
        """These parameters with those ``later`` gives put over them."""
        return CaseParams(
            self.given | later.given,
            later.n_lab if "criterion.n_lab" in later.given else self.n_lab,
            later.seed if "seed" in later.given else self.seed,
            later.friction_prep if "specimen.friction_prep" in later.given else self.friction_prep,
        )


@dataclass(frozen=True)
class SweepListing:
    """A sweep's ``sweep.json``: its cases, each by id (a plain folder name) with its parameters."""

    cases: tuple[tuple[str, CaseParams], ...]

    @classmethod
    def from_json(cls, data: dict) -> SweepListing:
        cases = []
        listed = data.get("cases")
        for case in listed if isinstance(listed, list) else []:
            cid = case.get("id") if isinstance(case, dict) else None
            if isinstance(cid, str) and cid and Path(cid).name == cid:
                cases.append((cid, CaseParams.from_json(case.get("params"))))
        return cls(tuple(cases))


@dataclass(frozen=True)
class CaseRow:
    """A sweep case's ``result.json`` (or ``error.json``): its parameters, its error as written when
    it is not done (``failure``; None: done) and the n_lab among its results."""

    params: CaseParams
    failure: str | None
    result_n_lab: float | None

    @classmethod
    def from_json(cls, data: dict) -> CaseRow:
        return cls(
            CaseParams.from_json(data.get("params")),
            None if data.get("status") == "done" else str(data.get("error")),
            number_at(data, "results", "n_lab"),
        )
