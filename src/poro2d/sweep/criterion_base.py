"""The base case of a criterion study: its config read once, a value the studies vary.

The relation, the density calibration, the state checks and the sensitivity study all run
the criterion on variations of one config: a smaller box for a quick look, density mode's
defaults, a friction, a first trial or a grading per case. The config is read once, at the
edge (a command, or the one call of a study), into a :class:`CriterionBase`; each study
derives the base it runs from with :func:`dataclasses.replace` (through the methods of
:class:`~poro2d.criterion.config.CriterionConfig`, the criterion's config as a value)
and hands it the parameters of its cases, so no study re-reads the file or edits another's
dict. The tables keep the order they were given in: a case's merged config, recorded in its
``params.json`` and named by its id, is the same whichever way the base was reached.
"""

from __future__ import annotations

import copy
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from poro2d.criterion.config import CriterionConfig
from poro2d.sweep.cases import SweepConfig, axes_of, make_sweep

#: tables of a config that describe a study, not the criterion cases it runs
STUDY_TABLES = ("relation", "sweep")


@dataclass(frozen=True)
class CriterionBase(CriterionConfig):
    """The base config of a criterion study (:class:`~poro2d.criterion.config.CriterionConfig`),
    which makes the sweeps of its cases."""

    @classmethod
    def from_config(
        cls, cfg: Mapping[str, Any], base_dir: Path | None = None, *, drop: tuple[str, ...] = STUDY_TABLES
    ) -> CriterionBase:
        """The base of a config as read (a copy: the caller's dict stays its own), without ``drop``."""
        return cls(copy.deepcopy({k: v for k, v in cfg.items() if k not in drop}), base_dir)

    def sweep(self, table: Mapping[str, Any], cases: list[dict[str, Any]]) -> SweepConfig:
        """The sweep of criterion ``cases`` (dotted parameters) on this base.

        ``table``: the ``[sweep]`` table that describes them in ``sweep.json`` (a grid or the
        list of cases, and the title), recorded beside the base's tables.
        """
        raw = {**self.as_config(), "sweep": dict(table)}
        return make_sweep(table.get("kind", "criterion"), raw, cases, axes_of(cases), base_dir=self.base_dir,
                          title=str(table.get("title", "")))  # fmt: skip


__all__ = ["STUDY_TABLES", "CriterionBase"]
