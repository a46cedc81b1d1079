"""The laboratory-test kit: what every box test (direct shear, biaxial) and the periodic cell share.

A test's settings that are also its files' table (:mod:`~poro2d.labtest.settings`), the box and
consolidation records and the base of a test's line in its study (:mod:`~poro2d.labtest.records`),
a curve of named columns (:mod:`~poro2d.labtest.curve`) and the servo-settle action
(:mod:`~poro2d.labtest.settle`). A new test is a case, a box, its stages and its readings built
on these.
"""
