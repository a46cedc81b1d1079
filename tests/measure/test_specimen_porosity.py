"""Porosity of a specimen away from its walls and surface: lattices with known porosity, the
Laguerre cells against Voronoi and against a brute-force power assignment, the plate's gap."""

import json
import math

import numpy as np
import pytest
from scipy.spatial import Voronoi

from poro2d.errors import InputError
from poro2d.measure import surface
from poro2d.measure.disks import mass_d50
from poro2d.measure.interior import interior_regions
from poro2d.measure.laguerre import laguerre_cells
from poro2d.measure.specimen_porosity import MEASURES, SpecimenPorosity, measure_specimen
from poro2d.measure.surface import plate_surface, surface_profile
from poro2d.report.specimen_figures import plot_local_porosity

HEX_POROSITY = 1.0 - math.pi / (2.0 * math.sqrt(3.0))
SQUARE_POROSITY = 1.0 - math.pi / 4.0


def hex_lattice(cols: int, rows: int, r: float = 0.5):
    """Touching equal disks on a triangular lattice, odd rows shifted by r; the box fits them."""
    d = 2.0 * r
    pts = []
    for j in range(rows):
        y = r + j * d * math.sqrt(3.0) / 2.0
        shift = r if j % 2 else 0.0
        pts += [(r + shift + i * d, y) for i in range(cols)]
    pos = np.array(pts)
    return pos, np.full(len(pos), r), cols * d + r, pos[-1, 1] + r


def square_lattice(cols: int, rows: int, r: float = 0.5):
    d = 2.0 * r
    gx, gy = np.meshgrid(r + d * np.arange(cols), r + d * np.arange(rows))
    pos = np.column_stack([gx.ravel(), gy.ravel()])
    return pos, np.full(len(pos), r), cols * d, rows * d


def random_packing(cols: int, rows: int, seed: int = 0):
    """Non-overlapping polydisperse disks: one per unit cell, jittered, radii 0.15-0.35."""
    rng = np.random.default_rng(seed)
    gx, gy = np.meshgrid(np.arange(cols) + 0.5, np.arange(rows) + 0.5)
    pos = np.column_stack([gx.ravel(), gy.ravel()]) + rng.uniform(-0.1, 0.1, (cols * rows, 2))
    return pos, rng.uniform(0.15, 0.35, cols * rows), float(cols), float(rows)


@pytest.fixture(scope="module")
def hexagonal():
    pos, r, W, H = hex_lattice(40, 32)
    return pos, r, W, H, measure_specimen(pos, r, W, H)


def test_hexagonal_packing_interior_porosity(hexagonal):
    """Away from the walls a triangular lattice of touching disks has 1 - pi / (2 sqrt 3)."""
    pos, r, W, H, m = hexagonal
    assert m.d50_m == 1.0 and m.interior_regions >= 3
    assert m.interior_porosity == pytest.approx(HEX_POROSITY, abs=1e-3)
    assert np.all(np.abs(m.details.interior.porosity - HEX_POROSITY) < 2.5e-3)  # each circle
    assert m.laguerre_interior_porosity == pytest.approx(HEX_POROSITY, abs=1e-12)
    assert m.interior_rect_porosity == pytest.approx(HEX_POROSITY, abs=3e-3)
    # the walls loosen the box: its porosity is above the lattice's, the interior's is not
    assert m.box_porosity > HEX_POROSITY + 0.01
    # every interior cell is the lattice's regular hexagon, 2 sqrt(3) r^2
    cells = m.details.cells
    x0, y0, x1, y1 = m.details.interior.rect
    inside = (pos[:, 0] > x0) & (pos[:, 0] < x1) & (pos[:, 1] > y0) & (pos[:, 1] < y1)
    assert np.allclose(cells.area[inside], 2.0 * math.sqrt(3.0) * 0.25, rtol=1e-9)


def test_square_packing_interior_porosity():
    pos, r, W, H = square_lattice(36, 26)
    m = measure_specimen(pos, r, W, H)
    assert m.laguerre_interior_porosity == pytest.approx(SQUARE_POROSITY, abs=1e-12)  # unit square cells
    # a square lattice fills its box exactly: the box is the lattice, the plate touches every top disk
    assert m.box_porosity == pytest.approx(SQUARE_POROSITY, abs=1e-12)
    assert m.plate_touching_disks == 36


