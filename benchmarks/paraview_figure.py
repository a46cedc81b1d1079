"""One step of a biaxial test's ParaView series as a figure (docs/paraview.md), and what it costs.

    python benchmarks/paraview_figure.py [--out docs/img/paraview_step.png] [--keep DIR]

Runs the built-in quick specimen (seed 0, about 320 disks) at sigma_3 = 100 kPa to an axial strain
of 0.03 twice, without and with ``vtk_every``, and prints the wall time of each and the cost of one
written step. The last step of the series is drawn as ParaView shows it after the steps of
docs/paraview.md: the disks glyphed at their radius, the contact network as tubes whose width and
colour follow the normal force, the walls. With pyvista installed (not a dependency of poro2d) it
is rendered by VTK off screen, as ParaView renders it (``--renderer pyvista``, the default when
pyvista imports); else the VTU file is read back with meshio and drawn with matplotlib.
"""

from __future__ import annotations

import argparse
import tempfile
import time
import xml.etree.ElementTree as ET
from pathlib import Path

#: the test: short enough for a minute on one core, long enough for force chains to form
SETTINGS = {"max_strain": 0.03, "record_strain": 0.001}


def run(folder: Path, vtk_every: int) -> float:
    """The quick biaxial test kept in ``folder``; its wall time (s)."""
    from poro2d.biaxial import BiaxialCase, BiaxialSettings, BiaxialTest
    from poro2d.store import Store

    settings = BiaxialSettings(**SETTINGS, vtk_every=vtk_every)
    t0 = time.perf_counter()
    BiaxialTest(BiaxialCase.quick(100.0, seed=0, settings=settings), Store(folder)).run()
    return time.perf_counter() - t0


def default_renderer() -> str:
    """pyvista when it imports, else matplotlib."""
    try:
        import pyvista  # noqa: F401
    except ImportError:
        return "matplotlib"
    return "pyvista"


def last_step(series: Path) -> tuple[Path, float, int]:
    """The file, axial strain and count of the series' steps (its last one)."""
    sets = ET.parse(series / "series_axial_strain.pvd").getroot().findall("./Collection/DataSet")
    return series / sets[-1].get("file"), float(sets[-1].get("timestep")), len(sets)


