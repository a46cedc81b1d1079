"""The figures of a criterion run, drawn from its result and the states its trials keep.

Every trial keeps its specimen as prepared (``prepared.npz``) and after the plate or lid
stage (``after_plate.npz``); their force chains are drawn beside them, with the wall forces
and the self weight the trial recorded. The paper's Figs. 5-7 are copies of three of them at
the top of the run's store (the first trial, the first whose top moved, the accepted one), and
the accepted specimen's state and local porosity are drawn from the state it was accepted on.
"""

from __future__ import annotations

from poro2d.criterion.lid import lid_shape, top_height
from poro2d.criterion.measures import WallForces
from poro2d.criterion.outputs import MOVED, accepted_state, trial_store
from poro2d.criterion.result import CriterionResult
from poro2d.errors import InputError
from poro2d.measure.specimen_porosity import measure_specimen
from poro2d.measure.specimen_state import specimen_state
from poro2d.report.figure_file import figure_files
from poro2d.report.force_chains import plot_simulation_force_chains
from poro2d.report.specimen_figures import plot_local_porosity, plot_specimen_state
from poro2d.store import Store, walk

#: a trial's figure of each state it keeps
PREPARED = ("prepared.npz", "forces_trial.png")
AFTER_PLATE = ("after_plate.npz", "forces_after_plate.png")


def draw_criterion(result: CriterionResult, store: Store) -> None:
    """Every trial's force chains, Figs. 5-7 at the top of ``store``, the accepted specimen's figures."""
    width = result.specimen.width
    for t in result.iterations:
        folder = trial_store(store, t)
        weight = t.self_weight_n_per_m
        if folder.has(PREPARED[0]):
            title = f"trial $n_{{2D}}$ = {t.trial_porosity:.3f}, top plate at $H$"
            _force_figure(folder, PREPARED, width, title, t.forces, weight)
        if folder.has(AFTER_PLATE[0]):
            what = "resting the lid" if t.plate.moved == "lid" else f"moving the top plate {t.plate.moved}"
            title = f"after {what}: $n'$ = {t.plate.new_porosity:.4f}"
            _force_figure(folder, AFTER_PLATE, width, title, t.forces_after, weight)
    _paper_figures(result, store)
    _accepted_figures(result, store, width)


def draw_stored_criterion(store: Store) -> None:
    """:func:`draw_criterion` of a finished run kept in ``store`` (its ``result.json`` read through
    the store: a replicate seed's, a sweep case's); nothing without one."""
    result = store.read_result("result.json", CriterionResult.from_dict)
    if result is not None:
        draw_criterion(result, store)


def draw_specimens(store: Store) -> None:
    """The figures of the preset specimens a run made in ``store`` (``poro2d calibrate``, ``strength
    --quick``): its ``criterion`` and each seed of its ``replicates``; nothing where none were made."""
    draw_stored_criterion(store.child("criterion"))
    for seed in walk(store.child("replicates"), "seed*"):
        draw_stored_criterion(seed)


def _force_figure(folder: Store, state: tuple[str, str], width: float, title: str, forces: WallForces,
                  weight: float) -> None:  # fmt: skip
    """The force chains of a kept state in the box under its top, with F_top, F_bottom and G noted."""
    sim = folder.load_state(state[0])
    plot_simulation_force_chains(
        sim, folder.path(state[1]), title=title, box=(0.0, 0.0, width, top_height(sim, width)),
        notes=[
            f"$F_{{top}}$ = {forces.f_top_n_per_m:.4g} N/m",
            f"$F_{{bottom}}$ = {forces.f_bottom_n_per_m:.4g} N/m",
            f"$G$ = {weight:.4g} N/m",
        ],
    )  # fmt: skip


def _paper_figures(result: CriterionResult, store: Store) -> None:
    """Fig. 5 (the first trial as prepared), Fig. 6 (the first trial whose top moved) and Fig. 7
    (the accepted trial, in the state it was accepted on), copied to the top of ``store`` with
    their SVGs."""
    trials = result.iterations
    if not trials:
        return
    pairs = [(trial_store(store, trials[0]), PREPARED[1], "fig5_forces_initial_trial.png")]
    moved = next((t for t in trials if t.plate.moved in MOVED), None)
    if moved is not None:
        pairs.append((trial_store(store, moved), AFTER_PLATE[1], "fig6_forces_after_plate.png"))
    found = accepted_state(result, store)
    if found is not None:
        figure = AFTER_PLATE[1] if found[1] == AFTER_PLATE[0] else PREPARED[1]
        pairs.append((found[0], figure, "fig7_forces_accepted.png"))
    for folder, name, as_name in pairs:
        # the figure and its vector twin, each copied when the trial has it
        for source, target in zip(figure_files(name), figure_files(as_name), strict=True):
            if folder.has(source.name):
                folder.copy(source.name, store, target.name)


def _accepted_figures(result: CriterionResult, store: Store, width: float) -> None:
    """``specimen_state.png`` (bands of equal height) and ``local_porosity.png`` (Laguerre cells)
    of the accepted specimen, measured on the state it was accepted on as its files were."""
    found = accepted_state(result, store)
    if found is None:
        return
    sim = found[0].load_state(found[1])
    n2d = next(t for t in result.iterations if t.decision.accepted).trial_porosity
    top = top_height(sim, width)
    state = specimen_state(sim, width, top, trial_porosity=n2d)
    title = f"accepted specimen, $n_{{2D}}$ = {n2d:.3f}: bands of equal height"
    plot_specimen_state(state, store.path("specimen_state.png"), title=title)
    p = sim.particles
    try:
        m = measure_specimen(p.pos, p.radius, width, top, lid=lid_shape(sim, width))
    except (InputError, RuntimeError):  # no map: the run's specimen_porosity.json says why
        return
    title = f"accepted specimen, $n_{{2D}}$ = {n2d:.3f}: local porosity (Laguerre cells)"
    plot_local_porosity(p.pos, p.radius, width, top, m, store.path("local_porosity.png"), title=title)


__all__ = ["draw_criterion", "draw_specimens", "draw_stored_criterion"]
