"""The working micro-parameters of a calibration (its ``calibrated.toml``) as a critical-state case's.

``poro2d calibrate`` writes the posterior maximum of the frictions (and of the disks' stiffness
when calibrated) into a ``[shear]`` or ``[biaxial]`` table; the critical state of the calibrated
material is that of those values, so the periodic cell takes them from the same file.
"""

from __future__ import annotations

import os

from poro2d.config import load_toml
from poro2d.errors import InputError, is_number

#: a calibrated table's key -> the critical-state case's field
CASE_FIELDS = {
    "particle_friction": "particle_friction",
    "rolling_friction": "rolling_friction",
    "particle_kn": "kn_particle",
    "particle_ks": "ks_particle",
}


def calibrated_values(path: str | os.PathLike) -> dict[str, float]:
    """The case fields a ``calibrated.toml`` fixes (the frictions, and kn, ks where calibrated)."""
    cfg = load_toml(path)
    tables = [name for name in ("shear", "biaxial") if isinstance(cfg.get(name), dict)]
    if not tables:
        raise InputError(
            "calibrated", str(path), "a calibrated.toml of poro2d calibrate (a [shear] or [biaxial] table)"
        )
    table = cfg[tables[0]]
    values = {}
    for key, name in CASE_FIELDS.items():
        if key in table:
            if not is_number(table[key]):
                raise InputError(f"{tables[0]}.{key}", table[key], "a number")
            values[name] = float(table[key])
    if "particle_friction" not in values:
        raise InputError(f"{tables[0]}.particle_friction", "missing", "the calibrated particle friction")
    return values


__all__ = ["CASE_FIELDS", "calibrated_values"]
