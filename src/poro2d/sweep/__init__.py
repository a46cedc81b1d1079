"""Sweeps: many cases (criterion runs, later direct shear tests) as Dask tasks.

``parse_sweep`` turns a config with a ``[sweep]`` table into cases with stable ids
(``make_sweep`` does the same for cases a study builds itself, from a
:class:`~poro2d.sweep.criterion_base.CriterionBase`); ``run_sweep`` runs the unfinished
ones into a :class:`~poro2d.store.Store` on a LocalCluster or an existing scheduler and
gathers one table. New case kinds are added with ``register_kind``.
"""

from poro2d.sweep.cases import KINDS, Case, SweepConfig, case_id, make_sweep, parse_sweep, register_kind
from poro2d.sweep.results import SweepResult
from poro2d.sweep.runner import run_sweep

__all__ = [
    "KINDS",
    "Case",
    "SweepConfig",
    "SweepResult",
    "case_id",
    "make_sweep",
    "parse_sweep",
    "register_kind",
    "run_sweep",
]
