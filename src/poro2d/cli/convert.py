"""``poro2d convert``: the 3D-to-2D porosity conversions of the paper (Eqs. 1-12).

``poro2d convert NLAB... [--n-max X --n-min Y] [--dry-density RHO_D --solid-density RHO_S]
[--nu-reading printed|solid_fraction] [--lattice-exact] [--format table|json|csv]``

``poro2d convert --e E [--e E ...] | --dr DR [--dr DR ...] | NLAB... | --dry-density RHO_D
--solid-density RHO_S, [--e-max X --e-min Y | --n-max X --n-min Y]``: the laboratory state in
geotechnical terms (:mod:`poro2d.lab_state`), selected by any of ``--e``, ``--dr``,
``--e-max``, ``--e-min``. The state must lie within the extremes; the command prints the state
it understood (e, n, D_r) before each table, and its json and csv carry e and D_r.

Output formats of ``convert``:

* ``table`` (default): one rich table per laboratory porosity, one row per method (id,
  name, equation, n2D, flags; skipped methods show the reason), warnings and notes below.
* ``json``: for one NLAB, one object whose keys are the method ids with the 2D porosity as
  value (``null`` where skipped or undefined), plus ``n_lab``, ``inputs``, ``relative_density``,
  ``flags``, ``skipped``, ``warnings``, ``notes``, ``details``, ``methods`` and
  ``poro2d_version``. For several NLAB values, a JSON list of such objects, in input order.
* ``csv``: a header row, then one row per (n_lab, method).

Given in geotechnical terms, the json objects also hold ``e`` and ``lab_state``
(:meth:`poro2d.lab_state.LabState.to_dict`), ``relative_density`` is the state's and
``inputs`` holds ``e_max``/``e_min`` when given; the csv has three more columns, ``e``,
``relative_density`` and ``given``. Without those options every output is as before.
"""

from __future__ import annotations

import csv
import enum
import io
import json
import re
from typing import Annotated

import click
import typer
from typer.core import TyperCommand

from poro2d import __version__
from poro2d import porosity as P
from poro2d.cli import options as opt
from poro2d.errors import InputError, check_range
from poro2d.lab_state import LabState, lab_state

_PARAM_ALLOWED = "a number in [0, 1)"


class OutputFormat(enum.StrEnum):
    table = "table"
    json = "json"
    csv = "csv"


class NuReading(enum.StrEnum):
    printed = "printed"
    solid_fraction = "solid_fraction"


def _parse_nlab(tokens: list[str]) -> list[float]:
    """Parse NLAB tokens ourselves so that '-0.1' and 'nan' reach our range check."""
    values = []
    for tok in tokens:
        try:
            v = float(tok)
        except ValueError:
            if tok.startswith("-"):
                raise click.NoSuchOption(tok) from None
            raise InputError("NLAB", tok, _PARAM_ALLOWED) from None
        if not (0.0 <= v < 1.0):  # also catches NaN
            raise InputError("NLAB", v, "[0, 1)")
        values.append(v)
    return values


def _lab_porosities(
    nlab: list[str] | None, dry_density: float | None, solid_density: float | None
) -> tuple[list[float], dict]:
    extra: dict = {}
    have_density = dry_density is not None or solid_density is not None
    if have_density:
        if dry_density is None:
            raise InputError("--dry-density", None, "(0, solid density] kg/m3, with --solid-density")
        if solid_density is None:
            raise InputError("--solid-density", None, "(0, inf) kg/m3, with --dry-density")
        if nlab:
            raise InputError(
                "NLAB",
                " ".join(nlab),
                "no NLAB values when --dry-density/--solid-density are given",
            )
        try:  # the state's checks: the densities of solids, a dry density of a physical void ratio
            n = lab_state(dry_density=dry_density, solid_density=solid_density).n_lab
        except InputError as exc:
            raise _cli_error(exc) from None
        extra = {"dry_density_kg_m3": dry_density, "solid_density_kg_m3": solid_density}
        return [n], extra
    if not nlab:
        raise InputError(
            "NLAB",
            None,
            "at least one laboratory porosity in [0, 1), or --dry-density with --solid-density",
        )
    return _parse_nlab(nlab), extra


