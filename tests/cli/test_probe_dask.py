"""The probe's Dask options, as a user meets them: every command that starts or joins a Dask cluster
refuses a dashboard that cannot listen and a scheduler that is a web server, on one line (exit 2),
before any work and within the connect limit."""

from __future__ import annotations

import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

from poro2d.cli import main
from poro2d.execute import dask_cluster

ROOT = Path(__file__).resolve().parents[2]
LAB = "normal_stress_kpa,peak_shear_stress_kpa\n50,40\n100,75\n200,140\n"
#: the commands with --scheduler, with arguments that pass their other checks; ``{o}`` the folder
COMMANDS = {
    "calibrate": ["calibrate", "--lab", "{lab}", "--preset", "paper", "--quick", "--out", "{o}", "--quiet"],
    "relation": ["relation", "--preset", "paper", "--quick", "--out", "{o}", "--quiet"],
    "sweep": ["sweep", "{sweep}", "--out", "{o}", "--quiet"],
    "sensitivity": ["sensitivity", "--preset", "paper", "--quick", "--out", "{o}", "--quiet"],
    "sand": ["sand", str(ROOT / "examples" / "soils" / "toyoura.toml"), "--out", "{o}", "--quiet"],
}
#: the commands that start a LocalCluster with a dashboard (sand's has none)
WITH_DASHBOARD = ["calibrate", "relation", "sweep", "sensitivity"]
#: the connect limit in these tests (s): the refusal must come within it, and some slack to start
LIMIT_S = 2


def _argv(command: str, tmp_path: Path, *extra: str) -> tuple[list[str], Path]:
    (tmp_path / "lab.csv").write_text(LAB)
    (tmp_path / "sweep.toml").write_text(
        '[specimen]\nlayers = 2\n[sweep]\nkind = "criterion"\nseed = [0, 1]\n'
    )
    out = tmp_path / "out"
    fields = {"o": out, "lab": tmp_path / "lab.csv", "sweep": tmp_path / "sweep.toml"}
    return [a.format(**fields) for a in COMMANDS[command]] + list(extra), out


def _refused(argv, capsys) -> str:
    with pytest.raises(SystemExit) as e:
        main(argv)
    out, err = capsys.readouterr()
    err = err.strip()
    assert e.value.code == 2 and out == "", (out, err)
    assert len(err.splitlines()) == 1 and err.startswith("error:"), err
    return err


def _spy_on_the_probe(monkeypatch) -> list[tuple[str, float]]:
    """Record each probe of a scheduler address (address, timeout); a Dask client must not start."""
    import distributed

    probes: list[tuple[str, float]] = []
    probe = dask_cluster.not_a_scheduler

    def recorded(address, timeout):
        probes.append((address, timeout))
        return probe(address, timeout)

    def no_client(*args, **kwargs):
        raise AssertionError("a Dask client was started for a server the probe refuses")

    monkeypatch.setattr(dask_cluster, "not_a_scheduler", recorded)
    monkeypatch.setattr(distributed, "Client", no_client)
    return probes


@pytest.fixture(scope="module")
def web_server():
    """``python3 -m http.server`` on a free port of 127.0.0.1: it waits for a request, never speaks first."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    server = subprocess.Popen(
        [sys.executable, "-m", "http.server", str(port), "--bind", "127.0.0.1"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    try:
        for _ in range(200):
            try:
                socket.create_connection(("127.0.0.1", port), timeout=0.5).close()
                break
            except OSError:
                time.sleep(0.05)
        yield port
    finally:
        server.terminate()
        server.wait()


@pytest.fixture
def busy_port():
    """A port of 127.0.0.1 held by a listening socket for the test."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        s.listen()
        yield s.getsockname()[1]


@pytest.mark.parametrize("command", list(COMMANDS))
def test_a_scheduler_that_is_a_web_server_is_refused_within_the_connect_limit(
    command, web_server, tmp_path, capsys, monkeypatch
):
    monkeypatch.setattr(dask_cluster, "CONNECT_TIMEOUT_S", LIMIT_S)
    probes = _spy_on_the_probe(monkeypatch)
    argv, out = _argv(command, tmp_path, "--scheduler", f"tcp://127.0.0.1:{web_server}")
    err = _refused(argv, capsys)
    # refused by the probe, which waited at most the connect limit; no client, no work
    assert probes == [(f"tcp://127.0.0.1:{web_server}", LIMIT_S)]
    assert "--scheduler" in err and "sent no Dask handshake" in err and f"{LIMIT_S} s" in err
    assert not out.exists()


def test_a_web_server_without_a_scheme_is_refused_too(web_server, tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(dask_cluster, "CONNECT_TIMEOUT_S", LIMIT_S)
    argv, out = _argv("sweep", tmp_path, "--scheduler", f"127.0.0.1:{web_server}")
    assert "sent no Dask handshake" in _refused(argv, capsys) and not out.exists()


@pytest.mark.parametrize("command", WITH_DASHBOARD)
def test_a_dashboard_on_an_unknown_host_is_refused_before_any_work(command, tmp_path, capsys):
    argv, out = _argv(command, tmp_path, "--dashboard", "no-such-host.invalid:8787")
    err = _refused(argv, capsys)
    assert "--dashboard" in err and "is not known" in err and not out.exists()


@pytest.mark.parametrize("command", WITH_DASHBOARD)
def test_a_dashboard_on_a_busy_port_is_refused_before_any_work(command, busy_port, tmp_path, capsys):
    argv, out = _argv(command, tmp_path, "--dashboard", f"127.0.0.1:{busy_port}")
    err = _refused(argv, capsys)
    assert "--dashboard" in err and f"port {busy_port} is in use" in err and not out.exists()
