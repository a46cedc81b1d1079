"""Ctrl-C: one line saying what was kept and how to resume, exit code 130."""

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from poro2d.cli import main
from poro2d.criterion import PorosityCriterion
from tests.conftest import default_sigint

SRC = Path(__file__).resolve().parents[2] / "src"


def test_keyboard_interrupt_in_a_command_prints_what_was_kept(tmp_path, monkeypatch, capsys):
    def interrupted(self):
        raise KeyboardInterrupt

    monkeypatch.setattr(PorosityCriterion, "run", interrupted)
    out = tmp_path / "o"
    with pytest.raises(SystemExit) as e:
        main(["criterion", "--preset", "paper", "--out", str(out), "--quiet"])
    assert e.value.code == 130
    err = capsys.readouterr().err.strip()
    assert err == f"interrupted: finished trials are kept in {out}; rerun the same command to resume"


def test_keyboard_interrupt_while_the_options_are_parsed_prints_its_line(monkeypatch, capsys):
    # typer turns a Ctrl-C outside the command into a silent Exit(130), returned as 130
    import typer.core

    def interrupted(self, *args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(typer.core.TyperGroup, "make_context", interrupted)
    with pytest.raises(SystemExit) as e:
        main(["relation", "--preset", "paper", "--quiet"])
    assert e.value.code == 130
    assert capsys.readouterr().err.strip() == "interrupted"


def test_sigint_during_a_run(tmp_path):
    # the paper's full specimen takes minutes to prepare: the signal arrives mid-run
    out = tmp_path / "o"
    env = dict(os.environ, PYTHONPATH=str(SRC))
    cmd = [sys.executable, "-m", "poro2d.cli", "criterion", "--preset", "paper", "--out", str(out), "--quiet"]
    proc = subprocess.Popen(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=default_sigint)  # fmt: skip
    try:
        deadline = time.monotonic() + 120
        while not (out / "config.json").is_file():  # written once the options are checked
            assert proc.poll() is None, proc.communicate()
            assert time.monotonic() < deadline, "the run did not start"
            time.sleep(0.1)
        time.sleep(3.0)  # past the imports, into the preparation of the specimen
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 130, err
    assert f"interrupted: finished trials are kept in {out}; rerun the same command to resume" in err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1
