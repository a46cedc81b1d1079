"""A seed refused at full size is replaced by the next unused one; the answer names both."""

from types import SimpleNamespace

import pytest

from poro2d.criterion.density import StateTarget
from poro2d.sand import load_sand_case
from poro2d.sand.result import SeedSpecimen, replaced_seeds
from poro2d.sand.run import seed_accepted, specimen_stage
from poro2d.store import Store
from poro2d.sweep import runner
from poro2d.sweep.records import CaseRow
from poro2d.sweep.relation import case_seed

REFUSED = "trial 1 (n2D = 0.1720) refused: check force_balance failed"
LAB = {"e_max": 0.977, "e_min": 0.597, "dr": 0.8}
#: where and when a case ran: nothing these tests read
UNTIMED = dict.fromkeys(("host", "pid", "worker", "started_utc", "time_s", "finished_utc"))
CFG = {"soil": {"name": "s"}, "grading": {"preset": "paper"}, "lab": LAB}


def _fake_sweep(refused: set[int], calls: list[list[int]]):
    """A sweep whose cases end at once: the seeds in ``refused`` not accepted."""

    def run_sweep(sweep, store, *, options):
        seeds = [c.params["seed"] for c in sweep.cases]
        calls.append(seeds)
        rows = [
            CaseRow(c.id, "criterion", c.params, **UNTIMED, status="done", error=None,
                    results={"converged": s not in refused, "message": "" if s not in refused else REFUSED})
            for c, s in zip(sweep.cases, seeds, strict=True)
        ]  # fmt: skip
        return SimpleNamespace(rows=rows[::-1], summary=None)  # in any order: the stage sorts them by seed

    return run_sweep


@pytest.mark.parametrize(
    "refused, replacements, tried, used",
    [
        (set(), 3, [[0, 1, 2]], [0, 1, 2]),
        ({1}, 3, [[0, 1, 2], [0, 1, 2, 3]], [0, 2, 3]),
        ({1, 3}, 3, [[0, 1, 2], [0, 1, 2, 3], [0, 1, 2, 3, 4]], [0, 2, 4]),
        ({0, 1}, 1, [[0, 1, 2], [0, 1, 2, 3]], [2, 3]),
        ({1}, 0, [[0, 1, 2]], [0, 2]),
    ],
)
def test_refused_seeds_are_replaced_by_the_next_ones(
    tmp_path, monkeypatch, refused, replacements, tried, used
):
    calls: list[list[int]] = []
    monkeypatch.setattr(runner, "run_sweep", _fake_sweep(refused, calls))
    case = load_sand_case({**CFG, "sand": {"seeds": 3, "replacements": replacements}})
    lines: list[str] = []
    rows = specimen_stage(case, StateTarget(0.3, 0.5, 0.17, 0.3), Store(tmp_path), None, lines.append)
    assert calls == tried  # a rerun asks the same sweeps: every finished seed is read back
    assert [int(r.params["seed"]) for r in rows] == tried[-1]
    assert [int(r.params["seed"]) for r in rows if seed_accepted(r)] == used
    assert len(lines) == len(tried) - 1 and all("in their place" in line for line in lines)


def test_the_configs_seed_is_the_first_seed_at_full_size(tmp_path, monkeypatch):
    # a second run with another first seed draws other specimens (before, seed = 10 was
    # accepted and the specimens were seeds 0, 1, 2 all the same); replacements follow on from it
    calls: list[list[int]] = []
    monkeypatch.setattr(runner, "run_sweep", _fake_sweep({11}, calls))
    case = load_sand_case({**CFG, "seed": 10, "sand": {"seeds": 3, "replacements": 3}})
    lines: list[str] = []
    rows = specimen_stage(case, StateTarget(0.3, 0.5, 0.17, 0.3), Store(tmp_path), None, lines.append)
    assert calls == [[10, 11, 12], [10, 11, 12, 13]]
    assert [int(r.params["seed"]) for r in rows if seed_accepted(r)] == [10, 12, 13]
    assert lines == ["seed(s) 11 not accepted: trying seed(s) 13 in their place"]
    kept = [SeedSpecimen.from_row(case_seed(r), r, "f" if seed_accepted(r) else None) for r in rows]
    assert [(g.seed, g.replaced_by) for g in replaced_seeds(kept, 3)] == [(11, 13)]
    assert replaced_seeds([k for k in kept if k.accepted], 3) == []  # none refused: none replaced


def test_the_answer_names_the_replaced_seed_and_why():
    kept = [SimpleNamespace(seed=s, accepted=s != 1, message="" if s != 1 else REFUSED) for s in range(4)]
    (gone,) = replaced_seeds(kept, 3)
    assert (gone.seed, gone.replaced_by, gone.reason) == (1, 3, REFUSED)
    assert gone.to_dict() == {"seed": 1, "reason": REFUSED, "replaced_by": 3}
    (left,) = replaced_seeds(kept[:3], 3)  # no replacement left: said so
    assert left.replaced_by is None


def test_replacements_are_checked_where_they_enter():
    from poro2d.errors import InputError

    assert load_sand_case(CFG).replacements == 3
    with pytest.raises(InputError) as e:
        load_sand_case({**CFG, "sand": {"replacements": -1}})
    assert e.value.parameter == "sand.replacements"


def test_the_configs_seed_is_the_first_seed_of_the_calibration_too():
    # another first seed repeats the whole answer from independent packings: the calibration's
    # cases at every friction run from it as well (before, they were seeds 0, 1 whatever it was)
    from poro2d.sand.run import calibration_case

    box = SimpleNamespace(width=0.1, height=0.05, layers=2)
    pf = SimpleNamespace(calibration_box=box, d50_m=0.002, jamming=SimpleNamespace(porosity=0.155))
    for seed, expect in ((None, [0, 1]), (10, [10, 11])):
        given = {} if seed is None else {"seed": seed}
        case = load_sand_case({**CFG, "sand": {"calibration_seeds": 2}, **given})
        cal = calibration_case(case, pf, [0.0, 1.0])
        assert cal.seed_list == expect
        assert sorted({c.params["seed"] for c in cal.sweep.cases}) == expect
        assert cal.key == calibration_case(load_sand_case(CFG), pf, [0.0, 1.0]).key  # one cache entry


def test_calibration_rows_are_read_by_their_seed():
    from poro2d.sweep.density import calibration_from_rows

    def row(mu, seed, n):
        params = {"specimen.friction_prep": mu, "seed": seed}
        results = {"converged": True, "last_new_porosity": n}
        done = {"status": "done", "error": None, "results": results}
        return CaseRow(f"c{mu}-{seed}", "criterion", params, **UNTIMED, **done)

    rows = [row(0.0, 11, 0.161), row(0.0, 10, 0.160), row(1.0, 10, 0.22), row(0.0, 3, 0.5), row(1.0, 12, 0.5)]
    cal = calibration_from_rows(rows, [0.0, 1.0], [10, 11])
    assert cal.samples == [[0.160, 0.161], [0.22, None]]  # seeds 3 and 12 are another calibration's
    assert cal.seeds == [10, 11]
    assert calibration_from_rows(rows[:1], [0.0, 1.0], 2).samples == [[None, None], [None, None]]
