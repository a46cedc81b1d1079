"""The side outputs of a criterion run: the accepted specimen and its files.

The loop of Fig. 3 (:mod:`poro2d.criterion.protocol`) computes trials and keeps their
states; once the run ends, the accepted specimen is written here (``specimen.npz``, its
VTU), with its homogeneity and stress state (``specimen_state.json``) and its porosities
(``specimen_porosity.json``). Every file goes through the :class:`~poro2d.store.Store`. The
figures (force chains, Figs. 5-7, the state and the local porosity map) are drawn afterwards
from the states the trials keep (``report/criterion_figures.py``).
"""

from __future__ import annotations

from poro2d.criterion.lid import flat_top, lid_shape, top_height
from poro2d.criterion.result import CriterionResult
from poro2d.criterion.trial import trial_name
from poro2d.dem import Simulation
from poro2d.errors import InputError
from poro2d.io_utils import Provenance
from poro2d.store import Store

#: how the top moved in a trial whose state after the plate stage was kept
MOVED = ("up", "down", "lid")


def write_accepted(result: CriterionResult, store: Store, width: float) -> None:
    """The accepted specimen at the top of ``store``, with its state and porosities.

    The accepted specimen is the state the decision was taken on: after the plate moved to
    touch (when it moved) or the specimen was cycled further to balance, else as prepared with
    the plate at H.
    """
    found = accepted_state(result, store)
    if found is None:
        return
    sim = found[0].load_state(found[1])
    lid = lid_shape(sim, width)
    if lid is None:
        found[0].copy(found[1], store, "specimen.npz")
    else:  # what leaves is a box of four walls (lid.flat_top); the lid is measured here
        store.save_state("specimen.npz", flat_top(sim, width),
                         extra={"stage": "accepted", "lid_heights_m": lid[1].tolist()})  # fmt: skip
    from poro2d.dem.export import write_vtu

    write_vtu(sim, store.path("vtu"), "accepted_specimen")
    n2d = next(t for t in result.iterations if t.decision.accepted).trial_porosity
    write_specimen_state(store, sim, width, n2d)
    write_specimen_porosity(store, sim, width, n2d)


def accepted_state(result: CriterionResult, store: Store) -> tuple[Store, str] | None:
    """The trial store and state file (``after_plate.npz`` or ``prepared.npz``) of the accepted
    trial of a converged run; None without one."""
    accepted = next((t for t in result.iterations if t.decision.accepted), None) if result.converged else None
    if accepted is None:
        return None
    folder = trial_store(store, accepted)
    # a specimen cycled further to balance or equilibrium is taken as it was then, also when the plate stayed
    cycled = accepted.balance_steps or accepted.equilibrium_steps
    moved_last = (accepted.plate.moved in MOVED or cycled) and folder.has("after_plate.npz")
    return folder, "after_plate.npz" if moved_last else "prepared.npz"


def trial_store(store: Store, trial) -> Store:
    """The sub-store of one trial of a run kept in ``store``."""
    return store.child(trial_name(trial.iteration, trial.trial_porosity))


def write_specimen_state(store: Store, sim: Simulation, width: float, n2d: float) -> None:
    """Homogeneity and stress state of the accepted specimen: ``specimen_state.json``."""
    from poro2d.measure.specimen_state import specimen_state

    state = specimen_state(sim, width, top_height(sim, width), trial_porosity=n2d)
    store.write_result("specimen_state.json", state)


def write_specimen_porosity(store: Store, sim: Simulation, width: float, n2d: float) -> None:
    """The accepted specimen's porosities: ``specimen_porosity.json``."""
    from poro2d.measure.specimen_porosity import measure_specimen

    p = sim.particles
    top = top_height(sim, width)
    try:
        m = measure_specimen(p.pos, p.radius, width, top, lid=lid_shape(sim, width))
    except (InputError, RuntimeError) as e:
        store.write_json("specimen_porosity.json", {"trial_porosity": n2d, "note": str(e),
                                                    "provenance": Provenance.now().to_dict()})  # fmt: skip
        return
    store.write_json(
        "specimen_porosity.json", dict(m.to_dict(), trial_porosity=n2d, provenance=Provenance.now().to_dict())
    )


__all__ = [
    "MOVED",
    "accepted_state",
    "trial_store",
    "write_accepted",
    "write_specimen_porosity",
    "write_specimen_state",
]
