"""The wall servo against its closed-form steady state.

A disk is squeezed between a floor that rises at a constant speed ``v`` and a servo
plate above it (no gravity). Once the plate follows the floor, the proportional servo
moves at ``v = gain e / (k dt)``, so its force error settles at ``e = v k dt / gain``
exactly (``k`` the plate's contact stiffness); an integral term drives it to zero.
"""

from __future__ import annotations

import numpy as np
import pytest

from poro2d.dem import Particles, Simulation, Walls
from poro2d.dem.contact_law import series

R = 1e-3
K_DISK, K_WALL = 4e5, 1e7
V = 2e-3  # floor speed (m/s)
TARGET = 5.0  # N


def _squeezed_disk() -> Simulation:
    p = Particles(pos=[[0.0, 0.0]], radius=[R], density=2650.0, thickness=0.01, kn=K_DISK, ks=K_DISK, mu=0.5)
    w = Walls()
    w.add((-2 * R, -R), (2 * R, -R), K_WALL, K_WALL, 0.5, name="floor")
    w.add((-2 * R, R), (2 * R, R), K_WALL, K_WALL, 0.5, name="plate")
    return Simulation(p, w, gravity=(0.0, 0.0), local_damping=0.7)


def _plate_error(integral: float, gain: float = 0.5) -> tuple[float, float]:
    sim = _squeezed_disk()
    sim.set_wall_servo("plate", TARGET, (0.0, -1.0), max_speed=0.05, gain=gain, integral=integral)
    sim.run(20_000)  # reach the target and settle
    sim.set_wall_velocity("floor", (0.0, V))
    sim.run(60_000)
    force = sim.wall_force("plate")[1]  # the disk pushes the plate up: compressive > 0
    return TARGET - force, sim.dt


@pytest.mark.parametrize("gain", [0.25, 0.5])
def test_proportional_servo_lags_by_v_k_dt_over_gain(gain):
    err, dt = _plate_error(0.0, gain)
    k = series(K_DISK, K_WALL)
    # the plate retreats (against its compressing direction): the force overshoots the target
    assert err == pytest.approx(-V * k * dt / gain, rel=1e-3)


def test_integral_servo_removes_the_lag():
    err_p, dt = _plate_error(0.0)
    err_i, _ = _plate_error(1e-3)
    assert abs(err_p) > 1e-3 * TARGET
    assert abs(err_i) < 1e-3 * abs(err_p)


def test_servo_integral_bad_input():
    from poro2d.errors import InputError

    sim = _squeezed_disk()
    with pytest.raises(InputError, match="servo integral gain"):
        sim.set_wall_servo("plate", TARGET, (0.0, -1.0), 0.05, 0.5, integral=-1.0)
    assert np.isfinite(sim.dt)
