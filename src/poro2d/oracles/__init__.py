"""Independent oracles: the same answers by a different method, in different code.

- ``engine_step``: one DEM step in plain NumPy (every pair tested directly, history in a
  dict), against which the compiled engine (:mod:`poro2d.dem`) is checked step by step;
- ``jamming``: the frictionless jamming fraction of a grading's disks in a periodic cell
  (FIRE, O'Hern's protocol), the reference for the dense end of the preparation (the
  tests, the pre-flight of a user's soil and the check of an over-full trial ask it).

Neither imports the engine or the compaction: an oracle that shared their code would
repeat their mistakes.
"""
