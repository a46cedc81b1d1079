"""What the export's provenance lines read from a criterion folder: its records as values.

:func:`poro2d.interop.origin.origin_lines` reads ``result.json``, ``config.json`` and
``soil.json`` once each and hands the object to a ``from_json`` here; a value of another shape
reads as not said, and the line says "unknown". Text a line quotes (a preset's name, a version)
is kept as written.
"""

from __future__ import annotations

from dataclasses import dataclass

from poro2d.grading import PAPER_UPSCALE
from poro2d.json_fields import finite_number, int_at, number_at, value_at


def _said(value) -> str | None:
    """A value a line quotes, as text; None when it is empty or missing (falsy)."""
    return str(value) if value else None


def _member(value, key: str):
    """``value[key]`` when ``value`` is a JSON object holding it, else None (a step into a record of
    another shape finds nothing)."""
    return value.get(key) if isinstance(value, dict) else None


@dataclass(frozen=True)
class RunStamp:
    """Who ran a criterion, and when: its ``provenance``'s version and time (None: not said)."""

    given: bool  # the record has a provenance at all
    version: str | None
    created_utc: str | None

    @classmethod
    def from_json(cls, value) -> RunStamp:
        """``value``: the record's ``provenance``, as it is."""
        return cls(bool(value), _said(_member(value, "poro2d_version")), _said(_member(value, "created_utc")))


@dataclass(frozen=True)
class RunFacts:
    """What a criterion's record says of its run: the preparation friction (when it names its
    ``specimen``), the seed (when it names one) and who ran it (``stamp``)."""

    names_specimen: bool = False
    friction_prep: float | None = None
    names_seed: bool = False
    seed: int | None = None
    stamp: RunStamp = RunStamp(False, None, None)

    @classmethod
    def from_json(cls, run, provenance) -> RunFacts:
        """``run``: the object naming ``specimen`` and ``seed`` (``result.json`` itself, ``config.json``'s
        ``run``), as it is; ``provenance``: the record's own."""
        return cls(
            bool(_member(run, "specimen")),
            number_at(run, "specimen", "friction_prep"),
            isinstance(run, dict) and "seed" in run,
            int_at(run, "seed"),
            RunStamp.from_json(provenance),
        )

    def or_else(self, other: RunFacts) -> RunFacts:
        """Each fact as this record says it, or as ``other`` does where this one is silent."""
        specimen = self if self.names_specimen else other
        seed = self if self.names_seed else other
        stamp = self.stamp if self.stamp.given else other.stamp
        return RunFacts(specimen.names_specimen, specimen.friction_prep, seed.names_seed, seed.seed, stamp)


@dataclass(frozen=True)
class ResultFacts:
    """A criterion's ``result.json``: the state it ran, the porosities of its accepted specimen
    and what it says of its run."""

    n_lab: float | None = None
    final_porosity: float | None = None
    box_porosity: float | None = None
    interior_porosity: float | None = None
    interior_porosity_std: float | None = None
    run: RunFacts = RunFacts()

    @classmethod
    def from_json(cls, data: dict) -> ResultFacts:
        numbers = ("n_lab", "final_porosity", "box_porosity", "interior_porosity", "interior_porosity_std")
        return cls(*(number_at(data, k) for k in numbers), RunFacts.from_json(data, data.get("provenance")))


@dataclass(frozen=True)
class GradingFacts:
    """The grading a criterion ran, as its config gives it: a ``preset`` or a ``csv`` file by
    ``name`` (the run's ``source``, when it records one, names the file it read), or ``sizes``
    given in the config (``sizes`` of them, None when not a list); the up-scaling factor and the
    cuts (``d_min_mm``, ``d_max_mm``) that the table gives. ``kind`` "unknown": no config."""

    kind: str
    name: str = ""
    source: str | None = None
    sizes: int | None = None
    upscale: float | None = None
    cuts: tuple[tuple[str, float | None], ...] = ()

    @classmethod
    def from_json(cls, data: dict) -> GradingFacts:
        if "config" not in data:
            return cls("unknown")
        table = _member(data.get("config"), "grading")
        table = table if isinstance(table, dict) and table else {"preset": "paper"}  # the criterion's default
        source = _said(_member(_member(data.get("run"), "grading"), "source"))
        cuts = tuple((k, number_at(table, k)) for k in ("d_min_mm", "d_max_mm") if table.get(k) is not None)
        if "preset" in table:
            kind, name, upscale = "preset", str(table["preset"]), table.get("upscale", PAPER_UPSCALE)
        elif "csv" in table:
            kind, name, upscale = "csv", str(table["csv"]), table.get("upscale", 1.0)
        else:
            kind, name, upscale = "sizes", "", table.get("upscale", 1.0)
        sizes = table.get("sizes_mm")
        return cls(
            kind, name, source, len(sizes) if isinstance(sizes, list) else None,
            finite_number(upscale), cuts,
        )  # fmt: skip


@dataclass(frozen=True)
class ConfigFacts:
    """A criterion's ``config.json``: the grading, the ``[density]`` table's mode and laboratory
    ``extremes`` (n_max, n_min; both fields None: no such table) and what its ``run`` says of the run."""

    grading: GradingFacts = GradingFacts("unknown")
    density_mode: str | None = None
    extremes: tuple[float | None, float | None] | None = None
    run: RunFacts = RunFacts()

    @classmethod
    def from_json(cls, data: dict) -> ConfigFacts:
        density = _member(data.get("config"), "density")
        table = isinstance(density, dict)
        return cls(
            grading=GradingFacts.from_json(data),
            density_mode=str(density.get("mode", "paper")) if table else None,
            extremes=(number_at(density, "n_max"), number_at(density, "n_min")) if table else None,
            run=RunFacts.from_json(data.get("run"), data.get("provenance")),
        )


@dataclass(frozen=True)
class SoilFacts:
    """``soil.json``, written by ``poro2d sand`` beside each specimen it names: the soil (``name``
    and ``reference`` as written; ``named`` False when ``soil`` is not an object), the mode, the
    laboratory state and the seed."""

    named: bool
    name: str
    reference: str | None
    mode: str | None
    n_lab: float | None
    relative_density: float | None
    seed: int | None

    @classmethod
    def from_json(cls, data: dict) -> SoilFacts:
        soil = data.get("soil")
        return cls(
            named=isinstance(soil, dict),
            name=str(_member(soil, "name")),
            reference=_said(_member(soil, "reference")),
            mode=_said(value_at(data, "mode")),
            n_lab=number_at(data, "state", "n_lab"),
            relative_density=number_at(data, "state", "relative_density"),
            seed=int_at(data, "seed"),
        )
