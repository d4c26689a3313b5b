"""The common solver interface: the paper's six stages as primitives.

A solver holds the particle state and offers the primitives that a step is
made of. The integrator (solvers/physics/integrators.py) composes them into a step
program of (stage, operation) pairs, and the stage clock times every
operation from outside, the same way for every solver:

    input   ``input(scene)``      validate the scene for this solver, bring the device up
    init    ``init()``            allocate and place the particles
    snp     ``snp()``             neighbour search (cell build, or nothing for all-pair)
    pi      ``rates(cont, mom)``  particle interaction: continuity and/or momentum sweep
    su      ``kick/advance/save/restore``  system update
    output  ``output()``          copy back, in particle-id order

The state lives in arrays of the array module ``xp`` (NumPy on the CPU,
CuPy on the GPU). The system update and the sweeps' coefficients are
per-particle functions written once (solvers/physics/pairs.py), which each solver
launches (:meth:`Solver.launch`) on its own device and threads.
All per-particle arrays sit in ``self.arrays`` so that a neighbour search
that reorders particles can permute all of them together.
"""

from __future__ import annotations

import abc
import contextlib
import math

import numpy as np

from solvers.boundaries import OpenLayer, RigidBody, Walls, boundary_models
from solvers.corrections import correction_names
from solvers.fields import Fields
from solvers.kernels import constants as kernel
from solvers.kernels import kernel_names
from solvers.method import INTEGRATORS
from solvers.scene import MODELS, PRECISIONS, Scene, SceneError

STAGES = ("input", "init", "snp", "pi", "su", "output")
STATE = ("lx", "ly", "sx", "sy", "u", "v", "drho")
RATES = ("ax", "ay", "dd")
# a 3D scene's (its dimension is the scene kind's): the z lattice coordinate, displacement, velocity and rate too
STATE_3D = ("lx", "ly", "lz", "sx", "sy", "sz", "u", "v", "w", "drho")
RATES_3D = ("ax", "ay", "az", "dd")
POSITIONS = {2: ("lx", "ly", "sx", "sy"), 3: ("lx", "ly", "lz", "sx", "sy", "sz")}  # what a search bins
VELOCITY = {2: ("u", "v"), 3: ("u", "v", "w")}
ACCELERATION = {2: ("ax", "ay"), 3: ("ax", "ay", "az")}


class SolverUnavailable(RuntimeError):
    """The solver cannot run on this machine (no GPU, missing library)."""


class EveryKernel:
    """The class attribute ``kernels`` of a solver that runs any kernel: every registered kernel's name, read at
    each access, so that a kernel registered later (solvers/kernels/) is offered too."""

    def __get__(self, obj, owner=None) -> tuple:
        return kernel_names()


class EveryCorrection:
    """The class attribute ``corrections`` of a solver that runs any kernel correction (each works through the
    solver's sweeps and ``launch``: solvers/corrections/): every registered one's name, read at each access."""

    def __get__(self, obj, owner=None) -> tuple:
        return correction_names()


