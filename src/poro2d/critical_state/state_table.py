"""The state-parameter map beside the relative-density map: a config's ``[state]`` table.

``poro2d sand`` and ``poro2d relation`` read it alike.

``[state]`` names the laboratory's critical-state line and the test's mean stress, and points at
the disks' own line (a folder of ``poro2d critical-state --pressure ...`` made with the soil's
grading and the specimens' working friction):

```toml
[state]
lab_line = "toyoura"          # or a CSV of p_kpa,e_cs points (relative to this file)
test_stress_kpa = 100         # p' at which psi is matched
line_2d = "cs-toyoura"        # the 2D critical-state line (relative to this file); optional
```

The answers of ``poro2d sand`` and ``poro2d relation`` stay the relative-density map's
(docs/equivalence.md says why); with ``[state]`` the result adds the state map's 2D void ratio
and porosity at the test stress, the laboratory's and the answer's normalised state parameters,
and whether a preparation can reach the state map's answer
(:func:`poro2d.state_map.map_state`). Without ``line_2d`` it says which command makes the line.
Everything is read and checked when the config is.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

from poro2d.config import check_keys
from poro2d.critical_state.line import CriticalStateLineResult, MeasuredLine
from poro2d.errors import InputError, check_range, is_number
from poro2d.grading import GradingCurve
from poro2d.lab_state import LabState
from poro2d.state_map import PRESSURE_RANGE_KPA, LabCriticalStateLine, map_state, read_lab_line
from poro2d.store import Store
from poro2d.typed_result import TypedResult

STATE_KEYS = {"lab_line", "test_stress_kpa", "line_2d"}
#: the working friction of a 2D line and of the specimens agree when this close
FRICTION_TOLERANCE = 1e-9


@dataclass(frozen=True)
class StateRequest:
    """A checked ``[state]`` table: the laboratory line, p', and the 2D line when given."""

    lab_line: LabCriticalStateLine
    test_stress_kpa: float
    line_2d: MeasuredLine | None
    line_2d_folder: str | None


def _path(base_dir: Path | None, text: str) -> Path:
    p = Path(text)
    return p if p.is_absolute() or base_dir is None else base_dir / p


def _same_shape(grading: GradingCurve, sizes: tuple[float, ...], percent: tuple[float, ...]) -> bool:
    """Whether a line's grading is the soil's up to a scale (void ratios do not depend on scale)."""
    theirs, pct = grading.sizes_m, grading.percent_passing
    if len(theirs) != len(sizes) or len(pct) != len(percent):
        return False
    scale = sizes[0] / theirs[0]
    return all(math.isclose(a, b * scale, rel_tol=1e-6) for a, b in zip(sizes, theirs, strict=True)) and all(
        math.isclose(a, b, abs_tol=1e-6) for a, b in zip(percent, pct, strict=True)
    )


def _line_2d(folder: Path, friction: float, rolling: float, grading) -> MeasuredLine:
    """The fit of a 2D line folder, refused unless it is a line of the soil's grading (to a scale)
    at the specimens' working frictions."""
    res = Store(folder, parameter="state.line_2d").read_result(
        "result.json", CriticalStateLineResult.from_dict
    )
    if res is None or not res.points:
        raise InputError(
            "state.line_2d", str(folder), "a finished poro2d critical-state folder of several pressures"
        )
    case = res.case
    for name, want, have in (("particle_friction", friction, case.particle_friction),
                             ("rolling_friction", rolling, case.rolling_friction)):  # fmt: skip
        if not math.isclose(want, have, abs_tol=FRICTION_TOLERANCE):
            raise InputError(
                f"state.line_2d {name}", have, f"the specimens' working value {want:g}",
                f"make the line with --particle-friction {friction:g} --rolling-friction {rolling:g}",
            )  # fmt: skip
    if not _same_shape(case.grading, tuple(grading.sizes_m), tuple(grading.percent_passing)):
        raise InputError(
            "state.line_2d grading", case.grading.source, "the soil's grading (to a scale)",
            "make the line with --grading set to the soil's sieve curve",
        )  # fmt: skip
    return res.measured()


def state_request(
    table, lab: LabState, base_dir: Path | None, friction: float, rolling: float, grading
) -> StateRequest | None:
    """The ``[state]`` table checked (None without one); ``friction``, ``rolling`` and ``grading``:
    the specimens' (a 2D line must be theirs)."""
    if table is None:
        return None
    check_keys("state", table, STATE_KEYS)
    if "lab_line" not in table or not isinstance(table["lab_line"], str):
        raise InputError("state.lab_line", table.get("lab_line"), "a published line (toyoura) or a CSV path")
    name = table["lab_line"]
    csv_path = str(_path(base_dir, name)) if name.lower().endswith(".csv") else name
    try:
        line = read_lab_line(csv_path)[0]
    except InputError as exc:
        raise InputError(f"state.lab_line ({exc.parameter})", exc.value, exc.allowed, exc.hint) from None
    stress = table.get("test_stress_kpa", 100.0)
    if not is_number(stress):
        raise InputError("state.test_stress_kpa", stress, "a number (kPa)")
    check_range("state.test_stress_kpa", stress, *PRESSURE_RANGE_KPA)
    line.void_ratio_at(float(stress))  # a table of points must span the test stress
    folder = table.get("line_2d")
    if folder is not None and not isinstance(folder, str):
        raise InputError("state.line_2d", folder, "a folder path (a string)")
    fit = None if folder is None else _line_2d(_path(base_dir, folder), friction, rolling, grading)
    if fit is not None:
        try:
            fit.void_ratio_at(float(stress))
        except InputError as exc:
            raise InputError("state.test_stress_kpa", stress, exc.allowed) from None
    if lab.n_max is None or lab.n_min is None:
        raise InputError("lab.e_max/e_min", None, "both extremes, for the state parameter's span")
    return StateRequest(line, float(stress), fit, None if folder is None else str(_path(base_dir, folder)))


