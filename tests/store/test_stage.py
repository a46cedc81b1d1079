"""The resumable-stage helper: compute once, read back, refuse other work, bind only once started."""

import json
import shutil

import pytest

from poro2d.errors import InputError
from poro2d.store.stage import Fingerprint, ResumableStage, differing_keys

SETTINGS = {"specimen": {"width": 0.06, "threads": 1}, "criterion": {"max_iterations": 2}, "seed": 0}


def _stage(folder, content=None, **kw):
    fp = Fingerprint(content if content is not None else SETTINGS, ignore=("specimen.threads",))
    return ResumableStage(folder, fp, record="config.json", extra={"config": {"as": "given"}}, **kw)


class Counter:
    """A stage's work: counts its calls, writes a side file first (as stages do)."""

    def __init__(self, folder, value=1.0, marker="result.json"):
        self.folder, self.value, self.marker, self.calls = folder, value, marker, 0

    def __call__(self):
        self.calls += 1
        assert self.marker is None or not (self.folder / self.marker).exists()  # the marker comes last
        (self.folder / "side.csv").write_text("x\n1\n")
        return {"value": self.value, "flag": True}


def test_fresh_stage_computes_writes_the_record_and_the_marker_last(tmp_path):
    work = Counter(tmp_path)
    assert _stage(tmp_path).run(work) == {"value": 1.0, "flag": True}
    assert work.calls == 1
    record = json.loads((tmp_path / "config.json").read_text())
    assert record == {"run": SETTINGS, "config": {"as": "given"}}
    assert json.loads((tmp_path / "result.json").read_text()) == {"value": 1.0, "flag": True}
    side, marker = (tmp_path / "side.csv").stat(), (tmp_path / "result.json").stat()
    assert marker.st_mtime_ns >= side.st_mtime_ns


def test_finished_stage_is_read_back_not_recomputed(tmp_path):
    _stage(tmp_path).run(Counter(tmp_path))
    again = Counter(tmp_path, value=2.0)
    assert _stage(tmp_path).run(again, decode=lambda d: d["value"]) == 1.0
    assert again.calls == 0


def test_performance_settings_are_not_compared(tmp_path):
    _stage(tmp_path).run(Counter(tmp_path))
    more_threads = dict(SETTINGS, specimen={"width": 0.06, "threads": 2})
    again = Counter(tmp_path)
    _stage(tmp_path, more_threads).run(again)
    assert again.calls == 0


def test_other_work_is_refused_naming_the_keys_that_differ(tmp_path):
    _stage(tmp_path).run(Counter(tmp_path))
    other = dict(SETTINGS, criterion={"max_iterations": 3}, seed=1)
    with pytest.raises(InputError) as e:
        _stage(tmp_path, other).run(Counter(tmp_path))
    assert e.value.parameter == "--out"
    assert "criterion.max_iterations, seed" in str(e.value) and "choose another --out" in str(e.value)
    assert json.loads((tmp_path / "config.json").read_text())["run"] == SETTINGS  # untouched


def test_the_parameter_and_the_wording_are_the_callers(tmp_path):
    _stage(tmp_path).run(Counter(tmp_path))
    other = dict(SETTINGS, seed=1)
    words = {
        "parameter": "out",
        "allowed": "the same run",
        "explain": lambda keys, old: f"seed was {old['seed']}",
    }
    with pytest.raises(InputError, match=r"out = .* allowed: the same run \(seed was 0\)"):
        _stage(tmp_path, other, **words).check()


def test_a_record_binds_only_once_work_has_started(tmp_path):
    _stage(tmp_path).bind()  # a run stopped before any work: only its record
    other = dict(SETTINGS, seed=1)
    work = Counter(tmp_path)
    _stage(tmp_path, other).run(work)
    assert work.calls == 1
    assert json.loads((tmp_path / "config.json").read_text())["run"]["seed"] == 1
    with pytest.raises(InputError, match="seed"):  # now it has: bound
        _stage(tmp_path).check()


def test_a_crash_in_the_stage_leaves_no_marker_and_a_rerun_computes(tmp_path):
    def crash():
        (tmp_path / "partial.npz").write_bytes(b"half")
        raise RuntimeError("killed")

    with pytest.raises(RuntimeError, match="killed"):
        _stage(tmp_path).run(crash)
    assert not (tmp_path / "result.json").exists()
    assert (tmp_path / "config.json").is_file()  # bound: work had started
    with pytest.raises(InputError):
        _stage(tmp_path, dict(SETTINGS, seed=1)).run(Counter(tmp_path))
    work = Counter(tmp_path)
    assert _stage(tmp_path).run(work)["value"] == 1.0 and work.calls == 1


