"""pcabench: benchmarking harness and study suite for SPH acoustics.

Data flow: scene -> solver (the package ``solvers``) -> stage clock (pcabench.execute.clock)
-> run record (pcabench.store.record) -> results store (pcabench.store)
-> reports (pcabench.reports).
"""

__version__ = "0.1.0"
