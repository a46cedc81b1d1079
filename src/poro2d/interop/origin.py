"""Where an exported specimen came from: the soil's provenance lines of every export header.

The criterion's folder records its run beside ``specimen.npz``: ``config.json`` (the config
as given, with the ``[grading]`` table, and the run's grading source) and ``result.json``
(the laboratory porosity, the preparation friction, the accepted n2D, the box and interior
porosity, the seed and the poro2d version that ran it). :func:`origin_lines` turns them into
lines, each starting with ``provenance:``; the export writes them as comments. The mode
(paper or density) and the relative density are the state folder's
(:mod:`poro2d.interop.state_specimen`): a specimen exported by its state has them, a sweep
case exported by its own folder is looked up in the state folder above it, and a criterion
folder of its own is paper mode. A checkpoint without these records beside it gets one line
saying its provenance is unknown: nothing is made up.
"""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

from poro2d.interop.state_specimen import KnownState, read_state_index, state_record
from poro2d.store import Store

#: every provenance line starts with this (after the target's comment sign)
PREFIX = "provenance:"
#: written by ``poro2d sand`` beside each specimen it names: the soil, its state, mode and seed
SOIL_FILE = "soil.json"


def origin_lines(checkpoint: str | Path, state: KnownState | None = None) -> list[str]:
    """The provenance lines of the specimen saved at ``checkpoint`` (without comment signs).

    ``state``: the state the specimen was found by
    (:meth:`~poro2d.interop.state_specimen.StateSpecimen.known`), None to look it up from the folder.
    """
    p = Path(checkpoint)
    folder = p.parent
    records = Store(folder)
    result = _criterion_record(records, "result.json", ("iterations", "specimen"))
    config = _criterion_record(records, "config.json", ("run",))
    soil = _criterion_record(records, SOIL_FILE, ("soil", "state"))
    if result is None and config is None and soil is None:
        return [
            f"{PREFIX} unknown (no criterion record, result.json or config.json, beside {_text(p.name)}: "
            "grading, laboratory state, mode and seed not recorded)"
        ]
    if state is None and soil is not None:  # a specimen folder that poro2d sand named
        lab = soil["state"] if isinstance(soil["state"], dict) else {}
        state = KnownState(soil.get("mode"), lab.get("n_lab"), lab.get("relative_density"), soil.get("seed"))
    if state is None:
        state = _state_of_case(folder)
    elif not state.mode:  # a sand folder that does not say: the state folder of the case
        case = _state_of_case(folder)
        state = replace(state, mode=case.mode if case is not None else None)
    result, config = result or {}, config or {}
    lines = [f"{PREFIX} grading {_grading(config)}"]
    if soil is not None and isinstance(soil["soil"], dict):
        who = soil["soil"]
        ref = f" ({_text(who.get('reference'))})" if who.get("reference") else ""
        lines.insert(0, f"{PREFIX} soil {_text(who.get('name'))}{ref}")
    lines.append(f"{PREFIX} laboratory state {_state(result, config, state, folder)}")
    spec = result.get("specimen") or (config.get("run") or {}).get("specimen") or {}
    mu = _num(spec.get("friction_prep")) if isinstance(spec, dict) else None
    lines.append(f"{PREFIX} preparation friction mu_prep (specimen.friction_prep) = {_value(mu)}")
    lines.append(f"{PREFIX} {_porosities(result)}")
    lines.append(f"{PREFIX} {_run(result, config, state)}")
    if state is not None and state.record:
        lines.append(f"{PREFIX} state read from {_text(state.record)}")
    return lines


def _criterion_record(records: Store, name: str, keys: tuple[str, ...]) -> dict | None:
    """The JSON object of a criterion's record file as it is (its keys are checked where read), None
    if missing, unreadable or of another kind."""
    if not records.has(name) or (records.root / name).stat().st_size > 50_000_000:
        return None
    data = records.read_json(name)
    return data if isinstance(data, dict) and all(k in data for k in keys) else None


