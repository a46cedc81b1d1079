"""Atomic integers and a spin barrier for threads that stay inside one compiled loop.

numba's ``prange`` starts and joins its threads at every parallel loop: two loops per
time step cost more than a small packing's step takes. The engine instead starts one
worker per thread once per kernel call and lets the workers meet at barriers between
the phases of each step (:mod:`poro2d.dem.kernels`). numba has no atomics of its own
on the CPU, so the few this needs are written here as LLVM intrinsics: sequentially
consistent loads, stores, fetch-and-add and compare-and-swap on ``int64`` array slots,
plus ``sched_yield`` so a waiting thread gives its core away on a busy machine, and the C
library's ``time`` so that the start handshake gives up after seconds of the clock, not after
a count of yields (a yield lasts a scheduler slice on a loaded machine: 400 000 of them took
minutes there).

The shared ``sync`` array (``int64``, :data:`N_SYNC` slots) holds the barrier state,
the start handshake and the run status that all workers read.
"""

from __future__ import annotations

from llvmlite import ir
from numba import njit, types
from numba.core import cgutils
from numba.extending import intrinsic

# slots of the shared int64 ``sync`` array
COUNT, GENERATION, START, ARRIVED, STATUS_WORD = range(5)
N_SYNC = 8  # spare slots: the array is one cache line

# states of the start handshake
WAITING, GO, ABORTED = 0, 1, 2

# Busy polls (about 0.1-0.5 ms) before a waiting thread starts yielding its core. Short
# waits must not yield: a system call per wait costs more than the wait and slows the
# thread afterwards (measured: 2 threads went from 1.6x to 1.9x one thread's speed).
SPINS = 200_000
# Whole seconds of the clock (so START_WAIT_S - 1 to START_WAIT_S of waiting) before the start
# handshake gives up. Workers that both run arrive within milliseconds; giving up costs only
# speed, since the call then goes on with one thread and the same numbers.
START_WAIT_S = 3


def _slot_pointer(context, builder, sig, args):
    aryty = sig.args[0]
    ary = context.make_array(aryty)(context, builder, args[0])
    idx = context.cast(builder, args[1], sig.args[1], types.intp)
    return cgutils.get_item_pointer(context, builder, aryty, ary, [idx])


def _is_i64_vector(a) -> bool:
    return isinstance(a, types.Array) and a.dtype == types.int64 and a.ndim == 1


@intrinsic
def atomic_load(typingctx, arr, idx):
    """``arr[idx]``, read atomically (acquire)."""
    if not (_is_i64_vector(arr) and isinstance(idx, types.Integer)):
        return None

    def codegen(context, builder, sig, args):
        ptr = _slot_pointer(context, builder, sig, args)
        return builder.load_atomic(ptr, "acquire", 8)

    return types.int64(arr, idx), codegen


def _slot_update(returns, emit):
    """An intrinsic ``f(arr, idx, val)`` on an int64 slot: ``emit(builder, ptr, v)`` writes ``v`` there.

    ``returns`` is its numba type: ``types.none`` (a store) or ``types.int64`` (the old value).
    """

    def typer(typingctx, arr, idx, val):
        if not (_is_i64_vector(arr) and isinstance(idx, types.Integer) and isinstance(val, types.Integer)):
            return None

        def codegen(context, builder, sig, args):
            ptr = _slot_pointer(context, builder, sig, args)
            old = emit(builder, ptr, context.cast(builder, args[2], sig.args[2], types.int64))
            return context.get_dummy_value() if returns is types.none else old

        return returns(arr, idx, val), codegen

    return intrinsic(typer)


#: ``arr[idx] = val``, written atomically (release)
atomic_store = _slot_update(types.none, lambda builder, ptr, v: builder.store_atomic(v, ptr, "release", 8))
#: ``arr[idx] += val`` atomically; returns the old value
atomic_add = _slot_update(types.int64, lambda builder, ptr, v: builder.atomic_rmw("add", ptr, v, "seq_cst"))


@intrinsic
def atomic_cas(typingctx, arr, idx, expected, new):
    """If ``arr[idx] == expected`` set it to ``new``, atomically; returns the old value."""
    ok = _is_i64_vector(arr) and all(isinstance(x, types.Integer) for x in (idx, expected, new))
    if not ok:
        return None

    def codegen(context, builder, sig, args):
        ptr = _slot_pointer(context, builder, sig, args)
        e = context.cast(builder, args[2], sig.args[2], types.int64)
        v = context.cast(builder, args[3], sig.args[3], types.int64)
        res = builder.cmpxchg(ptr, e, v, "seq_cst", "seq_cst")
        return builder.extract_value(res, 0)

    return types.int64(arr, idx, expected, new), codegen


@intrinsic
def sched_yield(typingctx):
    """POSIX ``sched_yield()``: let another runnable thread have this core."""

    def codegen(context, builder, sig, args):
        fnty = ir.FunctionType(ir.IntType(32), [])
        fn = cgutils.get_or_insert_function(builder.module, fnty, "sched_yield")
        builder.call(fn, [])
        return context.get_dummy_value()

    return types.none(), codegen


@intrinsic
def wall_seconds(typingctx):
    """C ``time(NULL)``: the calendar clock in whole seconds (``time_t`` is 64-bit here)."""

    def codegen(context, builder, sig, args):
        i8p = ir.IntType(8).as_pointer()
        fnty = ir.FunctionType(ir.IntType(64), [i8p])
        fn = cgutils.get_or_insert_function(builder.module, fnty, "time")
        return builder.call(fn, [ir.Constant(i8p, None)])

    return types.int64(), codegen


@njit(cache=True)
def barrier(sync, nthreads):
    """Wait until all ``nthreads`` workers have arrived (a sense-counting barrier).

    The last thread to arrive resets the count and advances the generation; the
    others poll the generation, first busily, then yielding their core. Everything a
    thread wrote before the barrier is visible to every thread after it.
    """
    if nthreads <= 1:
        return
    gen = atomic_load(sync, GENERATION)
    if atomic_add(sync, COUNT, 1) == nthreads - 1:
        atomic_store(sync, COUNT, 0)
        atomic_store(sync, GENERATION, gen + 1)
        return
    spins = 0
    while atomic_load(sync, GENERATION) == gen:
        spins += 1
        if spins > SPINS:
            sched_yield()


@njit(cache=True)
def start_handshake(sync, nthreads):
    """True when all ``nthreads`` workers run at the same time, False if they cannot.

    A threading layer may run two iterations of a parallel loop one after the other
    on one thread; workers that waited for each other at a barrier would then hang.
    Each worker arrives here first: the last arrival declares GO; a worker that has
    waited START_WAIT_S seconds of the clock in vain declares ABORTED instead. Exactly one of the
    two wins (compare-and-swap), and every worker returns the same answer.
    """
    if nthreads <= 1:
        return True
    if atomic_add(sync, ARRIVED, 1) == nthreads - 1:
        atomic_cas(sync, START, WAITING, GO)
    waited = 0
    since = 0
    while atomic_load(sync, START) == WAITING:
        waited += 1
        if waited == SPINS:
            since = wall_seconds()
        elif waited > SPINS:
            sched_yield()
            if wall_seconds() - since >= START_WAIT_S:
                atomic_cas(sync, START, WAITING, ABORTED)
    return atomic_load(sync, START) == GO


def fresh_sync():
    """A zeroed ``sync`` array: one per kernel call."""
    import numpy as np

    return np.zeros(N_SYNC, dtype=np.int64)
