"""Flush-to-zero for float32 CPU loops: subnormal numbers are treated as zero inside them.

The pulse's far field underflows in float32 (u ~ c0 M exp(-xi^2) falls
below 1.2e-38 a few widths out), and x86 cores take a slow microcode path
for every subnormal operand: measured here, it made the float32 sweeps
slower than the float64 ones. GPUs flush float32 subnormals in fast-math
code for the same reason. Inside a loop, :func:`flush_on` sets the x86
MXCSR's flush-to-zero and denormals-are-zero bits for the calling thread
and :func:`flush_off` puts the old word back, so nothing outside the loop
(numpy, Python) changes behaviour. Values below 1.2e-38 are physically zero
here (the pulse amplitude is ~0.5 m/s). On other architectures both are
no-ops.
"""

from __future__ import annotations

import platform

import numba
from llvmlite import ir
from numba import types
from numba.extending import intrinsic

FTZ_DAZ = 0x8040  # MXCSR bits: flush to zero (15), denormals are zero (6)
X86 = platform.machine().lower() in ("x86_64", "amd64", "i686", "x86")


def _mxcsr_call(builder, name, ptr):
    fnty = ir.FunctionType(ir.VoidType(), [ir.PointerType(ir.IntType(8))])
    fn = builder.module.declare_intrinsic(name, fnty=fnty)
    builder.call(fn, [builder.bitcast(ptr, ir.PointerType(ir.IntType(8)))])


@intrinsic
def _read_mxcsr(typingctx):
    def codegen(context, builder, signature, args):
        ptr = builder.alloca(ir.IntType(32))
        builder.store(ir.Constant(ir.IntType(32), 0), ptr)
        if X86:
            _mxcsr_call(builder, "llvm.x86.sse.stmxcsr", ptr)
        return builder.load(ptr)

    return types.uint32(), codegen


@intrinsic
def _write_mxcsr(typingctx, word):
    def codegen(context, builder, signature, args):
        if X86:
            ptr = builder.alloca(ir.IntType(32))
            builder.store(args[0], ptr)
            _mxcsr_call(builder, "llvm.x86.sse.ldmxcsr", ptr)
        return context.get_dummy_value()

    return types.void(types.uint32), codegen


@numba.njit(inline="always")
def flush_on(flush):
    """Set flush-to-zero for this thread if ``flush`` (a compile-time constant in the loops that call
    it); returns the word to give :func:`flush_off`."""
    saved = _read_mxcsr()
    if flush:
        _write_mxcsr(saved | numba.uint32(FTZ_DAZ))
    return saved


@numba.njit(inline="always")
def flush_off(flush, saved):
    """Restore this thread's floating-point control word after :func:`flush_on`."""
    if flush:
        _write_mxcsr(saved)
