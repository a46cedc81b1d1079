"""The store a study's one call writes to, held for the call.

A study (the relation, the sensitivity study, the criterion's density mode) is given a
:class:`~poro2d.store.Store` by its caller, the command making it from ``--out``. While the
study runs, its folder is held (:meth:`poro2d.store.Store.claim`): a second run writing
to the same folder is refused, not interleaved. Without a store nothing is kept: the
study's sweeps run in a scratch folder removed when it ends (a calibration still goes to
the shared cache, which is kept for every later run).
"""

from __future__ import annotations

import tempfile
from collections.abc import Iterator
from contextlib import contextmanager

from poro2d.execute.options import RunOptions
from poro2d.io_utils import check_output_dir
from poro2d.store import Store


@contextmanager
def study_store(store: Store | None, kind: str, options: RunOptions, announce=None) -> Iterator[Store]:
    """``store`` for a study's call: its folder and the scheduler checked, then ``announce()`` (the
    command's banner, so that a refusal stays its only line) and the store :func:`held`."""
    from poro2d.execute.dask_cluster import check_reachable

    if store is not None:
        check_output_dir(store.parameter, store.root)
    check_reachable(options.scheduler)
    if announce is not None:
        announce()
    with held(store, kind) as kept:
        yield kept


@contextmanager
def held(store: Store | None, kind: str | None = None) -> Iterator[Store]:
    """``store`` held for the block, as a ``kind`` run's folder (:meth:`~poro2d.store.Store.claim`);
    None: a scratch store, removed after the block."""
    if store is None:
        with tempfile.TemporaryDirectory(prefix="poro2d-") as scratch:
            yield Store(scratch)
        return
    with store.claim(kind):
        yield store


__all__ = ["held", "study_store"]