def _grading(config: dict) -> str:
    """Preset name or CSV file, up-scaling factor and cuts, from the config's ``[grading]``."""
    from poro2d.grading import PAPER_UPSCALE

    if "config" not in config:
        return "unknown (no config.json beside the specimen)"
    table = (config.get("config") or {}).get("grading")
    table = table if isinstance(table, dict) and table else {"preset": "paper"}  # the criterion's default
    run = (config.get("run") or {}).get("grading") or {}
    source = run.get("source") if isinstance(run, dict) and run.get("source") else None
    if "preset" in table:
        text = f"preset {_text(table['preset'])!r}" + (f" ({_text(source)})" if source else "")
        upscale = table.get("upscale", PAPER_UPSCALE)
    elif "csv" in table:
        text = f"CSV file {_text(source or table['csv'])}"
        upscale = table.get("upscale", 1.0)
    else:
        sizes = table.get("sizes_mm")
        count = f"{len(sizes)} " if isinstance(sizes, list) else ""
        text = f"{count}sieve sizes given in the config (sizes_mm, percent_passing)"
        upscale = table.get("upscale", 1.0)
    text += f", up-scaling factor {_value(_num(upscale))}"
    cuts = [
        f"{k} = {_value(_num(table[k]))} mm" for k in ("d_min_mm", "d_max_mm") if table.get(k) is not None
    ]
    return text + (
        "; cut at " + ", ".join(cuts) + " (of the up-scaled curve)" if cuts else "; no d_min/d_max cut"
    )


def _state(result: dict, config: dict, state: KnownState | None, folder: Path) -> str:
    """n_lab, Dr and the mode."""
    n_lab = state.n_lab if state is not None else _num(result.get("n_lab"))
    dr = state.relative_density if state is not None else _config_dr(n_lab, config)
    if state is not None:
        mode = state.mode or "unknown"
    elif (folder.parent / "params.json").is_file():  # a sweep case not found in a state folder above it
        mode = "unknown (a sweep case: export it by its state folder)"
    else:
        dens = (config.get("config") or {}).get("density")
        mode = dens.get("mode", "paper") if isinstance(dens, dict) else "paper"
        mode = _text(mode) + " (a criterion folder of its own)"
    dr_text = "unknown" if dr is None else f"{dr:.4f}"
    return f"n_lab = {_value(_num(n_lab))}, relative density Dr = {dr_text}; mode {mode}"


def _config_dr(n_lab: float | None, config: dict) -> float | None:
    """Dr of ``n_lab`` between the laboratory extremes the config's ``[density]`` gives, if it does."""
    from poro2d.errors import InputError
    from poro2d.porosity import relative_density

    dens = (config.get("config") or {}).get("density")
    hi, lo = (_num(dens.get(k)) for k in ("n_max", "n_min")) if isinstance(dens, dict) else (None, None)
    if n_lab is None or hi is None or lo is None:
        return None
    try:
        return float(relative_density(n_lab, hi, lo))
    except InputError:
        return None


def _porosities(result: dict) -> str:
    n2d = _num(result.get("final_porosity"))
    box = _num(result.get("box_porosity"))
    inner = _num(result.get("interior_porosity"))
    sd = _num(result.get("interior_porosity_std"))
    text = f"accepted n2D = {_value(n2d)}, box porosity n' = {_value(box, '.6g')}"
    if inner is None:
        return text + "; interior porosity unknown (not measured)"
    return text + f"; interior porosity = {inner:.6g}" + (f" +- {sd:.4g}" if sd is not None else "")


def _run(result: dict, config: dict, state: KnownState | None) -> str:
    seed = state.seed if state is not None else result.get("seed", (config.get("run") or {}).get("seed"))
    prov = result.get("provenance") or config.get("provenance") or {}
    version = prov.get("poro2d_version") if isinstance(prov, dict) else None
    when = prov.get("created_utc") if isinstance(prov, dict) else None
    text = f"seed {seed if isinstance(seed, int) and not isinstance(seed, bool) else 'unknown'}; "
    text += f"criterion run by poro2d {_text(version) if version else 'unknown'}"
    return text + (f" ({_text(when)})" if when else "")


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


def _num(value) -> float | None:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        return None
    return float(value)


def _value(v: float | None, fmt: str = "") -> str:
    if v is None:
        return "unknown"
    return format(v, fmt) if fmt else repr(v)


def _text(value) -> str:
    """One line of text (a path or a name with a line break would end the comment)."""
    return " ".join(str(value).split())
