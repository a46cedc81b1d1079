"""Where an exported specimen came from: the soil's provenance lines of every export header.

The criterion's folder records its run beside ``specimen.npz`` (``config.json``: the grading
table and source; ``result.json``: the laboratory porosity, the preparation friction, n2D, the
box and interior porosities, the seed and the version). :func:`origin_lines` turns them into
lines starting with ``provenance:``. The mode and relative density are the state folder's
(:mod:`poro2d.interop.state_specimen`): given with a specimen found by its state, looked up in
the state folder above a sweep case, paper mode for a criterion folder of its own. A checkpoint
without these records gets one line saying its provenance is unknown: nothing is made up.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import TypeVar

from poro2d.interop.provenance_records import ConfigFacts, GradingFacts, ResultFacts, RunFacts, SoilFacts
from poro2d.interop.state_specimen import KnownState, dr_text, read_state_index, state_record
from poro2d.json_fields import finite_number
from poro2d.store import Store

#: every provenance line starts with this (after the target's comment sign)
PREFIX = "provenance:"
#: written by ``poro2d sand`` beside each specimen it names: the soil, its state, mode and seed
SOIL_FILE = "soil.json"

R = TypeVar("R")  # a record read from a JSON file


def origin_lines(checkpoint: str | Path, state: KnownState | None = None) -> list[str]:
    """The provenance lines of the specimen saved at ``checkpoint`` (without comment signs).

    ``state``: the state the specimen was found by
    (:class:`~poro2d.interop.state_specimen.StateSpecimen`), None to look it up from the folder.
    """
    p = Path(checkpoint)
    folder = p.parent
    records = Store(folder)
    result = _criterion_record(records, "result.json", ("iterations", "specimen"), ResultFacts.from_json)
    config = _criterion_record(records, "config.json", ("run",), ConfigFacts.from_json)
    soil = _criterion_record(records, SOIL_FILE, ("soil", "state"), SoilFacts.from_json)
    if result is None and config is None and soil is None:
        return [
            f"{PREFIX} unknown (no criterion record, result.json or config.json, beside {_text(p.name)}: "
            "grading, laboratory state, mode and seed not recorded)"
        ]
    if state is None and soil is not None:  # a specimen folder that poro2d sand named
        state = KnownState(soil.mode, soil.n_lab, soil.relative_density, soil.seed)
    if state is None:
        state = _state_of_case(folder)
    elif not state.mode:  # a sand folder that does not say: the state folder of the case
        case = _state_of_case(folder)
        state = replace(state, mode=case.mode if case is not None else None)
    result, config = result or ResultFacts(), config or ConfigFacts()
    run = result.run.or_else(config.run)
    lines = [f"{PREFIX} grading {_grading(config.grading)}"]
    if soil is not None and soil.named:
        ref = f" ({_text(soil.reference)})" if soil.reference else ""
        lines.insert(0, f"{PREFIX} soil {_text(soil.name)}{ref}")
    lines.append(f"{PREFIX} laboratory state {_state(result, config, state, folder)}")
    lines.append(
        f"{PREFIX} preparation friction mu_prep (specimen.friction_prep) = {_value(run.friction_prep)}"
    )
    lines.append(f"{PREFIX} {_porosities(result)}")
    lines.append(f"{PREFIX} {_run(run, state)}")
    if state is not None and state.record:
        lines.append(f"{PREFIX} state read from {_text(state.record)}")
    return lines


def _criterion_record(
    records: Store, name: str, keys: tuple[str, ...], parse: Callable[[dict], R]
) -> R | None:
    """A criterion's record file read by ``parse`` from its JSON object (which keeps what the lines
    name), None if missing, unreadable or of another kind (an object without ``keys``)."""
    if not records.has(name) or (records.root / name).stat().st_size > 50_000_000:
        return None
    data = records.read_json(name)
    return parse(data) if isinstance(data, dict) and all(k in data for k in keys) else None


def _grading(g: GradingFacts) -> str:
    """Preset name or CSV file, up-scaling factor and cuts, from the config's ``[grading]``."""
    if g.kind == "unknown":
        return "unknown (no config.json beside the specimen)"
    if g.kind == "preset":
        text = f"preset {_text(g.name)!r}" + (f" ({_text(g.source)})" if g.source else "")
    elif g.kind == "csv":
        text = f"CSV file {_text(g.source or g.name)}"
    else:
        count = f"{g.sizes} " if g.sizes is not None else ""
        text = f"{count}sieve sizes given in the config (sizes_mm, percent_passing)"
    text += f", up-scaling factor {_value(g.upscale)}"
    cuts = [f"{k} = {_value(v)} mm" for k, v in g.cuts]
    return text + (
        "; cut at " + ", ".join(cuts) + " (of the up-scaled curve)" if cuts else "; no d_min/d_max cut"
    )


