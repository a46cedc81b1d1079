"""Tests of ``poro2d.interop``: export, import and the runs in LAMMPS and YADE."""
