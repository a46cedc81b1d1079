"""`poro2d paper --quick`: the whole pipeline on a reduced specimen, and its report."""

import json
import os
import re
import shutil
import subprocess

import pytest

from poro2d.cli import main


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    out = tmp_path_factory.mktemp("paper")
    cwd = os.getcwd()
    os.chdir(out.parent)  # a relative --out, as in the README
    try:
        main(["paper", "--quick", "--out", out.name, "--quiet"])  # raises SystemExit on failure
    finally:
        os.chdir(cwd)
    return out


@pytest.mark.scenario
def test_every_stage_wrote_its_results(quick):
    res = json.loads((quick / "results.json").read_text())
    assert res["quick"] is True
    methods = {m["method"]: m["n2d"] for m in res["conversions"]["methods"]}
    assert methods["parabolic"] == pytest.approx(0.42 * 0.3434**2 + 0.25 * 0.3434)
    assert res["criterion"]["converged"]
    assert res["criterion"]["iterations"][0]["trial_porosity"] == 0.14  # Eq. 12, rounded
    tests = res["shear"]["tests"]
    assert [t["normal_stress_kpa"] for t in tests] == [50.0, 100.0, 200.0]
    assert all(t["peak_shear_stress_kpa"] > 0 for t in tests)
    assert set(res["timings"]) == {"conversions_s", "criterion_s", "replicates_s", "shear_s"}
    # three specimens (seeds 0, 1, 2), each accepted by the criterion itself, sheared at three stresses
    reps = res["shear"]["replicates"]
    assert reps["specimens"] == ["seed0", "seed1", "seed2"]
    assert [r["n"] for r in reps["per_normal_stress"]] == [3, 3, 3]
    assert all(r["converged"] for r in res["replicate_specimens"])
    lo, hi = reps["fit"]["friction_angle_ci_deg"]
    assert lo < res["shear"]["friction_angle_deg"] < hi
    assert res["provenance"]["poro2d_version"]
    for f in (
        "conversions/fig1_relations.png",
        "criterion/fig5_forces_initial_trial.png",
        "criterion/specimen.npz",
        "criterion/specimen_state.png",
        "criterion/specimen_state.json",
        "shear/seed0/fig8a_shear_curves.png",
        "shear/fig8b_peak_strength_replicates.png",
        "shear/fig8a_shear_curves_replicates.png",
        "replicates/seed1/specimen.npz",
        "replicates/seed2/specimen.npz",
    ):
        assert (quick / f).stat().st_size > 0, f


@pytest.mark.scenario
def test_report_puts_the_paper_beside_poro2d(quick):
    md = (quick / "report.md").read_text()
    html = (quick / "report.html").read_text()
    assert "| accepted 2D porosity |" in md and "0.15" in md  # the paper's value, beside ours
    assert "reconstruction" in md  # the grading is said to be reconstructed
    assert "Local damping 0.7" in md  # a setting the paper does not state
    assert "homogeneity and stress state" in md and "K0 = sigma_h / sigma_v" in md
    assert html.count("data:image/png;base64,") >= 6  # figures embedded: no server, no side files
    assert "figure missing" not in html


@pytest.mark.scenario
def test_rerun_reuses_finished_stages(quick):
    done = sorted((quick / "criterion" / "trials").glob("*/*.npz")) + sorted(
        (quick / "shear").glob("seed*/sn*/result.json")
    )
    assert len(done) >= 4
    before = [f.stat().st_mtime_ns for f in done]
    main(["paper", "--quick", "--out", str(quick), "--quiet"])
    assert [f.stat().st_mtime_ns for f in done] == before  # no specimen rebuilt, no test rerun


@pytest.mark.scenario
def test_a_folder_of_another_paper_run_is_refused(quick, capsys):
    files = sorted(p for p in quick.rglob("*") if p.is_file())
    before = [p.stat().st_mtime_ns for p in files]
    with pytest.raises(SystemExit) as e:
        main(["paper", "--quick", "--seed", "1", "--out", str(quick), "--quiet"])
    err = capsys.readouterr().err
    assert e.value.code == 2 and "other --seed" in err and "choose another --out" in err
    assert [p.stat().st_mtime_ns for p in files] == before  # refused before anything was written
    assert json.loads((quick / "paper.json").read_text())["run"] == {"quick": True, "seed": 0}


