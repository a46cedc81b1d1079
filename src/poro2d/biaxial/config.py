"""The ``[biaxial]`` table of a TOML config: the settings of a biaxial test and what to run.

Read once, at the edge (``poro2d biaxial --config FILE``): unknown keys, values of the wrong
type, infinities and values out of range are refused on one line naming ``biaxial.<key>``
before any work. The table holds :class:`~poro2d.biaxial.settings.BiaxialSettings`' fields and
the keys of :data:`RUN_KEYS` (the stresses, the replicates, the specimens); the command's own
options win over the table. Other tables of the project's config files may sit beside it.
"""

from __future__ import annotations

import dataclasses
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from poro2d.biaxial.settings import CONFINING_RANGE_KPA, BiaxialSettings
from poro2d.config import check_finite, check_keys, check_number_list, dataclass_from_table, load_toml
from poro2d.criterion.config import TOP_KEYS
from poro2d.errors import InputError, check_int, is_number

#: keys of the table that say what to run, not how a test runs
RUN_KEYS = ("confining_kpa", "replicates", "seed", "quick", "specimens", "lab", "workers")
#: the fields of the settings
SETTING_KEYS = tuple(f.name for f in dataclasses.fields(BiaxialSettings))


@dataclass(frozen=True)
class BiaxialConfig:
    """A config's ``[biaxial]`` table, checked: ``settings`` (BiaxialSettings' fields as given),
    ``run`` (the keys of :data:`RUN_KEYS` given) and ``base`` (the folder paths start from)."""

    settings: dict[str, Any]
    run: dict[str, Any]
    base: Path | None = None

    def build(self, **options: Any) -> BiaxialSettings:
        """The settings: the table's, each option that is not None winning over it."""
        return dataclass_from_table(BiaxialSettings, "biaxial", self.settings, **options)

    def path(self, key: str) -> str | None:
        """A path of the table (``lab``), relative to the config file's folder."""
        value = self.run.get(key)
        return None if value is None else _resolve(value, self.base)

    def specimens(self) -> list[str] | None:
        """The table's specimen paths, relative to the config file's folder (None: not given)."""
        given = self.run.get("specimens")
        return None if given is None else [_resolve(p, self.base) for p in given]


def _resolve(value: str, base: Path | None) -> str:
    return str((base / value).resolve()) if base is not None else value


def load_biaxial_config(path: str | os.PathLike | None) -> BiaxialConfig:
    """The ``[biaxial]`` table of the TOML file at ``path``, checked (an empty one without a path)."""
    if path is None:
        return BiaxialConfig({}, {})
    cfg = load_toml(path)
    check_keys("config", cfg, TOP_KEYS | {"biaxial"})
    table = cfg.get("biaxial", {})
    check_keys("biaxial", table, set(SETTING_KEYS) | set(RUN_KEYS))
    check_finite("biaxial", table)
    run = {k: table[k] for k in RUN_KEYS if k in table}
    check_run_keys(run)
    settings = {k: v for k, v in table.items() if k not in RUN_KEYS}
    try:
        dataclass_from_table(BiaxialSettings, "biaxial", settings)
    except InputError as exc:  # a range refused by the settings: named as the table's key
        name = exc.parameter if exc.parameter.startswith("biaxial.") else f"biaxial.{exc.parameter}"
        raise InputError(name, exc.value, exc.allowed) from None
    return BiaxialConfig(settings, run, Path(path).resolve().parent)


def check_run_keys(run: dict[str, Any]) -> None:
    """Types and ranges of the keys that say what to run."""
    if "confining_kpa" in run:
        v = run["confining_kpa"]
        check_number_list(
            "biaxial.confining_kpa", [v] if is_number(v) else v, *CONFINING_RANGE_KPA, max_items=20
        )
    for key, lo, hi in (("replicates", 1, 50), ("seed", 0, 2**31 - 1), ("workers", 1, 64)):
        if key in run:
            check_int(f"biaxial.{key}", run[key], lo, hi)
    if "quick" in run and not isinstance(run["quick"], bool):
        raise InputError("biaxial.quick", run["quick"], "true or false")
    if "lab" in run and not isinstance(run["lab"], str):
        raise InputError("biaxial.lab", run["lab"], "a path (a string)")
    if "specimens" in run:
        v = run["specimens"]
        if not (isinstance(v, list) and v and all(isinstance(p, str) for p in v)):
            raise InputError("biaxial.specimens", v, "a list of specimen paths (strings)")


__all__ = ["RUN_KEYS", "BiaxialConfig", "check_run_keys", "load_biaxial_config"]
