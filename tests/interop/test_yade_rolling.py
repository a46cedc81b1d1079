"""A rolled specimen's YADE script runs poro2d's rolling spring (Debian's ``yade``).

Checked in YADE itself: the rolling stiffness and cap of every contact (ks R^2 and mu_r R,
R = r1 r2 / (r1 + r2), the smaller mu_r), a disk on an incline against the analytic motion
of a rolling disk braked by its limit moment, and a settled specimen against poro2d.
"""

import json
import math
import os
import shutil
import subprocess
from dataclasses import replace

import numpy as np
import pytest

from poro2d.dem.simulation import Simulation
from poro2d.dem.state import Particles, Walls
from poro2d.interop import yade
from poro2d.interop.agreement import settle_poro2d
from poro2d.interop.settled import RestCase
from poro2d.interop.specimen_data import from_checkpoint, from_simulation
from poro2d.interop.yade_run import find_yade, settle_yade, yade_env

pytestmark = pytest.mark.scenario

G = 9.81
R = 1e-3
RHO = 2650.0
T = 0.01
KN = 1e6
KS = 0.7e6
MU_R = 0.3

#: runs the exported script's set-up (not its own run block), then STEPS steps, and prints
#: the first disk's motion and every contact's rolling spring as one JSON line
_DRIVER = """
import json, os
__name__ = "exported"
exec(compile(open("specimen_yade.py").read(), "specimen_yade.py", "exec"))
__name__ = "__main__"
O.run(int(os.environ["STEPS"]), True)
s = O.bodies[0].state
contacts = [
    {"ids": sorted([i.id1, i.id2]), "kr": i.phys.kr, "limit": i.phys.maxRollPl, "ks": i.phys.ks,
     "moment": abs(i.phys.moment_bending[2]), "fn": i.phys.normalForce.norm()}
    for i in O.interactions
]
print("poro2d-check", json.dumps({"time": O.time, "x": s.pos[0], "vx": s.vel[0], "omega": s.angVel[2],
                                  "contacts": contacts}))
"""


def _yade() -> None:
    if shutil.which("yade") is None and not os.environ.get("YADE_EXE"):
        if os.environ.get("CI", "").lower() == "true":
            pytest.fail("CI=true but Debian's yade is not installed (apt-get install -y yade)")
        pytest.skip("YADE is not installed (Debian: apt-get install -y yade; or set YADE_EXE)")


def _steps_in_yade(spec, workdir, steps: int) -> dict:
    """The exported script cycled ``steps`` steps in YADE (no stop at rest): what the driver printed."""
    _yade()
    yade.write_specimen(spec, workdir, ratio=0.0)
    (workdir / "driver.py").write_text(_DRIVER)
    env = yade_env() | {"STEPS": str(steps)}
    proc = subprocess.run(
        [find_yade(), "-n", "-x", "driver.py"],
        cwd=workdir,
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    )
    lines = [ln for ln in proc.stdout.splitlines() if ln.startswith("poro2d-check ")]
    assert proc.returncode == 0 and lines, proc.stderr[-2000:]
    return json.loads(lines[-1].split(" ", 1)[1])


def _disk_on_incline(theta: float) -> Simulation:
    """A disk resting on a plane, gravity tilted by ``theta``; sliding friction 5 stops slip."""
    mass = RHO * math.pi * R * R * T
    overlap = mass * G * math.cos(theta) / (0.5 * KN)
    p = Particles(
        pos=[[0.0, R - overlap]], radius=R, density=RHO, thickness=T, kn=KN, ks=KS, mu=5.0, mu_r=MU_R
    )
    w = Walls()
    w.add((-1.0, 0.0), (1.0, 0.0), KN, KS, 5.0, "plane", mu_r=MU_R)
    return Simulation(p, w, gravity=(G * math.sin(theta), -G * math.cos(theta)), local_damping=0.0)


