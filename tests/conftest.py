"""Fixtures shared by several test modules: each is built once per session, then only read."""

import os

import pytest

# pytest-xdist starts its workers with COLUMNS=80: the commands' tables would then wrap as in an
# 80-column terminal, where a plain run writes them whole (poro2d.console); a worker sees what a
# plain run sees
if os.environ.get("PYTEST_XDIST_WORKER"):
    os.environ.pop("COLUMNS", None)
    os.environ.pop("LINES", None)

from poro2d.dem import checkpoint
from poro2d.specimen import paper_grading
from poro2d.specimen.compaction import SpecimenSpec, prepare_specimen


@pytest.fixture(scope="session")
def specimen(tmp_path_factory):
    """A small prepared specimen (0.06 m x 0.03 m, about 110 disks) saved as a checkpoint.

    Built once for the whole session: the shear, strength, rolling, protocol, export and
    calibration tests read it (a test that needs to change it works on a copy)."""
    sim, rep = prepare_specimen(SpecimenSpec(width=0.06, height=0.03, layers=2), paper_grading(), 0.2, seed=0)
    assert rep.converged
    path = tmp_path_factory.mktemp("specimen") / "specimen.npz"
    checkpoint.save(sim, path)
    return path


def default_sigint() -> None:
    """``preexec_fn`` for a child that must answer Ctrl-C: a shell without job control starts
    its background commands (``cmd &``, as a CI runner may) with SIGINT ignored, children
    inherit that, and Python then installs no KeyboardInterrupt handler."""
    import signal

    signal.signal(signal.SIGINT, signal.SIG_DFL)
