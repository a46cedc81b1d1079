"""The side outputs of a criterion run: figures, the accepted specimen and its files.

The loop of Fig. 3 (:mod:`poro2d.criterion.protocol`) computes trials and keeps their
states; what a reader looks at besides the result lives here: the force-chain figure of
a trial's state (drawn by :mod:`poro2d.report.force_chains`), and, once the run ends, the
paper-style figures copied to the top of the store, the accepted specimen
(``specimen.npz``, its VTU), its homogeneity and stress state (``specimen_state.json``)
and its porosities (``specimen_porosity.json``, the local porosity map). Every file goes
through the :class:`~poro2d.store.Store`; figures are saved at ``store.path(name)``.
"""

from __future__ import annotations

from poro2d.criterion.lid import flat_top, lid_shape, top_height
from poro2d.criterion.measures import WallForces
from poro2d.criterion.result import CriterionResult
from poro2d.criterion.trial import trial_name
from poro2d.dem import Simulation
from poro2d.errors import InputError
from poro2d.io_utils import Provenance
from poro2d.store import Store

#: how the top moved in a trial whose state after the plate stage was kept
MOVED = ("up", "down", "lid")


def force_figure(
    store: Store, name: str, sim: Simulation, width: float, title: str, forces: WallForces, weight: float
) -> None:
    """The force chains of ``sim`` in the box under its top, with F_top, F_bottom and G noted."""
    from poro2d.report.force_chains import plot_simulation_force_chains

    plot_simulation_force_chains(
        sim, store.path(name), title=title, box=(0.0, 0.0, width, top_height(sim, width)),
        notes=[
            f"F_top = {forces.f_top_n_per_m:.4g} N/m",
            f"F_bottom = {forces.f_bottom_n_per_m:.4g} N/m",
            f"G = {weight:.4g} N/m",
        ],
    )  # fmt: skip


def write_accepted(result: CriterionResult, store: Store, width: float, *, figures: bool = True) -> None:
    """Copy the paper-style figures and the accepted specimen to the top of ``store``.

    Fig. 5 is the first trial as prepared, Fig. 6 the first trial whose top moved, Fig. 7
    the accepted trial. The accepted specimen is the state the decision was taken on:
    after the plate moved to touch (when it moved), else as prepared with the plate at H.
    """
    trials = result.iterations
    if not trials:
        return
    first = trials[0]
    pairs = [(_trial_store(store, first), "forces_trial.png", "fig5_forces_initial_trial.png")]
    moved = next((t for t in trials if t.plate.moved in MOVED), None)
    if moved is not None:
        pairs.append((_trial_store(store, moved), "forces_after_plate.png", "fig6_forces_after_plate.png"))
    accepted = next((t for t in trials if t.decision.accepted), None) if result.converged else None
    if accepted is not None:
        folder = _trial_store(store, accepted)
        moved_last = accepted.plate.moved in MOVED and folder.has("after_plate.npz")
        state = "after_plate" if moved_last else "prepared"
        figure = "forces_after_plate.png" if moved_last else "forces_trial.png"
        pairs.append((folder, figure, "fig7_forces_accepted.png"))
        sim = folder.load_state(f"{state}.npz")
        lid = lid_shape(sim, width)
        if lid is None:
            folder.copy(f"{state}.npz", store, "specimen.npz")
        else:  # what leaves is a box of four walls (lid.flat_top); the lid is measured here
            store.save_state("specimen.npz", flat_top(sim, width),
                             extra={"stage": "accepted", "lid_heights_m": lid[1].tolist()})  # fmt: skip
        from poro2d.dem.export import write_vtu

        write_vtu(sim, store.path("vtu"), "accepted_specimen")
        n2d = accepted.trial_porosity
        write_specimen_state(store, sim, width, n2d, figures=figures)
        write_specimen_porosity(store, sim, width, n2d, figures=figures)
    for folder, name, as_name in pairs:
        if folder.has(name):
            folder.copy(name, store, as_name)


def _trial_store(store: Store, trial) -> Store:
    return store.child(trial_name(trial.iteration, trial.trial_porosity))


def write_specimen_state(store: Store, sim: Simulation, width: float, n2d: float, *, figures: bool) -> None:
    """Homogeneity and stress state of the accepted specimen: ``specimen_state.json`` and its figure."""
    from poro2d.measure.specimen_state import specimen_state
    from poro2d.report.specimen_figures import plot_specimen_state

    state = specimen_state(sim, width, top_height(sim, width), trial_porosity=n2d)
    store.write_result("specimen_state.json", state)
    if figures:
        title = f"accepted specimen, n2D = {n2d:.3f}: bands of equal height"
        plot_specimen_state(state, store.path("specimen_state.png"), title=title)


def write_specimen_porosity(
    store: Store, sim: Simulation, width: float, n2d: float, *, figures: bool
) -> None:
    """The accepted specimen's porosities: ``specimen_porosity.json`` and the local porosity map."""
    from poro2d.measure.specimen_porosity import measure_specimen
    from poro2d.report.specimen_figures import plot_local_porosity

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
    if figures:
        title = f"accepted specimen, n2D = {n2d:.3f}: local porosity (Laguerre cells)"
        plot_local_porosity(p.pos, p.radius, width, top, m, store.path("local_porosity.png"), title=title)


__all__ = ["force_figure", "write_accepted", "write_specimen_porosity", "write_specimen_state"]
