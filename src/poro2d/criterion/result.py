"""The criterion's result (``result.json`` of a criterion run) and replicate seeds' runs, typed."""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from poro2d.measure.specimen_porosity import SpecimenPorosity
from poro2d.typed_result import NOT_IN_FILE, TypedResult


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
        "plate_contact_fraction", "preparation_note",
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
    # a wide grading's equilibrium test and why (poro2d.specimen.compaction.preparation_note)
    preparation_note: str | None = None


@dataclass(eq=False)
class ReplicatesResult(TypedResult):
    """Replicate seeds' criterion runs: one row per seed, in seed order (``rows``).

    A row says whether the seed's criterion accepted a porosity (``seed``, ``final_porosity``,
    ``converged``, ``trials``, ``message``, ``folder`` under ``out``, ``time_s``); the rows
    are what ``poro2d paper`` writes as ``replicate_specimens`` in ``results.json``.
    ``out`` (not a key) is the folder holding the seeds' folders.
    """

    rows: list[dict[str, Any]]
    out: Path | None = field(default=None, kw_only=True, metadata=NOT_IN_FILE)

    @property
    def specimens(self) -> dict[str, Path]:
        """The accepted specimens by label (``seed1``, ...): each seed's ``specimen.npz``."""
        return {f"seed{r['seed']}": Path(self.out) / r["folder"] / "specimen.npz" for r in self.rows
                if r["converged"]}  # fmt: skip


@dataclass(eq=False)
class SpecimenStateResult(TypedResult):
    """The accepted specimen's homogeneity and stress state by band (``specimen_state.json``)."""

    bands: list[dict[str, Any]]
    porosity_definition: str
    porosity_mean: float
    porosity_sd: float
    porosity_range: float
    k0_mean: float | None
    k0_sd: float | None
    sigma_v_bottom_over_geostatic: float | None
    stress_sign: str
    trial_porosity: float


#: the figures a criterion run may leave at the top of its folder, by name
CRITERION_FIGURES = (
    "fig5_forces_initial_trial.png", "fig6_forces_after_plate.png", "fig7_forces_accepted.png",
    "specimen_state.png", "local_porosity.png",
)  # fmt: skip


@dataclass
class CriterionOutputs:
    """A criterion run's results as the paper report shows them, each through its class.

    ``result``: ``result.json``; ``state`` and ``porosity``: the accepted specimen's
    ``specimen_state.json`` and ``specimen_porosity.json`` (None when the run accepted none);
    ``figures``: the figures the run wrote (name in :data:`CRITERION_FIGURES` -> path).
    """

    result: CriterionResult
    state: SpecimenStateResult | None = None
    porosity: SpecimenPorosity | None = None
    figures: dict[str, Path] = field(default_factory=dict)

    @classmethod
    def read(cls, folder: str | Path, result: CriterionResult | None = None) -> CriterionOutputs:
        """A finished criterion folder read back (``result``: the run's result, when in hand)."""
        folder = Path(folder)
        if result is None:
            result = CriterionResult.from_dict(_json(folder / "result.json"))
        state = _json(folder / "specimen_state.json")
        porosity = _json(folder / "specimen_porosity.json")
        return cls(
            result,
            None if state is None else SpecimenStateResult.from_dict(state),
            None if porosity is None else SpecimenPorosity.from_dict(porosity),
            {name: folder / name for name in CRITERION_FIGURES if (folder / name).is_file()},
        )


def _json(path: Path) -> dict | None:
    return json.loads(path.read_text()) if path.is_file() else None


__all__ = [
    "CRITERION_FIGURES",
    "CriterionOutputs",
    "CriterionResult",
    "ReplicatesResult",
    "SpecimenStateResult",
]
