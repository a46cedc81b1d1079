"""Rolling resistance (elastic-plastic rolling spring) against analytic results.

* a disk on an incline with sliding prevented: at rest below tan(theta) = mu_r, rolling
  above it with the acceleration of a rolling disk braked by the limit moment;
* the limit moment mu_r R Fn of disk-wall and disk-disk contacts (R = r1 r2 / (r1 + r2)),
  the rolling stiffness ks R^2 below it, the smaller mu_r of the two bodies;
* the energy a rolling spring dissipates over a rotation cycle: the limit moment times
  the plastic rotation;
* the history across list rebuilds, renumbering and checkpoints;
* mu_r = 0 gives the numbers of the engine before rolling resistance, bit for bit.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from poro2d.dem import checkpoint
from poro2d.dem.simulation import Simulation
from poro2d.dem.state import Particles, Walls
from poro2d.errors import InputError
from tests.rolling_baseline import CASES, baseline_state

DATA = Path(__file__).parents[1] / "data"
R = 1e-3
RHO = 2650.0
T = 0.01
KN = 1e6
KS = 0.7e6
G = 9.81


# --------------------------------------------------------------------------- incline
def _disk_on_incline(theta: float, mu_r: float, damping: float) -> Simulation:
    """A disk resting on a plane, gravity tilted by ``theta``; sliding friction 5 stops slip."""
    mass = RHO * math.pi * R * R * T
    overlap = mass * G * math.cos(theta) / (0.5 * KN)  # disk and plane springs in series
    p = Particles(
        pos=[[0.0, R - overlap]], radius=R, density=RHO, thickness=T, kn=KN, ks=KS, mu=5.0, mu_r=mu_r
    )
    w = Walls()
    w.add((-1.0, 0.0), (1.0, 0.0), KN, KS, 5.0, "plane", mu_r=mu_r)
    return Simulation(p, w, gravity=(G * math.sin(theta), -G * math.cos(theta)), local_damping=damping)


MU_R = 0.3


def test_disk_below_its_rolling_limit_stays_put():
    """tan(theta) = 0.8 mu_r: the limit moment holds the disk (no damping: nothing else could)."""
    sim = _disk_on_incline(math.atan(0.8 * MU_R), MU_R, damping=0.0)
    x0 = float(sim.particles.pos[0, 0])
    sim.run(20_000)  # about 0.05 s: a rolling disk would cover over 2 mm
    assert abs(sim.particles.pos[0, 0] - x0) < 1e-4 * R
    assert abs(sim.particles.vel[0, 0]) < 1e-4
    # and the same disk without rolling resistance rolls away
    free = _disk_on_incline(math.atan(0.8 * MU_R), 0.0, damping=0.0)
    free.run(20_000)
    assert free.particles.pos[0, 0] - x0 > 0.5 * R


def test_disk_below_its_rolling_limit_comes_to_rest_with_damping():
    sim = _disk_on_incline(math.atan(0.8 * MU_R), MU_R, damping=0.3)
    sim.run(20_000)
    assert np.hypot(*sim.particles.vel[0]) < 1e-7
    assert abs(sim.particles.omega[0]) < 1e-4


@pytest.mark.parametrize("factor", [1.2, 2.0])
def test_disk_above_its_rolling_limit_rolls_with_the_braked_acceleration(factor):
    """tan(theta) = factor mu_r: a = (g sin(theta) - M_lim / (m R)) / (1 + I / (m R^2))."""
    theta = math.atan(factor * MU_R)
    sim = _disk_on_incline(theta, MU_R, damping=0.0)
    x0 = float(sim.particles.pos[0, 0])
    sim.run(20_000)
    # M_lim = mu_r R m g cos(theta); I = m R^2 / 2
    a = (2.0 / 3.0) * G * (math.sin(theta) - MU_R * math.cos(theta))
    t = sim.time
    assert sim.particles.pos[0, 0] - x0 == pytest.approx(0.5 * a * t * t, rel=0.01)
    assert sim.particles.vel[0, 0] == pytest.approx(a * t, rel=0.01)
    # rolling, not sliding: the rim speed matches the centre's
    assert -sim.particles.omega[0] * R == pytest.approx(sim.particles.vel[0, 0], rel=0.01)
    _pp, pw = sim.rolling_moments()
    fn = sim.contacts().fn[0]
    assert pw[0] == pytest.approx(MU_R * R * fn, rel=1e-12)  # the limit, resisting the roll


# ----------------------------------------------------------------------- limit moment
def _pressed_disk(mu_r_disk: float, mu_r_wall: float, overlap: float) -> Simulation:
    """A disk held (prescribed) against a frictionless plane, its spin imposed."""
    p = Particles(pos=[[0.0, R - overlap]], radius=R, density=RHO, thickness=T, kn=KN, ks=KS, mu=0.0,
                  mu_r=mu_r_disk)  # fmt: skip
    w = Walls()
    w.add((-1.0, 0.0), (1.0, 0.0), 2 * KN, 2 * KS, 0.0, "plane", mu_r=mu_r_wall)
    w.add((-1.0, 0.5), (1.0, 0.5), KN, KS, 0.0, "far")  # touches nothing: moved to force rebuilds
    sim = Simulation(p, w, gravity=(0.0, 0.0), local_damping=0.0)
    sim.fix_particles(np.array([True]), omega=50.0)
    return sim


def _series(a: float, b: float) -> float:
    return a * b / (a + b)


def test_disk_wall_limit_moment_and_stiffness():
    overlap = 1e-5
    sim = _pressed_disk(0.4, 0.25, overlap)
    fn = _series(KN, 2 * KN) * overlap
    kr = _series(KS, 2 * KS) * R * R
    sim.run(10)
    assert sim.moment[0] == pytest.approx(-kr * 50.0 * 10 * sim.dt, rel=1e-9)  # elastic
    sim.run(20_000)
    limit = 0.25 * R * fn  # the smaller of the two rolling frictions
    assert sim.moment[0] == pytest.approx(-limit, rel=1e-9)
    assert np.allclose(sim.wall_force("plane"), (0.0, -fn), rtol=1e-9)  # a couple: no force
    sim.particles.omega[0] = -50.0
    sim.run(20_000)
    assert sim.moment[0] == pytest.approx(limit, rel=1e-9)


def _two_disks(r1: float, r2: float, overlap: float, mu_r: tuple[float, float]) -> Simulation:
    p = Particles(pos=[[0.0, 0.0], [r1 + r2 - overlap, 0.0]], radius=[r1, r2], density=RHO, thickness=T,
                  kn=[KN, 2 * KN], ks=[KS, 2 * KS], mu=0.0, mu_r=list(mu_r))  # fmt: skip
    w = Walls()
    w.add((-1.0, 0.5), (1.0, 0.5), KN, KS, 0.0, "far")
    sim = Simulation(p, w, gravity=(0.0, 0.0), local_damping=0.0)
    sim.fix_particles(np.array([True, True]))
    sim.particles.omega[:] = (30.0, -20.0)
    return sim


def test_disk_disk_limit_moment_with_effective_radius():
    r1, r2, overlap = 1e-3, 2e-3, 1e-5
    sim = _two_disks(r1, r2, overlap, (0.5, 0.2))
    reff = r1 * r2 / (r1 + r2)
    fn = _series(KN, 2 * KN) * overlap
    kr = _series(KS, 2 * KS) * reff * reff
    sim.run(10)
    elastic = kr * (30.0 - -20.0) * 10 * sim.dt
    assert sim.moment == pytest.approx([-elastic, elastic], rel=1e-9)
    sim.run(20_000)
    limit = 0.2 * reff * fn
    assert sim.moment == pytest.approx([-limit, limit], rel=1e-9)


def test_rolling_moment_survives_rebuilds_and_renumbering():
    sim = _two_disks(1e-3, 2e-3, 1e-5, (0.3, 0.3))
    sim.run(20_000)
    at_limit = sim.moment.copy()
    sim.particles.omega[:] = 0.0
    sim.translate_wall("far", 0.0, 0.0)  # forces a list rebuild before the next step
    res = sim.run(5)
    assert res.rebuilds == 1
    assert np.array_equal(sim.moment, at_limit)  # history kept, nothing turned
    sim.reorder(np.array([1, 0]))  # the pair's first disk changes
    sim.run(5)
    assert np.array_equal(sim.moment, at_limit[::-1])


def test_losing_contact_ends_the_rolling_history():
    sim = _two_disks(1e-3, 1e-3, 1e-5, (0.3, 0.3))
    sim.run(20_000)
    sim.particles.vel[1] = (0.5, 0.0)  # pulled apart, then pushed back
    sim.run(100)
    assert sim.moment[0] == 0.0
    sim.particles.vel[1] = (-0.5, 0.0)
    sim.particles.omega[:] = 0.0
    sim.run(100)
    assert sim.contacts().fn.size == 1 and sim.moment[0] == 0.0


# ------------------------------------------------------------------------- energy
def test_energy_dissipated_over_a_rotation_cycle():
    """Work put in by the imposed rotation = spring energy left + limit moment x plastic rotation."""
    overlap = 1e-5
    mu_r = 0.3
    sim = _pressed_disk(mu_r, mu_r, overlap)
    fn = _series(KN, 2 * KN) * overlap
    kr = _series(KS, 2 * KS) * R * R
    m_lim = mu_r * R * fn
    theta_y = m_lim / kr
    omega = 2.0
    n_leg = round(3.0 * theta_y / (omega * sim.dt))  # amplitude 3 theta_y, ~1000 steps to yield
    assert n_leg > 2000
    theta_a = n_leg * omega * sim.dt
    work = 0.0
    m_prev = 0.0
    for spin, legs in ((omega, 1), (-omega, 2), (omega, 2)):
        sim.particles.omega[0] = spin
        for _ in range(legs * n_leg):
            sim.run(1)
            m = float(sim.moment[0])
            work -= 0.5 * (m + m_prev) * spin * sim.dt  # exact for the elastic steps
            m_prev = m
    # 0 -> +a, +a -> -a, -a -> +a: plastic rotation (a - y) + 2 (2a - 2y)
    dissipated = m_lim * 5.0 * (theta_a - theta_y)
    stored = m_lim**2 / (2.0 * kr)
    assert m_prev == pytest.approx(-m_lim, rel=1e-12)
    # the trapezoid sum is exact while elastic; only the steps that cross the limit differ
    assert work == pytest.approx(stored + dissipated, rel=1e-6)
    assert work - stored == pytest.approx(dissipated, rel=1e-6)


# ----------------------------------------------------------------- stability, inputs
def test_rolling_springs_stay_stable_at_the_automatic_step():
    """Rolling springs that never yield (mu_r huge) in a dense packing, without damping."""
    from tests.rolling_baseline import packing

    sim = packing(1, 2)
    sim.set_local_damping(0.0)
    dt_before = sim.dt
    sim.set_rolling_friction(1e6, walls=1e6)
    assert sim.dt < dt_before  # the rolling springs are allowed for
    sim.set_wall_velocity("top", (0.0, 0.0))
    sim.run(6000)
    assert np.all(np.isfinite(sim.particles.omega))
    assert float(np.abs(sim.particles.omega).max()) < 1e3


def test_bad_rolling_friction_is_refused():
    with pytest.raises(InputError, match="rolling friction"):
        Particles(pos=[[0.0, 0.0]], radius=R, density=RHO, thickness=T, kn=KN, ks=KS, mu=0.1, mu_r=-0.1)
    with pytest.raises(InputError, match="wall w rolling friction"):
        Walls().add((0.0, 0.0), (1.0, 0.0), KN, KS, 0.1, "w", mu_r=float("nan"))
    sim = _pressed_disk(0.1, 0.1, 1e-5)
    with pytest.raises(InputError, match="rolling friction"):
        sim.set_rolling_friction(-1.0)


# ------------------------------------------------------------------ checkpoints
def test_checkpoint_keeps_the_rolling_history(tmp_path):
    a = _two_disks(1e-3, 2e-3, 1e-5, (0.3, 0.2))
    a.run(1000)
    path = checkpoint.save(a, tmp_path / "a.npz")
    b = checkpoint.load(path)
    assert np.array_equal(b.particles.mu_r, a.particles.mu_r)
    a.run(2000)
    b.run(2000)
    assert np.array_equal(a.moment, b.moment) and np.array_equal(a.pairs.mr, b.pairs.mr)


def test_checkpoint_without_rolling_is_as_before(tmp_path):
    """No rolling arrays stored at mu_r = 0 (file and digest as before); loads with zeros."""
    sim = _two_disks(1e-3, 2e-3, 1e-5, (0.0, 0.0))
    sim.run(10)
    path = checkpoint.save(sim, tmp_path / "c.npz")
    with np.load(path) as z:
        names = set(z.files)
    assert not any("mu_r" in k or "_mr" in k for k in names)
    loaded = checkpoint.load(path)
    assert np.array_equal(loaded.particles.mu_r, [0.0, 0.0])
    assert loaded.walls.rolling_friction().tolist() == [0.0]
    assert not loaded.pairs.mr.any() and loaded.pairs.mr.shape == loaded.pairs.other.shape


# ------------------------------------------------------------- bit for bit at 0
@pytest.mark.parametrize("case", sorted(CASES))
def test_mu_r_zero_is_bit_identical_to_the_engine_before(case):
    """The state after 400 steps equals, bit for bit, that of the engine without rolling resistance."""
    saved = np.load(DATA / "rolling_off_baseline.npz")
    now = baseline_state(cases=(case,))
    keys = [k for k in saved.files if k.startswith(f"{case}.")]
    assert len(keys) == 9
    for key in keys:
        assert np.array_equal(saved[key], now[key]), key


# ------------------------------------------------------------------ LAMMPS export
def test_lammps_export_carries_the_rolling_spring(tmp_path):
    """k_roll = the contact's ks, mu_roll = the smaller mu_r, no rolling dashpot; none at mu_r = 0."""
    from poro2d.interop import lammps as lmp
    from poro2d.interop.specimen_data import from_simulation

    pos = [[2 * R, 1.5 * R], [5 * R, 1.5 * R], [8 * R, 1.5 * R]]
    p = Particles(pos=pos, radius=R, density=RHO, thickness=T, kn=KN, ks=KS, mu=0.5, mu_r=0.3)
    sim = Simulation(p, Walls.box(0.0, 0.0, 10 * R, 4 * R, 2 * KN, 2 * KS, 0.4, mu_r=0.1))
    spec = from_simulation(sim)
    ks_pp, ks_pw = _series(KS, KS), _series(KS, 2 * KS)
    script = lmp.input_script(spec)
    assert f"damping mass_velocity rolling sds {ks_pp!r} 0 0.3\n" in script  # pair_coeff
    assert script.count(f"damping mass_velocity rolling sds {ks_pw!r} 0 0.1 ") == 4  # the walls
    lmp.write_specimen(spec, tmp_path)
    assert "# poro2d rolling_friction 0.3 0.1 0.1 0.1 0.1\n" in (tmp_path / lmp.DATA_FILE).read_text()
    sim.set_rolling_friction(0.0)
    plain = lmp.input_script(from_simulation(sim))
    assert "rolling" not in plain
    with pytest.raises(InputError, match="granular"):
        lmp.contact_law("classic", KN, KS, 0.5, 0.3)


# ------------------------------------------------------------------ specimen settings
def test_specimen_rolling_friction_is_set_with_the_working_friction():
    from poro2d.specimen import paper_grading
    from poro2d.specimen.compaction import SpecimenSpec, prepare_specimen

    assert "rolling_friction" not in SpecimenSpec().to_dict()  # results written before keep their keys
    assert SpecimenSpec(rolling_friction=0.2).to_dict()["rolling_friction"] == 0.2
    from poro2d.config import dataclass_from_table

    assert dataclass_from_table(SpecimenSpec, "specimen", {"rolling_friction": 0.3}).rolling_friction == 0.3
    with pytest.raises(InputError, match="rolling_friction"):
        SpecimenSpec(rolling_friction=-0.1)
    spec = SpecimenSpec(width=0.06, height=0.03, layers=2, rolling_friction=0.2)
    sim, report = prepare_specimen(spec, paper_grading(), 0.21, seed=3)
    assert report.converged
    assert np.all(sim.particles.mu_r == 0.2) and np.all(sim.walls.rolling_friction() == 0.2)
    assert np.count_nonzero(sim.rolling_moments()[0]) > 0.5 * sim.rolling_moments()[0].size