def _state(result: ResultFacts, config: ConfigFacts, state: KnownState | None, folder: Path) -> str:
    """n_lab, Dr and the mode."""
    n_lab = state.n_lab if state is not None else result.n_lab
    dr = state.relative_density if state is not None else _config_dr(n_lab, config)
    if state is not None:
        mode = state.mode or "unknown"
    elif (folder.parent / "params.json").is_file():  # a sweep case not found in a state folder above it
        mode = "unknown (a sweep case: export it by its state folder)"
    else:
        mode = "paper" if config.density_mode is None else config.density_mode
        mode = _text(mode) + " (a criterion folder of its own)"
    return f"n_lab = {_value(finite_number(n_lab))}, relative density Dr = {dr_text(dr)}; mode {mode}"


def _config_dr(n_lab: float | None, config: ConfigFacts) -> float | None:
    """Dr of ``n_lab`` between the laboratory extremes the config's ``[density]`` gives, if it does."""
    from poro2d.errors import InputError
    from poro2d.porosity import relative_density

    if n_lab is None or config.extremes is None or None in config.extremes:
        return None
    try:
        return float(relative_density(n_lab, *config.extremes))
    except InputError:
        return None


def _porosities(result: ResultFacts) -> str:
    n2d, box = result.final_porosity, result.box_porosity
    inner, sd = result.interior_porosity, result.interior_porosity_std
    text = f"accepted n2D = {_value(n2d)}, box porosity n' = {_value(box, '.6g')}"
    if inner is None:
        return text + "; interior porosity unknown (not measured)"
    return text + f"; interior porosity = {inner:.6g}" + (f" +- {sd:.4g}" if sd is not None else "")


def _run(run: RunFacts, state: KnownState | None) -> str:
    seed = state.seed if state is not None else run.seed
    stamp = run.stamp
    text = f"seed {seed if isinstance(seed, int) and not isinstance(seed, bool) else 'unknown'}; "
    text += f"criterion run by poro2d {_text(stamp.version) if stamp.version else 'unknown'}"
    return text + (f" ({_text(stamp.created_utc)})" if stamp.created_utc else "")


def _state_of_case(folder: Path) -> KnownState | None:
    """The state of a sweep case's criterion folder (``<sweep>/cases/<id>/run``), from the state
    folder whose sweep it is (the sweep folder itself, or the folder above ``states/``)."""
    from poro2d.errors import InputError

    if not (folder.parent / "params.json").is_file():
        return None
    sweep = folder.parent.parent.parent
    for place in (sweep, sweep.parent):
        record = state_record(place)
        if record is None:
            continue
        try:
            index = read_state_index(record)
        except InputError:  # a damaged record above the case: its state is not known from there
            continue
        for case in index.cases:
            if case.folder is not None and case.folder.resolve() == folder.resolve():
                dr = next((d for n, d in index.states if abs(n - case.n_lab) <= 1e-9), None)
                return KnownState(index.mode, case.n_lab, dr, case.seed, record=str(record))
    return None


def _value(v: float | None, fmt: str = "") -> str:
    if v is None:
        return "unknown"
    return format(v, fmt) if fmt else repr(v)


def _text(value) -> str:
    """One line of text (a path or a name with a line break would end the comment)."""
    return " ".join(str(value).split())
