"""The interop readers hand typed records on, never a file's raw JSON or a dump as a dict."""

import numpy as np
import pytest

from poro2d.interop.lammps_run import LammpsError, read_dump

_DUMP = """ITEM: TIMESTEP
0
ITEM: NUMBER OF ATOMS
2
ITEM: BOX BOUNDS pp pp pp
0 1
0 1
-0.5 0.5
ITEM: ATOMS id x y radius
1 0.1 0.2 0.01
2 0.3 0.4 0.02
ITEM: TIMESTEP
100
ITEM: NUMBER OF ATOMS
2
ITEM: BOX BOUNDS pp pp pp
0 1
0 1
-0.5 0.5
ITEM: ATOMS id x y radius
2 0.35 0.45 0.02
1 0.15 0.25000000000000006 0.01
"""


def test_a_dump_is_read_as_its_last_frame_with_columns_by_name(tmp_path):
    path = tmp_path / "final.dump"
    path.write_text(_DUMP)
    frame = read_dump(path)
    assert frame.columns == ("id", "x", "y", "radius")
    assert frame.values.shape == (2, 4)
    assert np.array_equal(frame.column("id"), [2.0, 1.0])  # the last snapshot, in its own order
    assert frame.column("y")[1] == 0.25000000000000006  # every digit as written
    frame.column("x")[0] = -1.0  # a copy: the frame is not changed through it
    assert frame.column("x")[0] == 0.35
    with pytest.raises(LammpsError, match=r"no column 'vx' \(it has id x y radius\)"):
        frame.column("vx")
