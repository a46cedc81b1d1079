"""The criterion's plate servo as a controller of its own: the top settles in the force window.

Step 3 of Fig. 3 moves the top plate (down when F_top = 0, up when it is too large) until
0 < F_top < ``force_fraction`` x G holds at equilibrium. :class:`PlateServo` does that on
any simulation whose top is one of the controllers of :mod:`poro2d.criterion.lid` (the
paper's :class:`~poro2d.criterion.lid.FlatPlate`, or the fill acceptance's
:class:`~poro2d.criterion.lid.SegmentedLid`): the criterion's trials use it, and so does
the check of an imported specimen (:mod:`poro2d.interop.check`), with the same settings
and so the same steps. Its phases run through the laboratory-test kit's one servo-settle loop
(:func:`poro2d.labtest.settle.settle_until`), each with its own stop rule.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

from poro2d.criterion.lid import CREEP_D50, CREEP_RATIO, CREEP_SWITCH, FlatPlate, SegmentedLid
from poro2d.criterion.settings import CriterionSettings
from poro2d.dem import Simulation
from poro2d.dem.export import frame_of
from poro2d.dem.reporters import Reporter
from poro2d.labtest.reporters import SeriesRecorder
from poro2d.labtest.settle import StopRule, settle_until
from poro2d.labtest.vtk_series import VtkSeries
from poro2d.record import Record

_log = logging.getLogger(__name__)


@dataclass(frozen=True)
class PlateSettle(Record):
    """What the plate stage of :meth:`PlateServo.settle` did: the ``plate_*`` keys of a trial's row."""

    ROW = (
        ("plate_settled", "settled"), ("plate_steps", "steps"), ("plate_rounds", "rounds"),
        ("plate_final_max_ratio", "final_max_ratio"), ("plate_displacement_m", "displacement_m"),
        ("plate_height_m", "height_m"),
    )  # fmt: skip

    settled: bool
    steps: int
    rounds: int
    final_max_ratio: float
    displacement_m: float
    height_m: float

    def then(self, later: PlateSettle) -> PlateSettle:
        """This stage followed by ``later``: one record of both (steps, rounds and moves add up)."""
        return PlateSettle(
            later.settled, self.steps + later.steps, self.rounds + later.rounds,
            later.final_max_ratio, self.displacement_m + later.displacement_m, later.height_m,
        )  # fmt: skip

    @classmethod
    def from_row(cls, row: dict) -> PlateSettle:
        return cls(
            row.get("plate_settled"), row.get("plate_steps"), row.get("plate_rounds"),
            row.get("plate_final_max_ratio"), row.get("plate_displacement_m"), row.get("plate_height_m"),
        )  # fmt: skip


def held_at_rest(converged: bool, creeps: bool, ratio: float, target: float) -> bool:
    """Whether a held top's specimen counts as at rest for the acceptance.

    A flat plate's specimen was judged while the plate settled (equilibrium, or a creep below
    ``plate_drift`` H); a creeping lid's has stopped creeping under it, and counts at rest at
    equilibrium or at a creeping packing's ratio, below ``CREEP_RATIO`` x ``target``.
    """
    return converged or not creeps or ratio < CREEP_RATIO * target


def in_window(f_top: float, weight: float, fraction: float) -> bool:
    """The window of Fig. 3: 0 < F_top < ``fraction`` x G (both per metre of thickness)."""
    return 0.0 < f_top < fraction * weight


def rises_free_to_roll(
    f_top: float, weight: float, fraction: float, overfull: bool, rolling_friction: float
) -> bool:
    """Whether the plate first rises with rolling friction off (:meth:`PlateServo.relax_rolling`).

    It does whenever it must rise (an over-full box, or F_top at or above the window's limit
    ``fraction`` x ``weight``, N/m) over disks with rolling friction: rolling friction locks the
    side stress of a squeezed packing, over-full or merely dense, and a disk left pressed into
    a side wall fails the in-box check. A plate that moves down, or disks free to roll, change
    nothing.
    """
    return rolling_friction > 0.0 and (overfull or f_top >= fraction * weight)