def test_square_packing_circles_average_to_the_lattice_over_phases():
    """In a crystal one circle's porosity depends on where its centre falls in the lattice cell:
    up to +/- 0.008 for a circle of radius 4 d in a square lattice, and the circles of one
    specimen may all share a bad phase (in a 36 x 26 box all six are 0.006-0.007 low). Boxes of
    other sizes put the circles at other phases; over them the circles average to 1 - pi / 4."""
    values = []
    for k in range(10):
        pos, r, W, H = square_lattice(36 + k, 26 + (3 * k) % 10)
        values.append(interior_regions(pos, r, W, H).porosity)
    values = np.concatenate(values)
    assert values.size > 80
    assert np.all(np.abs(values - SQUARE_POROSITY) < 0.008)
    assert float(np.mean(values)) == pytest.approx(SQUARE_POROSITY, abs=1e-3)


def test_laguerre_cells_tile_the_box():
    pos, r, W, H = random_packing(30, 20, seed=3)
    cells = laguerre_cells(pos, r, W, H)
    assert cells.empty == 0
    assert float(np.sum(cells.area)) == pytest.approx(W * H, rel=1e-9)
    # each polygon's own shoelace area is its reported area, and all vertices lie in the box
    polys = cells.polygons()
    shoelace = [0.5 * np.sum(p[:, 0] * np.roll(p[:, 1], -1) - np.roll(p[:, 0], -1) * p[:, 1]) for p in polys]
    assert np.allclose(shoelace, cells.area, rtol=1e-9, atol=1e-12)
    v = cells.vertices
    assert v[:, 0].min() > -1e-9 and v[:, 0].max() < W + 1e-9
    assert v[:, 1].min() > -1e-9 and v[:, 1].max() < H + 1e-9


def test_laguerre_cells_are_power_cells():
    """A point of the box belongs to the disk of least power |p - c|^2 - r^2: brute force on
    random points, for disks of very different sizes."""
    pos, r, W, H = random_packing(15, 10, seed=5)
    r = r * np.where(np.arange(r.size) % 3 == 0, 1.4, 0.6)  # big and small neighbours
    cells = laguerre_cells(pos, r, W, H)
    polys = cells.polygons()
    rng = np.random.default_rng(7)
    pts = rng.uniform([0.0, 0.0], [W, H], (500, 2))
    power = np.sum((pts[:, None, :] - pos[None]) ** 2, axis=2) - r[None] ** 2
    owner = np.argmin(power, axis=1)
    for p, k in zip(pts, owner, strict=True):
        poly = polys[k]
        edge = np.roll(poly, -1, axis=0) - poly
        rel = p - poly
        cross = edge[:, 0] * rel[:, 1] - edge[:, 1] * rel[:, 0]
        assert np.all(cross >= -1e-9), f"point {p} not in the cell of disk {k}"


def test_equal_radii_give_the_voronoi_diagram():
    rng = np.random.default_rng(11)
    W, H = 20.0, 14.0
    pos = rng.uniform([0.5, 0.5], [W - 0.5, H - 0.5], (250, 2))
    r = np.full(len(pos), 0.3)  # overlaps do not matter to the diagram
    cells = laguerre_cells(pos, r, W, H)
    vor = Voronoi(pos)
    checked = 0
    for i, region_index in enumerate(vor.point_region):
        region = vor.regions[region_index]
        if -1 in region or not region:
            continue
        verts = vor.vertices[region]
        if verts.min() < 0.1 or np.any(verts[:, 0] > W - 0.1) or np.any(verts[:, 1] > H - 0.1):
            continue  # a cell the box cuts
        area = 0.5 * abs(
            np.sum(verts[:, 0] * np.roll(verts[:, 1], -1) - np.roll(verts[:, 0], -1) * verts[:, 1])
        )
        assert cells.area[i] == pytest.approx(area, rel=1e-9)
        mine = cells.polygons()[i]
        dist = np.min(np.hypot(*(mine[:, None, :] - verts[None]).transpose(2, 0, 1)), axis=0)
        assert np.all(dist < 1e-9)  # every Voronoi vertex is a vertex of the cell
        checked += 1
    assert checked > 100


