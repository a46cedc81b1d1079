"""Spare cores to the cases still running (:mod:`poro2d.execute.core_share`): the rule, the board
the driver posts on, and the account of the cores."""

from __future__ import annotations

import pytest

from poro2d.execute import core_share as C


@pytest.mark.parametrize(
    ("workers", "cases", "cap", "threads"),
    [
        (2, 5, 2, 1),  # the cases fill the workers: one thread each
        (2, 2, 2, 1),
        (2, 1, 2, 2),  # the last case takes the idle core
        (16, 4, 2, 2),  # capped at the partitions: no change of round-off
        (16, 4, 8, 4),
        (16, 3, 8, 5),  # 16 // 3
        (16, 1, 8, 8),
        (3, 2, 2, 1),  # 3 // 2 = 1: a core stays idle rather than split unevenly
        (1, 1, 2, 1),
    ],
)
def test_threads_per_case_is_workers_over_cases_capped_at_the_partitions(workers, cases, cap, threads):
    assert C.threads_per_case(workers, cases, cap) == threads


@pytest.fixture
def now(monkeypatch) -> list[float]:
    """The lenders' clock, moved by hand."""
    t = [100.0]
    monkeypatch.setattr(C.time, "monotonic", lambda: t[0])
    return t


def test_the_board_is_read_at_most_once_a_second_and_gone_with_its_folder(now):
    with C.share_board() as board:
        lender = C.ThreadLender(board)
        assert lender() == 1  # posted when the board is made
        board.post(2)
        assert lender() == 1  # read less than POLL_S ago
        now[0] += C.POLL_S
        assert lender() == 2
    now[0] += C.POLL_S
    assert board.read() is None and lender() == 2  # the run ended: the last count is kept


def _row(worker: str, time_s: float, lent: float = 0.0):
    from poro2d.sweep.records import CaseRow

    return CaseRow.from_dict({"case_id": "c", "status": "done", "worker": worker, "time_s": time_s,
                              "lent_core_s": lent})  # fmt: skip


def _clock(monkeypatch, lend: bool):
    """Three cases on two workers: a on w1 0-10 s, b on w2 0-20 s, c on w1 10-30 s, alone from
    20 s (on two threads with ``lend``: 10 core-s more)."""
    t = [0.0]
    monkeypatch.setattr(C.time, "perf_counter", lambda: t[0])
    with C.share_board() as board:
        clock = C.CoreClock(2, 3, 2, board if lend else None)
        for end in (10.0, 20.0, 30.0):
            t[0] = end
            clock.case_ended()
            if lend:
                assert board.read() == C.threads_per_case(2, clock.left, 2)
        return clock.use([_row("w1", 10.0), _row("w2", 20.0), _row("w1", 20.0, 10.0 if lend else 0.0)])


def test_three_cases_on_two_workers_leave_no_core_idle_when_the_last_takes_two(monkeypatch):
    use = _clock(monkeypatch, lend=True)
    assert use.wall_s == 30.0 and use.busy_core_s == 60.0 and use.idle_core_s == 0.0
    assert use.cases_per_worker == {"w1": 2, "w2": 1} and use.cases == 3
    # [seconds, cases left, threads per case] at each change
    assert use.threads_over_time == [[0.0, 3, 1], [10.0, 2, 1], [20.0, 1, 2], [30.0, 0, 2]]
    assert "threads per case 1 -> 2" in C.use_text(use) and "idle 0 s of 60 s" in C.use_text(use)
    # without lending, the third case runs alone on one core for 10 s: 10 core-s idle
    alone = _clock(monkeypatch, lend=False)
    assert alone.busy_core_s == 50.0 and alone.idle_core_s == 10.0
    assert alone.threads_over_time == [[0.0, 3, 1], [10.0, 2, 1], [20.0, 1, 1], [30.0, 0, 1]]
    assert C.WorkerUse.from_dict(use.to_dict()).to_dict() == use.to_dict()


def test_a_case_takes_only_the_threads_that_have_a_free_core():
    # (posted, other processes' busy cores, the machine's cores) -> threads taken
    assert C.free_cores_allow(2, None, 2) == 2  # the machine's load unknown: what is posted
    assert C.free_cores_allow(2, 0.1, 2) == 2  # a quiet machine: the idle core is free
    assert C.free_cores_allow(2, 0.9, 2) == 1  # another process holds the core: it would wait on it
    assert C.free_cores_allow(2, 6.0, 2) == 1  # a loaded machine: one thread, never none
    assert C.free_cores_allow(8, 10.5, 16) == 5 and C.free_cores_allow(1, 0.0, 16) == 1


def test_the_lender_holds_back_threads_while_other_processes_use_the_cores(now, monkeypatch):
    with C.share_board() as board:
        board.post(2)
        lender = C.ThreadLender(board)
        lender.cores = 2
        monkeypatch.setattr(lender.load, "cores", lambda: 1.8)  # another program runs meanwhile
        assert lender() == 1
        now[0] += C.POLL_S
        monkeypatch.setattr(lender.load, "cores", lambda: 0.05)  # it ended
        assert lender() == 2
    load = C.OtherLoad()
    assert load.cores() is None or load.cores() >= 0.0