def test_every_contact_gets_the_rolling_stiffness_and_cap_of_poro2d(tmp_path):
    """Two disks of radii 1 and 2 mm on a floor: mu_r 0.3 and 0.2 on the disks, 0.25 on the floor."""
    p = Particles(
        pos=[[0.0, 0.999e-3], [2.82e-3, 1.999e-3]], radius=[1e-3, 2e-3], density=RHO, thickness=T,
        kn=KN, ks=KS, mu=0.5, mu_r=[0.3, 0.2],
    )  # fmt: skip
    w = Walls()
    w.add((-0.01, 0.0), (0.01, 0.0), 2 * KN, 2 * KS, 0.5, "bottom", mu_r=0.25)
    spec = from_simulation(Simulation(p, w, gravity=(0.0, -G), local_damping=0.0))
    contacts = {tuple(c["ids"]): c for c in _steps_in_yade(spec, tmp_path, 1)["contacts"]}
    assert set(contacts) == {(0, 1), (0, 2), (1, 2)}  # disks 0, 1; the floor is body 2
    ks_wall = KS * 2 * KS / (3 * KS)
    expected = {
        (0, 1): (KS / 2, 1e-3 * 2e-3 / 3e-3, 0.2),  # R = r1 r2 / (r1 + r2), the smaller mu_r
        (0, 2): (ks_wall, 1e-3, 0.25),  # against a wall: the disk's radius
        (1, 2): (ks_wall, 2e-3, 0.2),
    }
    for ids, (ks, r_eff, mu_r) in expected.items():
        c = contacts[ids]
        assert c["kr"] == pytest.approx(ks * r_eff**2, rel=1e-12)
        assert c["limit"] == pytest.approx(mu_r * r_eff, rel=1e-12)


def test_a_disk_below_its_rolling_limit_stays_put_in_yade(tmp_path):
    """tan(theta) = 0.8 mu_r, no damping: only the rolling spring holds the disk."""
    sim = _disk_on_incline(math.atan(0.8 * MU_R))
    out = _steps_in_yade(from_simulation(sim), tmp_path, 20_000)
    assert abs(out["x"]) < 1e-4 * R
    assert abs(out["vx"]) < 1e-4


def test_a_disk_above_its_rolling_limit_rolls_with_the_braked_acceleration_in_yade(tmp_path):
    """tan(theta) = 1.2 mu_r: a = 2/3 g (sin(theta) - mu_r cos(theta)), rolling without slip."""
    theta = math.atan(1.2 * MU_R)
    sim = _disk_on_incline(theta)
    out = _steps_in_yade(from_simulation(sim), tmp_path, 20_000)
    a = (2.0 / 3.0) * G * (math.sin(theta) - MU_R * math.cos(theta))
    t = out["time"]
    assert out["x"] == pytest.approx(0.5 * a * t * t, rel=0.01)
    assert out["vx"] == pytest.approx(a * t, rel=0.01)
    assert -out["omega"] * R == pytest.approx(out["vx"], rel=0.01)
    (contact,) = out["contacts"]
    assert contact["moment"] == pytest.approx(MU_R * R * contact["fn"], rel=1e-12)  # at its limit


def test_a_rolled_specimen_settles_in_yade_as_in_poro2d(saved, tmp_path):
    """mu_r = 0.2 on disks and walls: the wall forces at rest agree to 1e-4 of the weight."""
    _yade()
    spec = from_checkpoint(saved)
    spec = replace(spec, mu_r=np.full(spec.n, 0.2), walls=[replace(w, mu_r=0.2) for w in spec.walls])
    theirs = settle_yade(RestCase(spec, ratio=1e-6, max_steps=200_000), tmp_path)
    ours = settle_poro2d(RestCase(spec, ratio=1e-8))
    assert theirs.converged and ours.converged
    g = spec.weight_per_thickness()
    for key in ("f_top_n_per_m", "f_bottom_n_per_m", "side_friction_up_n_per_m"):
        assert getattr(theirs, key) == pytest.approx(getattr(ours, key), abs=1e-4 * g)
    unrolled = settle_poro2d(
        RestCase(replace(spec, mu_r=None, walls=[replace(w, mu_r=0.0) for w in spec.walls]), ratio=1e-8)
    )
    # the plate's force moves with rolling resistance by more than the agreement: a real check
    assert abs(ours.f_top_n_per_m - unrolled.f_top_n_per_m) > 10 * abs(
        theirs.f_top_n_per_m - ours.f_top_n_per_m
    )
