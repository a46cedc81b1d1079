"""Cluster options refused before any work: a dashboard that cannot listen, a scheduler that is not Dask."""

from __future__ import annotations

import socket
import struct
import threading

import pytest

from poro2d.cli import main
from poro2d.errors import InputError
from poro2d.execute.cluster_options import bind_problem, check_dashboard
from poro2d.execute.dask_cluster import not_a_scheduler


@pytest.fixture
def busy_port():
    """A port of 127.0.0.1 held by a listening socket for the test."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        s.listen()
        yield s.getsockname()[1]


def _server(greeting: bytes | None):
    """A server on 127.0.0.1 that sends ``greeting`` to each connection (None: nothing), then holds it."""
    srv = socket.socket()
    srv.bind(("127.0.0.1", 0))
    srv.listen()
    held = []

    def serve():
        while True:
            try:
                conn, _ = srv.accept()
            except OSError:
                return
            held.append(conn)
            if greeting is not None:
                conn.sendall(greeting)

    threading.Thread(target=serve, daemon=True).start()
    return srv, held


@pytest.mark.parametrize(
    ("value", "words"),
    [
        ("no-such-host.invalid:8787", "is not known"),
        ("192.0.2.1:8787", "not an address of this machine"),  # TEST-NET-1: never local
    ],
)
def test_dashboard_on_an_unknown_or_foreign_host_is_refused(value, words):
    with pytest.raises(InputError, match=words) as e:
        check_dashboard(value)
    assert e.value.parameter == "--dashboard"


def test_dashboard_on_a_taken_port_is_refused_and_a_free_one_kept(busy_port):
    with pytest.raises(InputError, match=f"port {busy_port} is in use"):
        check_dashboard(f"127.0.0.1:{busy_port}")
    assert check_dashboard("127.0.0.1:0") == "127.0.0.1:0"
    assert bind_problem("", 0) is None


def test_a_server_that_does_not_speak_dask_is_not_a_scheduler():
    silent, held = _server(None)
    http, held2 = _server(b"HTTP/1.0 400 Bad Request\r\n\r\n")
    dask_like, held3 = _server(struct.pack("<QQ", 58, 1))
    try:
        assert "sent no Dask handshake" in not_a_scheduler(f"tcp://127.0.0.1:{silent.getsockname()[1]}", 0.5)
        assert "does not speak Dask" in not_a_scheduler(f"tcp://127.0.0.1:{http.getsockname()[1]}", 0.5)
        assert not_a_scheduler(f"tcp://127.0.0.1:{dask_like.getsockname()[1]}", 0.5) is None
        assert not_a_scheduler("tls://127.0.0.1:1", 0.5) is None  # other schemes: the client's timeout
    finally:
        for s in (silent, http, dask_like, *held, *held2, *held3):
            s.close()


def test_sensitivity_refuses_a_taken_dashboard_port_on_one_line_before_work(busy_port, tmp_path, capsys):
    with pytest.raises(SystemExit) as e:
        main(["sensitivity", "--preset", "paper", "--quick", "--dashboard", f"127.0.0.1:{busy_port}",
              "--out", str(tmp_path / "s")])  # fmt: skip
    assert e.value.code == 2
    err = capsys.readouterr().err.strip()
    assert "--dashboard" in err and "in use" in err and len(err.splitlines()) == 1
    assert not (tmp_path / "s").exists()


def test_closing_a_finished_local_cluster_hides_the_nannys_kill_notice(caplog):
    import logging

    from poro2d.execute.dask_cluster import DaskCluster

    class SlowToStop:  # a LocalCluster whose worker outlived the nanny's wait as it closed
        def close(self):
            logging.getLogger("distributed.nanny").warning(
                "Worker process still alive after 4 seconds, killing"
            )
            logging.getLogger("distributed.nanny").error("a real failure")

    cluster = DaskCluster(None, 1, None, 1)
    cluster.local = SlowToStop()
    nanny = logging.getLogger("distributed.nanny")
    before = nanny.level
    with caplog.at_level(logging.DEBUG, logger="distributed"):
        nanny.setLevel(before)
        cluster.close()
    messages = [r.getMessage() for r in caplog.records]
    assert "a real failure" in messages and not any("still alive" in m for m in messages)
    assert nanny.level == before and cluster.local is None
