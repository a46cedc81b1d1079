"""Fused multiply-add for the compiled kernels: ``fma(a, b, c)``, ``a * b + c`` rounded once.

The step's arithmetic is mostly chains of a product feeding a sum: the contact law's
projections, a lever arm's moment, the leapfrog updates. One fused instruction per link
halves the latency of such a chain and rounds once instead of twice (IEEE 754's
fusedMultiplyAdd: the result is the exact ``a * b + c`` correctly rounded, so it is at least
as close to the exact value as the two operations it replaces).

Why an explicit call and not numba's ``fastmath={"contract"}``: contraction lets the compiler
choose which products to fuse, and it chooses per compiled variant. The kernel compiles one
variant for steps that store every pair's geometry and one for those that do not, one with
rolling resistance and one without; fused in different places, they gave different numbers,
so a run's result came to depend on where its calls ended (a progress display) and on whether
a zero rolling friction was given. Fused where the source says, every variant computes the
same numbers, and so does every machine: ``llvm.fma`` is correctly rounded wherever it runs
(one instruction on x86-64 with FMA3 and on ARM64, a library call elsewhere).
"""

from __future__ import annotations

from llvmlite import ir
from numba import types
from numba.extending import intrinsic


@intrinsic
def fma(typingctx, a, b, c):
    """``a * b + c`` with one rounding (float64 only)."""
    if not all(isinstance(x, types.Float) and x.bitwidth == 64 for x in (a, b, c)):
        return None

    def codegen(context, builder, sig, args):
        d = ir.DoubleType()
        fn = builder.module.declare_intrinsic("llvm.fma", [d], ir.FunctionType(d, [d, d, d]))
        return builder.call(fn, args)

    return types.float64(types.float64, types.float64, types.float64), codegen
