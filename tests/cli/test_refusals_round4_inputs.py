"""Numbers from a config, an option or a file checked where they enter (issue 42, round 4).

Each case was a traceback, a silent acceptance or a refusal naming a quantity the user never
typed; each is now one line, exit 2, naming the key or option typed, before any work and
with nothing left in the output folder. Names printed to the terminal are shown as text.
"""

from __future__ import annotations

import http.server
import math
import threading
import warnings

import pytest

import poro2d.sand.preflight as sand_preflight
import poro2d.sand.run as sand_run
from poro2d.cli import main
from poro2d.errors import InputError
from poro2d.grading import GradingCurve
from poro2d.lab_state import lab_state
from poro2d.specimen.compaction import SpecimenSpec
from tests.cli.test_refusals import stop_real_work, work

GRADING = "[grading]\nsizes_mm = [0.1, 0.2, 0.3]\npercent_passing = [0, 50, 100]\nupscale = 10\n"
LAB = "[lab]\ne_max = 0.977\ne_min = 0.597\ndr = 0.8\n"
SOIL = '[soil]\nname = "test sand"\n'

#: files the cases refer to as {d}/name
FILES = {
    "kn_inf.toml": "[specimen]\nkn_particle = inf\n",
    "ks_nan.toml": "[specimen]\nks_particle = nan\n",
    "mu_inf.toml": "[specimen]\nfriction_wall = inf\n",
    "rho_nan.toml": "[specimen]\nsolid_density = nan\n",
    "width_inf.toml": "[specimen]\nwidth = inf\n",
    "width_huge.toml": "[specimen]\nwidth = 1e308\n",
    "box_1mm.toml": "[specimen]\nwidth = 0.001\nheight = 0.001\n",
    "d_max_box.toml": '[grading]\npreset = "paper"\nd_max_mm = 500\n',
    "d_max_huge.toml": '[grading]\npreset = "paper"\nd_max_mm = 1e6\n',
    "upscale_huge.toml": "[grading]\nsizes_mm = [1, 2]\npercent_passing = [0, 100]\nupscale = 1e300\n",
    "sand_n_lab.toml": SOIL + GRADING + LAB + '[criterion]\nn_lab = "abc"\n',
    "sand_upscale.toml": SOIL + GRADING.replace("upscale = 10", "upscale = 0.001") + LAB,
    "sand_low.toml": SOIL + GRADING + LAB + "[specimen]\nwidth = 0.02\nheight = 0.002\nlayers = 1\n",
    "grain_huge.csv": "size_mm,percent_passing\n0.1,0\n1e308,100\n",
}

#: (command line, words of its one line); {d} is the folder holding FILES
CASES = [
    # 1. stiffness, friction and density keys that are not finite
    (["criterion", "-c", "{d}/kn_inf.toml"], ["specimen.kn_particle = inf", "a finite number"]),
    (["criterion", "-c", "{d}/ks_nan.toml"], ["specimen.ks_particle = nan", "a finite number"]),
    (["criterion", "-c", "{d}/mu_inf.toml"], ["specimen.friction_wall = inf"]),
    (["criterion", "-c", "{d}/rho_nan.toml"], ["specimen.solid_density = nan"]),
    # 2. a box of no laboratory's size
    (["criterion", "-c", "{d}/width_inf.toml"], ["specimen.width = inf"]),
    (["criterion", "-c", "{d}/width_huge.toml"], ["specimen.width = 1e+308", "[0, 10]"]),
    # 3. a value of the wrong type in a sand config
    (["sand", "{d}/sand_n_lab.toml", "--preflight"], ["criterion.n_lab = 'abc'", "a number"]),
    # 6. --workers out of range, not a negative estimate or two cores
    (["sand", "{d}/sand_n_lab.toml", "--preflight", "--workers", "-1", "--budget", "1"], ["--workers = -1"]),
    (["sand", "{d}/sand_n_lab.toml", "--preflight", "--workers", "0"], ["--workers = 0", "an integer in [1"]),
    # 7. a grain of no soil
    (["critical-state", "--grading", "{d}/grain_huge.csv"], ["--grading sizes_mm", "[0.0001, 10000] mm"]),
    # 8. a cut of the grading larger than the box
    (["criterion", "-c", "{d}/d_max_box.toml"], ["grading.d_max_mm = 500", "305 mm"]),
    (["criterion", "-c", "{d}/d_max_huge.toml"], ["grading.d_max_mm = 1000000.0"]),
    (["criterion", "-c", "{d}/upscale_huge.toml"], ["grading.upscale = 1e+300"]),
    # 9. named as typed: the state, the up-scaling, the box, the strain
    (["convert", "--e", "1e308"], ["--e = 1e+308", "[0, 100]"]),
    (["convert", "--e-max", "1e308", "--e-min", "0.6", "--e", "0.7"], ["--e-max = 1e+308"]),
    (["convert", "--dry-density", "1e-300", "--solid-density", "2650"], ["--dry-density = 1e-300", "2650"]),
    (["sand", "{d}/sand_upscale.toml", "--preflight"], ["grading.upscale = 0.001", "up-scale more"]),
    (["criterion", "-c", "{d}/box_1mm.toml"], ["box = '0.001 m x 0.001 m"]),
    (["sand", "{d}/sand_low.toml", "--preflight"], ["box = '0.02 m x 0.002 m", "the largest disk (0.003 m)"]),
    (["critical-state", "--strain", "0.01"], ["--strain = 0.01"]),
]


