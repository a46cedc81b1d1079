"""The box's one home: wall names and order beside ``Walls.box``, its faces read back in one place."""

import numpy as np
import pytest

from poro2d.dem import Walls
from poro2d.dem.state import BOX_WALLS
from poro2d.errors import InputError
from poro2d.specimen.box import box_faces


def test_walls_box_adds_the_box_walls_in_their_order():
    w = Walls.box(0.0, 0.0, 0.305, 0.124, 1e7, 1e7, 1.5)
    assert tuple(w.names) == BOX_WALLS


def test_box_faces_reads_the_wall_lines_not_the_extended_segment_ends():
    w = Walls.box(-0.01, 0.02, 0.3, 0.15, 1e7, 1e7, 1.5)
    assert box_faces(w.names, w.p0) == (-0.01, 0.3, 0.02, 0.15)


def test_box_faces_ignores_other_walls_and_their_order():
    w = Walls.box(0.0, 0.0, 1.0, 2.0, 1e7, 1e7, 1.5)
    order = [3, 1, 0, 2]
    names = ["lid", *(w.names[k] for k in order)]
    p0 = np.vstack([[5.0, 5.0], w.p0[order]])
    assert box_faces(names, p0) == (0.0, 1.0, 0.0, 2.0)


def test_a_set_of_walls_without_the_four_of_a_box_is_refused_naming_the_parameter():
    w = Walls.box(0.0, 0.0, 1.0, 1.0, 1e7, 1e7, 1.5)
    named = r"specimen walls = \['bottom', 'right', 'top'\].*bottom, right, top, left"
    with pytest.raises(InputError, match=named):
        box_faces(w.names[:3], w.p0[:3], "specimen walls")
