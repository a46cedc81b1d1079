"""What an engine reports once a specimen has come to rest: the typed result of the agreement runs."""

from __future__ import annotations

from dataclasses import dataclass

from poro2d.typed_result import TypedResult


@dataclass(eq=False, kw_only=True)
class SettledRun(TypedResult):
    """One engine's run of an exported specimen to rest (poro2d, LAMMPS or YADE).

    Wall forces per metre: the plate's ``f_top_n_per_m``, the floor's ``f_bottom_n_per_m``
    and the side walls' upward friction; ``steps`` cycled, whether the stop criterion was
    met (``converged``) and the wall time in ``seconds``. The other keys are those an
    engine measures (each is left out when it is None): poro2d and LAMMPS the mean contact
    force, coordination number, contacts and the largest unbalanced-force ratio
    (``max_ratio``), LAMMPS its version; YADE its mean ``unbalanced_force``, its version
    and the ``workdir`` it ran in.
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
    unbalanced_force: float | None = None
    steps: int
    converged: bool
    max_ratio: float | None = None
    seconds: float
    lammps_version: str | None = None
    yade_version: str | None = None
    workdir: str | None = None


__all__ = ["SettledRun"]