#: the command's names of :func:`poro2d.lab_state.lab_state`'s keywords
_CLI_NAMES = {
    "n": "NLAB",
    **{
        k: "--" + k.replace("_", "-")
        for k in ("e", "dr", "dry_density", "solid_density", "e_max", "e_min", "n_max", "n_min")
    },
}
_CLI_WORDS = re.compile(r"\b(dry_density|solid_density|e_max|e_min|n_max|n_min)\b")
_STATE_KINDS = (
    "NLAB porosities, --e void ratios, --dr relative densities, or --dry-density with --solid-density"
)


def _cli_error(exc: InputError) -> InputError:
    """``exc`` of :mod:`poro2d.lab_state` in the command's words (``e_max`` -> ``--e-max``)."""

    def words(text: str) -> str:
        return _CLI_WORDS.sub(lambda m: _CLI_NAMES[m.group(1)], text)

    return InputError(
        _CLI_NAMES.get(exc.parameter, exc.parameter), exc.value, words(exc.allowed), words(exc.hint)
    )


def _is_geotechnical(e: list[float] | None, dr: list[float] | None, e_max, e_min) -> bool:
    """The geotechnical description is asked for by any of --e, --dr, --e-max, --e-min."""
    return bool(e) or bool(dr) or e_max is not None or e_min is not None


def _lab_states(
    nlab: list[str] | None,
    e: list[float] | None,
    dr: list[float] | None,
    dry_density: float | None,
    solid_density: float | None,
    extremes: dict,
) -> tuple[list[LabState], dict]:
    """The laboratory states of the geotechnical description, one kind of state only."""
    kinds = {
        "NLAB": " ".join(nlab) if nlab else None,
        "--e": " ".join(f"{v:g}" for v in e) if e else None,
        "--dr": " ".join(f"{v:g}" for v in dr) if dr else None,
        "--dry-density": None if dry_density is None else f"{dry_density:g}",
    }
    given = [k for k, v in kinds.items() if v is not None]
    if not given:
        raise InputError("NLAB", None, f"a laboratory state: {_STATE_KINDS}")
    if len(given) > 1:
        first, second = given[:2]
        raise InputError(
            second,
            kinds[second],
            f"no {second} when {first} is given",
            f"give the state once: {_STATE_KINDS}",
        )
    kind = given[0]
    if kind == "NLAB":
        states = [dict(n=v) for v in _parse_nlab(nlab)]
    elif kind == "--e":
        states = [dict(e=v) for v in e]
    elif kind == "--dr":
        states = [dict(dr=v) for v in dr]
    else:
        states = [dict(dry_density=dry_density)]
    try:
        out = [lab_state(**st, solid_density=solid_density, **extremes) for st in states]
    except InputError as exc:
        raise _cli_error(exc) from None
    extra: dict = {}
    if dry_density is not None:
        extra = {"dry_density_kg_m3": dry_density, "solid_density_kg_m3": solid_density}
    for key in ("e_max", "e_min"):
        if extremes[key] is not None:
            extra[key] = extremes[key]
    return out, extra


def _state_line(state: LabState, extra: dict) -> str:
    """The state the command understood, in one line: what was given, then e, n and D_r."""
    given = {"e": f"e = {state.e:g}", "n": f"n = {state.n_lab:g}"}.get(state.given)
    if state.given == "Dr":
        given = f"D_r = {state.relative_density:g}"
    elif given is None:
        rho_d, rho_s = extra["dry_density_kg_m3"], extra["solid_density_kg_m3"]
        given = f"rho_d = {rho_d:g}, rho_s = {rho_s:g} kg/m3"
    line = f"lab state (given as {given}): e = {state.e:.4f}, n_lab = {state.n_lab:.4f}"
    if state.relative_density is None:
        return line + ", D_r: no extremes given"
    e_max, e_min = float(P.void_ratio(state.n_max)), float(P.void_ratio(state.n_min))
    return (
        line + f", D_r = {state.relative_density:.3f}; "
        f"e_max = {e_max:.4g}, e_min = {e_min:.4g} (n_max = {state.n_max:.4f}, n_min = {state.n_min:.4f})"
    )