def _md_images(md_path):
    return re.findall(r"!\[[^\]]*\]\(([^)]+)\)", md_path.read_text())


@pytest.mark.scenario
def test_report_md_links_its_figures_relative_to_itself(quick, tmp_path, monkeypatch):
    """The Markdown report's pictures open where it lies, from any directory, and after a move."""
    links = _md_images(quick / "report.md")
    assert len(links) >= 6
    assert all(not os.path.isabs(x) and not x.startswith(quick.name) for x in links), links
    monkeypatch.chdir(tmp_path)  # another working directory
    moved = tmp_path / "elsewhere" / "copy-of-paper-out"
    shutil.copytree(quick, moved)
    for folder in (quick, moved):
        for link in links:
            assert (folder / link).is_file(), (folder, link)


def _chromium() -> str:
    """Debian's chromium; CI (CI=true) must have it, elsewhere the test is skipped without it."""
    exe = shutil.which("chromium")
    if exe is None:
        if os.environ.get("CI", "").lower() == "true":
            pytest.fail("CI=true but Debian's chromium is not installed (apt-get install -y chromium)")
        pytest.skip("Debian's chromium is not installed")
    return exe


@pytest.mark.scenario
def test_report_renders_in_headless_chromium(quick, tmp_path):
    """The HTML opens from disk in a browser; nothing spills past the page column."""
    import numpy as np
    from matplotlib.image import imread

    shot = tmp_path / "report.png"
    cmd = [
        _chromium(), "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
        "--disable-background-networking", "--disable-component-update", "--disable-sync",
        "--hide-scrollbars",
        f"--user-data-dir={tmp_path / 'profile'}", "--window-size=1200,2400",
        f"--screenshot={shot}", (quick / "report.html").as_uri(),
    ]  # fmt: skip
    subprocess.run(cmd, check=True, capture_output=True, timeout=120)
    img = imread(shot)[..., :3]
    assert img.shape[1] == 1200
    ink = (img < 0.9).any(axis=2)  # pixels that are not (near) white
    assert ink[:, 100:1100].mean() > 0.02  # text, tables and figures are drawn
    assert not ink[:, 1120:].any()  # the right margin stays empty: nothing overflows
    assert np.isfinite(img).all()


def test_bad_option_writes_nothing(tmp_path, capsys):
    # refused before the conversions stage: the corrected command then starts from a clean folder
    out = tmp_path / "paper"
    with pytest.raises(SystemExit) as e:
        main(["paper", "--quick", "--threads", "0", "--out", str(out), "--quiet"])
    assert e.value.code == 2 and "threads" in capsys.readouterr().err
    assert not out.exists()


@pytest.mark.scenario
def test_every_figure_is_print_ready(quick):
    """Every figure `poro2d paper` wrote is a 300 dpi PNG with an SVG beside it, its symbols as symbols."""
    from tests.report.print_checks import check_print_ready

    pngs = sorted(quick.rglob("*.png"))
    assert len(pngs) >= 20  # conversions, every trial's force chains, Figs. 5-8, the specimens' states
    for png in pngs:
        check_print_ready(png)
    assert not {p.with_suffix(".png") for p in quick.rglob("*.svg")} - set(pngs)  # no SVG alone


@pytest.mark.scenario
def test_report_states_the_caveat_and_the_checks(quick):
    from poro2d.report.paper_report import PAPER_MODE_CAVEAT

    md = (quick / "report.md").read_text()
    assert md.index(PAPER_MODE_CAVEAT) < md.index("## Summary")
    assert "### Quasi-static checks" in md and "coordination number at the end" in md
    assert "Jaky (1944): K0 = 1 - sin phi" in md