def draw(vtu: Path, strain: float, out: Path) -> None:
    """The step as ParaView's Glyph and colour-by-force view shows it, with matplotlib."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import meshio
    from matplotlib.collections import LineCollection, PatchCollection
    from matplotlib.patches import Circle

    mesh = meshio.read(vtu)
    n = len(mesh.cells_dict["vertex"])
    xy, r = mesh.points[:n, :2] * 1e3, mesh.point_data["radius"][:n] * 1e3
    lines = mesh.cells_dict["line"]
    kind = mesh.cell_data["cell_kind"][1]
    fn = mesh.cell_data["normal_force"][1]
    segments = mesh.points[lines][:, :, :2] * 1e3
    contact = kind >= 2
    fig, ax = plt.subplots(figsize=(3.6, 6.0), dpi=300)
    ax.add_collection(PatchCollection([Circle(c, q) for c, q in zip(xy, r, strict=True)],
                                      facecolor="0.88", edgecolor="0.55", linewidth=0.3))  # fmt: skip
    scale = fn[contact] / fn[contact].max()
    chains = LineCollection(
        segments[contact], array=fn[contact], cmap="cividis", linewidths=0.3 + 2.7 * scale
    )
    ax.add_collection(chains)
    ax.add_collection(LineCollection(segments[kind == 1], colors="k", linewidths=1.5))
    fig.colorbar(chains, ax=ax, fraction=0.05, pad=0.02, label="normal force $f_n$ (N)")
    ax.set_aspect("equal")
    margin = 2.0  # mm of wall beyond the disks: the walls' segments are longer than the specimen
    ax.set_xlim((xy[:, 0] - r).min() - margin, (xy[:, 0] + r).max() + margin)
    ax.set_ylim((xy[:, 1] - r).min() - margin, (xy[:, 1] + r).max() + margin)
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_title(rf"biaxial, $\sigma_3$ = 100 kPa, $\varepsilon_1$ = {strain:.3f}", fontsize=9)
    fig.tight_layout()
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=300, bbox_inches="tight")


def draw_pyvista(vtu: Path, strain: float, out: Path) -> None:
    """The step rendered by VTK off screen: Glyph (disks scaled by radius), Tube (contacts scaled and
    coloured by the normal force) and the walls, the filters of docs/paraview.md."""
    import numpy as np
    import pyvista as pv

    grid = pv.read(vtu)
    kind = grid.cell_data["cell_kind"]
    disks = grid.extract_cells(np.flatnonzero(kind == 0))
    centres = pv.PolyData(disks.points)
    centres["radius"] = disks.point_data["radius"]
    disc = pv.Disc(inner=0.0, outer=0.5, c_res=32)  # ParaView's glyphs have a radius of 0.5
    glyphs = centres.glyph(scale="radius", factor=2.0, orient=False, geom=disc)
    # each disk's rim as a thin line, so that touching neighbours of one grey are told apart
    rim = disc.extract_feature_edges(
        boundary_edges=True, non_manifold_edges=False, feature_edges=False, manifold_edges=False
    )
    rims = centres.glyph(scale="radius", factor=2.0, orient=False, geom=rim)
    lines = grid.extract_cells(np.flatnonzero(kind >= 2)).extract_surface(algorithm=None)
    width = 0.06 * float(centres["radius"].min())
    tubes = lines.cell_data_to_point_data().tube(radius=width, scalars="normal_force", radius_factor=8.0)
    plot = pv.Plotter(off_screen=True, window_size=(1100, 1500))
    plot.set_background("white")
    plot.add_mesh(glyphs, color="#d9d9d9", lighting=False)
    plot.add_mesh(rims, color="#8c8c8c", line_width=1, lighting=False)
    bar = {"title": "normal force f_n (N)", "color": "black", "vertical": True, "position_x": 0.84}
    plot.add_mesh(tubes, scalars="normal_force", cmap="cividis", scalar_bar_args=bar)
    plot.add_mesh(grid.extract_cells(np.flatnonzero(kind == 1)), color="black", line_width=4)
    title = plot.add_text(
        f"biaxial, σ₃ = 100 kPa, axial strain ε₁ = {strain:.3f}", font_size=12, color="black"
    )
    symbol_font(title.GetTextProperty())
    x0, x1, y0, y1, _, _ = glyphs.bounds
    plot.view_xy()
    plot.camera.parallel_projection = True
    plot.camera.focal_point = (0.5 * (x0 + x1) + 0.12 * (x1 - x0), 0.5 * (y0 + y1), 0.0)
    plot.camera.position = (*plot.camera.focal_point[:2], 1.0)
    plot.camera.parallel_scale = 0.56 * (y1 - y0)
    out.parent.mkdir(parents=True, exist_ok=True)
    plot.screenshot(str(out))


def symbol_font(prop) -> None:
    """Set a VTK text property to matplotlib's DejaVu Sans, which has the Greek letters and
    subscript digits that VTK's own embedded fonts lack."""
    from matplotlib import font_manager

    prop.SetFontFamily(4)  # VTK_FONT_FILE: the font is read from the file below
    prop.SetFontFile(font_manager.findfont("DejaVu Sans"))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=Path("docs/img/paraview_step.png"))
    ap.add_argument("--keep", type=Path, default=None, help="output folder to keep (default: temporary)")
    ap.add_argument("--every", type=int, default=1000, help="vtk_every (steps)")
    ap.add_argument("--draw", type=Path, default=None, help="draw the last step of this vtk/ folder only")
    ap.add_argument("--renderer", choices=("pyvista", "matplotlib"), default=None)
    args = ap.parse_args()
    render = draw_pyvista if (args.renderer or default_renderer()) == "pyvista" else draw
    if args.draw is not None:
        vtu, strain, _ = last_step(args.draw)
        render(vtu, strain, args.out)
        return
    with tempfile.TemporaryDirectory() as tmp:
        root = args.keep or Path(tmp)
        run(root / "warm", 0)  # the kernels compiled or loaded before the clock counts
        plain = run(root / "plain", 0)
        series = run(root / "series", args.every)
        vtu, strain, steps = last_step(root / "series" / "vtk")
        print(f"without the series: {plain:.2f} s; with a step every {args.every} steps: {series:.2f} s")
        cost = (series - plain) / steps * 1e3
        print(f"{steps} steps written: {cost:.1f} ms a step ({vtu.stat().st_size} bytes a file)")
        render(vtu, strain, args.out)
        print(f"figure: {args.out} (step {vtu.name}, axial strain {strain:.4f})")


if __name__ == "__main__":
    main()