def _fmt(v: float | None, digits: int = 4) -> str:
    return "-" if v is None else f"{v:.{digits}f}"


#: the help texts the laboratory state's options share
_REPEAT = " (repeat for several states)."
_EXTREME = "Laboratory {} void ratio {} ({} state), with {}."
_N_EXTREME = "Laboratory {} porosity n_lab,{} ({} state)."


def _option(name: str, *help: str):
    """A ``convert`` option ``name``, its help the texts given one after the other."""
    return typer.Option(name, help="".join(help))


def conversion_to_json(
    conv: P.Conversion, extra_inputs: dict | None = None, state: LabState | None = None
) -> dict:
    """The JSON object of one laboratory porosity (method ids as keys, see module doc).

    A dict as the file holds it: its first keys are the methods a conversion ran, which vary.

    With ``state`` (the :class:`~poro2d.lab_state.LabState` that ``conv`` converted) the
    object also holds ``e`` and ``lab_state``, and its ``relative_density`` is the state's.
    """
    obj: dict = {mid: r.value for mid, r in conv.results.items()}
    dr = None
    if state is not None:
        dr = state.relative_density
    elif conv.n_max is not None and conv.n_min is not None:
        dr = float(P.relative_density(conv.n_lab, conv.n_max, conv.n_min))
    obj.update(
        {
            "n_lab": conv.n_lab,
            **({} if state is None else {"e": state.e}),
            "inputs": {
                "n_lab": conv.n_lab,
                "n_max": conv.n_max,
                "n_min": conv.n_min,
                **conv.options,
                **(extra_inputs or {}),
            },
            "relative_density": dr,
            **({} if state is None else {"lab_state": state.to_dict()}),
            "flags": {mid: r.flags for mid, r in conv.results.items()},
            "skipped": {mid: r.skipped for mid, r in conv.results.items() if r.skipped},
            "warnings": conv.warnings,
            "notes": conv.notes,
            "details": {mid: r.details for mid, r in conv.results.items() if r.details},
            "methods": {
                mid: {"name": r.name, "equation": r.equation, "source": r.source}
                for mid, r in conv.results.items()
            },
            "poro2d_version": __version__,
        }
    )
    return obj


def _print_table(conv: P.Conversion, extra_inputs: dict, state: LabState | None = None) -> None:
    from poro2d.console import OutputConsole, Table

    console = OutputConsole(highlight=False)  # files and pipes: the whole table, not 80 columns of it
    if state is not None:
        console.print(_state_line(state, extra_inputs))
    title = f"n_lab = {conv.n_lab:.4f}"
    if state is not None:
        title += f", e = {state.e:.4f}"
    if state is None and extra_inputs:  # a state given in geotechnical terms: its line says it all
        title += (
            f" (from rho_d = {extra_inputs['dry_density_kg_m3']:g}, "
            f"rho_s = {extra_inputs['solid_density_kg_m3']:g} kg/m3)"
        )
    if conv.n_max is not None and conv.n_min is not None:
        dr = float(P.relative_density(conv.n_lab, conv.n_max, conv.n_min))
        if state is not None and state.relative_density is not None:
            dr = state.relative_density
        title += f", n_max = {conv.n_max:g}, n_min = {conv.n_min:g}, D_r = {dr:.3f}"
    elif conv.n_min is not None:
        title += f", n_min = {conv.n_min:g}"
    table = Table(title=title, title_justify="left")
    table.add_column("id", no_wrap=True)
    table.add_column("name")
    table.add_column("equation", no_wrap=True)
    table.add_column("n2D", justify="right", no_wrap=True)
    table.add_column("flags")
    for r in conv.results.values():
        if r.value is None:
            n2d = "[dim]skipped[/]"
            flags = ", ".join(r.flags + [f"skipped: {r.skipped}"])
        else:
            n2d = f"[red]{r.value:.4f}[/]" if r.value < 0 else f"{r.value:.4f}"
            flags = ", ".join(r.flags) + other_reading(r)
        table.add_row(r.id, r.name, r.equation, n2d, flags)
    console.print(table)
    for w in conv.warnings:
        console.print(f"[yellow]warning:[/] {w}")
    for note in conv.notes:
        console.print(f"note: {note}")