def test_a_disk_inside_a_big_one_has_an_empty_cell():
    """A small disk mostly inside a big one can lose its power cell: area 0, local porosity NaN."""
    pos = np.array([[5.0, 5.0], [5.5, 5.0], [2.0, 2.0], [2.0, 8.0]])
    r = np.array([2.0, 0.2, 1.0, 1.0])
    cells = laguerre_cells(pos, r, 9.0, 10.0)
    assert cells.empty == 1 and cells.area[1] == 0.0 and np.isnan(cells.local_porosity[1])
    assert float(np.sum(cells.area)) == pytest.approx(90.0, rel=1e-9)
    assert len(cells.polygons()[1]) == 0


def test_plate_above_a_flat_top_gives_the_analytic_gap():
    """Over a row of touching disks the surface's mean level is y_c + pi r / 4; a plate g above
    the disks' tops leaves a mean gap g + r (1 - pi / 4). The largest gap, g + r at the contacts,
    is seen from the samples nearest them, dx / 2 away: g + r - sqrt(2 r (dx / 2) - (dx / 2)^2)."""
    pos, r, W, H = square_lattice(12, 4)
    g = 0.3
    plate = plate_surface(pos, r, W, H + g, d50=1.0, bins=24_000)
    assert plate.gap_mean_m == pytest.approx(g + 0.5 * (1.0 - math.pi / 4.0), rel=1e-4)
    assert plate.gap_mean_d50 == pytest.approx(plate.gap_mean_m)
    half = 0.5 * W / 24_000
    assert plate.gap_max_m == pytest.approx(g + 0.5 - math.sqrt(2 * 0.5 * half - half**2), rel=1e-9)
    assert plate.contact_fraction == 0.0 and plate.touching_disks == 0


def test_plate_touching_a_flat_top():
    """A plate on the row's tops touches every top disk; the surface is within tol of it where
    sqrt(r^2 - x^2) > r - tol, over 2 sqrt(2 r tol - tol^2) of each disk's width."""
    pos, r, W, H = square_lattice(12, 4)
    plate = plate_surface(pos, r, W, H, d50=1.0, contact_tol_d50=0.05, bins=24_000)
    assert plate.touching_disks == 12
    assert plate.contact_fraction == pytest.approx(2.0 * math.sqrt(2 * 0.5 * 0.05 - 0.05**2), abs=1e-3)
    assert plate.gap_mean_m == pytest.approx(0.5 * (1.0 - math.pi / 4.0), rel=1e-4)


def test_disks_pressed_into_the_plate_leave_no_negative_gap():
    """With the plate e below the tops, the caps above it count as zero gap, not as negative:
    the mean gap is the unclipped r (1 - pi / 4) - e plus the caps' area per unit width."""
    pos, r, W, H = square_lattice(12, 4)
    e = 0.01
    plate = plate_surface(pos, r, W, H - e, d50=1.0, bins=24_000)
    cap = 0.25 * math.acos((0.5 - e) / 0.5) - (0.5 - e) * math.sqrt(2 * 0.5 * e - e**2)
    assert plate.gap_mean_m == pytest.approx(0.5 * (1.0 - math.pi / 4.0) - e + cap, rel=1e-4)
    assert plate.touching_disks == 12


def test_surface_profile_matches_a_loop_and_does_not_depend_on_chunks(monkeypatch):
    pos, r, W, H = random_packing(12, 5, seed=2)
    x, h = surface_profile(pos, r, W, 500)
    expected = np.zeros_like(x)
    for (cx, cy), ri in zip(pos, r, strict=True):
        inside = np.abs(x - cx) <= ri
        expected[inside] = np.maximum(expected[inside], cy + np.sqrt(ri**2 - (x[inside] - cx) ** 2))
    assert np.allclose(h, expected, rtol=0, atol=1e-12)
    monkeypatch.setattr(surface, "_PAIRS_PER_CHUNK", 37)
    assert np.array_equal(surface_profile(pos, r, W, 500)[1], h)


def test_surface_level_sits_below_the_tops_and_decides_the_interior():
    """The top margin is kept from the smoothed surface: for a flat lattice row its mean level."""
    pos, r, W, H = square_lattice(36, 26)
    reg = interior_regions(pos, r, W, H, margin_d50=2.0, circle_d50=3.0)
    level = H - 0.5 + 0.5 * math.pi / 4.0
    assert reg.surface_level_m == pytest.approx(level, abs=2e-3)
    assert reg.rect == pytest.approx((2.0, 2.0, W - 2.0, level - 2.0), abs=2e-3)
    assert np.all(reg.centres[:, 1] + reg.circle_radius_m <= reg.rect[3] + 1e-12)
    gaps = np.hypot(*(reg.centres[:, None, :] - reg.centres[None]).transpose(2, 0, 1))
    assert np.min(gaps + np.eye(reg.count) * 1e9) >= 2 * reg.circle_radius_m - 1e-12  # no overlap


