"""The criterion's result (``result.json`` of a criterion run), as a typed record."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from poro2d.typed_result import TypedResult


@dataclass(eq=False)
class CriterionResult(TypedResult):
    """What a run of Fig. 3 found, with every trial (``iterations``: one dict per trial row).

    ``final_porosity`` is the accepted n2D, None when the run did not converge (``message``
    says why; ``failed_trial`` is the trial that was refused, if one was). Beside it, for an
    accepted specimen: ``box_porosity``, the paper's n' of the accepted state (W x plate
    height, the gap under the plate included), and ``interior_porosity`` with its spread
    over the measurement circles, the packing's own porosity (docs/porosity.md says which to
    use), with the surface under the plate (mean gap in d50, share of the width in contact).
    """

    OPTIONAL = (
        "box_porosity", "interior_porosity", "interior_porosity_std", "surface_gap_mean_d50",
        "plate_contact_fraction",
    )  # fmt: skip

    final_porosity: float | None
    converged: bool
    message: str
    n_lab: float
    initial_trial_porosity: float
    initial_from: str
    iterations: list[dict[str, Any]]
    seed: int
    settings: dict[str, Any]
    specimen: dict[str, Any]
    local_damping_note: str
    provenance: dict[str, Any]
    failed_trial: int | None = None
    time_total_s: float | None = None
    box_porosity: float | None = None
    interior_porosity: float | None = None
    interior_porosity_std: float | None = None
    surface_gap_mean_d50: float | None = None
    plate_contact_fraction: float | None = None


__all__ = ["CriterionResult"]
