"""The store: named result files written atomically and read back checked."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

from poro2d.dem import Particles, Simulation, Walls
from poro2d.store import Store, walk
from poro2d.typed_result import TypedResult


@dataclass(eq=False)
class _Answer(TypedResult):
    porosity: float
    converged: bool


def test_json_and_typed_results_round_trip(tmp_path):
    s = Store(tmp_path / "run")
    s.write_json("a/b.json", {"x": 1.5, "bad": math.nan})
    assert s.read_json("a/b.json") == {"x": 1.5, "bad": None}
    s.write_result("result.json", _Answer(0.17, True))
    back = s.read_result("result.json", _Answer.from_dict)
    assert isinstance(back, _Answer) and back.to_dict() == {"porosity": 0.17, "converged": True}
    assert s.read_result("missing.json", _Answer.from_dict) is None


def test_damaged_files_read_as_missing(tmp_path):
    s = Store(tmp_path)
    (tmp_path / "r.json").write_text('{"porosity": 0.1')
    (tmp_path / "a.npz").write_bytes(b"PK\x03\x04 not a zip")
    assert s.read_json("r.json") is None
    assert s.read_arrays("a.npz") is None


def test_tables_and_arrays(tmp_path):
    s = Store(tmp_path)
    s.write_csv("rows.csv", [{"a": 1, "b": 2.5}, {"a": 2, "c": "x"}])
    frame = s.read_frame("rows.csv")
    assert list(frame.columns) == ["a", "b", "c"] and frame["a"].tolist() == [1, 2]
    s.write_frame("f.csv", pd.DataFrame({"y": [0.5, 0.25]}))
    assert s.read_frame("f.csv")["y"].tolist() == [0.5, 0.25]
    s.write_parquet("f.parquet", pd.DataFrame({"y": [0.5, 0.25]}))
    assert pd.read_parquet(tmp_path / "f.parquet")["y"].tolist() == [0.5, 0.25]
    s.write_arrays("a.npz", x=np.arange(3.0), y=np.ones(2, dtype=np.int64))
    arrays = s.read_arrays("a.npz")
    assert arrays["x"].tolist() == [0.0, 1.0, 2.0] and arrays["y"].dtype == np.int64
    assert not [p.name for p in tmp_path.iterdir() if p.name.startswith(".")], "no temporaries left"


def test_children_copy_remove_and_walk(tmp_path):
    s = Store(tmp_path)
    t = s.child("trials", "01_n0.2")
    t.write_text("note.txt", "hello")
    assert t.has("note.txt") and t.read_text("note.txt") == "hello"
    t.copy("note.txt", s, "top.txt")
    assert s.read_text("top.txt") == "hello"
    t.remove("note.txt")
    t.remove("note.txt")  # twice: no error
    assert not t.has("note.txt")
    assert [c.root.name for c in walk(s.child("trials"), "*_n*")] == ["01_n0.2"]
    assert s.child("trials") == Store(tmp_path / "trials")


def test_checkpoints_resume_the_saved_state(tmp_path):
    p = Particles(
        np.array([[0.01, 0.01], [0.0141, 0.01]]), np.array([0.002, 0.002]), 2650.0, 0.008, 4e5, 4e5, 0.5
    )
    sim = Simulation(p, Walls.box(0, 0, 0.05, 0.05, 1e7, 1e7, 0.5))
    sim.run(200)
    ck = Store(tmp_path).checkpoints("stage.npz")
    assert ck.resume() is None
    ck.save(sim, extra={"done": 200})
    back, extra = ck.resume()
    assert extra == {"done": 200} and back.step_count == 200
    assert np.array_equal(back.particles.pos, sim.particles.pos)
    ck.clear()
    assert ck.resume() is None
