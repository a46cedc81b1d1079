"""An exported specimen run to rest in one engine: its case (:class:`RestCase`), the last line
the exported scripts print (:func:`result_numbers`) and what the engine reports (:class:`SettledRun`)."""

from __future__ import annotations

from dataclasses import dataclass

from poro2d.errors import Integer, Real, check_fields
from poro2d.interop.specimen_data import SpecimenData
from poro2d.typed_result import TypedResult

#: the tag of the line the exported LAMMPS and YADE scripts print last
RESULT_TAG = "poro2d-result"
#: what a run to rest may be asked for
REST_RANGES = {"ratio": Real(0.0, 1.0, lo_open=True, hi_open=True), "max_steps": Integer(1)}


@dataclass(frozen=True)
class RestCase:
    """A specimen run to rest from its exported state (disks at rest, no contact history), checked
    when made: cycled until the engine's unbalanced-force ``ratio`` is met, at most ``max_steps``."""

    spec: SpecimenData
    ratio: float = 1e-5
    max_steps: int = 2_000_000

    def __post_init__(self) -> None:
        check_fields(self, REST_RANGES)


def result_numbers(output: str, error: type[Exception], source: str) -> dict[str, float]:
    """The numbers of the last ``poro2d-result key value ...`` line of ``output``, by key;
    ``error`` naming ``source`` when it has none."""
    lines = [ln for ln in output.splitlines() if ln.startswith(RESULT_TAG + " ")]
    if not lines:
        raise error(f"no '{RESULT_TAG}' line in {source}")
    words = lines[-1].split()[1:]
    return {words[i]: float(words[i + 1]) for i in range(0, len(words) - 1, 2)}


@dataclass(eq=False, kw_only=True)
class SettledRun(TypedResult):
    """One engine's run of an exported specimen to rest (poro2d, LAMMPS or YADE).

    Wall forces per metre, ``steps`` cycled, whether the stop criterion was met and the wall
    time; the keys only some engines measure are left out when None: poro2d and LAMMPS the
    contact forces, coordination and largest unbalanced-force ratio, YADE its own mean
    ``unbalanced_force`` and the ``workdir`` it ran in, each code its version.
    """

    OPTIONAL = (
        "mean_contact_force_n", "coordination_number", "contacts", "unbalanced_force", "max_ratio",
        "lammps_version", "yade_version", "workdir",
    )  # fmt: skip

    f_top_n_per_m: float
    f_bottom_n_per_m: float
    side_friction_up_n_per_m: float
    mean_contact_force_n: float | None = None
    coordination_number: float | None = None
    contacts: int | None = None
    unbalanced_force: float | None = None  # YADE's utils.unbalancedForce(): its own measure of rest
    steps: int
    converged: bool
    max_ratio: float | None = None
    seconds: float
    lammps_version: str | None = None
    yade_version: str | None = None
    workdir: str | None = None


__all__ = ["RestCase", "SettledRun", "result_numbers"]
