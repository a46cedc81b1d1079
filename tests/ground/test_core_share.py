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


def test_the_board_is_read_at_most_once_a_second_and_gone_with_its_folder(monkeypatch):
    now = [100.0]
    monkeypatch.setattr(C.time, "monotonic", lambda: now[0])
    with C.share_board() as board:
        lender = C.ThreadLender(board)
        assert lender() == 1  # posted when the board is made
        board.post(2)
        assert lender() == 1  # read less than POLL_S ago
        now[0] += C.POLL_S
        assert lender() == 2
    now[0] += C.POLL_S
    assert board.read() is None and lender() == 2  # the run ended: the last count is kept


def _clock(monkeypatch, workers: int, cases: int, lend: bool):
    """A clock whose cases end at 10, 20 and 30 s; ``lend``: with a board."""
    t = [0.0]
    monkeypatch.setattr(C.time, "perf_counter", lambda: t[0])
    with C.share_board() as board:
        clock = C.CoreClock(workers, cases, 2, board if lend else None)
        for end in (10.0, 20.0, 30.0):
            t[0] = end
            clock.case_ended()
            if lend:
                assert board.read() == C.threads_per_case(workers, clock.left, 2)
        return clock.use(["w1", "w2", "w1"])


def test_three_cases_on_two_workers_leave_no_core_idle_when_the_last_takes_two(monkeypatch):
    use = _clock(monkeypatch, 2, 3, lend=True)
    assert use.wall_s == 30.0 and use.busy_core_s == 60.0 and use.idle_core_s == 0.0
    assert use.cases_per_worker == {"w1": 2, "w2": 1} and use.cases == 3
    # [seconds, cases left, threads per case] at each change
    assert use.threads_over_time == [[0.0, 3, 1], [10.0, 2, 1], [20.0, 1, 2], [30.0, 0, 2]]
    assert "threads per case 1 -> 2" in C.use_text(use) and "idle 0 s of 60 s" in C.use_text(use)
    # without lending, the third case runs alone on one core for 10 s: 10 core-s idle
    alone = _clock(monkeypatch, 2, 3, lend=False)
    assert alone.busy_core_s == 50.0 and alone.idle_core_s == 10.0
    assert C.WorkerUse.from_dict(use.to_dict()).to_dict() == use.to_dict()
