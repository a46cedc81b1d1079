"""The critical-state reference: a periodic cell sheared to large strain at a low inertial number.

The material's own steady-state friction and solid fraction for a grading and its
micro-parameters, free of any box (docs/critical-state.md): :class:`CriticalStateCase` in,
:class:`CriticalStateTestResult` (one seed) or :class:`CriticalStateResult` (the spread over
seeds) out.
"""

from poro2d.critical_state.case import CriticalStateCase
from poro2d.critical_state.results import CriticalStateResult, CriticalStateTestResult
from poro2d.critical_state.run import CriticalStateStudy, run_critical_state, run_critical_states

__all__ = [
    "CriticalStateCase",
    "CriticalStateResult",
    "CriticalStateStudy",
    "CriticalStateTestResult",
    "run_critical_state",
    "run_critical_states",
]