def other_reading(result: P.MethodResult) -> str:
    """`` (solid_fraction: 0.1094)``: Eq. 2 under the reading of nu not chosen, beside the chosen
    one's flag, since the paper does not settle which one it plotted (docs/conversions.md)."""
    other = result.details.get("other_reading")
    return f" ({other['nu_reading']}: {other['n2d']:.4f})" if other else ""


_CSV_HEADER = ["n_lab", "n_max", "n_min", "method", "name", "equation", "n2d", "flags", "skipped"]
_CSV_HEADER += ["nu_reading", "lattice_exact"]
#: the columns a state given in geotechnical terms adds to the csv
_CSV_STATE_HEADER = ["e", "relative_density", "given"]


def _csv_rows(conv: P.Conversion, state: LabState | None = None) -> list[list]:
    """A row per method (``_CSV_HEADER``), with ``_CSV_STATE_HEADER``'s columns for a ``state``."""
    more = []
    if state is not None:
        more = [repr(state.e), _repr(state.relative_density), state.given]
    options = [conv.options["nu_reading"], str(conv.options["lattice_exact"]).lower()]
    head = [repr(conv.n_lab), _repr(conv.n_max), _repr(conv.n_min)]
    return [
        [*head, r.id, r.name, r.equation, _repr(r.value), ";".join(r.flags), r.skipped or "", *options, *more]
        for r in conv.results.values()
    ]


def _repr(v: float | None) -> str:
    """A number as the csv writes it, exactly (``repr``); empty for None."""
    return "" if v is None else repr(v)


def convert(
    nlab: Annotated[
        list[str] | None,
        typer.Argument(
            metavar="NLAB...",
            help="Laboratory (3D) porosities in [0, 1). Several values are allowed.",
            show_default=False,
        ),
    ] = None,
    e: Annotated[list[float] | None, _option("--e", "Void ratio e of the laboratory state", _REPEAT)] = None,
    dr: Annotated[
        list[float] | None,
        _option(
            "--dr", "Relative density Dr = (e_max - e)/(e_max - e_min) in [0, 1], with the extremes", _REPEAT
        ),
    ] = None,
    e_max: Annotated[
        float | None, _option("--e-max", _EXTREME.format("maximum", "e_max", "loosest", "--e-min"))
    ] = None,
    e_min: Annotated[
        float | None, _option("--e-min", _EXTREME.format("minimum", "e_min", "densest", "--e-max"))
    ] = None,
    n_max: Annotated[float | None, _option("--n-max", _N_EXTREME.format("maximum", "max", "loosest"))] = None,
    n_min: Annotated[float | None, _option("--n-min", _N_EXTREME.format("minimum", "min", "densest"))] = None,
    dry_density: Annotated[
        float | None, _option("--dry-density", "Dry density rho_d in kg/m3; gives n_lab = 1 - rho_d/rho_s.")
    ] = None,
    solid_density: Annotated[
        float | None, _option("--solid-density", "Density of the solids rho_s in kg/m3 (e.g. 2650).")
    ] = None,
    nu_reading: Annotated[
        NuReading,
        opt.nu_reading(help="Eq. 2: nu = n_min/n_FCC as printed, or (1-n_min)/(1-n_FCC) (solid fraction)."),
    ] = NuReading.printed,
    lattice_exact: Annotated[
        bool,
        opt.lattice_exact(help="Eqs. 7-11: 1-pi/4 and 1-pi/(2 sqrt 3) instead of the printed 0.2146/0.0931."),
    ] = False,
    fmt: Annotated[
        OutputFormat, _option("--format", "Output format: table, json or csv.")
    ] = OutputFormat.table,
) -> None:
    """Convert laboratory porosities to 2D with every method of the paper (Eqs. 1-12).

    The laboratory state is NLAB porosities, --dry-density with --solid-density, or, in
    geotechnical terms, --e void ratios or --dr relative densities with the extremes
    --e-max/--e-min (or --n-max/--n-min).
    """
    if _is_geotechnical(e, dr, e_max, e_min):
        extremes = {"e_max": e_max, "e_min": e_min, "n_max": n_max, "n_min": n_min}
        states, extra = _lab_states(nlab, e, dr, dry_density, solid_density, extremes)
        _write_conversions(states, extra, nu_reading, lattice_exact, fmt)
        return
    values, extra = _lab_porosities(nlab, dry_density, solid_density)
    if n_max is not None:
        check_range("--n-max", n_max, 0.0, 1.0, hi_open=True)
    if n_min is not None:
        check_range("--n-min", n_min, 0.0, 1.0, hi_open=True)
    if n_max is not None and n_min is not None and not n_max > n_min:
        raise InputError("--n-max", n_max, f"greater than --n-min = {n_min}")
    convs = [
        P.convert_all(v, n_max, n_min, nu_reading=nu_reading.value, lattice_exact=lattice_exact)
        for v in values
    ]
    _write(convs, [None] * len(convs), extra, fmt)


