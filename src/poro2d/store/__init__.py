"""Result files, checkpoints and resumable stages: the only code that reads and writes them.

:class:`Store` (``folder.py``) is a folder of named result files; protocols are handed one
(or None, and then keep nothing) and never form a path. :class:`ResumableStage`
(``stage.py``) is the one load-or-compute rule of every resumable run: a record binds a
folder to its inputs, a marker written last says a stage is done. :meth:`Store.claim` is the
one claim of an output folder (:func:`claimed`: of a store or None; :func:`claims`: for a call).
"""

from poro2d.store.folder import Checkpoints, Store, claimed, claims, walk
from poro2d.store.stage import Fingerprint, ResumableStage, differing_keys, test_stage

__all__ = [
    "Checkpoints", "Fingerprint", "ResumableStage", "Store", "claimed", "claims", "differing_keys",
    "test_stage", "walk",
]  # fmt: skip
