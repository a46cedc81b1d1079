"""The store: named result files written atomically and read back checked."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd
import pytest

from poro2d.dem import Particles, Simulation, Walls
from poro2d.errors import InputError
from poro2d.store import Store, digests, folder, walk
from poro2d.store.stage import Fingerprint
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


def test_parquet_written_with_an_engine(tmp_path):
    pytest.importorskip("pyarrow", reason="pyarrow is optional (the parquet and test extras bring it)")
    assert folder.parquet_engine_available()
    Store(tmp_path).write_parquet("f.parquet", pd.DataFrame({"y": [0.5, 0.25]}))
    assert pd.read_parquet(tmp_path / "f.parquet")["y"].tolist() == [0.5, 0.25]


def test_no_parquet_engine_writes_nothing_and_drops_a_stale_file(tmp_path, monkeypatch):
    """Without pyarrow the store writes no Parquet file, and one left by an earlier run (out of
    date once the table is rewritten) is removed, from the manifest too."""
    s = Store(tmp_path)
    s.write_text("f.parquet", "an earlier run's table")
    monkeypatch.setattr(folder, "parquet_engine_available", lambda: False)
    assert s.write_parquet("f.parquet", pd.DataFrame({"y": [0.5]})) is None
    assert not (tmp_path / "f.parquet").exists() and not s.has("f.parquet")
    assert "f.parquet" not in (tmp_path / digests.MANIFEST).read_text()


def test_tables_and_arrays(tmp_path):
    s = Store(tmp_path)
    s.write_csv("rows.csv", [{"a": 1, "b": 2.5}, {"a": 2, "c": "x"}])
    frame = s.read_frame("rows.csv")
    assert list(frame.columns) == ["a", "b", "c"] and frame["a"].tolist() == [1, 2]
    s.write_frame("f.csv", pd.DataFrame({"y": [0.5, 0.25]}))
    assert s.read_frame("f.csv")["y"].tolist() == [0.5, 0.25]
    s.write_arrays("a.npz", x=np.arange(3.0), y=np.ones(2, dtype=np.int64))
    arrays = s.read_arrays("a.npz")
    assert arrays["x"].tolist() == [0.0, 1.0, 2.0] and arrays["y"].dtype == np.int64
    hidden = [p.name for p in tmp_path.iterdir() if p.name.startswith(".")]
    assert hidden == [digests.MANIFEST], "no temporaries left"


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
    meta, arrays = Store(tmp_path).read_state("stage.npz")  # the whole file read and checked
    assert meta["extra"] == {"done": 200} and arrays
    ck.clear()
    assert ck.resume() is None
    ck.save(sim, extra={"done": 200})
    (tmp_path / "stage.npz").write_bytes((tmp_path / "stage.npz").read_bytes()[:-10])
    assert ck.resume() is None and not (tmp_path / "stage.npz").exists()  # damaged: start again


def test_a_file_changed_since_it_was_written_is_not_used(tmp_path):
    """Edited by hand, truncated or replaced: read as missing, refused where it cannot be recomputed."""
    s = Store(tmp_path)
    s.write_result("result.json", _Answer(0.17, True))
    (tmp_path / "result.json").write_text((tmp_path / "result.json").read_text().replace("0.17", "0.5"))
    assert s.read_json("result.json") is None and not s.intact("result.json")
    s.write_arrays("a.npz", x=np.arange(1000.0))
    data = (tmp_path / "a.npz").read_bytes()
    (tmp_path / "a.npz").write_bytes(data[: len(data) // 2])
    assert s.read_arrays("a.npz") is None
    s.write_csv("c.csv", [{"a": 1}])
    (tmp_path / "c.csv").write_text("a\n2\n")
    with pytest.raises(InputError, match="changed since it was written"):
        s.read_frame("c.csv")
    s.write_csv("c.csv", [{"a": 3}])  # written again: trusted again
    assert s.read_frame("c.csv")["a"].tolist() == [3]


def test_files_the_store_did_not_write_are_read_unchecked(tmp_path):
    (tmp_path / "old.json").write_text('{"porosity": 0.2}')
    assert Store(tmp_path).read_json("old.json") == {"porosity": 0.2}


def test_a_stage_whose_marker_was_edited_runs_again(tmp_path):
    calls = []

    def compute():
        calls.append(1)
        return {"peak_kpa": 42.0}

    stage = Store(tmp_path).stage(Fingerprint({"case": 1}))
    assert stage.run(compute) == {"peak_kpa": 42.0}
    assert stage.run(compute) == {"peak_kpa": 42.0} and len(calls) == 1  # resumed
    (tmp_path / "result.json").write_text('{"peak_kpa": 4200.0}')
    assert stage.run(compute) == {"peak_kpa": 42.0} and len(calls) == 2  # recomputed, not used


def test_a_state_read_once_starts_runs_as_its_file_does(tmp_path):
    from poro2d.dem import checkpoint

    p = Particles(
        np.array([[0.01, 0.01], [0.0141, 0.01]]), np.array([0.002, 0.002]), 2650.0, 0.008, 4e5, 4e5, 0.5
    )
    sim = Simulation(p, Walls.box(0, 0, 0.05, 0.05, 1e7, 1e7, 0.5))
    sim.run(100)
    s = Store(tmp_path)
    s.save_state("state.npz", sim)
    meta, arrays = s.read_state("state.npz")
    assert checkpoint.content_digest(meta, arrays) == checkpoint.state_digest(tmp_path / "state.npz")
    a = checkpoint.from_content(meta, arrays)
    a.run(100)
    b = s.load_state("state.npz")
    b.run(100)
    assert np.array_equal(a.particles.pos, b.particles.pos)
    again = checkpoint.from_content(meta, arrays)  # the content is unchanged by the first run
    assert np.array_equal(again.particles.pos, s.load_state("state.npz").particles.pos)


def test_csv_rows_read_back_as_written(tmp_path):
    s = Store(tmp_path)
    x = 0.1 + 0.2  # a float whose shortest repr has 17 digits
    s.write_csv("t.csv", [{"a": 1, "b": x}, {"a": 2, "b": "text, quoted"}])
    assert s.read_rows("t.csv") == [{"a": "1", "b": repr(x)}, {"a": "2", "b": "text, quoted"}]
    assert float(s.read_rows("t.csv")[0]["b"]) == x
    assert s.read_rows("missing.csv") is None


def test_a_call_holds_the_folder_of_the_store_it_is_given(tmp_path):
    """``claims`` holds a store (or a command's folder) by its folder; None holds nothing."""
    from poro2d.store import claims

    @claims("shear")
    def run(store):
        return None if store is None else store.root.is_dir()  # held: made for the call

    assert run(None) is None and not list(tmp_path.iterdir())
    assert run(Store(tmp_path / "out", parameter="--into"))

    @claims("export", "out")
    def command(out):
        return out.is_dir()

    assert command(tmp_path / "path")


def test_a_claim_marks_the_folder_refuses_another_kind_and_resumes_its_own(tmp_path):
    from poro2d.locks import KIND_NAME, folder_kind
    from poro2d.store import claimed

    store = Store(tmp_path / "out", parameter="--into")
    with store.claim("shear") as held:
        assert held is store and folder_kind(store.root) == "shear"
        store.write_json("result.json", {"x": 1})
    with store.claim("shear"):  # the same kind: resumes
        pass
    with pytest.raises(InputError) as e, store.claim("biaxial"):
        pass
    assert "--into" in str(e.value) and "a shear run" in str(e.value)
    assert (store.root / KIND_NAME).read_text() == "shear\n"
    with claimed(None, "shear") as nothing:  # a run that keeps nothing holds nothing
        assert nothing is None
    with Store(tmp_path / "empty").claim("shear"):  # a block that writes nothing leaves no folder
        pass
    assert not (tmp_path / "empty").exists()


def test_every_package_claims_a_kind_the_locks_know():
    """Each package names its kind (``KIND``); the locks list every kind's own files (``KIND_SIGNS``)."""
    import importlib

    from poro2d.locks import KIND_SIGNS

    modules = ["poro2d.criterion.run", "poro2d.shear.run", "poro2d.biaxial.run", "poro2d.critical_state.run",
               "poro2d.sweep.runner", "poro2d.sand.run", "poro2d.calibration.run", "poro2d.paper",
               "poro2d.cli.strength", "poro2d.cli.export", "poro2d.cli.import_specimen"]  # fmt: skip
    kinds = [importlib.import_module(m).KIND for m in modules]
    assert sorted(kinds) == sorted(set(kinds)) and set(kinds) <= set(KIND_SIGNS)