def _write_conversions(
    states: list[LabState], extra: dict, nu_reading: NuReading, lattice_exact: bool, fmt: OutputFormat
) -> None:
    """Every conversion of each laboratory state, in the format asked for, with e and D_r."""
    convs = [
        P.convert_all(s.n_lab, s.n_max, s.n_min, nu_reading=nu_reading.value, lattice_exact=lattice_exact)
        for s in states
    ]
    _write(convs, states, extra, fmt)


def _write(convs: list[P.Conversion], states: list, extra: dict, fmt: OutputFormat) -> None:
    """The conversions in the format asked for; ``states`` their laboratory states, or Nones when
    the state was given as porosities (then without e, D_r and the state's csv columns)."""
    pairs = list(zip(convs, states, strict=True))
    if fmt is OutputFormat.json:
        objs = [conversion_to_json(c, extra, state=s) for c, s in pairs]
        typer.echo(json.dumps(objs[0] if len(objs) == 1 else objs, indent=2, allow_nan=False))
    elif fmt is OutputFormat.csv:
        buf = io.StringIO()
        w = csv.writer(buf, lineterminator="\n")
        w.writerow(_CSV_HEADER + (_CSV_STATE_HEADER if states[0] is not None else []))
        for c, s in pairs:
            w.writerows(_csv_rows(c, s))
        typer.echo(buf.getvalue(), nl=False)
    else:
        for c, s in pairs:
            _print_table(c, extra, s)


try:  # recent typer ships its own copy of click; its errors are not click's
    from typer._click.exceptions import ClickException as _TyperClickException
except ImportError:  # pragma: no cover - typer using the click package directly
    _TyperClickException = None


class OneLineUsageCommand(TyperCommand):
    """Turn usage errors of typer's bundled click into ``click.UsageError``.

    The root ``main()`` prints ``click`` exceptions as one line with their exit code (2);
    a usage error raised by typer's own copy of click would otherwise escape as a
    traceback.
    """

    def make_context(self, info_name, args, parent=None, **extra):
        try:
            return super().make_context(info_name, args, parent=parent, **extra)
        except Exception as exc:
            if (
                _TyperClickException is not None
                and isinstance(exc, _TyperClickException)
                and not isinstance(exc, click.ClickException)
            ):
                raise click.UsageError(f"{info_name}: {exc.format_message()}") from None
            raise


def register(app: typer.Typer) -> None:
    """Attach ``convert`` to the root app."""
    app.command(
        "convert",
        cls=OneLineUsageCommand,
        context_settings={"ignore_unknown_options": True},
    )(convert)
