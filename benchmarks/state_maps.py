"""A finished sand answer held against a finished 2D critical-state line: both maps side by side.

    python benchmarks/state_maps.py LINE_DIR SAND_DIR [--lab-line toyoura]

LINE_DIR: a ``poro2d critical-state --pressure ...`` folder (or ``benchmarks/critical_state_line.py
--keep``); SAND_DIR: a ``poro2d sand`` folder (its ``sand.json``). Prints what
``poro2d critical-state --sand SAND_DIR --lab-line ...`` prints after computing its line, without
running the line again: the 2D ends' and the answer's psi / (e2D,max - e2D,min) at each of the
line's pressures, the laboratory's normalised psi and the state map's 2D void ratio
(docs/equivalence.md).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("line", type=Path)
    ap.add_argument("sand", type=Path)
    ap.add_argument("--lab-line", default="toyoura")
    args = ap.parse_args()

    from poro2d.cli.critical_state_held import held_states, print_held
    from poro2d.critical_state.line import CriticalStateLineResult, StateMark

    result = CriticalStateLineResult.from_dict(json.loads((args.line / "result.json").read_text()))
    held = held_states(args.sand, args.lab_line, result.pressures_kpa)
    result.marks = [
        StateMark.of(label, e, result.measured(), result.pressures_kpa, held.span) for label, e in held.marks
    ]
    print(result.headline())
    print_held(result, held)


if __name__ == "__main__":
    main()
