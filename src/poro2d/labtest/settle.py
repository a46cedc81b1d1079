"""The servo-settle action: run a servoed specimen until a stop rule says it has settled.

Every consolidation of a box test, and the criterion's plate stage, servo walls to their
targets and run the engine until the specimen settles. :func:`settle_until` is that loop, once:
the engine runs in blocks of ``every`` steps (a block's end changes no number) and after each
block a stop rule, ``done(sim) -> bool``, is asked whether the specimen has settled, until
``max_steps``. The rule is what differs from test to test: the box tests' is
:class:`AtEquilibrium` (the maximum unbalanced-force ratio below a limit and the walls' stress
error below a tolerance, the servos' targets renewed while not), which :func:`settle` applies
on a clock started again at 0; the criterion's plate stage brings its own (the force window
held for a streak of checks, then the window at equilibrium or a plate that only creeps:
:mod:`poro2d.criterion.servo`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from poro2d.dem import Simulation
from poro2d.dem.reporters import Reporter
from poro2d.labtest.reporters import ProgressFn, ProgressReporter, StopTest

#: ``done(sim)``: a stop rule, asked after each block of steps whether the specimen has settled
StopRule = Callable[[Simulation], bool]

#: how often (steps) a settling specimen is checked (and its servos' targets renewed)
SETTLE_CHECK = 500


def settle_until(
    sim: Simulation, done: StopRule, max_steps: int, *, every: int = SETTLE_CHECK,
    progress: ProgressFn | None = None, phase: str = "consolidating", bar: bool | str = False,
    also: Sequence[Reporter] = (),
) -> int:  # fmt: skip
    """Run ``sim`` (its servos already on) in blocks of ``every`` steps until ``done(sim)``, at most
    ``max_steps`` steps; the steps run.

    ``progress``: told ``phase`` and the share of ``max_steps`` run before each check; ``bar``: the
    engine's own progress bar (:meth:`~poro2d.dem.Simulation.run`), its label when a string;
    ``also``: reporters that only read the engine (a ParaView series), before the stop test.
    """
    told = ProgressReporter(every, progress, phase, lambda _, k: min(k / max_steps, 1.0))
    return sim.run(max_steps, reporters=[told, *also, StopTest(every, done)], progress=bar).steps


@dataclass
class AtEquilibrium:
    """The box tests' stop rule: the maximum unbalanced-force ratio below ``ratio_limit`` and
    ``error(sim)`` (the walls' relative stress error) below ``tolerance``; ``renew`` (the servos'
    targets set again, a stress over a changing contact length) after each check that has not
    settled. ``ratio`` and ``stress_error``: their values at the last check."""

    error: Callable[[Simulation], float]
    ratio_limit: float
    tolerance: float
    renew: Callable[[Simulation], None] | None = None
    ratio: float = math.inf
    stress_error: float = math.inf

    @property
    def reached(self) -> bool:
        return bool(self.ratio < self.ratio_limit and self.stress_error < self.tolerance)

    def __call__(self, sim: Simulation) -> bool:
        self.ratio, self.stress_error = sim.unbalanced_ratios()[0], self.error(sim)
        if not self.reached and self.renew is not None:
            self.renew(sim)
        return self.reached


@dataclass(frozen=True)
class Settled:
    """How :func:`settle` ended: the steps run, the unbalanced-force ratio and the stress error at
    the last check, and whether both were within their limits (``reached``)."""

    steps: int
    ratio: float
    error: float
    reached: bool


def settle(
    sim: Simulation, error: Callable[[Simulation], float], *, ratio_limit: float, tolerance: float,
    max_steps: int, every: int = SETTLE_CHECK, renew: Callable[[Simulation], None] | None = None,
    progress: ProgressFn | None = None, phase: str = "consolidating",
) -> Settled:  # fmt: skip
    """Settle ``sim`` by :class:`AtEquilibrium` (its arguments are the rule's) within ``max_steps``
    steps counted from a clock started again at 0 (:func:`settle_until`)."""
    rule = AtEquilibrium(error, ratio_limit, tolerance, renew)
    sim.reset_clock()
    steps = settle_until(sim, rule, max_steps, every=every, progress=progress, phase=phase)
    return Settled(steps, rule.ratio, rule.stress_error, rule.reached)


__all__ = ["SETTLE_CHECK", "AtEquilibrium", "ProgressFn", "Settled", "StopRule", "settle", "settle_until"]
