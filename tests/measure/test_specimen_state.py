"""Homogeneity and stress state of a specimen: stresses from the contacts against statics."""

import numpy as np
import pytest

from poro2d.errors import InputError
from poro2d.grading import paper_grading
from poro2d.measure.specimen_state import specimen_state
from poro2d.report.specimen_figures import plot_specimen_state
from poro2d.specimen.compaction import SpecimenSpec, prepare_specimen


@pytest.fixture(scope="module")
def settled():
    """A specimen resting under its own weight: frictionless side walls, plate lifted off."""
    spec = SpecimenSpec(width=0.1, height=0.05, layers=2, friction_wall=0.0)
    sim, _ = prepare_specimen(spec, paper_grading(), 0.19, 1)
    sim.translate_wall("top", 0.0, 0.02)
    assert sim.solve(1e-4, 400_000).converged
    p = sim.particles
    surface = float(np.max(p.pos[:, 1] + p.radius))
    return sim, spec, surface


def test_vertical_stress_carries_the_weight_above(settled):
    """With frictionless side walls each band's sigma_v (Love-Weber, from the contacts) is the
    weight of the disks above it per unit width: statics, not a fit."""
    sim, spec, surface = settled
    st = specimen_state(sim, spec.width, surface, bands=5)
    rows = st.bands
    sv = np.array([r.sigma_v_pa for r in rows])
    assert np.all(np.diff(sv) < 0)  # grows with depth
    # the top band holds only a few disks and its own surface: compare the four below it
    for r in rows[:-1]:
        assert r.sigma_v_pa == pytest.approx(r.sigma_v_geostatic_pa, rel=0.08)
    # the weight of everything reaches the floor: the bottom wall force is the disks' weight
    weight = float(np.sum(sim.particles.mass)) * 9.81 / sim.particles.thickness
    assert -sim.wall_force("bottom")[1] / sim.particles.thickness == pytest.approx(weight, rel=1e-3)
    assert 0.0 < st.porosity_range < 0.2 and st.k0_mean > 0


def test_figure_and_band_count(settled, tmp_path):
    sim, spec, surface = settled
    st = specimen_state(sim, spec.width, surface, bands=4)
    assert len(st.bands) == 4 and st.bands[-1].z_top_m == pytest.approx(surface)
    path = plot_specimen_state(st, tmp_path / "state.png", title="t")
    assert path.stat().st_size > 10_000
    with pytest.raises(InputError, match="bands"):
        specimen_state(sim, spec.width, surface, bands=1)
