"""Where the specimens landed against the state asked: the relative density they reached.

The criterion accepts a full-size specimen whose box porosity n' lies within its tolerance of
the trial (0.002 by default), so three specimens prepared at one friction may all sit a
little off the target, denser when the calibration read the friction low and looser when it
read it high. Their n' says by how much. Two numbers follow from it:

* **the relative density reached**: the specimens' mean n' moved into the calibration box by
  the walls' share the full box loses (:func:`poro2d.sand.run.full_box_trial`), then placed
  between the calibration's 2D extremes as the target was (void ratio, as Dr in the
  laboratory; :func:`poro2d.criterion.density.target_porosity_2d`);
* **the interior porosity at the target itself**: each specimen's interior porosity lies
  below its n' by the walls' loose layer (n' - interior, about the same for every specimen of a
  box), so the target less that offset is the interior porosity of a specimen at exactly the
  asked Dr. Its standard error is the offset's over the specimens and the target's over the
  calibration's seeds (:func:`~poro2d.criterion.density.target_error`): free of the friction's
  sampling, which moves the specimens' n' and interior porosity together.

The answer stays the specimens' own interior porosity (the specimens users export); these say
how close to the asked state it was prepared.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from poro2d import porosity as P
from poro2d.criterion.density import Calibration, target_error
from poro2d.typed_result import TypedResult


@dataclass(eq=False)
class StateReached(TypedResult):
    """The specimens' state against the target (``state_reached`` in ``sand.json``).

    ``box_target``: the full box's target n' (the calibration box's target less the walls'
    share); ``box_mean``: the accepted specimens' mean n'; ``relative_density_asked`` and
    ``relative_density_reached``: Dr of the laboratory state and of the specimens on the 2D
    extremes; ``walls_offset``: the specimens' mean n' - interior porosity, with its sd;
    ``target_se``: the target's standard error from the ends' seeds (the calibration box's,
    taken for the full box's); ``interior_at_target``: ``box_target`` - ``walls_offset``, with its
    standard error (the offset's sd / sqrt(n) and ``target_se`` in quadrature; None with one
    specimen or no spread in the ends); ``wide_grading``: the grading is wide
    (:func:`poro2d.specimen.compaction.is_wide`), where the walls' share model that moves the
    target into the full box was measured to fall short (docs/sand.md), and the line says so.
    """

    box_target: float
    box_mean: float
    relative_density_asked: float
    relative_density_reached: float
    walls_offset: float | None
    walls_offset_sd: float | None
    target_se: float | None
    interior_at_target: float | None
    interior_at_target_se: float | None
    wide_grading: bool = False

    @classmethod
    def of(cls, dr: float, n2d_target: float, box_target: float, cal: Calibration,
           boxes: list[float], interiors: list[float],
           wide: bool = False) -> StateReached | None:  # fmt: skip
        """From the state's ``dr``, its 2D target in the calibration box (``n2d_target``) and in
        the full box (``box_target``), the calibration ``cal`` (its extremes and seeds) and the
        accepted specimens' box and interior porosities (in pairs; an interior porosity may be
        None, in a box too small for an interior region: then no interior porosity at the target);
        ``wide``: whether the grading is wide. None without an accepted specimen."""

        def finite(x) -> bool:
            return x is not None and math.isfinite(x)

        box = np.array([b for b in boxes if finite(b)], dtype=float)
        n2d_min, n2d_max = cal.n2d_min, cal.n2d_max
        if not box.size or not n2d_min < n2d_max:
            return None
        in_small_box = float(box.mean()) + (n2d_target - box_target)
        reached = float(P.relative_density(in_small_box, n2d_max, n2d_min))
        t_se = target_error(dr, cal)
        offset = np.array([b - i for b, i in zip(boxes, interiors, strict=True) if finite(b) and finite(i)])
        walls = float(offset.mean()) if offset.size else None  # a box too small for an interior: none
        sd = float(offset.std(ddof=1)) if offset.size > 1 else None
        known = sd is not None and math.isfinite(t_se)
        return cls(
            box_target=float(box_target),
            box_mean=float(box.mean()),
            relative_density_asked=float(dr),
            relative_density_reached=reached,
            walls_offset=walls,
            walls_offset_sd=sd,
            target_se=float(t_se) if math.isfinite(t_se) else None,
            interior_at_target=None if walls is None else float(box_target) - walls,
            interior_at_target_se=math.hypot(sd / math.sqrt(offset.size), t_se) if known else None,
            wide_grading=bool(wide),
        )

    def text(self) -> str:
        """One line: the Dr reached against the Dr asked, and the interior porosity at the target."""
        head = (
            f"specimens at Dr {self.relative_density_reached:.3f} (asked {self.relative_density_asked:.3f}): "
            f"box n' {self.box_mean:.4f} against the target {self.box_target:.4f}"
        )
        if self.interior_at_target is None:
            bare = " (no interior region in this box: no interior porosity at the target)"
            return head + bare + self._caveat()
        se = self.interior_at_target_se
        se_text = "" if se is None else f", standard error {se:.4f}"
        return (
            f"{head}; the interior porosity at the target itself {self.interior_at_target:.4f}{se_text} "
            f"(the target less the walls' loose layer, {self.walls_offset:.4f})" + self._caveat()
        )

    def _caveat(self) -> str:
        if not self.wide_grading:
            return ""
        return (
            "; a wide grading: the full box's target comes from a walls' share model that fell short "
            "on one (G1-1, docs/sand.md), so this Dr and this porosity may be off by a few hundredths in Dr"
        )


__all__ = ["StateReached"]