class Solver(abc.ABC):
    """Base class: state, system update, output. Subclasses: ``snp`` and ``launch``, and a neighbour search.

    The class attributes below state what a solver is and can do. The harness
    (run specs, predictions, cluster resources, the command line, the reports
    and both benchmark suites) reads them through the registry
    (solvers/registry.py) and nowhere states them again.
    """

    name: str = ""  # what --solver calls it; a class with a name is a solver the registry offers
    summary: str = ""  # one line for --help: what it is, what it needs
    device: str = "cpu"  # cpu or gpu: where the pair loops run
    precisions: tuple = PRECISIONS
    models: tuple = MODELS
    integrators: tuple = INTEGRATORS
    kernels: tuple = EveryKernel()  # a tuple of kernel names restricts a solver; by default, every registered one
    corrections: tuple = EveryCorrection()  # likewise the kernel corrections (solvers/corrections/)
    boundaries: tuple = ("free-x", "periodic-y")  # the boundary kinds it can run (solvers/scenes/base.py)
    pair_loops: tuple = ("gather",)  # how it can visit pairs (gather, list, all-pairs); the first is its default
    threaded: bool = False  # runs on more than one CPU thread (--threads N|all); else serial
    serial_why: str = "as in the paper"  # why a serial solver is serial, for the one-line refusal
    neighbour_search: type | None = None  # the search's class (solvers/search/): built per scene as ``self.nnps``
    search: str = "linked list"  # the neighbour search in the paper's words (linked list, all-pair): the reports
    # set the paper's numbers only beside the same search
    order: float = 1.0  # step time ~ N^order (1: a cell list; 2: every pair tested): the predictor's prior
    resources: dict = {"timing": 1}  # what one run takes on a Dask worker: one timed run per worker at a time
    xp = np

    pair_loop: str = "gather"  # the loop this instance uses (one of ``pair_loops``)

    def __init__(self, threads: int = 1, pair_loop: str = "auto"):
        self.threads = threads
        self.pair_loop = self.pair_loops[0] if pair_loop == "auto" else pair_loop
        self.scene: Scene | None = None
        self.arrays: dict = {}
        self.saved: dict = {}
        self.t = 0.0

    # ------------------------------------------------------------ what it can do
    @classmethod
    def available(cls) -> None:
        """Raise SolverUnavailable (one line: what to install or where to run) unless it can run here."""

    @classmethod
    def pair_loops_for(cls, scene: Scene) -> tuple:
        """The pair loops this solver runs ``scene`` with (of ``pair_loops``; a 3D scene's may be fewer)."""
        return tuple(cls.pair_loops)

    @classmethod
    def choose_pair_loop(cls, scene: Scene, requested: str = "auto") -> str:
        """The pair loop for ``scene``: ``requested``, or for ``auto`` the solver's choice (its first)."""
        return cls.pair_loops[0] if requested == "auto" else requested

    @classmethod
    def memory_bytes(cls, scene: Scene, pair_loop: str = "auto") -> int:
        """Bytes a run of ``scene`` takes on the solver's device, B (the harness checks them against the
        machine's memory): the particle arrays (:meth:`Scene.memory_bytes`) unless a solver says more."""
        return scene.memory_bytes()

    @classmethod
    def supports(cls, scene: Scene) -> None:
        """SceneError naming the parameter unless this solver offers the scene's precision, model,
        integrator and kernel."""
        for what, offered in (
            ("precision", cls.precisions),
            ("model", cls.models),
            ("integrator", cls.integrators),
            ("kernel", cls.kernels),
            ("correction", cls.corrections),
        ):
            if getattr(scene, what) not in offered:
                raise SceneError(f"{what}: {cls.name} offers {', '.join(offered)} (got {getattr(scene, what)!r})")
        missing = sorted(set(scene.boundaries) - set(cls.boundaries))
        if missing:
            raise SceneError(
                f"--scene {scene.name}: {cls.name} cannot run its {', '.join(missing)} boundaries "
                f"(it supports {', '.join(cls.boundaries)})"
            )

    # ------------------------------------------------------------ stages
    def input(self, scene: Scene) -> None:
        """Validate ``scene`` for this solver and prepare constants."""
        if not isinstance(scene, Scene):
            raise SceneError(f"scene must be a Scene (got {type(scene).__name__})")
        self.supports(scene)
        self.check_scene(scene)
        self.scene = scene
        self.dtype = np.dtype(scene.precision)
        self.k = kernel.constants(scene, self.dtype)
        self.moving = scene.model == "lagrangian"
        self.displaced = True  # until the particles are placed (after_init)
        self.correction = scene.sph_correction
        # the scene's walls, open layer and body (solvers/boundaries/), each called at its points of a step
        self.boundary_models = boundary_models(scene)
        self.walls, self.layer, self.body = (
            next((m for m in self.boundary_models if isinstance(m, kind)), None)
            for kind in (Walls, OpenLayer, RigidBody)
        )
        self.absorber = self.layer.absorber if self.layer is not None else None
        self.split = bool(self.layer is not None and self.layer.split)
        self.boundary_state = sum((m.state for m in self.boundary_models), ())  # saved and restored with drho
        self.boundary_rates = sum((m.rates for m in self.boundary_models), ())  # summed over RK stages

    def check_scene(self, scene: Scene) -> None:
        """Solver-specific limits; raise SceneError naming the parameter."""

    def init(self) -> None:
        """Allocate and place the particles on the lattice with the analytic pulse."""
        if self.scene.dims == 3:
            return self.init_3d()
        s, xp, dt = self.scene, self.xp, self.dtype
        ids = xp.arange(s.n_particles, dtype=xp.int64)
        lx = (ids % s.nx).astype(dt)
        ly = (ids // s.nx).astype(dt)
        x = s.x_lo + (lx.astype(xp.float64) + 0.5) * s.dx
        y = s.y_lo + (ly.astype(xp.float64) + 0.5) * s.dx
        u, v, drho = s.kind.initial_fields(s, x, y, xp)  # the scene kind's fields at t = 0 (solvers/scenes/)
        # Lagrangian and fixed: m_j = rho_j(0) dx^2, so m/rho is the true volume at t = 0.
        rho_init = s.rho0 + (0.0 if s.model == "linear" else 1.0) * drho
        a = {
            "lx": lx,
            "ly": ly,
            "sx": xp.zeros(s.n_particles, dt),
            "sy": xp.zeros(s.n_particles, dt),
            "u": u.astype(dt),
            "v": v.astype(dt),
            "drho": drho.astype(dt),
            "mass": (rho_init * s.dx * s.dx).astype(dt),
        }
        for name in RATES + ("vol", "pr"):
            a[name] = xp.zeros(s.n_particles, dt)
        self.arrays = a
        for model in self.boundary_models:  # a body's particles' roles and places, a split layer's parts of drho
            model.start(self, x, y, drho)
        self.saved = {}
        self.t = 0.0
        self.reordered = 0  # how many times the arrays were put in a new order (a body's indices follow it)
        self.moves = 0  # how many times moving particles moved (an advance, a restore)
        self.correction_factors = None  # a kernel correction's factors and the positions they are of
        self.after_init()

    def init_3d(self) -> None:
        """:meth:`init` on a 3D lattice: particle id (lz ny + ly) nx + lx, mass rho_j(0) dx^3."""
        s, xp, dt = self.scene, self.xp, self.dtype
        ids = xp.arange(s.n_particles, dtype=xp.int64)
        lx, ly, lz = ((ids % s.nx).astype(dt), (ids // s.nx % s.ny).astype(dt), (ids // (s.nx * s.ny)).astype(dt))
        x, y, z = (lo + (c.astype(xp.float64) + 0.5) * s.dx for lo, c in ((s.x_lo, lx), (s.y_lo, ly), (s.z_lo, lz)))
        u, v, w, drho = s.kind.initial_fields(s, x, y, xp, z=z)
        rho_init = s.rho0 + (0.0 if s.model == "linear" else 1.0) * drho
        a = {"lx": lx, "ly": ly, "lz": lz, "u": u.astype(dt), "v": v.astype(dt), "w": w.astype(dt)}
        a.update(drho=drho.astype(dt), mass=(rho_init * s.dx**3).astype(dt))
        for name in ("sx", "sy", "sz", *RATES_3D, "vol", "pr"):
            a[name] = xp.zeros(s.n_particles, dt)
        self.arrays = a
        for model in self.boundary_models:  # an open layer (a sponge: nothing to start), a body's roles
            model.start(self, x, y, drho, z=z)
        self.saved = {}
        self.t = 0.0
        self.reordered = 0
        self.moves = 0
        self.correction_factors = None
        self.after_init()

    @property
    def positions(self) -> tuple:
        """The names of the position arrays a search bins and a pair loop takes (lattice coordinates, then
        displacements): 2D or 3D by the scene."""
        return POSITIONS[self.scene.dims]

    def after_init(self) -> None:
        """Whether any particle is off its lattice site (``displaced``), the neighbour search for the scene
        (``self.nnps``), once the arrays exist; a hook for device-specific setup too."""
        self.displaced = self.moving or any(
            bool(np.any(self.to_host(self.arrays[name]))) for name in ("sx", "sy", "sz") if name in self.arrays
        )
        if self.neighbour_search is not None:
            self.nnps = self.search_for_scene()

    def search_for_scene(self):
        """The neighbour search (``neighbour_search``) built for the scene, once the particles are placed."""
        return self.neighbour_search(self.scene, self.launch, self.xp)

    @abc.abstractmethod
    def snp(self) -> None:
        """Neighbour search for the current positions."""

    def rates(self, continuity: bool, momentum: bool) -> None:
        """PI: fill dd (continuity) and/or ax, ay (momentum) from the current state (and ddx, the x part of dd,
        for a split absorber), through the scene's kernel correction (solvers/corrections/: none, the sweeps)."""
        self.prepare_boundaries()
        vol, pr = self.correction.coefficients(continuity, momentum)
        self.coefficients(vol or continuity, pr or momentum)
        self.correction.sweep(self, continuity, momentum)

    @contextlib.contextmanager
    def swapped(self, **arrays):
        """The per-particle arrays ``arrays`` stand in for the solver's own of those names inside the block (a
        correction's sweeps over other fields)."""
        a = self.arrays
        kept = {name: a[name] for name in arrays}
        a.update(arrays)
        try:
            yield
        finally:
            a.update(kept)

    def moments(self) -> tuple:
        """The moment matrix (M_xx, M_xy, M_yy) and Gamma (x, y) of every particle at the current positions and
        volumes (the kernel gradient correction's, solvers/corrections/gradient.py), as new arrays."""
        count = 9 if self.scene.dims == 3 else 5  # in 3D (M_xx, M_xy, M_xz, M_yy, M_yz, M_zz) and Gamma (x, y, z)
        out = tuple(self.xp.zeros(self.scene.n_particles, self.dtype) for _ in range(count))
        self.launch("moments", *self.geometry(), self.arrays["vol"], *out, self.k)
        return out

    def prepare_boundaries(self) -> bool:
        """Each boundary model before the pair sums (a body's ghosts take the fluid's values mirrored across its
        wall); True where one changed drho."""
        changed = False
        for model in self.boundary_models:
            changed = model.before_sweep(self) or changed
        return changed

    def coefficients(self, continuity: bool, momentum: bool) -> None:
        """Per-particle coefficients of the sweeps: vol = m / rho (continuity), pr = c0^2 drho / rho^2 (momentum)."""
        a = self.arrays
        self.launch("coefficients", a["drho"], a["mass"], a["vol"], a["pr"], continuity, momentum, self.k)

    @abc.abstractmethod
    def launch(self, name: str, *args):
        """Run kernel ``name`` over every particle on this solver's device and threads: at least the
        per-particle ones of solvers/physics/pairs.py (coefficients, kick, advance)."""

    def _sweep(self, continuity: bool, momentum: bool) -> None:
        """The neighbour loops themselves, over the search's arguments (``self.nnps``)."""
        a, dims = self.arrays, self.scene.dims
        velocity, acceleration = (a[name] for name in VELOCITY[dims]), (a[name] for name in ACCELERATION[dims])
        if continuity:
            self.launch("continuity", *self.geometry(), *velocity, a["vol"], a["drho"], a["dd"], self.k)
        if momentum:
            self.launch("momentum", *self.geometry(), a["mass"], a["pr"], *acceleration, self.k)

    def geometry(self) -> tuple:
        """What every pair loop takes first, from the neighbour search: cells (if any) and positions."""
        return self.nnps.arguments(self.arrays)

    # ------------------------------------------------------------ system update
    def kick(self, f: float) -> None:
        """u += f dt a (damped before and after in an open edge's layer: :meth:`absorb`)."""
        a, dims = self.arrays, self.scene.dims
        self.absorb(f, "velocity")
        velocity, acceleration = (a[name] for name in VELOCITY[dims]), (a[name] for name in ACCELERATION[dims])
        self.launch("kick", *velocity, *acceleration, self.dtype.type(f * self.scene.dt))
        self.absorb(f, "velocity")

    def advance(self, f: float) -> None:
        """drho += f dt D and, for moving particles, x += f dt u; time += f dt (drho damped before and after in
        an open edge's layer: :meth:`absorb`)."""
        self.absorb(f, "density")
        self.advance_launch(f)
        for model in self.boundary_models:  # a split layer's x part of drho, with drho
            model.advanced(self, f)
        self.absorb(f, "density")
        self.moved()
        if self.moving:  # a body's particles back at their places
            for model in self.boundary_models:
                model.moved(self)
        self.t += f * self.scene.dt

    def advance_launch(self, f: float) -> None:
        """The advance's kernel: drho += f dt D and, for moving particles, x += f dt u."""
        self.launch("advance", *self.advance_arguments(f))

    def advance_arguments(self, f: float) -> tuple:
        """What the advance's kernel takes: drho, its rate, the displacements and velocities of the scene's axes,
        f dt (s) and whether the particles move."""
        a, dims = self.arrays, self.scene.dims
        moved = (a[name] for name in (*POSITIONS[dims][dims:], *VELOCITY[dims]))
        return a["drho"], a["dd"], *moved, self.dtype.type(f * self.scene.dt), self.moving

    def moved(self) -> None:
        """Moving particles have new positions: what was computed from the old ones (the layer's factors) goes."""
        if self.moving:
            self.moves += 1

    def absorb(self, f: float, fields: str) -> None:
        """The open edges' absorbing layers (solvers/boundaries/absorbers/): ``fields`` ("velocity" or "density")
        damped by half of an update of f dt, called before and after that update, so that the damping is a term of the
        update (stable at the closed scene's CFL: solvers/boundaries/absorbers/base.py); nothing on a closed scene."""
        for model in self.boundary_models:
            model.damp(self, f, fields)

    def continuity_parts(self) -> None:
        """A split absorber's (the PML's) parts of the continuity rate: the x part into ``ddx`` (and in 3D the y
        part into ``ddy``), each the same sweep with the other velocity components zero, the rate being linear in
        the velocities (the coefficients are the ones just computed)."""
        a, velocity = self.arrays, VELOCITY[self.scene.dims]
        for axis, rate in enumerate(self.layer.rates):
            others = {name: self.no_velocity for i, name in enumerate(velocity) if i != axis}
            with self.swapped(dd=a[rate], **others):
                self._sweep(True, False)

    def save(self) -> None:
        """Keep a copy of the state (for two-stage integrators)."""
        kept = ("sx", "sy", "sz", "u", "v", "w", "drho") if self.scene.dims == 3 else ("sx", "sy", "u", "v", "drho")
        for name in kept + self.boundary_state:
            self.saved[name] = self.arrays[name].copy()
        self.saved_t = self.t

    def restore(self, names) -> None:
        """Put back the saved copies of ``names`` (time goes back with drho, and drho's x part with it)."""
        if "drho" in names:
            names = (*names, *self.boundary_state)
        if self.scene.dims == 3:  # the z components with the x and y the integrator names
            names = (*names, *(third for name, third in (("sx", "sz"), ("u", "w")) if name in names))
        for name in names:
            self.arrays[name][...] = self.saved[name]
        if "sx" in names:
            self.moved()
        if "drho" in names:
            self.t = self.saved_t

    def accumulate(self, weight: float, first: bool = False) -> None:
        """A Runge-Kutta stage's rates, times ``weight``, into the step's sums (``first``: they start here): the
        density rate (and its x part for a split absorber), the acceleration and, for moving particles, the
        velocity (the positions' rate). Kept beside the saved state, so that a search that reorders the
        particles reorders them too."""
        w = self.dtype.type(weight)
        for name in self.summed():
            key, arr = "sum_" + name, self.arrays[name]
            total = self.saved.get(key)
            if first or total is None:
                if total is None or total.shape != arr.shape:
                    total = self.xp.empty_like(arr)
                self.xp.multiply(arr, w, out=total)
                self.saved[key] = total
            else:
                total += w * arr

    def use_sum(self) -> None:
        """The step's weighted sums (:meth:`accumulate`) become the rates (and the velocity the positions move
        with): the next ``advance`` and ``kick`` from the saved state make the Runge-Kutta step."""
        for name in self.summed():
            self.arrays[name][...] = self.saved["sum_" + name]

    def summed(self) -> tuple:
        """The fields a Runge-Kutta step sums over its stages."""
        dims = self.scene.dims
        return (RATES_3D if dims == 3 else RATES) + self.boundary_rates + (VELOCITY[dims] if self.moving else ())

    def permute(self, order) -> None:
        """Reorder every per-particle array (state, rates, saved copies) by ``order``."""
        self.reordered += 1
        for store in (self.arrays, self.saved):
            for name, arr in store.items():
                store[name] = self.gathered(arr, order)

    def gathered(self, arr, order):
        """``arr`` in the order ``order`` (a new array; a solver may reuse its own buffers)."""
        return self.xp.take(arr, order)

    # ------------------------------------------------------------ output and checks
    def output(self) -> Fields:
        """Copy the fields back to the host in particle-id order."""
        s = self.scene
        if s.dims == 3:
            return self.output_3d()
        h = {name: self.to_host(self.arrays[name]) for name in STATE}
        column = np.rint(h["lx"]).astype(np.int64) % s.nx
        ids = (np.rint(h["ly"]).astype(np.int64) % s.ny) * s.nx + column
        order = np.argsort(ids, kind="stable")
        if s.n_layer:  # open edges: the particles of the scored domain only (their home site inside it)
            order = order[s.scored(column[order], ids[order] // s.nx)]
        x = s.x_lo + (h["lx"].astype(np.float64) + 0.5) * s.dx + h["sx"]
        y = s.y_lo + (h["ly"].astype(np.float64) + 0.5) * s.dx + h["sy"]
        return Fields(
            x=x[order],
            y=y[order],
            u=h["u"][order].astype(np.float64),
            v=h["v"][order].astype(np.float64),
            drho=h["drho"][order].astype(np.float64),
            t=self.t,
        )

    def output_3d(self) -> Fields:
        """:meth:`output` of a 3D scene: every particle in particle-id order, z and w with them."""
        s = self.scene
        h = {name: self.to_host(self.arrays[name]) for name in STATE_3D}
        c = [np.rint(h[name]).astype(np.int64) % n for name, n in (("lx", s.nx), ("ly", s.ny), ("lz", s.nz))]
        order = np.argsort((c[2] * s.ny + c[1]) * s.nx + c[0], kind="stable")
        if s.n_layer:  # open faces: the scored domain's particles only (their home site inside it)
            order = order[s.scored_3d(c[0][order], c[1][order], c[2][order])]
        place = {
            axis: lo + (h["l" + axis].astype(np.float64) + 0.5) * s.dx + h["s" + axis]
            for axis, lo in (("x", s.x_lo), ("y", s.y_lo), ("z", s.z_lo))
        }
        out = {name: h[name][order].astype(np.float64) for name in ("u", "v", "w", "drho")}
        return Fields(x=place["x"][order], y=place["y"][order], z=place["z"][order], t=self.t, **out)

    def to_host(self, arr) -> np.ndarray:
        return np.asarray(arr)

    def sample(self, points) -> np.ndarray:
        """drho (kg/m^3, float64) at ``points`` ((p, dims), m) from the fluid particles within a cutoff of each, by
        first-order moving least squares (solvers/sampling.py): a probe's reading. The weights are kept while the
        particles neither move nor change order."""
        from solvers.sampling import mls_weights

        s, a, xp = self.scene, self.arrays, self.xp
        dims = s.dims
        points = np.asarray(points, dtype=np.float64).reshape(-1, dims)
        key = (getattr(self, "reordered", 0), points.tobytes())
        cached = getattr(self, "_probes", None)
        if self.moving or cached is None or cached[0] != key:
            lows = (s.x_lo, s.y_lo, s.z_lo)[:dims]
            axes = [lo + (a[f"l{c}"].astype(xp.float64) + 0.5) * s.dx + a[f"s{c}"] for lo, c in zip(lows, "xyz"[:dims])]
            near = xp.zeros(axes[0].shape, dtype=bool)
            for p in points:
                near |= sum((q - c) ** 2 for q, c in zip(axes, p)) < (s.cutoff * (1 + 1e-9)) ** 2
            if "role" in a:
                near &= a["role"] == 0
            idx = xp.flatnonzero(near)
            pos = np.stack([self.to_host(q[idx]) for q in axes], axis=1)
            cached = (key, idx, mls_weights(s, points, pos, s.dx**dims))
            self._probes = cached
        _key, idx, weights = cached
        return weights @ self.to_host(a["drho"][idx]).astype(np.float64)

    def extremes(self) -> dict:
        """{field: max |value| over particles}: 'velocity' (m/s, over its components) and 'drho' (kg/m^3); NaN for
        a field that is not finite (what a run checks against Scene.blowup_bounds after every step)."""
        a, out = self.arrays, {}
        for field, names in (("velocity", VELOCITY[self.scene.dims]), ("drho", ("drho",))):
            m = max(float(abs(a[name]).max()) for name in names)  # NaN anywhere: NaN (max propagates it)
            out[field] = m if math.isfinite(m) else math.nan
        return out

    def mean_neighbours(self) -> float:
        """Mean count of neighbours within the cutoff at the current positions, by the neighbour search on
        arrays of its own: no side effect (the state is not re-sorted: the count is the same in any order)."""
        return self.nnps.count(self.arrays, self.k) / self.scene.n_particles

    # ------------------------------------------------------------ timing support
    def warmup(self) -> float:
        """Compile every kernel this solver will use on a tiny scene; wall seconds."""
        return 0.0

    def synchronize(self) -> None:
        """Wait for queued device work (no-op on the CPU)."""


def cell_grid(scene: Scene) -> tuple:
    """(cw, ch, ncx, ncy, x_grid, width, height): cells at least one cutoff tall filling the lattice's height
    (``height`` the y period, m; 0 where the y edges are free, particles past them clamped into the edge
    rows), and in x either one cutoff wide with one spare each side for particles drifting past free edges
    (the grid's left edge ``x_grid`` one cell left of the lattice, ``width`` 0), or at least one cutoff wide
    filling the periodic width (``x_grid`` 0, ``width`` the period, m), or, with a rigid wall, at least one
    cutoff wide filling the lattice's width, a wall being the grid's edge (its column holds every particle
    with mirror neighbours, and they are in it) and a free edge opposite keeping its spare cell."""
    ncy = max(int(math.floor(scene.height / scene.cutoff + 1e-9)), 1)
    ch, height = scene.height / ncy, scene.height if scene.periodic_y else 0.0
    if scene.periodic_x or scene.walls:
        inside = int(math.floor(scene.width / scene.cutoff + 1e-9))
        if inside < 3:
            raise SceneError(
                f"x_max - x_min must hold 3 cells of one cutoff ({3 * scene.cutoff:.6g} m) for the "
                f"{'x-periodic' if scene.periodic_x else 'walled'} {scene.name} scene (got {scene.width:.6g} m)"
            )
        cw = scene.width / inside
        if scene.periodic_x:
            return cw, ch, inside, ncy, 0.0, scene.width, height
        spare_left, spare_right = Walls.spare_cells(scene)
        return cw, ch, inside + spare_left + spare_right, ncy, -cw if spare_left else 0.0, 0.0, height
    ncx = int(math.ceil(scene.width / scene.cutoff)) + 2  # the lattice's width: an open edge's layer included
    return scene.cutoff, ch, ncx, ncy, -scene.cutoff, 0.0, height


def stencil_reach(scene: Scene) -> tuple:
    """Cells a cutoff spans along x, y and z in a 3D scene's grid: eight along x (a row trimmed to the sphere's
    chord to an eighth of a cutoff), along y and z two where a cell then still spans 2 dx (the fourth-order and
    the paper's kernels, 6 dx cutoffs), else one: rows of a few particles cost more than the candidates they drop
    (measured by ``pcabench study --three-d``'s pair-cost runs, docs/performance.md "A pair in 3D")."""
    across = 2 if scene.cutoff >= 4.0 * scene.dx else 1
    return 8, across, across


def cell_grid_3d(scene: Scene) -> tuple:
    """(cw, ch, cd, ncx, ncy, ncz, x_grid, width, height, depth, reach_x, reach_y, reach_z) of a 3D scene: along
    each axis cells at least a cutoff over the reach (:func:`stencil_reach`) wide, along a periodic axis a whole
    number of them filling the period (the period, m, given), along a free x a cutoff spare each side (particles
    past a free edge are clamped into the edge cells in y and z, as in 2D: :func:`cell_grid`)."""
    reaches = stencil_reach(scene)
    sizes, counts, periods = [], [], []
    for span, periodic, reach in zip(
        (scene.width, scene.height, scene.depth), (scene.periodic_x, scene.periodic_y, scene.periodic_z), reaches
    ):
        n = max(int(math.floor(span * reach / scene.cutoff + 1e-9)), 1)
        sizes.append(span / n)
        counts.append(n)
        periods.append(span if periodic else 0.0)
    x_grid = 0.0
    if not scene.periodic_x:  # a cutoff spare each side, as the 2D free x edges
        reach = reaches[0]
        sizes[0], x_grid = scene.cutoff / reach, -scene.cutoff
        counts[0] = int(math.ceil(scene.width * reach / scene.cutoff)) + 2 * reach
    return (*sizes, *counts, x_grid, *periods, *reaches)


def tiny_scene(scene: Scene) -> Scene:
    """A few hundred particles with the same scene kind, model, integrator and precision (for JIT warm-up): no
    probes (the run's own points lie in the run's domain, not in this one)."""
    scene = scene.replace(probes=())
    own = scene.kind.tiny(scene)
    if own is not None:
        return own
    return scene.replace(
        dx=1.0,
        x_min=-10.0,
        x_max=10.0,
        y_min=-10.0,
        y_max=10.0,
        pulse_center=0.0,
        pulse_width=scene.default("pulse_width"),
        mach=scene.default("mach"),
        strip_height=None,
        steps=2,
        t_end=None,
        h_factor=scene.default("h_factor"),
        cutoff_factor=min(scene.cutoff_factor, 3.0),
    )