def test_a_moved_folder_resumes(tmp_path):
    first = tmp_path / "a" / "out"
    first.mkdir(parents=True)
    _stage(first).run(Counter(first))
    moved = tmp_path / "b" / "elsewhere"
    shutil.copytree(first, moved)
    shutil.rmtree(first)
    again = Counter(moved)
    assert _stage(moved).run(again)["value"] == 1.0 and again.calls == 0


def test_several_markers_share_one_record(tmp_path):
    stage = _stage(tmp_path)
    stage.run(Counter(tmp_path))
    sub = Counter(tmp_path, value=3.0, marker="trials/01/trial.json")
    assert stage.run(sub, "trials/01/trial.json")["value"] == 3.0
    assert stage.run(Counter(tmp_path), "trials/01/trial.json")["value"] == 3.0
    assert sub.calls == 1


def test_accept_refuses_a_marker_of_an_unfinished_shape(tmp_path):
    stage = _stage(tmp_path)
    stage.bind()
    (tmp_path / "result.json").write_text(json.dumps({"status": "failed"}))
    assert stage.stored(accept=lambda d: d.get("status") == "done") is None
    assert stage.stored() == {"status": "failed"}


def test_work_without_a_record_is_refused_or_adopted(tmp_path):
    (tmp_path / "result.json").write_text(json.dumps({"value": 9.0}))
    with pytest.raises(InputError, match="without a record"):
        _stage(tmp_path).check()
    work = Counter(tmp_path, marker=None)
    assert _stage(tmp_path, unrecorded="adopt").run(work)["value"] == 1.0  # the marker is not trusted
    assert work.calls == 1 and (tmp_path / "config.json").is_file()


def test_a_fresh_result_has_the_types_a_resumed_one_reads_back(tmp_path):
    import numpy as np

    def compute():
        return {"x": np.float64("nan"), "ok": np.bool_(True), "pair": (1, 2)}

    fresh = _stage(tmp_path).run(compute)
    resumed = _stage(tmp_path).run(compute)
    assert fresh == resumed == {"x": None, "ok": True, "pair": [1, 2]}  # JSON has no NaN
    assert type(fresh["ok"]) is bool


def test_record_without_a_key_is_the_fingerprint_itself(tmp_path):
    case = {"id": "abc", "kind": "probe", "params": {"x": 1}, "config": {"x": 1}}
    labels = ("id", "params")
    stage = ResumableStage(tmp_path, Fingerprint(case, ignore=labels), record="params.json", key=None)
    stage.run(lambda: {"status": "done"})
    assert json.loads((tmp_path / "params.json").read_text()) == case
    relabelled = Fingerprint(dict(case, params={"probe.x": 1}), ignore=labels)
    assert ResumableStage(tmp_path, relabelled, record="params.json", key=None).stored() == {"status": "done"}


def test_fingerprint_digest_and_differences():
    a = Fingerprint({"s": {"w": 0.3, "threads": 1}, "n": [1, 2]}, ignore=("s.threads",))
    b = Fingerprint({"n": [1, 2], "s": {"threads": 4, "w": 0.3}}, ignore=("s.threads",))
    assert a.digest == b.digest and a.differences(b.content) == []
    assert a.differences({"s": {"w": 0.2}, "n": [1, 2, 3], "extra": 0}) == ["extra", "n", "s.w"]
    assert differing_keys({"a": {"b": 1}}, {"a": {"b": 1, "c": 2}}) == ["a.c"]


# -- the one rule of a laboratory test's folder (direct shear and biaxial alike) ------------------
TEST = {"specimen_digest": "abc", "confining_kpa": 100.0, "settings": {"max_strain": 0.02}}


def _test_stage(folder, **changes):
    from poro2d.store.stage import test_stage

    fp = Fingerprint({**TEST, **changes})
    return test_stage(folder, fp, specimen="s.npz", stress=("confining_kpa", "confining stress"))


@pytest.mark.parametrize(
    ("changes", "words"),
    [
        ({"confining_kpa": 50.0}, "a test of another confining stress (100.0 kPa); use a new --out"),
        ({"specimen_digest": "def"}, "a test of another specimen"),
        ({"settings": {"max_strain": 0.03}}, "a test of other settings (max_strain)"),
    ],
)
def test_a_test_folder_holding_another_test_is_refused_naming_it_and_kept(tmp_path, changes, words):
    first = _test_stage(tmp_path)
    first.run(lambda: {"done": 1})
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    with pytest.raises(InputError) as e:
        _test_stage(tmp_path, **changes).run(lambda: {"done": 2})
    assert str(tmp_path) in str(e.value) and words in str(e.value), str(e.value)
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before  # nothing emptied
    assert _test_stage(tmp_path).run(lambda: {"done": 3}) == {"done": 1}  # the same test resumes
    record = json.loads((tmp_path / "test.json").read_text())
    assert record["specimen"] == "s.npz" and record["key"] == first.fingerprint.digest