@dataclass(eq=False)
class StateMapRecord(TypedResult):
    """``state_map`` in ``sand.json``: both maps at the test stress (void ratios; n = e / (1 + e)).

    ``psi_norm_lab`` the laboratory's psi / (e_max - e_min); ``psi_norm_by_dr`` that of the
    answer (the relative-density map's) against the 2D line; ``e2d_by_state``, ``n2d_by_state``
    the state map's answer and ``state_within_ends`` whether a preparation reaches it; the 2D
    numbers are None without a 2D line (``note`` says how to make one).
    """

    test_stress_kpa: float
    lab_line: str
    e_cs_lab: float
    psi_lab: float
    psi_norm_lab: float
    line_2d: str | None
    e_cs_2d: float | None
    e2d_by_dr: float
    psi_norm_by_dr: float | None
    e2d_by_state: float | None
    n2d_by_state: float | None
    state_within_ends: bool | None
    note: str


def _void(n: float) -> float:
    return n / (1.0 - n)


def state_map_record(request: StateRequest, lab: LabState, n2d_max: float, n2d_min: float, n2d_dr: float,
                     grading_csv: str) -> StateMapRecord:  # fmt: skip
    """Both maps of ``lab`` at the request's stress: the 2D ends and the Dr map's answer as porosities."""
    e_max, e_min = _void(lab.n_max), _void(lab.n_min)
    p = request.test_stress_kpa
    e_cs = request.lab_line.void_ratio_at(p)
    psi = lab.e - e_cs
    base = {"test_stress_kpa": p, "lab_line": request.lab_line.text(), "e_cs_lab": e_cs, "psi_lab": psi,
            "psi_norm_lab": psi / (e_max - e_min), "line_2d": request.line_2d_folder,
            "e2d_by_dr": _void(n2d_dr)}  # fmt: skip
    if request.line_2d is None:
        return StateMapRecord(
            **base, e_cs_2d=None, psi_norm_by_dr=None, e2d_by_state=None, n2d_by_state=None,
            state_within_ends=None,
            note="no 2D line: make one with poro2d critical-state --grading "
            f"{grading_csv} --particle-friction F --pressure 50,100,200,400 --strain 6, then give it as "
            "[state] line_2d",
        )  # fmt: skip
    m = map_state(lab.e, e_max, e_min, request.lab_line, p, request.line_2d.void_ratio_at,
                  _void(n2d_max), _void(n2d_min))  # fmt: skip
    return StateMapRecord(
        **base, e_cs_2d=m.e_cs_2d, psi_norm_by_dr=(base["e2d_by_dr"] - m.e_cs_2d) / (m.e2d_max - m.e2d_min),
        e2d_by_state=m.e2d_by_state,
        n2d_by_state=m.porosity(m.e2d_by_state), state_within_ends=m.state_within_ends,
        note="the state map's answer lies within the 2D ends" if m.state_within_ends
        else "the state map's answer lies beyond the 2D ends: no preparation reaches it",
    )  # fmt: skip


def state_map_lines(rec: StateMapRecord) -> list[str]:
    """The state map beside the answer, in plain sentences (the command and summary.md print them)."""
    head = (
        f"state map at p' = {rec.test_stress_kpa:g} kPa (laboratory line {rec.lab_line}): the laboratory "
        f"state lies at psi / (e_max - e_min) = {rec.psi_norm_lab:+.3f}"
    )
    if rec.e_cs_2d is None:
        return [head + ".", rec.note]
    return [
        head
        + f"; against the 2D line (e_cs = {rec.e_cs_2d:.4f} there) the answer above, the relative-density "
        f"map's, lies at {rec.psi_norm_by_dr:+.3f} of the 2D span.",
        f"matching the state parameter instead asks for e2D = {rec.e2d_by_state:.4f} (n2D = "
        f"{rec.n2d_by_state:.4f}): {rec.note}. The answer stays the relative-density map's "
        "(docs/equivalence.md).",
    ]


__all__ = [
    "STATE_KEYS",
    "StateMapRecord",
    "StateRequest",
    "state_map_lines",
    "state_map_record",
    "state_request",
]
