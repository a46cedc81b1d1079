"""``poro2d critical-state --sand DIR``: a sand folder's 2D states held against the 2D line.

The 2D ends of ``poro2d sand`` (its preparation's loosest and densest) and its answer, as void
ratios, get their state parameter psi = e - e_cs,2D(p') at every pressure of the line; with
``--lab-line`` (a published laboratory line or a CSV of points) the laboratory state's
normalised psi and the state-parameter map's 2D void ratio are printed beside them
(:func:`poro2d.state_map.map_state`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from poro2d.console import OutputConsole, Table

console = OutputConsole()


@dataclass(frozen=True)
class HeldStates:
    """A sand folder's 2D states to hold against the line, and its laboratory state."""

    marks: list[tuple[str, float]]
    span: float
    e_lab: float
    e_max: float
    e_min: float
    e2d_max: float
    e2d_min: float
    lab_line: object | None


def _void(n: float) -> float:
    return n / (1.0 - n)


def held_states(sand: Path | None, lab_line: str | None, pressures) -> HeldStates | None:
    """The 2D ends and the answer of a ``poro2d sand`` folder (void ratios), and the laboratory line."""
    from poro2d.errors import InputError
    from poro2d.sand.result import SandResult
    from poro2d.state_map import read_lab_line
    from poro2d.store import Store

    if sand is None:
        if lab_line is not None:
            raise InputError("--lab-line", lab_line, "given with --sand (the laboratory state it maps)")
        return None
    if len(pressures) < 2:
        raise InputError(
            "--sand", str(sand), "given with several --pressure values (a line to hold it against)"
        )
    res = (
        Store(sand, parameter="--sand").read_result("sand.json", SandResult.from_dict)
        if sand.is_dir()
        else None
    )
    if res is None or res.state.n_max is None or res.state.n_min is None:
        raise InputError(
            "--sand", str(sand), "a finished poro2d sand folder (its sand.json, with e_max and e_min)"
        )
    line = None
    if lab_line is not None:
        try:
            line = read_lab_line(lab_line)[0]
        except InputError as exc:
            name = "--lab-line" if exc.parameter == "lab line" else f"--lab-line {exc.parameter}"
            raise InputError(name, exc.value, exc.allowed, exc.hint) from None
    hi, lo, target = _void(res.n2d_max), _void(res.n2d_min), _void(res.n2d_target)
    dr = res.state.relative_density
    marks = [("2D loose end", hi), ("2D dense end", lo), (f"Dr map, Dr {dr:.2f}", target)]
    return HeldStates(marks, hi - lo, res.state.e, _void(res.state.n_max), _void(res.state.n_min), hi, lo,
                      line)  # fmt: skip


def _mapped(m) -> str:
    """The state map's 2D void ratio and porosity, '!' when no preparation reaches it."""
    mark = "" if m.state_within_ends else " !"
    return f"{m.e2d_by_state:.4f} ({m.porosity(m.e2d_by_state):.4f}){mark}"


def print_held(result, held: HeldStates) -> None:
    """The sand's 2D states against the line (psi / (e2D,max - e2D,min) at each p'), and with a
    laboratory line, the state-parameter map beside the Dr map."""
    from poro2d.state_map import map_state

    t = Table(
        title="2D states against the line: psi / (e2D,max - e2D,min) at each p' (> 0: loose, contracts)"
    )
    t.add_column("state", justify="left")
    t.add_column("e2D", justify="right")
    for p in result.pressures_kpa:
        t.add_column(f"{p:g} kPa", justify="right")
    for m in result.marks:
        t.add_row(m.label, f"{m.void_ratio:.4f}", *(f"{v:+.3f}" for v in m.psi_normalised))
    if held.lab_line is not None:
        line = result.measured()
        maps = [
            map_state(held.e_lab, held.e_max, held.e_min, held.lab_line, p, line.void_ratio_at,
                      held.e2d_max, held.e2d_min)
            for p in result.pressures_kpa
        ]  # fmt: skip
        t.add_row(
            "laboratory psi / (e_max - e_min)", f"e {held.e_lab:.4f}", *(f"{m.psi_norm:+.3f}" for m in maps)
        )
        t.add_row("state map: e2D (n2D)", "", *(_mapped(m) for m in maps))
    console.print(t)
    if held.lab_line is not None:
        console.print(
            f"laboratory line: {held.lab_line.text()}; '!': beyond the 2D ends, no preparation reaches it"
        )


__all__ = ["HeldStates", "held_states", "print_held"]
