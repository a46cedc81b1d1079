"""The servo-settle action: run a servoed specimen until it is at equilibrium on its targets.

Every consolidation of a box test, and the criterion's plate stage, servo walls to their
targets and run the engine until the specimen settles. :func:`settle` is that loop, once: the
engine's clock starts again at 0, the engine runs in blocks of ``every`` steps (a block's end
changes no number), and after each block the maximum unbalanced-force ratio and the walls' stress
error are read. Settled: the ratio below ``ratio_limit`` and the error below ``tolerance``;
otherwise ``renew`` may set the servos' targets again (a stress over a changing contact
length), until ``max_steps``.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

from poro2d.dem import Simulation

#: ``progress(phase, fraction)``: called between blocks of steps, for a progress display
ProgressFn = Callable[[str, float], None]

#: how often (steps) a settling specimen is checked (and its servos' targets renewed)
SETTLE_CHECK = 500


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
    """Run ``sim`` (its servos already on) until its maximum unbalanced-force ratio is below
    ``ratio_limit`` and ``error(sim)`` (the walls' relative stress error) below ``tolerance``,
    within ``max_steps`` steps counted from a clock started again at 0.

    ``renew``: called after each check that has not settled (the servos' targets set again);
    ``progress``: told ``phase`` and the share of ``max_steps`` run after each check.
    """
    last = {"ratio": math.inf, "error": math.inf}

    def settled(sm: Simulation) -> bool:
        last.update(ratio=sm.unbalanced_ratios()[0], error=error(sm))
        if progress is not None:
            progress(phase, min(sm.step_count / max_steps, 1.0))
        done = last["ratio"] < ratio_limit and last["error"] < tolerance
        if not done and renew is not None:
            renew(sm)
        return done

    sim.reset_clock()
    steps = sim.run(max_steps, every=every, callback=settled).steps
    reached = last["ratio"] < ratio_limit and last["error"] < tolerance
    return Settled(steps, last["ratio"], last["error"], bool(reached))


__all__ = ["SETTLE_CHECK", "ProgressFn", "Settled", "settle"]
