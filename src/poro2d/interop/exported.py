"""The specimen an export writes: found in what the user named, and checked before any file.

``poro2d export`` takes a checkpoint, a criterion folder, or a folder of states (a relation,
a density-mode criterion or a ``sand`` folder) with the state asked for; this module holds that
search as a Python call, so that a script or notebook exports as the command does.
"""

from __future__ import annotations

from pathlib import Path

from poro2d.errors import InputError
from poro2d.interop.origin import origin_lines
from poro2d.interop.specimen_data import from_checkpoint, resolve_specimen
from poro2d.interop.state_specimen import STATE_RECORDS, state_record, state_specimen
from poro2d.io_utils import check_output_dir
from poro2d.specimen.accepted import check_accepted


def export_specimen(specimen, out: str | Path, *, n_lab=None, dr=None, seed=None):
    """(specimen, state) of ``export``: the specimen with its provenance lines, and the
    :class:`~poro2d.interop.state_specimen.StateSpecimen` it was found by (None for a checkpoint
    or criterion folder given as such).

    A specimen the criterion did not accept is refused; so are the options of a folder of
    states given with anything else (rather than ignored).
    """

    has_specimen = Path(specimen).is_file() or (Path(specimen) / "specimen.npz").is_file()
    record = None if has_specimen else state_record(specimen)
    if record is None:
        for option, value in (("--n-lab", n_lab), ("--dr", dr), ("--seed", seed)):
            if value is not None:
                what = "is a specimen" if has_specimen else "holds neither a specimen nor a record of states"
                allowed = "only with a folder of states (" + ", ".join(STATE_RECORDS) + ")"
                raise InputError(option, value, allowed, f"{specimen} {what}")
        check_output_dir("--out", out)
        check_accepted(specimen)
        return from_checkpoint(specimen), None
    state = state_specimen(specimen, n_lab=n_lab, dr=dr, seed=0 if seed is None else seed)
    check_output_dir("--out", out)
    check_accepted(state.folder)
    spec = from_checkpoint(state.folder)
    spec.origin = origin_lines(resolve_specimen(state.folder), state)
    return spec, state
