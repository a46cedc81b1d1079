"""Atomic writes: permissions, leftovers of killed writes, strict JSON."""

import json
import os
import stat

import numpy as np
import pytest

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


def test_leftover_temporaries_of_the_target_are_removed(tmp_path):
    # what a killed write of fig.png leaves behind, and files that must stay
    stale = [tmp_path / ".fig.png.ab12cd_x.png", tmp_path / ".fig.png.xxxx.png"]
    keep = [
        tmp_path / ".fig.png.b.png.k3j4l5m6.png",  # a temporary of the target fig.png.b.png
        tmp_path / ".other.png.ab12cd_x.png",  # of another target
        tmp_path / "fig.png.ab12cd_x.png",  # not hidden: not a temporary
        tmp_path / ".fig.png.ab12cd_x.svg",  # another suffix
    ]
    for p in stale + keep:
        p.write_bytes(b"partial")
    with atomic_path(tmp_path / "fig.png") as tmp:
        tmp.write_bytes(b"complete")
    assert (tmp_path / "fig.png").read_bytes() == b"complete"
    assert not any(p.exists() for p in stale)
    assert all(p.exists() for p in keep)
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(["fig.png"] + [p.name for p in keep])


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
