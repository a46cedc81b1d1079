"""Whether the laboratory data can tell the calibrated parameters apart, checked before any test.

A calibration fits two frictions, f_p and mu_r. Each laboratory value (a peak at one normal
stress, or the end stress of a whole curve) is one equation: with fewer values than
parameters, every pair on a line through the parameter plane reproduces the data as well as
any other, and the posterior's maximum is a point picked along that line by the surrogate's
curvature, not by the data. Such a calibration is refused: its answer would read as identified.
"""

from __future__ import annotations

from poro2d.errors import InputError


def check_enough_lab_values(source: str, targets: list[tuple[str, float, float]], parameters: int) -> None:
    """At least ``parameters`` laboratory values (``targets``: observable, normal stress, value)."""
    if len(targets) < parameters:
        given = ", ".join(f"{kind} at {sigma:g} kPa" for kind, sigma, _ in targets)
        raise InputError(
            "--lab", source,
            f"at least {parameters} laboratory values for the {parameters} calibrated frictions: peaks at "
            f"{parameters} normal stresses, or a whole curve (its peak and its end stress)",
            f"{len(targets)} given ({given}): the data fit a line of (f_p, mu_r) pairs equally",
        )  # fmt: skip


__all__ = ["check_enough_lab_values"]
