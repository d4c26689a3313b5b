"""``python tools/ptx_check.py [--cc 9.0]``: compile the GPU solver's 3D kernels (solvers/loops/gpu3d.py) to PTX for a
card's compute capability on a machine without a GPU, with the argument types the solver passes, in both
precisions and for a compact and a truncated kernel (a checkout's tool, not part of the installed package).

numba's CUDA simulator runs the kernels as Python, so it cannot tell whether numba-cuda compiles them; a lent
card's minutes should not be the first to find out. This needs NVVM, which is not one of pcabench's dependencies:
``pip install nvidia-cuda-nvcc-cu12 nvidia-cuda-nvrtc-cu12`` (no driver needed). numba-cuda asks the driver for
the current device's compute capability when it compiles a device function; here there is none, so this tool
answers for it (a stand-in for ``numba.cuda.dispatcher.get_current_device``, in this process only). Exit 0 when
every kernel compiled."""

from __future__ import annotations

import argparse
import sys
import time

import numba
import numpy as np


def capability(text: str) -> tuple:
    """``MAJOR.MINOR`` (both whole numbers, 3.5 to 12.x) as a tuple, or argparse's one-line error."""
    parts = text.split(".")
    if len(parts) != 2 or not all(p.isdigit() for p in parts) or not 3 <= int(parts[0]) <= 12:
        raise argparse.ArgumentTypeError(f"MAJOR.MINOR, 3.5 to 12.x, such as 9.0 (got {text!r})")
    return int(parts[0]), int(parts[1])


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python tools/ptx_check.py", description=__doc__.split("\n")[0])
    p.add_argument("--cc", type=capability, default=(9, 0), help="compute capability to compile for (default 9.0)")
    cc = p.parse_args(argv).cc

    from numba import cuda, types
    from numba.cuda import dispatcher

    import solvers.loops.gpu3d as kernels
    from solvers import Scene
    from solvers.kernels.constants import exp_neg_math
    from solvers.physics.pairs import make_pairs
    from solvers.physics.pairs3d import make_pairs3d
    from solvers.registry import make_solver

    class Card:
        compute_capability = cc

    dispatcher.get_current_device = lambda: Card()
    failed = 0
    methods = (("wendland-c2", {"h_factor": 1.3}), ("laguerre-gauss", {"h_factor": 1.5, "cutoff_factor": 4.0}))
    for precision in ("float64", "float32"):
        for kernel, method in methods:
            device = cuda.jit(device=True, fastmath=precision == "float32")
            kernels.P = make_pairs3d(device, exp_neg_math, kernel, precision)  # as solvers.gpu.cuda_kernels binds them
            kernels.C = make_pairs(device, exp_neg_math, kernel, precision)
            scene = Scene(0.5, "acoustic-pulse-3d", kernel=kernel, precision=precision, steps=2, **method)
            solver = make_solver("linkedlist-cpu", pair_loop="gather")  # the GPU's dtypes: cells int32, begin uint32
            solver.input(scene)
            solver.init()
            solver.snp()
            a, g, k, c = solver.arrays, solver.geometry(), solver.k, solver.dtype.type(0.1)
            n = scene.n_particles
            ints = np.zeros(n, np.int32)
            nine = [np.zeros(n, solver.dtype) for _ in range(9)]
            cases = {
                "cell_count": (*(a[x] for x in ("lx", "ly", "lz", "sx", "sy", "sz")), ints, ints, ints,
                               *solver.nnps.grid.index_arguments(scene.dx)),
                "continuity": (*g, a["u"], a["v"], a["w"], a["vol"], a["drho"], a["dd"], k),
                "momentum": (*g, a["mass"], a["pr"], a["ax"], a["ay"], a["az"], k),
                "moments": (*g, a["vol"], *nine, k),
                "neighbours": (*g, ints, k),
                "kick": (a["u"], a["v"], a["w"], a["ax"], a["ay"], a["az"], c),
                "advance": (a["drho"], a["dd"], a["sx"], a["sy"], a["sz"], a["u"], a["v"], a["w"], c, True, a["mass"],
                            a["vol"], a["pr"], k),
                "corrected_velocity": (a["u"], a["v"], a["w"], *nine),
                "corrected_continuity": (a["dd"], a["drho"], *nine[:6], k),
                "corrected_momentum": (a["ax"], a["ay"], a["az"], a["drho"], *nine, k),
            }  # fmt: skip
            for name, args in cases.items():
                t0, what = time.perf_counter(), f"{precision} {kernel} {name}"
                signature = types.void(*(numba.typeof(x) for x in args))
                try:
                    ptx, _ = cuda.compile_ptx(getattr(kernels, name), signature, cc=cc, fastmath=precision == "float32")
                    print(f"{what}: ok ({len(ptx):,} characters, {time.perf_counter() - t0:.1f} s)")
                except Exception as exc:  # noqa: BLE001 - each kernel's failure is reported, the rest still compile
                    failed += 1
                    print(f"{what}: FAILED: {type(exc).__name__}: {' '.join(str(exc).split())[:400]}")
    print(f"{'every kernel compiled' if not failed else f'{failed} kernels failed'} for compute capability {cc}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