@dataclass(frozen=True)
class PlateServo:
    """Servo the top of a box until 0 < F_top < ``force_fraction`` G holds at equilibrium.

    ``settings``: the thresholds and servo gains (``CriterionSettings``); ``ratio`` and
    ``equilibrium``: when the specimen counts as at equilibrium (its maximum, mean or
    load-bearing unbalanced-force ratio below ``ratio``, as the specimen's preparation
    judged it); ``height``: the box height H, the scale of the allowed plate drift;
    ``progress``: a bar per approach when True; ``series``: where the approach and settling
    phases are kept as a ParaView series, a step every ``vtk_every`` steps of the engine's count at
    the top's height (None: none).
    """

    settings: CriterionSettings
    ratio: float
    equilibrium: str
    height: float
    progress: bool = False
    series: VtkSeries | None = None

    def watch(self, sim: Simulation, top: FlatPlate | SegmentedLid) -> list[Reporter]:
        """The reporter that writes the series during a phase (none without a series)."""
        if self.series is None:
            return []
        clock = lambda sm: (sm.step_count, sm.time, top.height(sm))  # noqa: E731
        return [SeriesRecorder(self.settings.vtk_every, self.series, frame_of, clock, start=sim.step_count)]

    def target(self, sim: Simulation, weight: float) -> float:
        """The force (N) the plate or lid servos to: ``servo_target_fraction`` of the window's limit."""
        s = self.settings
        return s.servo_target_fraction * (s.force_fraction * weight) * sim.particles.thickness

    def settle(
        self, sim: Simulation, weight: float, top: FlatPlate | SegmentedLid | None = None
    ) -> PlateSettle:
        """Servo ``top`` (the flat plate by default) until the window holds at equilibrium.

        Each round (:meth:`round`) has two phases. The approach servos the plate briskly
        towards ``servo_target_fraction`` x the limit until F_top has stayed in the window
        for ``window_checks`` checks. The settling phase keeps a gentle servo on (a low gain
        and speed, so the plate follows slow creep of the specimen without shaking it)
        until, with F_top in the window, the specimen is at equilibrium or the plate has
        rested for ``settle_checks`` checks (drift below ``plate_drift`` x H: only creep
        left). The plate is then held still, the specimen cycled towards equilibrium, and
        F_top checked once more (the final ratio is reported); if it left the window, a new
        round starts. A lid is driven the same way, its segments each to their share of
        the force, and counts as in the window only while it rests on the specimen over
        most of the width. A creeping lid (a frictional preparation's,
        :class:`~poro2d.criterion.lid.SegmentedLid`) leaves its approach once near the window,
        settles until it no longer creeps, comes to equilibrium still servoed and is then held;
        its round counts only at equilibrium. ``weight``: the self weight G (N/m).

        Returns the plate stage's record (:class:`PlateSettle`): whether it settled, the
        steps and rounds, the final unbalanced-force ratio, the displacement and height.
        """
        s = self.settings
        top = FlatPlate(sim) if top is None else top
        y_start = top.height(sim)
        steps = 0
        rounds = 0
        ok = False
        final_ratio = float("nan")
        while steps < s.max_plate_steps and not ok:
            rounds += 1
            steps, ok, final_ratio = self.round(sim, weight, rounds, steps, top)
        y_end = top.height(sim)
        return PlateSettle(ok, steps, rounds, final_ratio, y_end - y_start, y_end)

    def relax_rolling(self, sim: Simulation, weight: float, rolling_friction: float) -> PlateSettle:
        """Let an over-full specimen with rolling friction rise to the window free to roll.

        An over-full box (a trial denser than its grading packs) starts the plate stage
        squeezed hundreds of times its weight. Without rolling friction its disks roll apart
        as the plate rises, sideways as well as up. Rolling friction locks them: the packing
        rises as a plug wedged between the side walls (their friction holding it down by
        about the force it had pressed up with), and disks stay pressed into the walls by
        more than the in-box check allows: the trial was refused. The plate therefore first
        rises with rolling friction off (disks and walls), which frees the locked stress;
        the rolling friction ``rolling_friction`` is then set again and the caller settles
        the plate with it. Returns the plate stage of the free rise.
        """
        sim.set_rolling_friction(0.0, walls=0.0)
        free = self.settle(sim, weight)
        sim.set_rolling_friction(rolling_friction, walls=rolling_friction)
        return free

    def round(
        self, sim: Simulation, weight: float, rounds: int, steps: int, top: FlatPlate | SegmentedLid
    ) -> tuple[int, bool, float]:
        """One round of :meth:`settle`: approach, settle, hold the plate still.

        ``steps``: the plate steps before this round (every phase stops at
        ``max_plate_steps`` in all). Returns the steps after it, whether F_top is in the
        window once held, and the maximum unbalanced-force ratio reached while held.
        """
        s = self.settings
        t = sim.particles.thickness
        cap = s.force_fraction * weight  # N/m
        target = self.target(sim, weight)  # N

        def left() -> int:
            return max(s.max_plate_steps - steps, 1)

        top.servo(sim, target, s.servo_max_speed, s.servo_gain)
        label = f"top {top.name} (round {rounds})" if self.progress else False
        steps += settle_until(
            sim, self._approached(top, target, weight), left(), every=s.check_every, bar=label,
            also=self.watch(sim, top),
        )  # fmt: skip
        top.servo(sim, target, s.settle_max_speed, s.settle_gain)
        steps += settle_until(
            sim, self._settled(top, target, weight), left(), every=s.check_every, also=self.watch(sim, top)
        )
        if not top.creeps:
            top.hold(sim)
        # a creeping lid comes to equilibrium still servoed to its force, and is held there: held
        # first, the grains creeping away from it left segments out of contact at equilibrium
        res = sim.solve(self.ratio, min(left(), 20 * s.check_every), measure=self.equilibrium)
        steps += res.steps
        top.hold(sim)
        f = top.force(sim) / t
        _log.debug(
            "plate round %d: F_top %.4g N/m (limit %.4g), held: converged %s ratio %.3g, %d steps",
            rounds, f, cap, res.converged, res.max_ratio, steps,
        )  # fmt: skip
        ok = in_window(f, weight, s.force_fraction) and top.resting(sim, target)
        return (
            steps,
            ok and held_at_rest(res.converged, top.creeps, res.measured_ratio, self.ratio),
            res.measured_ratio,
        )

    def holds(self, sim: Simulation, top: FlatPlate | SegmentedLid, target: float, weight: float) -> bool:
        """F_top in the window, with a lid resting on the specimen over most of the width."""
        f = top.force(sim) / sim.particles.thickness
        return in_window(f, weight, self.settings.force_fraction) and top.resting(sim, target)

    def _approached(self, top: FlatPlate | SegmentedLid, target: float, weight: float) -> StopRule:
        """The approach's stop test: F_top in the window for ``window_checks`` checks running.

        A creeping lid switches to the gentle servo at the first check that finds it resting on
        the specimen under less than ``CREEP_SWITCH`` times the window's limit: the brisk servo
        only bangs its segments on the creeping grains from there (a segment out of contact
        comes down at full speed), and the gentle one takes the force into the window.
        """
        s = self.settings
        need = 1 if top.creeps else s.window_checks
        streak = [0]

        def near(sm: Simulation) -> bool:
            f = top.force(sm) / sm.particles.thickness
            return f < CREEP_SWITCH * s.force_fraction * weight and top.resting(sm, target)

        def steady(sm: Simulation) -> bool:
            ok = near(sm) if top.creeps else self.holds(sm, top, target, weight)
            streak[0] = streak[0] + 1 if ok else 0
            return streak[0] >= need

        return steady

    def _settled(self, top: FlatPlate | SegmentedLid, target: float, weight: float) -> StopRule:
        """The settling phase's stop test: F_top in the window and the specimen at rest.

        At rest means at equilibrium, or a plate that rests in the window while the
        specimen only creeps (its drift over the last ``settle_checks`` checks below
        ``plate_drift`` x H). A creeping lid (:class:`~poro2d.criterion.lid.SegmentedLid`) is
        at rest once it rests on the specimen and its drift over those checks is below
        ``CREEP_D50`` d50, whatever its force at the check: the held lid's force is judged at
        equilibrium afterwards.
        """
        if top.creeps:
            return self._crept(top, target)
        s = self.settings
        calm: list[float] = []

        def settled(sm: Simulation) -> bool:
            if not self.holds(sm, top, target, weight):
                calm.clear()
                return False
            if sm.ratio_of(self.equilibrium) < self.ratio:
                return True
            calm.append(top.height(sm))
            if len(calm) < s.settle_checks:
                return False
            return max(calm[-s.settle_checks :]) - min(calm[-s.settle_checks :]) < s.plate_drift * self.height

        return settled

    def _crept(self, lid: SegmentedLid, target: float) -> StopRule:
        """A creeping lid's settling test: resting at this check, its height within ``CREEP_D50``
        d50 over the last ``settle_checks`` checks. A check where it rests on less of the width
        does not start the count again: on a creeping surface the segments' contacts flicker too,
        while the lid's height tells whether it still moves."""
        n = self.settings.settle_checks
        heights: list[float] = []

        def crept(sm: Simulation) -> bool:
            heights.append(lid.height(sm))
            calm = len(heights) >= n and max(heights[-n:]) - min(heights[-n:]) < CREEP_D50 * lid.d50
            return calm and lid.resting(sm, target)

        return crept


__all__ = ["PlateServo", "PlateSettle", "held_at_rest", "in_window", "rises_free_to_roll"]
