"""Atomic writes: permissions, leftovers of killed writes, strict JSON."""

import json
import os
import stat
import subprocess
import sys
import time

import numpy as np
import pytest

from poro2d import io_utils
from poro2d.io_utils import atomic_path, current_umask, write_csv, write_json


@pytest.fixture
def umask_022():
    old = os.umask(0o022)
    yield
    os.umask(old)


def _mode(path):
    return stat.S_IMODE(path.stat().st_mode)


def test_written_files_follow_the_umask(tmp_path, umask_022):
    # a temporary file is created 0600; the result must be readable like any new file
    write_json(tmp_path / "a.json", {"x": 1})
    write_csv(tmp_path / "a.csv", [{"x": 1}])
    with atomic_path(tmp_path / "a.bin") as tmp:
        tmp.write_bytes(b"1")
    for name in ("a.json", "a.csv", "a.bin"):
        assert _mode(tmp_path / name) == 0o644, name
    os.umask(0o077)
    write_json(tmp_path / "private.json", {"x": 1})
    assert _mode(tmp_path / "private.json") == 0o600


def test_current_umask_reads_without_changing_it(umask_022):
    assert current_umask() == 0o022
    assert current_umask() == 0o022


def _dead_pid() -> int:
    """The pid of a process that has ended (reaped, so no longer running)."""
    proc = subprocess.Popen([sys.executable, "-c", "pass"])
    proc.wait()
    return proc.pid


def _age(path, days: float) -> None:
    t = time.time() - days * 86400
    os.utime(path, (t, t))


def test_leftover_temporaries_of_the_target_are_removed(tmp_path):
    # what killed writes of fig.png leave behind, and files that must stay
    host = io_utils._host_tag()
    dead = _dead_pid()
    stale = [
        tmp_path / f".fig.png.{dead}-{host}-ab12cd_x.png",  # its writer is dead
        tmp_path / ".fig.png.xxxx.png",  # no writer in its name, untouched for two days
        tmp_path / ".fig.png.7-otherhost-ab12.png",  # another host's, untouched for two days
    ]
    keep = [
        tmp_path / f".fig.png.{os.getpid()}-{host}-ab12cd_x.png",  # a live writer's (this process)
        tmp_path / f".fig.png.{os.getppid()}-{host}-k3j4.png",  # another live process's
        tmp_path / ".fig.png.8-otherhost-ab12.png",  # another host's, recent: it may be writing
        tmp_path / ".fig.png.yyyy.png",  # no writer in its name, recent
        tmp_path / f".fig.png.b.png.{dead}-{host}-k3j4l5m6.png",  # a temporary of the target fig.png.b.png
        tmp_path / f".other.png.{dead}-{host}-ab12cd_x.png",  # of another target
        tmp_path / f"fig.png.{dead}-{host}-ab12cd_x.png",  # not hidden: not a temporary
        tmp_path / f".fig.png.{dead}-{host}-ab12cd_x.svg",  # another suffix
    ]
    for p in stale + keep:
        p.write_bytes(b"partial")
    _age(stale[1], 2)
    _age(stale[2], 2)
    with atomic_path(tmp_path / "fig.png") as tmp:
        tmp.write_bytes(b"complete")
    assert (tmp_path / "fig.png").read_bytes() == b"complete"
    assert not any(p.exists() for p in stale)
    assert all(p.exists() for p in keep)
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(["fig.png"] + [p.name for p in keep])


_SLOW_WRITER = """
import sys, time
from pathlib import Path
from poro2d.io_utils import atomic_path

target, started = Path(sys.argv[1]), Path(sys.argv[2])
with atomic_path(target) as tmp:
    tmp.write_text("first")
    started.write_text(tmp.name)
    while not (target.parent / "go").exists():
        time.sleep(0.02)
"""


def test_a_live_writers_temporary_survives_another_write(tmp_path):
    # two processes write one target: the second must not remove the first one's temporary,
    # whose rename would then fail (FileNotFoundError on a shared calibration cache)
    target, started = tmp_path / "results.csv", tmp_path / "started"
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    first = subprocess.Popen([sys.executable, "-c", _SLOW_WRITER, str(target), str(started)], env=env)
    try:
        deadline = time.monotonic() + 60
        while not started.exists() and first.poll() is None and time.monotonic() < deadline:
            time.sleep(0.02)
        temporary = tmp_path / started.read_text()
        with atomic_path(target) as tmp:
            tmp.write_text("second")
        assert temporary.is_file()
        (tmp_path / "go").touch()
        assert first.wait(60) == 0
    finally:
        first.kill()
    assert target.read_text() == "first"  # the first writer's rename went through


def test_a_failed_write_leaves_neither_target_nor_temporary(tmp_path):
    with pytest.raises(RuntimeError), atomic_path(tmp_path / "r.json") as tmp:
        tmp.write_text("{")
        raise RuntimeError
    assert list(tmp_path.iterdir()) == []


def test_results_are_strict_json_with_real_booleans(tmp_path):
    data = {
        "ok": np.bool_(True),
        "no": np.False_,
        "n": np.int64(3),
        "undefined": float("nan"),
        "curve": np.array([1.0, np.nan, np.inf]),
        "nested": [{"r": -np.inf}, (1, 2)],
    }
    write_json(tmp_path / "r.json", data)
    text = (tmp_path / "r.json").read_text()
    assert "NaN" not in text and "Infinity" not in text
    back = json.loads(text, parse_constant=lambda c: pytest.fail(f"invalid JSON token {c}"))
    assert back == {
        "ok": True,
        "no": False,
        "n": 3,
        "undefined": None,
        "curve": [1.0, None, None],
        "nested": [{"r": None}, [1, 2]],
    }
    assert type(back["ok"]) is bool and type(back["no"]) is bool


def test_a_config_with_a_non_finite_number_is_not_written(tmp_path):
    with pytest.raises(ValueError):
        write_json(tmp_path / "config.json", {"specimen": {"width": float("inf")}}, config=True)
    assert list(tmp_path.iterdir()) == []
    write_json(tmp_path / "config.json", {"specimen": {"width": np.float64(0.3)}}, config=True)
    assert json.loads((tmp_path / "config.json").read_text()) == {"specimen": {"width": 0.3}}


def test_a_byte_order_mark_is_dropped_from_utf8_files(tmp_path):
    from poro2d.config import load_toml
    from poro2d.io_utils import read_utf8

    p = tmp_path / "case.toml"
    p.write_bytes(b"\xef\xbb\xbfseed = 3\n")
    assert read_utf8("config", p, "a UTF-8 file") == "seed = 3\n"
    assert load_toml(p) == {"seed": 3}
