"""Tests of ``poro2d.calibration``: ``poro2d calibrate``."""


def calibrate(*args, store=None, options=None, **kw):
    """``run_calibration`` of the case ``CalibrationCase.of(*args, **kw)``, as the command calls it."""
    from poro2d.calibration import CalibrationCase, run_calibration
    from poro2d.execute.options import RunOptions

    case = CalibrationCase.of(*args, **kw)
    return run_calibration(case, store, options=options or RunOptions(progress=False))
