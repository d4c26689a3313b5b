"""Time integrators as step programs over the solver primitives.

A program is a list of (stage, operation) pairs; the stage clock times each
operation and books it to its stage, so every solver is timed the same way.
The first step may begin with a priming search and sweep (the rates at t=0).

- ``verlet`` (default): Stormer-Verlet on (u, drho). Half-kick u with the
  pressure gradient at drho_n, update drho (and x, if particles move) with the
  mid-step u, half-kick with the gradient at drho_{n+1}, which the next step
  reuses. One continuity-only and one momentum-only sweep per step; second
  order, no amplitude drift.
- ``kdk1``: the common one-sweep kick-drift-kick: both rates from one
  neighbour loop after the drift, so the density update uses a continuity
  rate that lags half a step. First order; its amplitude grows.
- ``euler``: forward Euler, one sweep of both rates; grows at any dt.
- ``rk2``: explicit midpoint, two sweeps of both rates per step.
- ``rk4``: classical fourth-order Runge-Kutta, four sweeps of both rates per step. Each stage starts from
  the step's saved state (``restore``, then ``advance`` and ``kick`` by the stage's fraction of dt); the
  stages' rates are summed with weights 1/6, 1/3, 1/3, 1/6 (``accumulate``) and the step is one update by
  the weighted sum (``use_sum``), so an open edge's layer damps it as it damps every other update. With a
  fourth-order operator (solvers/corrections/, the Laguerre-Gauss kernel) Verlet's second-order phase
  error is the floor; RK4 removes it. Stable to c0 |D| dt = 2 sqrt(2).
"""

from __future__ import annotations

VELOCITY = ("u", "v")
POSITION_DENSITY = ("sx", "sy", "drho")


def step_program(integrator: str, solver, first: bool) -> list:
    """The (stage, callable) list of one step of ``integrator`` on ``solver`` (on a scene with open edges each
    kick and advance damps its own fields in the layer: ``Solver.absorb``)."""
    s = solver
    snp = ("snp", s.snp)
    both = ("pi", lambda: s.rates(True, True))
    if integrator == "verlet":
        prime = [snp, ("pi", lambda: s.rates(False, True))] if first else []
        return prime + [
            ("su", lambda: s.kick(0.5)),
            ("pi", lambda: s.rates(True, False)),
            ("su", lambda: s.advance(1.0)),
            snp,
            ("pi", lambda: s.rates(False, True)),
            ("su", lambda: s.kick(0.5)),
        ]
    if integrator == "kdk1":
        prime = [snp, both] if first else []
        return prime + [
            ("su", lambda: s.kick(0.5)),
            ("su", lambda: s.advance(1.0)),
            snp,
            both,
            ("su", lambda: s.kick(0.5)),
        ]
    if integrator == "euler":
        return [snp, both, ("su", lambda: s.advance(1.0)), ("su", lambda: s.kick(1.0))]
    if integrator == "rk2":
        return [
            snp,
            both,
            ("su", s.save),
            ("su", lambda: s.advance(0.5)),
            ("su", lambda: s.kick(0.5)),
            snp,
            both,
            ("su", lambda: s.restore(POSITION_DENSITY)),
            ("su", lambda: s.advance(1.0)),  # drift with the mid-point velocity
            ("su", lambda: s.restore(VELOCITY)),
            ("su", lambda: s.kick(1.0)),
        ]
    if integrator == "rk4":
        program = [snp, both, ("su", s.save), ("su", lambda: s.accumulate(1.0 / 6.0, first=True))]
        for f, weight in ((0.5, 1.0 / 3.0), (0.5, 1.0 / 3.0), (1.0, 1.0 / 6.0)):
            program += stage(s, f) + [snp, both, ("su", lambda w=weight: s.accumulate(w))]
        return program + [("su", s.use_sum)] + stage(s, 1.0)
    raise ValueError(f"integrator must be one of verlet, kdk1, euler, rk2, rk4 (got {integrator!r})")


def stage(s, f: float) -> list:
    """The state at the step's start (``save``) moved by ``f`` dt along the current rates: positions with the
    current velocity, then the velocity (a Runge-Kutta stage)."""
    return [
        ("su", lambda: s.restore(POSITION_DENSITY)),
        ("su", lambda: s.advance(f)),
        ("su", lambda: s.restore(VELOCITY)),
        ("su", lambda: s.kick(f)),
    ]


def advance_steps(solver, integrator: str, steps: int, first: bool = True, each=None) -> None:
    """``steps`` steps of ``integrator`` on ``solver`` (input and initialised), the primitives one after another,
    untimed (the harness, pcabench/execute/run.py, times each); ``first``: the first of them is the run's first
    step; ``each()`` after every step (a test's measure)."""
    for n in range(steps):
        for _stage, op in step_program(integrator, solver, first=first and n == 0):
            op()
        if each is not None:
            each()


def evolve(solver, scene, steps: int | None = None):
    """``scene`` on ``solver`` from its initial fields for ``steps`` steps (the scene's own by default), untimed:
    the solver, to read its output or arrays."""
    solver.input(scene)
    solver.init()
    advance_steps(solver, scene.integrator, scene.n_steps if steps is None else steps)
    return solver


class _Count:
    """Enough of a solver for :func:`step_program` to count its sweeps."""

    def __init__(self):
        self.sweeps = 0

    def rates(self, continuity: bool, momentum: bool) -> None:
        self.sweeps += int(continuity) + int(momentum)

    def __getattr__(self, name):
        return lambda *args, **kwargs: None


def sweeps_per_step(integrator: str) -> int:
    """Neighbour sweeps (continuity or momentum, one each) of one step of ``integrator`` after the first: the
    step's cost in units of a sweep (verlet 2, rk2 4, rk4 8)."""
    counter = _Count()
    for _stage, op in step_program(integrator, counter, first=False):
        op()
    return counter.sweeps
