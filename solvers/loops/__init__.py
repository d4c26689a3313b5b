"""The compiled loops as templates: plain module-level Python over a few free names (the pair functions
``P``, a flag such as ``flush``), which :mod:`solvers.jitcache` specialises per precision, kernel and
threading, compiles and caches on disk once per machine.

A template's free names are set to ``None`` here with a comment saying what binds them; the template
imports absolutely (its specialisations are written out beside no package), and every first-party module
it imports is part of the key of its cache. Each template is read by one solver module:

    updates.py   the per-particle loops (coefficients, kick, advance, gather)   solvers/physics/backend.py
    sorting.py   the cell sort (counting sort, x-sort within cells)            solvers/linkedlist_cpu.py, pairlist.py
    cells.py     the linked-list sweeps over the 3x3 cell stencil              solvers/linkedlist_cpu.py
    allpair.py   the all-pair sweeps                                           solvers/allpair_cpu.py
    pairlist.py  the pair list's build and its two sweeps                      solvers/search/pairlist.py
    gpu.py       the GPU solver's device kernels (numba-cuda)                  solvers/gpu/cuda_kernels.py
"""