def test_small_specimens_get_smaller_circles_then_a_refusal_naming_the_margin():
    pos, r, W, H = hex_lattice(20, 12)  # 20 d x 10.4 d: no room for 3 circles of 4 d50
    m = measure_specimen(pos, r, W, H)
    assert m.interior_regions >= 3
    assert 1.5 * m.d50_m <= m.circle_radius_m < 4.0 * m.d50_m
    assert m.interior_porosity == pytest.approx(1.0 - np.pi / (2.0 * np.sqrt(3.0)), abs=0.01)
    pos, r, W, H = hex_lattice(12, 7)  # 12 d x 6 d: not even 3 circles of 1.5 d50
    with pytest.raises(InputError, match="margin_d50") as err:
        measure_specimen(pos, r, W, H)
    assert "too small" in str(err.value)
    with pytest.raises(InputError, match="margin_d50"):
        measure_specimen(pos, r, W, H, margin_d50=-1.0)
    with pytest.raises(InputError, match="pos"):
        measure_specimen(pos, r, W, H - 1.0)  # the top row's centres above the plate
    with pytest.raises(InputError, match="radius"):
        measure_specimen(pos, r[:-1], W, H)


def test_measure_specimen_box_porosity_and_dict_round_trip(tmp_path):
    pos, r, W, H = random_packing(36, 24, seed=9)
    plate = H + 3.0
    m = measure_specimen(pos, r, W, plate)
    assert m.box_porosity == 1.0 - float(np.sum(np.pi * r**2)) / (W * plate)
    assert m.interior_porosity_min <= m.interior_porosity <= m.interior_porosity_max
    assert m.interior_porosity < m.box_porosity  # the 3 d gap under the plate belongs to the box only
    assert m.d50_m == mass_d50(r) and m.margin_d50 == 2.0
    d = m.to_dict()
    assert all(type(v) in (float, int) for v in d.values())
    assert type(d["interior_regions"]) is int and type(d["plate_touching_disks"]) is int
    back = SpecimenPorosity.from_dict(json.loads(json.dumps(d, allow_nan=False)))
    assert back.to_dict() == m.to_dict() and back.to_dict() == d
    numpy_typed = SpecimenPorosity(
        **{k: np.float64(v) if type(v) is float else np.int64(v) for k, v in d.items()}
    )
    assert numpy_typed.to_dict() == d and all(type(v) in (float, int) for v in numpy_typed.to_dict().values())
    assert type(numpy_typed.to_dict()["interior_regions"]) is int
    path = plot_local_porosity(pos, r, W, plate, m, tmp_path / "local.png", title="random")
    assert path.stat().st_size > 20_000


def test_one_record_is_the_measures_and_the_criterions_file():
    """measure_specimen's record holds the measures alone; the criterion's specimen_porosity.json
    adds the trial porosity and provenance, or only a note for a specimen too small to measure."""
    pos, r, W, H = random_packing(36, 24, seed=9)
    m = measure_specimen(pos, r, W, H + 3.0)
    assert list(m.to_dict()) == list(MEASURES) and m.details is not None and "details" not in m.to_dict()
    m.trial_porosity, m.provenance = 0.2, {"poro2d_version": "x"}
    assert list(m.to_dict()) == [*MEASURES, "trial_porosity", "provenance"]
    small = {"trial_porosity": 0.2, "note": "specimen too small for the margin", "provenance": {}}
    assert SpecimenPorosity(**small).to_dict() == small
    back = SpecimenPorosity.from_dict(small)
    assert back.to_dict() == small and back.box_porosity is None and "box_porosity" not in back.to_dict()


def test_mass_d50_is_the_median_by_area():
    assert mass_d50([1.0, 1.0, 1.0, 3.0]) == 6.0  # the big disk holds 9/12 of the area
    assert mass_d50([2.0, 1.0, 1.0, 1.0, 1.0, 1.0]) == 2.0  # the five small disks hold 5/9
    assert mass_d50([0.5] * 7) == 1.0
    with pytest.raises(InputError, match="radius"):
        mass_d50([1.0, -1.0])
