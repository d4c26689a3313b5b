"""The card's ceilings, measured: device copy bandwidth, FP32 and FP64 FMA rates, the SM clock (stage 1 of
pcabench gpu-check)."""

from __future__ import annotations

import subprocess

import numpy as np

from solvers.gpu.device import device_backend


# ---------------------------------------------------------------- 1. the card's ceilings
def measure_ceilings(cupy) -> dict:
    """Device-to-device copy bandwidth (bytes read + written), FP32/FP64 FMA rates, and the SM clock."""
    cuda, _ = device_backend()
    out = {}
    n = 512 * 2**20 // 4  # 512 MiB per buffer
    a = cupy.random.random(n, dtype=cupy.float32)
    b = cupy.empty_like(a)
    for _ in range(3):
        b[...] = a
    start, end = cupy.cuda.Event(), cupy.cuda.Event()
    times = []
    for _ in range(10):
        start.record()
        b[...] = a
        end.record()
        end.synchronize()
        times.append(cupy.cuda.get_elapsed_time(start, end) / 1e3)
    out["copy_bandwidth_tbs"] = round(2 * a.nbytes / float(np.median(times)) / 1e12, 3)
    del a, b

    def fma_kernel():
        @cuda.jit
        def k(x, iters, m, c):
            i = cuda.grid(1)
            a0 = x[i]
            a1 = a0 + 1
            a2 = a0 + 2
            a3 = a0 + 3
            a4 = a0 + 4
            a5 = a0 + 5
            a6 = a0 + 6
            a7 = a0 + 7
            for _ in range(iters):
                a0 = a0 * m + c
                a1 = a1 * m + c
                a2 = a2 * m + c
                a3 = a3 * m + c
                a4 = a4 * m + c
                a5 = a5 * m + c
                a6 = a6 * m + c
                a7 = a7 * m + c
            x[i] = a0 + a1 + a2 + a3 + a4 + a5 + a6 + a7

        return k

    for dtype, key in ((np.float32, "fp32_fma_tflops"), (np.float64, "fp64_fma_tflops")):
        threads, iters = 132 * 2048 * 4, 2048
        x = cupy.ones(threads, dtype=dtype)
        k = fma_kernel()
        m, c = dtype(0.999), dtype(0.001)  # typed constants keep the chain in dtype
        k[threads // 256, 256](x, iters, m, c)
        cupy.cuda.runtime.deviceSynchronize()
        start.record()
        k[threads // 256, 256](x, iters, m, c)
        end.record()
        end.synchronize()
        seconds = cupy.cuda.get_elapsed_time(start, end) / 1e3
        out[key] = round(2 * 8 * iters * threads / seconds / 1e12, 2)
    out["sm_clock_mhz_under_load"] = _smi_clock()
    out["note"] = "measured by pcabench gpu-check (median of 10 copies; one FMA-chain kernel each)"
    return out


def _smi_clock():
    """The SM clock nvidia-smi reports right after the FMA kernels, MHz (None without nvidia-smi)."""
    try:
        text = (
            subprocess.run(
                ["nvidia-smi", "--query-gpu=clocks.sm,clocks.max.sm", "--format=csv,noheader,nounits"],
                capture_output=True,
                text=True,
                timeout=20,
            )
            .stdout.strip()
            .splitlines()[0]
        )
        now, most = (int(v) for v in text.split(","))
        return {"now": now, "max": most}
    except (OSError, ValueError, IndexError, subprocess.SubprocessError):
        return None
