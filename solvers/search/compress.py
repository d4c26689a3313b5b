"""Stream compaction for the pair-list build: keep the candidates within the cutoff, in order.

The build computes the separations of every candidate of a particle (about
120) and keeps those within the cutoff (about 64). As a scalar loop the
keep costs as much as the distances themselves (87 ns for 121 candidates,
in either precision, measured here), because each kept entry is a
data-dependent store. On cores with AVX-512 the compiler's vector compress
(``llvm.experimental.vector.compress``, the vcompress instruction) packs 8
float64 or 16 float32 lanes per instruction: 33 ns in float64 and 15 ns in
float32 for the same 121 candidates (the memory form,
``llvm.masked.compressstore``, took 46-52 and 30 ns: microcoded on these
cores). Each step stores a whole vector at the next free slot, zeros past
the kept lanes, which the next step overwrites: source and destination
rows need :data:`PAD` spare entries. Where the core has no AVX-512, or
numba's LLVM predates the vector compress (LLVM 19),
:func:`compress_within` is the scalar loop, with the same result.
"""

from __future__ import annotations

import numba
import numpy as np
from llvmlite import binding, ir
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic

VECTOR_BITS = 512
PAD = 16  # spare entries each source and destination row needs: the widest vector's lanes


LLVM_HAS_VECTOR_COMPRESS = binding.llvm_version_info >= (19,)


def host_has_avx512() -> bool:
    """Whether numba compiles for a core with AVX-512 (the host, unless NUMBA_CPU_NAME says otherwise)."""
    if numba.config.CPU_NAME not in (None, "host"):
        return False
    try:
        return bool(binding.get_host_cpu_features().get("avx512f", False))
    except RuntimeError:  # features unknown on this platform
        return False


VECTOR_COMPRESS = LLVM_HAS_VECTOR_COMPRESS and host_has_avx512()
U = np.uint64


def _splat(builder, value, lanes):
    vec = ir.Constant(ir.VectorType(value.type, lanes), ir.Undefined)
    for lane in range(lanes):
        vec = builder.insert_element(vec, value, ir.Constant(ir.IntType(32), lane))
    return vec


def _llvm_suffix(element) -> str:
    return {"double": "f64", "float": "f32"}.get(str(element), str(element))


@intrinsic
def compress_vector(typingctx, js, rxs, rys, r2s, cj, crx, cry, cr2, nq, limit):
    """The vector compress: entries q < nq of (js, rxs, rys, r2s) with r2s[q] < limit to the front of
    (cj, crx, cry, cr2); returns how many."""
    sig = types.uint64(js, rxs, rys, r2s, cj, crx, cry, cr2, types.uint64, limit)

    def codegen(context, builder, signature, args):
        lanes = VECTOR_BITS // r2s.dtype.bitwidth
        i64 = ir.IntType(64)
        data = [context.make_array(t)(context, builder, a).data for t, a in zip(signature.args[:8], args[:8])]
        nq, limit_value = args[8], args[9]
        mask_type = ir.VectorType(ir.IntType(1), lanes)

        def compress_store(vec_type):
            fnty = ir.FunctionType(vec_type, [vec_type, mask_type, vec_type])
            name = f"llvm.experimental.vector.compress.v{lanes}{_llvm_suffix(vec_type.element)}"
            fn = cgutils.get_or_insert_function(builder.module, fnty, name)

            def store(src, at, dst, mask):
                vec = builder.load(builder.bitcast(builder.gep(src, [at]), ir.PointerType(vec_type)))
                vec.align = 4
                packed = builder.call(fn, [vec, mask, ir.Constant(vec_type, None)])  # lanes past the kept: 0
                st = builder.store(packed, builder.bitcast(dst, ir.PointerType(vec_type)))
                st.align = 4
                return vec

            return store

        index_store = compress_store(ir.VectorType(context.get_value_type(js.dtype), lanes))
        float_store = compress_store(ir.VectorType(context.get_value_type(r2s.dtype), lanes))
        popcount = builder.module.declare_intrinsic("llvm.ctpop", [ir.IntType(lanes)])
        vlimit, vnq = _splat(builder, limit_value, lanes), _splat(builder, nq, lanes)
        lane_index = ir.Constant(ir.VectorType(i64, lanes), list(range(lanes)))
        kept = cgutils.alloca_once_value(builder, ir.Constant(i64, 0))
        steps = builder.udiv(builder.add(nq, ir.Constant(i64, lanes - 1)), ir.Constant(i64, lanes))
        with cgutils.for_range(builder, steps) as loop:
            q = builder.mul(loop.index, ir.Constant(i64, lanes))
            valid = builder.icmp_unsigned("<", builder.add(_splat(builder, q, lanes), lane_index), vnq)
            r2 = builder.load(builder.bitcast(builder.gep(data[3], [q]), ir.PointerType(vlimit.type)))
            r2.align = 4
            mask = builder.and_(builder.fcmp_ordered("<", r2, vlimit), valid)
            at = builder.load(kept)
            index_store(data[0], q, builder.gep(data[4], [at]), mask)
            float_store(data[1], q, builder.gep(data[5], [at]), mask)
            float_store(data[2], q, builder.gep(data[6], [at]), mask)
            float_store(data[3], q, builder.gep(data[7], [at]), mask)
            count = builder.zext(builder.call(popcount, [builder.bitcast(mask, ir.IntType(lanes))]), i64)
            builder.store(builder.add(at, count), kept)
        return builder.load(kept)

    return sig, codegen


@numba.njit(inline="always")
def compress_scalar(js, rxs, rys, r2s, cj, crx, cry, cr2, nq, limit):
    """The scalar compress: every candidate written at slot m, m advancing only for those kept."""
    m = U(0)
    for q in range(nq):
        cj[m] = js[q]
        crx[m] = rxs[q]
        cry[m] = rys[q]
        cr2[m] = r2s[q]
        m += U(r2s[q] < limit)
    return m


# (js, rxs, rys, r2s, cj, crx, cry, cr2, nq, limit) -> kept: the entries q < nq with r2s[q] < limit, in order,
# to the front of (cj, crx, cry, cr2); rows need PAD spare entries
compress_within = compress_vector if VECTOR_COMPRESS else compress_scalar