@pytest.fixture
def no_work(monkeypatch):
    """Every entry point of real work raises, the sand pre-flight's too: a case that gets there
    was not refused in time."""
    stop_real_work(monkeypatch)
    monkeypatch.setattr(sand_run, "calibration_stage", work)
    monkeypatch.setattr(sand_preflight, "jamming_of", work)  # the pre-flight's only long part


def _files(folder) -> None:
    for name, text in FILES.items():
        (folder / name).write_text(text, encoding="utf-8")


def _one_line(argv, capsys) -> str:
    with pytest.raises(SystemExit) as exc:
        main(argv)
    out, err = capsys.readouterr()
    lines = err.strip().splitlines()
    assert exc.value.code == 2 and out == "", (out, err)
    assert len(lines) == 1 and lines[0].startswith("error: "), err
    return lines[0]


@pytest.mark.parametrize(("argv", "words"), CASES, ids=[" ".join(a)[:60] for a, _ in CASES])
def test_refused_on_one_line_naming_what_was_typed(argv, words, tmp_path, capsys, no_work, monkeypatch):
    files = tmp_path / "files"
    files.mkdir()
    _files(files)
    monkeypatch.chdir(tmp_path)  # default --out folders land here, and must not appear
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)  # no overflow on the way to the refusal
        line = _one_line([a.format(d=files) for a in argv], capsys)
    for w in words:
        assert w in line, (w, line)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["files"]  # nothing written


def test_settings_refuse_infinities_however_made():
    for key in ("kn_particle", "ks_wall", "friction_particle", "solid_density", "width"):
        with pytest.raises(InputError, match=f"{key} = inf is invalid; allowed: a finite number"):
            SpecimenSpec(**{key: math.inf})
    with pytest.raises(InputError, match="sizes_mm"):
        GradingCurve.from_lists([0.1, 1e308], [0, 100])
    with pytest.raises(InputError, match=r"^e = 1e\+308"):
        lab_state(e=1e308)


def test_a_refused_sand_config_leaves_no_mark_in_a_folder_in_use(tmp_path, capsys, no_work, monkeypatch):
    # the box refusal comes with the pre-flight: the folder must not be claimed before it
    (tmp_path / "notes.txt").write_text("mine")
    config = tmp_path.parent / f"{tmp_path.name}-box.toml"
    config.write_text(SOIL + GRADING + LAB + "[specimen]\nwidth = 0.001\nheight = 0.001\n")
    monkeypatch.chdir(tmp_path)
    assert "box = '0.001 m x 0.001 m" in _one_line(["sand", str(config), "--out", "."], capsys)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["notes.txt"]


class _WebPage(http.server.BaseHTTPRequestHandler):
    def do_GET(self):  # noqa: N802 - the name http.server calls
        self.send_response(200)
        self.end_headers()
        self.wfile.write(b"<html>not a scheduler</html>")

    def log_message(self, *args):  # quiet
        pass


@pytest.fixture
def web_server():
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), _WebPage)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    yield server.server_address[1]
    server.shutdown()
    server.server_close()


@pytest.mark.parametrize("scheme", ["ws", "tls"])
def test_a_web_server_behind_another_scheme_is_refused_on_one_line(scheme, web_server, tmp_path, capsys,
                                                                   no_work, monkeypatch):  # fmt: skip
    monkeypatch.chdir(tmp_path)
    address = f"{scheme}://127.0.0.1:{web_server}"
    argv = ["relation", "--preset", "paper", "--quick", "--quiet", "--scheduler", address]
    line = _one_line(argv, capsys)
    assert f"--scheduler = '{address}'" in line and "a running Dask scheduler" in line
    assert list(tmp_path.iterdir()) == []


def test_a_soil_name_is_shown_as_text(tmp_path, capsys, monkeypatch):
    config = tmp_path / "soil.toml"  # TOML's escapes: the file itself holds no control character
    name = '"bad [bold]name[/] \\u001b[31mred\\u001b[0m \\u202eright"'
    config.write_text(f"[soil]\nname = {name}\n" + GRADING + LAB)
    monkeypatch.chdir(tmp_path)
    main(["sand", str(config), "--preflight"])
    out = capsys.readouterr().out
    assert "\x1b" not in out and "\u202e" not in out
    assert "pre-flight: bad [bold]name[/] \\x1b[31mred\\x1b[0m \\u202eright" in out
    from poro2d.console import shown

    assert shown("[red]x[/]\t") == "\\[red]x\\[/]\\t"


def test_the_paper_mode_note_names_the_density_table():
    from rich.console import Console

    from poro2d.cli.criterion import PAPER_MODE_NOTE

    out = Console(record=True, width=400)
    out.print(PAPER_MODE_NOTE)
    assert "(--n-max/--n-min or [density])" in out.export_text()  # a table's name, not markup
