"""The criterion's result (``result.json`` of a criterion run) and replicate seeds' runs, typed."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar

from poro2d.criterion.settings import CriterionSettings
from poro2d.criterion.trial import Trial
from poro2d.io_utils import Provenance
from poro2d.measure.specimen_porosity import SpecimenPorosity
from poro2d.measure.specimen_state import SpecimenStateResult
from poro2d.specimen.compaction import SpecimenSpec
from poro2d.specimen.specimen_set import SpecimenSet
from poro2d.store import Store
from poro2d.typed_result import NOT_IN_FILE, TypedResult


@dataclass(eq=False)
class CriterionResult(TypedResult):
    """What a run of Fig. 3 found, with every trial (``iterations``: one ``Trial`` each).

    ``final_porosity`` is the accepted n2D, None when the run did not converge (``message``
    says why; ``failed_trial`` is the trial that was refused, if one was). Beside it, for an
    accepted specimen: ``box_porosity``, the paper's n' of the accepted state (W x plate
    height, the gap under the plate included), and ``interior_porosity`` with its spread
    over the measurement circles, the packing's own porosity (docs/porosity.md says which to
    use), with the surface under the plate (mean gap in d50, share of the width in contact),
    and, for a specimen whose light disks' inertial masses were raised in its quasi-static
    stages, the time step they shared (``mass_scaling_dt_s``) and how many (``mass_scaled_disks``).
    """

    OPTIONAL = (
        "box_porosity", "interior_porosity", "interior_porosity_std", "surface_gap_mean_d50",
        "plate_contact_fraction", "preparation_note", "mass_scaling_dt_s", "mass_scaled_disks",
    )  # fmt: skip
    #: every trial as its row (:class:`~poro2d.criterion.trial.Trial`), the settings and specimen
    #: as the run's own values (their rows the file's ``settings`` and ``specimen``)
    PARTS: ClassVar[dict[str, type]] = {
        "iterations": Trial, "settings": CriterionSettings, "specimen": SpecimenSpec,
        "provenance": Provenance,
    }  # fmt: skip

    final_porosity: float | None
    converged: bool
    message: str
    n_lab: float
    initial_trial_porosity: float
    initial_from: str
    iterations: list[Trial]
    seed: int
    settings: CriterionSettings
    specimen: SpecimenSpec
    local_damping_note: str
    provenance: Provenance
    failed_trial: int | None = None
    time_total_s: float | None = None
    box_porosity: float | None = None
    interior_porosity: float | None = None
    interior_porosity_std: float | None = None
    surface_gap_mean_d50: float | None = None
    plate_contact_fraction: float | None = None
    # a wide grading's equilibrium test and why (poro2d.specimen.compaction.preparation_note)
    preparation_note: str | None = None
    # the accepted specimen's density scaling, only when its light disks' masses were raised:
    # the time step they share and how many (poro2d.specimen.compaction.mass_scaling_step)
    mass_scaling_dt_s: float | None = None
    mass_scaled_disks: int | None = None

    def to_dict(self) -> dict[str, Any]:
        """The file's keys; the specimen's preparation rolling friction, when set, stands after its
        other settings, where the files of the criterion have always had it."""
        out = super().to_dict()
        specimen = out.get("specimen")
        if isinstance(specimen, dict) and "rolling_friction_prep" in specimen:
            specimen = dict(specimen)
            specimen["rolling_friction_prep"] = specimen.pop("rolling_friction_prep")
            specimen["extra"] = specimen.pop("extra")
            out["specimen"] = specimen
        return out


@dataclass(eq=False)
class ReplicateRow(TypedResult):
    """One seed's criterion run among replicates: whether it accepted a porosity, in how many trials.

    ``folder``: the seed's sub-store (``seed<N>``); ``time_s``: the run's wall time. A row of
    :class:`ReplicatesResult` and of the paper summary's ``replicate_specimens``.
    """

    seed: int
    final_porosity: float | None
    converged: bool
    trials: int
    message: str
    folder: str
    time_s: float


@dataclass(eq=False)
class ReplicatesResult(TypedResult):
    """Replicate seeds' criterion runs: one :class:`ReplicateRow` per seed, in seed order (``rows``).

    The rows are what ``poro2d paper`` writes as ``replicate_specimens`` in ``results.json``.
    ``store`` (not a key) is the store holding the seeds' sub-stores.
    """

    PARTS: ClassVar[dict[str, type[TypedResult]]] = {"rows": ReplicateRow}

    rows: list[ReplicateRow]
    store: Store | None = field(default=None, kw_only=True, metadata=NOT_IN_FILE)

    @property
    def seeds_used(self) -> list[int]:
        """The seeds whose specimens were accepted, in seed order."""
        return [r.seed for r in self.rows if r.converged]

    @property
    def seeds_replaced(self) -> list[int]:
        """The seeds tried and not accepted (replaced by the next unused ones while any were left)."""
        return [r.seed for r in self.rows if not r.converged]

    @property
    def specimens(self) -> SpecimenSet:
        """The accepted specimens by label (``seed1``, ...), each seed's ``specimen.npz``, in seed order."""
        assert self.store is not None
        return SpecimenSet.made((f"seed{r.seed}", self.store.child(r.folder).path("specimen.npz"))
                                for r in self.rows if r.converged)  # fmt: skip


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
    def read(cls, store: Store, result: CriterionResult | None = None) -> CriterionOutputs:
        """A finished criterion run read back from its store (``result``: the run's result, when in hand)."""
        if result is None:
            result = store.read_result("result.json", CriterionResult.from_dict)
        return cls(
            result,
            store.read_result("specimen_state.json", SpecimenStateResult.from_dict),
            store.read_result("specimen_porosity.json", SpecimenPorosity.from_dict),
            {name: store.path(name) for name in CRITERION_FIGURES if store.has(name)},
        )


__all__ = [
    "CRITERION_FIGURES",
    "CriterionOutputs",
    "CriterionResult",
    "ReplicateRow",
    "ReplicatesResult",
    "SpecimenStateResult",
]
