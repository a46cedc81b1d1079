"""``poro2d paper`` with fewer specimens than asked for: the answer printed and written, the refused
seeds named, exit code 1 (as ``poro2d sand``); with a refused seed replaced, exit code 0.

The stages are stood in for by the stored summary of a finished run with the replicate rows a
run would have (no DEM work): what is tested is what the command makes of them.
"""

import json
from pathlib import Path

import pytest

from poro2d import paper
from poro2d.cli import main
from poro2d.criterion.result import ReplicateRow
from poro2d.report import paper_report

DATA = Path(__file__).parents[1] / "data" / "before_typed_results" / "paper_results.json"


def row(seed: int, accepted: bool, why: str = "") -> ReplicateRow:
    return ReplicateRow(seed, 0.22 if accepted else None, accepted, 2, why, f"seed{seed}", 0.0)


@pytest.fixture
def stages(monkeypatch):
    """Stand the stages in by the stored summary with the given replicate rows; returns the
    summaries the report was handed."""
    reported = []

    def report(out, summary, criterion, **parts):
        reported.append(summary)
        return [Path(out) / "report.md", Path(out) / "report.html"]

    monkeypatch.setattr(paper_report, "write_paper_report", report)

    def use(rows: list[ReplicateRow]) -> list:
        def run_stages(store, stage, crit, case, *, progress):
            summary = paper.PaperSummary.from_dict(json.loads(DATA.read_text()))
            summary.replicate_specimens = rows
            return summary, None, {}, {}

        monkeypatch.setattr(paper, "_run_stages", run_stages)
        return reported

    return use


def run(out: Path) -> int:
    """``poro2d paper --quick --replicates 3`` into ``out``: its exit code."""
    try:
        main(["paper", "--quick", "--replicates", "3", "--out", str(out), "--quiet"])
    except SystemExit as e:
        return e.code
    return 0


def test_fewer_specimens_than_asked_for_exit_1_after_the_answer(tmp_path, stages, capsys):
    # seed 2 refused, seed 3 tried in its place and refused too, no replacement left
    reported = stages(
        [row(1, True), row(2, False, "check force_balance failed"), row(3, False, "check x failed")]
    )
    assert run(tmp_path / "p") == 1
    printed = capsys.readouterr().out
    assert "replicate seed 2 not accepted (check force_balance failed): replaced by seed 3" in printed
    assert "replicate seed 3 not accepted (check x failed): no seed left to replace it" in printed
    assert "error: 2 of 3 specimens asked for were accepted and sheared (seeds 0, 1)" in printed
    # the answer is still written, and says what it is over
    stored = json.loads((tmp_path / "p" / "results.json").read_text())
    assert stored["specimens_asked"] == 3 and stored["specimen_seeds"] == [0, 1]
    assert stored["seeds_replaced"] == [
        {"seed": 2, "reason": "check force_balance failed", "replaced_by": 3},
        {"seed": 3, "reason": "check x failed", "replaced_by": None},
    ]
    assert reported[0].specimens_short == 1
    # and read back from the file, the summary says the same
    assert paper.PaperSummary.from_dict(stored).specimens_short == 1


def test_a_refused_seed_replaced_exits_0_and_names_it(tmp_path, stages, capsys):
    stages([row(1, True), row(2, False, "check force_balance failed"), row(3, True)])
    assert run(tmp_path / "p") == 0
    printed = capsys.readouterr().out
    assert "replicate seed 2 not accepted (check force_balance failed): replaced by seed 3" in printed
    assert "3 of 3 specimens asked for were accepted and sheared (seeds 0, 1, 3)" in printed
    assert "error" not in printed
    stored = json.loads((tmp_path / "p" / "results.json").read_text())
    assert stored["specimen_seeds"] == [0, 1, 3] and stored["seeds_replaced"][0]["replaced_by"] == 3


def test_every_seed_accepted_says_nothing_more(tmp_path, stages, capsys):
    stages([row(1, True), row(2, True)])
    assert run(tmp_path / "p") == 0
    printed = capsys.readouterr().out
    assert "not accepted" not in printed and "specimens asked for" not in printed
    stored = json.loads((tmp_path / "p" / "results.json").read_text())
    assert (
        stored["specimens_asked"] == 3
        and stored["specimen_seeds"] == [0, 1, 2]
        and stored["seeds_replaced"] == []
    )
