"""The scene: what to simulate, as one frozen, validated value.

Defaults are the reference paper's: a square lattice of spacing ``dx`` on
x in [-10, 40] m, y in [-10, 10] m (periodic in y, free left/right edges),
a medium at rest (rho0 = 1 kg/m^3, c0 = 1 m/s) carrying a right-travelling
Gaussian pulse of Mach 0.05, a Gaussian kernel with h = 2.13 dx truncated at
3 h, and dt = 0.2 dx / c0. The kernel may instead be any registered kernel
(solvers/kernels/); one of compact support (the Wendland kernels: 2h) is cut
there instead.

A scene holds its numerical method as a value (:class:`~solvers.method.Method`:
kernel, h/dx, truncation, CFL, integrator, correction; the paper's its default),
its edges as another (:class:`~solvers.edges.Edges`: which are open, and the
absorbing layer beyond them) and a body's options as a third
(:class:`~solvers.body.BodyOptions`: its radius, its wall's model). Its parameters
are one flat list (:data:`Scene.PARAMETERS`: its keywords, its record's columns,
its options), the method's, the edges' and the body's read through from those values.

A scene states its particle count and memory before anything is allocated
(:meth:`Scene.memory_bytes`) and rejects nonsense with a message that names
the parameter and the allowed range (:class:`SceneError`). It is a pure value:
it checks its arrays against ``memory_limit_bytes`` when it states one and
never reads the machine (the harness sets that limit to the memory available,
pcabench/machine/memory.py, before any work).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields, replace
from typing import ClassVar

from solvers.body import BodyOptions
from solvers.corrections import DEFAULT_CORRECTION, Correction, correction_named
from solvers.edges import Edges
from solvers.kernels import Kernel, kernel_named
from solvers.method import FIELDS as METHOD_FIELDS
from solvers.method import Method, is_finite_number
from solvers.scenes import DEFAULT_SCENE, scene_kind

MODELS = ("lagrangian", "fixed", "linear")
# Arrays per particle an integrator keeps beyond FLOAT_ARRAYS_PER_PARTICLE: rk4's sums of its stages' rates (the
# rates, the velocity and a split absorber's x part) and the temporary of each sum.
INTEGRATOR_ARRAYS = {"rk4": 7}
PRECISIONS = ("float64", "float32")

# Arrays a solver holds per particle (state, rates, sort buffers, rk2/rk4 copies and sums),
# counted generously so that the estimate is an upper bound for every solver.
FLOAT_ARRAYS_PER_PARTICLE = 26
INT_ARRAYS_PER_PARTICLE = 4  # cell id, permutation, sort scratch (int32/int64)


# The y-periodic height must hold the kernel support (2 cutoffs) and the cell
# list's 3-row stencil without seeing a neighbour twice: this many cutoffs.
STRIP_CUTOFFS = 3.0

MAX_STEPS = 10_000_000  # the most steps a run may take (1e7)
MIN_CFL = 1e-3  # the smallest cfl: 1e7 steps of it cross 1e4 cells, a step smaller than any study needs

# Scene parameters that choose the numerical method rather than the physics.
# The domain: the scene kind's default (solvers/scenes/) where not given.
DOMAIN = ("x_min", "x_max", "y_min", "y_max")
PAPER_DOMAIN = {"x_min": -10.0, "x_max": 40.0, "y_min": -10.0, "y_max": 10.0}
DEPTH = ("z_min", "z_max")  # a 3D scene's z extent (a 2D scene's stays None)
PAPER_DEPTH = {"z_min": -10.0, "z_max": 10.0}  # a 3D kind's where it states none
# Arrays a 3D particle holds beyond a 2D one's: its z lattice coordinate and displacement, w, the z rate (and their
# copies and sums), counted generously like FLOAT_ARRAYS_PER_PARTICLE
FLOAT_ARRAYS_3D = 8
# a PML's parts of drho and their rates (drho_x, drho_y, ddx, ddy: twice, as a GPU solver keeps its state's rows
# and their sorted copies) and the zero velocity of a part's sweep
PML_ARRAYS_3D = 9
# Parameters whose default is the scene kind's where it states one (SceneKind.defaults), else these (the paper's;
# a body's radius only where the kind has a body).
PAPER_PULSE = {"pulse_width": 3.0, "pulse_center": 0.0}
PER_KIND = ("pulse_width", "pulse_center", "cylinder_radius", "sphere_radius")
BODY_PER_KIND = ("cylinder_radius", "sphere_radius")  # of PER_KIND: the body's options (solvers/body.py)
LAYER_UNSET = Edges.layer_unset()  # a closed scene's layer options
DEFAULT_METHOD = Method.paper()  # Scene's method unless given (solvers/method.py: the paper's)


class SceneError(ValueError):
    """A scene parameter is outside its allowed range."""


def bytes_per_particle(precision: str, extra: int = 0) -> int:
    """Upper bound of the memory one particle costs a solver, in bytes (``extra``: arrays a method keeps beyond
    the standard solver's: a kernel correction's factors)."""
    item = 8 if precision == "float64" else 4
    return (FLOAT_ARRAYS_PER_PARTICLE + extra) * item + INT_ARRAYS_PER_PARTICLE * 8


@dataclass(frozen=True, init=False)
class Scene:
    """One simulation, fully specified. Lengths in m, times in s, density in kg/m^3."""

    dx: float
    name: str = DEFAULT_SCENE  # the scene kind (solvers/scenes/): the problem, its boundaries and reference
    x_min: float | None = None  # the domain, m; None: the scene kind's default (the paper's: [-10, 40] x [-10, 10])
    x_max: float | None = None
    y_min: float | None = None
    y_max: float | None = None
    z_min: float | None = None  # a 3D scene's depth, m (None: the kind's; a 2D scene has none)
    z_max: float | None = None
    strip_height: float | None = None  # replaces [y_min, y_max] by a centred strip
    rho0: float = 1.0
    c0: float = 1.0
    mach: float = 0.05
    pulse_width: float | None = None  # the 3 in exp(-((x - c0 t)/3)^2), m; None: the kind's (the paper's 3)
    pulse_center: float | None = None  # pulse position at t = 0, m; None: the kind's (the paper's 0)
    probes: tuple = ()  # points ((x, y) or (x, y, z), ...) m where a run records drho every few steps, beside its own
    edges: Edges = Edges()  # the open edges and their layer (solvers/edges.py); open "": the kind's
    body_options: BodyOptions = BodyOptions()  # a rigid body's radius and wall model (solvers/body.py)
    method: Method = DEFAULT_METHOD  # kernel, h/dx, truncation, CFL, integrator, correction (solvers/method.py)
    model: str = "lagrangian"
    precision: str = "float64"
    steps: int | None = None
    t_end: float | None = None
    blowup_factor: float = 4.0  # unstable once max|u| > blowup_factor * mach * c0 or max|drho| > ... * mach * rho0
    memory_limit_bytes: int | None = field(default=None, compare=False)

    # The scene's parameters, flat: its keywords, its record's columns and its options (pcabench/parameters.py),
    # in this order; the method's and the edges' are read through from those values.
    PARAMETERS: ClassVar[tuple] = (
        "dx", "name", "x_min", "x_max", "y_min", "y_max", "z_min", "z_max", "strip_height", "rho0", "c0", "mach",
        "pulse_width", "pulse_center", "cylinder_radius", "sphere_radius", "boundary_method", "probes", "open",
        "layer_width", "absorber", "absorber_strength", "h_factor", "cutoff_factor", "kernel", "correction", "cfl",
        "model", "integrator", "precision", "steps", "t_end", "blowup_factor",
    )  # fmt: skip

    def __init__(
        self, dx: float, name: str = DEFAULT_SCENE, *, method=None, edges=None, body_options=None, **given
    ) -> None:
        """A scene of lattice spacing ``dx`` (m) of the scene kind ``name``: every other parameter a keyword of
        :data:`PARAMETERS`. ``method``, ``edges`` and ``body_options`` give those values whole; a flat keyword
        (``kernel=``, ``open=``, ``cylinder_radius=``) refines the value it belongs to."""
        unknown = sorted(set(given) - set(self.PARAMETERS) - {"memory_limit_bytes"})
        if unknown:
            raise TypeError(f"Scene() got an unexpected keyword argument {unknown[0]!r}")
        method = DEFAULT_METHOD if method is None else method
        edges = Edges() if edges is None else edges
        body_options = BodyOptions() if body_options is None else body_options
        values = (("method", method, Method), ("edges", edges, Edges), ("body_options", body_options, BodyOptions))
        for keyword, value, kind in values:
            if not isinstance(value, kind):
                raise SceneError(f"{keyword} must be a {kind.__name__} value (got {type(value).__name__} {value!r})")
        numerics = {k: given.pop(k) if k in given else getattr(method, k) for k in METHOD_FIELDS}
        if numerics["cutoff_factor"] is None:  # a compact kernel's method: its cut is its support
            numerics["cutoff_factor"] = DEFAULT_METHOD.cutoff_factor
        try:
            compact = kernel_named(numerics["kernel"]).support is not None
        except (ValueError, TypeError):  # an unknown kernel: named by _validate
            compact = False
        if compact and numerics["cutoff_factor"] == DEFAULT_METHOD.cutoff_factor:
            numerics["cutoff_factor"] = None  # no part of a compact kernel's method (another cut: refused below)
        object.__setattr__(self, "method", Method(**numerics))
        object.__setattr__(
            self, "edges", Edges(**{k: given.pop(k) if k in given else getattr(edges, k) for k in Edges.names()})
        )
        body = {k: given.pop(k) if k in given else getattr(body_options, k) for k in BodyOptions.names()}
        object.__setattr__(self, "body_options", BodyOptions(**body))
        object.__setattr__(self, "dx", dx)
        object.__setattr__(self, "name", name)
        for f in fields(self):
            if f.name not in ("dx", "name", "method", "edges", "body_options"):
                object.__setattr__(self, f.name, given.pop(f.name, f.default))
        self.__post_init__()

    # ------------------------------------------------------------ the method's and the edges' parameters
    @property
    def kernel(self) -> str:
        """A registered kernel's name (solvers/kernels/)."""
        return self.method.kernel

    @property
    def h_factor(self) -> float:
        """h / dx."""
        return self.method.h_factor

    @property
    def cutoff_factor(self) -> float:
        """cutoff / h of a truncated kernel (the Gaussian); a compact kernel's is the default, no part of it."""
        cut = self.method.cutoff_factor
        return DEFAULT_METHOD.cutoff_factor if cut is None else cut

    @property
    def cfl(self) -> float:
        """dt c0 / dx (dt lowered slightly to land on t_end)."""
        return self.method.cfl

    @property
    def integrator(self) -> str:
        """The time integrator (INTEGRATORS)."""
        return self.method.integrator

    @property
    def correction(self) -> str:
        """A registered kernel correction's name (solvers/corrections/)."""
        return self.method.correction

    @property
    def open(self) -> str:
        """The open edges ("x": both x edges), each with an absorbing layer beyond the domain ("": closed)."""
        return self.edges.open

    @property
    def layer_width(self) -> float | None:
        """The layer's width asked for, m; None: the absorber's default."""
        return self.edges.layer_width

    @property
    def absorber(self) -> str:
        """What damps the layer (solvers/boundaries/absorbers/); "": the scene's (:attr:`absorber_used`)."""
        return self.edges.absorber

    @property
    def absorber_strength(self) -> float | None:
        """The absorber's strength asked for, 1/s; None: the absorber's default for the scene."""
        return self.edges.absorber_strength

    # ------------------------------------------------------------ the body's parameters
    @property
    def cylinder_radius(self) -> float | None:
        """A rigid cylinder's radius, m (a scene kind with a body in 2D; else None)."""
        return self.body_options.cylinder_radius

    @property
    def sphere_radius(self) -> float | None:
        """A rigid sphere's radius, m (a 3D scene kind with a body; else None)."""
        return self.body_options.sphere_radius

    @property
    def boundary_method(self) -> str:
        """How a body's curved wall is modelled, as asked (solvers/boundaries/bodies/); "": the default
        (:attr:`boundary_method_used`)."""
        return self.body_options.boundary_method

    def __post_init__(self) -> None:
        if self.steps is None and self.t_end is None:
            object.__setattr__(self, "steps", 100)  # the paper's protocol
        try:
            kind = scene_kind(self.name)
        except ValueError as exc:
            raise SceneError(str(exc)) from None
        for key in DOMAIN:
            if getattr(self, key) is None:
                object.__setattr__(self, key, kind.domain.get(key, PAPER_DOMAIN[key]))
        for key in DEPTH:
            if getattr(self, key) is None and kind.dims == 3:
                object.__setattr__(self, key, kind.domain.get(key, PAPER_DEPTH[key]))
        for key in PER_KIND:
            if getattr(self, key) is None:
                value = kind.defaults.get(key, PAPER_PULSE.get(key))
                if key in BODY_PER_KIND:
                    object.__setattr__(self, "body_options", replace(self.body_options, **{key: value}))
                else:
                    object.__setattr__(self, key, value)
        if not self.open:
            object.__setattr__(self, "edges", replace(self.edges, open=kind.defaults.get("open", "")))
        words = "x,y,z" if kind.dims == 3 else "x,y"
        try:
            points = tuple(tuple(float(c) for c in p) for p in self.probes or ())
        except (TypeError, ValueError):
            raise SceneError(f"--probe takes points {words} in m (got {self.probes!r})") from None
        for p in points:
            if len(p) != kind.dims:
                raise SceneError(
                    f"--probe takes points {words} in m in the {self.name} scene ({kind.dims}D; got "
                    f"{','.join(f'{c:g}' for c in p)})"
                )
        object.__setattr__(self, "probes", points)
        self._validate()

    @property
    def dims(self) -> int:
        """The scene's dimension, 2 or 3: its kind's (solvers/scenes/)."""
        return self.kind.dims

    # ------------------------------------------------------------ validation
    def _validate(self) -> None:
        def need(ok: bool, msg: str) -> None:
            if not ok:
                raise SceneError(msg)

        def finite(name: str) -> float:
            value = getattr(self, name)
            need(is_finite_number(value), f"{name} must be a finite number (got {value!r})")
            return float(value)

        for name in (
            "dx",
            "x_min",
            "x_max",
            "y_min",
            "y_max",
            "rho0",
            "c0",
            "mach",
            "pulse_width",
            "pulse_center",
            "cfl",
            "blowup_factor",
        ):
            finite(name)
        need(self.dx > 0, f"dx must be > 0 m (got {self.dx})")
        if "x_max" in self.kind.walls:
            need(
                self.x_max > self.x_min,
                f"--wall-x must be right of the domain's left edge x_min = {self.x_min:g} m (got {self.x_max:g})",
            )
        need(self.x_max > self.x_min, f"x_max must be > x_min (got {self.x_min}..{self.x_max})")
        need(self.y_max > self.y_min, f"y_max must be > y_min (got {self.y_min}..{self.y_max})")
        self._validate_depth(need, finite)
        if self.strip_height is not None:
            finite("strip_height")
            need(self.strip_height > 0, f"strip_height must be > 0 m (got {self.strip_height})")
        # the particle count in floating point first: a tiny dx must not overflow an integer
        count = (self.x_max - self.x_min) / self.dx * (self.height_span / self.dx) * self.layers_span
        if not count <= 2**31 - 1:
            limit, smallest = self.memory_limit(), self.dx_for_particles(2**31 - 1)
            if limit is None:
                need(
                    False,
                    f"dx = {self.dx} m gives {count:.3g} particles: more than the 2^31-1 supported; "
                    f"the smallest dx that fits is about {smallest:.3g} m",
                )
            need(
                False,
                f"dx = {self.dx} m gives {count:.3g} particles: more than the 2^31-1 supported and the "
                f"memory available ({limit / 2**30:.3g} GiB); the smallest dx that fits is about "
                f"{max(self.smallest_dx_fitting(limit), smallest):.3g} m",
            )
        need(self.rho0 > 0, f"rho0 must be > 0 kg/m^3 (got {self.rho0})")
        need(self.c0 > 0, f"c0 must be > 0 m/s (got {self.c0})")
        need(0 < self.mach < 1, f"mach must be in (0, 1) (got {self.mach})")
        need(self.pulse_width > 0, f"pulse_width must be > 0 m (got {self.pulse_width})")
        for problem in self.method.problems():  # kernel, h/dx, truncation, correction, integrator
            need(False, problem)
        need(
            MIN_CFL <= self.cfl <= 50,
            f"cfl (dt*c0/dx) must be in [{MIN_CFL:g}, 50] (got {self.cfl:g}): below it a run of "
            f"{MAX_STEPS:,} steps would not cross one cell",
        )
        need(self.blowup_factor > 1, f"blowup_factor must be > 1 (got {self.blowup_factor})")
        need(self.model in MODELS, f"model must be one of {', '.join(MODELS)} (got {self.model!r})")
        need(self.precision in PRECISIONS, f"precision must be one of {', '.join(PRECISIONS)} (got {self.precision!r})")
        need(self.steps is None or self.t_end is None, "give steps or t_end, not both")
        if self.steps is not None:
            need(
                isinstance(self.steps, int) and not isinstance(self.steps, bool) and self.steps >= 1,
                f"steps must be an integer >= 1 (got {self.steps!r})",
            )
            need(self.steps <= MAX_STEPS, f"steps must be <= 1e7 (got {self.steps})")
        if self.t_end is not None:
            finite("t_end")
            need(self.t_end > 0, f"t_end must be > 0 s (got {self.t_end})")
            need(
                self.t_end / self.dt_max <= MAX_STEPS,
                f"t_end = {self.t_end} s needs more than 1e7 steps at dt = {self.dt_max:g} s",
            )
        for problem in self.kind.check(self):  # the scene kind's own parameters first: they name its options
            need(False, problem)
        self._validate_body(need, finite)
        self._validate_probes(need)
        self._validate_open(need, finite)
        least = STRIP_CUTOFFS * self.cutoff
        need(
            not self.periodic_y or self.height >= least * (1 - 1e-9),
            f"{'strip_height' if self.strip_height is not None else 'y_max - y_min'} must be at least "
            f"3 cutoffs = {least:.6g} m at dx = {self.dx} (the kernel support plus the 3x3 cell "
            f"stencil; got {self.height:.6g} m after rounding to whole rows of dx)",
        )
        need(self.nx >= 1 and self.ny >= 1 and self.nz >= 1, f"dx = {self.dx} m is larger than the domain")
        need(
            not self.periodic_z or self.depth >= least * (1 - 1e-9),
            f"z_max - z_min must be at least 3 cutoffs = {least:.6g} m at dx = {self.dx} for the z-periodic "
            f"{self.name} scene (got {self.depth:.6g} m)",
        )
        if self.periodic_x or self.kind.walls:
            need(
                self.width >= least * (1 - 1e-9),
                f"x_max - x_min must be at least 3 cutoffs = {least:.6g} m at dx = {self.dx} for the "
                f"{'x-periodic' if self.periodic_x else 'walled'} {self.name} scene (got {self.width:.6g} m)",
            )
        breaking = self.kind.breaking_time(self)
        # the end time the user set: --t-end, or --steps of dt = --cfl x --dx / c0 (the options it comes from)
        ends = (
            f"--t-end {self.t_end:g}"
            if self.t_end is not None
            else f"--steps {self.n_steps} x dt (--cfl {self.cfl:g} x --dx {self.dx:g} / c0) = {self.t_final:g} s"
        )
        need(
            self.model == "linear" or self.t_final < breaking,
            f"{ends}: the run passes the pulse's nonlinear breaking time {breaking:.3g} s at "
            f"--mach {self.mach:g}, --pulse-width {self.pulse_width:g} m (the isothermal solution has a shock "
            f"there): end earlier, lower --mach, or use the linear model",
        )
        limit = self.memory_limit()  # None: the scene states no limit (the harness gives it one)
        if limit is not None:
            need(
                self.memory_bytes() <= limit,
                f"dx = {self.dx} m needs {self.n_particles:,} particles and about "
                f"{self.memory_bytes() / 2**30:.3g} GiB, more than the {limit / 2**30:.3g} GiB available; "
                f"the smallest dx that fits is about {self.smallest_dx_fitting(limit):.3g} m",
            )

    def _validate_depth(self, need, finite) -> None:
        """A 3D scene's z extent (and its kernel normalised in 3D, a solver-free method it can run); a 2D
        scene's none."""
        if self.dims == 2:
            for key in DEPTH:
                need(getattr(self, key) is None, f"{key}: the {self.name} scene is 2D (it has no z extent)")
            return
        for key in DEPTH:
            finite(key)
        need(self.z_max > self.z_min, f"z_max must be > z_min (got {self.z_min}..{self.z_max})")
        need(self.strip_height is None, f"--strip-height: the {self.name} scene is 3D (a strip is a 2D scene's)")
        try:
            self.sph_kernel.in_dims(3)
        except ValueError as exc:
            need(False, str(exc))

    def probe_points(self) -> dict:
        """{name: (x, y) or (x, y, z)}: where a run records drho (the scene kind's points, then ``probes`` as P1, P2,
        ...), m."""
        points = dict(self.kind.probe_points(self))
        points.update({f"P{i + 1}": p for i, p in enumerate(self.probes)})
        return points

    def _validate_probes(self, need) -> None:
        box = [(self.x_min, self.x_max), (self.y_min, self.y_max)] + ([(self.z_min, self.z_max)] * (self.dims == 3))
        for p in self.probes:
            need(
                all(math.isfinite(c) and lo <= c <= hi for c, (lo, hi) in zip(p, box)),
                f"--probe {','.join(f'{c:g}' for c in p)} is outside the domain "
                + " x ".join(f"[{lo:g}, {hi:g}]" for lo, hi in box)
                + " m",
            )
            if self.body is not None:
                x0, y0, a = self.body
                centre = (x0, y0, 0.0)[: self.dims]  # a cylinder's axis, a sphere's centre
                need(
                    math.dist(p, centre) >= a + self.cutoff,
                    f"--probe {','.join(f'{c:g}' for c in p)} is inside the body or within a cutoff of its wall (r < "
                    f"{a + self.cutoff:.4g} m from its {'centre' if self.dims == 3 else 'axis'})",
                )

    def _validate_body(self, need, finite) -> None:
        """The body's options (:meth:`solvers.body.BodyOptions.problems`): the first problem, in one line."""
        for problem in self.body_options.problems(self):
            need(False, problem)

    @property
    def body(self) -> tuple | None:
        """(x0, y0, radius) of the scene's rigid body, m (a cylinder, its axis at x0, y0; in a 3D scene a sphere,
        its centre at x0, y0 and z = 0), or None."""
        return self.kind.body_of(self) if self.kind.body else None

    @property
    def boundary_method_used(self) -> str:
        """How the body's wall is modelled (:meth:`solvers.body.BodyOptions.boundary_method_used`)."""
        return self.body_options.boundary_method_used(self.correction)

    @property
    def blowup_bounds(self) -> dict:
        """{field: (bound, unit, formula)}: a run has blown up once max|field| passes its bound (the velocity, m/s,
        over its components; drho, kg/m^3): ``blowup_factor`` times the pulse's amplitude, mach c0 and mach rho0."""
        return {
            "velocity": (self.blowup_factor * self.mach * self.c0, "m/s", "blowup_factor * mach * c0"),
            "drho": (self.blowup_factor * self.mach * self.rho0, "kg/m^3", "blowup_factor * mach * rho0"),
        }

    @property
    def cautions(self) -> tuple[str, ...]:
        """Lines a run or a prediction of this scene prints before its work: a combination known to blow up
        (:attr:`known_failure`), a truncated kernel cut below where it keeps its order."""
        out = [self.known_failure] if self.known_failure else []
        try:
            order_cut = getattr(kernel_named(self.kernel), "order_cutoff", None)
        except ValueError:
            order_cut = None
        if order_cut is not None and self.cutoff_factor < order_cut - 1e-9:
            out.append(
                f"--kernel {self.kernel} cut at {self.cutoff_factor:g} h loses its order (the cut's error leads); "
                f"--cutoff {order_cut:g} keeps it"
            )
        return tuple(out)

    @property
    def known_failure(self) -> str:
        """One line where this combination of body and method is known to blow up (a ghost body with a kernel
        correction), naming what holds; "" otherwise."""
        if self.body is None or self.correction == DEFAULT_CORRECTION:
            return ""
        from solvers.boundaries.bodies import CORRECTED_BOUNDARY_METHOD, boundary_method_named

        try:
            why = getattr(boundary_method_named(self.boundary_method_used), "fails_with_correction", "")
        except ValueError:  # an unknown method: named by _validate
            return ""
        return (
            f"--boundary-method {self.boundary_method_used} with --correction {self.correction} is known to blow up: "
            f"{why}; --boundary-method {CORRECTED_BOUNDARY_METHOD} holds"
            if why
            else ""
        )

    def _validate_open(self, need, finite) -> None:
        """The open edges (:meth:`solvers.edges.Edges.problems`): the first problem, in one line."""
        for problem in self.edges.problems(self):
            need(False, problem)

    # ------------------------------------------------------------ open edges
    @property
    def n_layer(self) -> int:
        """Columns (rows) of the absorbing layer beyond each open edge (0 where none is open); SceneError naming
        --absorber and the choices if it is unknown (met wherever asked first: the lattice's size needs it)."""
        try:
            return self.edges.n_layer(self)
        except ValueError as exc:
            raise SceneError(str(exc)) from None

    @property
    def layer_columns(self) -> int:
        """Lattice columns of the layer beyond each x edge: n_layer where x is open, else 0."""
        return self.n_layer if self.edges.open_x else 0

    @property
    def layer_rows(self) -> int:
        """Lattice rows of the layer beyond each y edge: n_layer where y is open, else 0."""
        return self.n_layer if self.edges.open_y else 0

    @property
    def layer_depth(self) -> int:
        """Lattice layers of the absorbing layer beyond each z face: n_layer where z is open, else 0."""
        return self.n_layer if self.edges.open_z else 0

    @property
    def layer(self) -> float:
        """The absorbing layer's width, m: whole columns of dx (0 where no edge is open)."""
        return self.n_layer * self.dx

    def scored(self, column, row=None):
        """Which lattice sites (home column and row indices, arrays) are the scored domain's: all but an open
        edge's layers (a run's output keeps these)."""
        c, r = self.layer_columns, self.layer_rows
        inside = (column >= c) & (column < self.nx - c)
        if r and row is not None:
            inside &= (row >= r) & (row < self.ny - r)
        return inside

    def scored_3d(self, column, row, layer):
        """:meth:`scored` of a 3D lattice: all sites but the open faces' layers."""
        c, r, d = self.layer_columns, self.layer_rows, self.layer_depth
        inside = (column >= c) & (column < self.nx - c) & (row >= r) & (row < self.ny - r)
        return inside & (layer >= d) & (layer < self.nz - d)

    @property
    def strength(self) -> float:
        """The absorber's strength, 1/s: the scene's, or the absorber's default for it."""
        try:
            return self.edges.strength(self)
        except ValueError as exc:
            raise SceneError(str(exc)) from None

    @property
    def absorber_used(self) -> str:
        """The absorber that damps the layer (:meth:`solvers.edges.Edges.absorber_used`)."""
        return self.edges.absorber_used(self)

    # ------------------------------------------------------------ geometry
    @property
    def kind(self):
        """The scene kind (solvers/scenes/): initial fields, boundaries, reference and error measures."""
        return scene_kind(self.name)

    @property
    def periodic_x(self) -> bool:
        """Whether the lattice is periodic in x (else its left and right edges are free or walls): the scene
        kind's periodic x, unless its x edges are open."""
        return "x" in self.kind.periodic and not self.edges.open_x

    @property
    def periodic_y(self) -> bool:
        """Whether the lattice is periodic in y (else its bottom and top edges are free): the scene kind's
        periodic y, unless its y edges are open."""
        return "y" in self.kind.periodic and not self.edges.open_y

    @property
    def periodic_z(self) -> bool:
        """Whether a 3D lattice is periodic in z (False for a 2D scene), unless its z faces are open."""
        return self.dims == 3 and "z" in self.kind.periodic and not self.edges.open_z

    @property
    def boundaries(self) -> frozenset:
        """The boundary kinds a solver needs for this scene (free-x, periodic-x, wall-x, free-y, periodic-y)."""
        return self.kind.boundaries(self)

    @property
    def width(self) -> float:
        """Width of the lattice in x, m (the period where x is periodic)."""
        return self.nx * self.dx

    @property
    def h(self) -> float:
        """Smoothing length, m."""
        return self.h_factor * self.dx

    @property
    def cutoff(self) -> float:
        """Interaction radius, m: the kernel's support (:meth:`cutoff_ratio` h)."""
        return self.cutoff_ratio(self.kernel, self.cutoff_factor) * self.h

    @property
    def sph_kernel(self) -> Kernel:
        """The kernel ``kernel`` names (solvers/kernels/): W, G and the compiled G of this scene's method."""
        return kernel_named(self.kernel)

    @property
    def sph_correction(self) -> Correction:
        """The kernel correction ``correction`` names (solvers/corrections/): how PI turns the sweeps into rates."""
        return correction_named(self.correction)

    @property
    def nx(self) -> int:
        """Lattice columns: the domain's, and an absorbing layer's each side where x is open."""
        return max(int(round((self.x_max - self.x_min) / self.dx)), 0) + 2 * self.layer_columns

    @property
    def ny(self) -> int:
        """Lattice rows: the domain's, and an absorbing layer's each side where y is open; the periodic height
        is ny * dx."""
        span = self.strip_height if self.strip_height is not None else self.y_max - self.y_min
        return max(int(round(span / self.dx)), 0) + 2 * self.layer_rows

    @property
    def nz(self) -> int:
        """Lattice layers in z: a 3D scene's (the periodic depth is nz * dx), 1 for a 2D scene."""
        if self.dims == 2:
            return 1
        return max(int(round((self.z_max - self.z_min) / self.dx)), 0) + 2 * self.layer_depth

    @property
    def depth(self) -> float:
        """Depth of a 3D lattice in z, m (the period where z is periodic); 0 for a 2D scene."""
        return self.nz * self.dx if self.dims == 3 else 0.0

    @property
    def z_lo(self) -> float:
        """Front of a 3D lattice in z, m (0 for a 2D scene)."""
        return self.z_min - self.layer_depth * self.dx if self.dims == 3 else 0.0

    @property
    def height(self) -> float:
        """Height of the lattice in y, m (a whole number of rows; the period where y is periodic)."""
        return self.ny * self.dx

    @property
    def y_lo(self) -> float:
        """Bottom of the lattice, m (the strip is centred on the domain; an open edge's layer below y_min)."""
        if self.strip_height is None:
            return self.y_min - self.layer_rows * self.dx
        return 0.5 * (self.y_min + self.y_max) - 0.5 * self.height

    @property
    def x_lo(self) -> float:
        """Left edge of the lattice, m: x_min, or where the only wall is the right edge, x_max - nx dx (the
        lattice flush with the wall, its last column half a spacing from it)."""
        if self.kind.walls == ("x_max",):
            return self.x_max - self.width
        return self.x_min - self.layer_columns * self.dx

    @property
    def walls(self) -> dict:
        """{edge: x of the rigid wall there, m} for the scene kind's walls ("x_min", "x_max"): the lattice's
        edges, half a spacing from its first and last columns (with two walls the right one is at
        x_min + nx dx, within dx/2 of x_max)."""
        edges = {"x_min": self.x_lo, "x_max": self.x_lo + self.width}
        return {edge: edges[edge] for edge in self.kind.walls}

    @property
    def n_particles(self) -> int:
        return self.nx * self.ny * self.nz

    @property
    def n_scored(self) -> int:
        """The particles of the scored domain: all of them, but an open edge's layers (the run's output)."""
        return (self.nx - 2 * self.layer_columns) * (self.ny - 2 * self.layer_rows) * (self.nz - 2 * self.layer_depth)

    # ------------------------------------------------------------ time
    @property
    def dt_max(self) -> float:
        return self.cfl * self.dx / self.c0

    @property
    def n_steps(self) -> int:
        if self.steps is not None:
            return self.steps
        return max(1, math.ceil(self.t_end / self.dt_max - 1e-9))

    @property
    def dt(self) -> float:
        """Time step, s: cfl*dx/c0, or a little less so that t_end is hit exactly."""
        if self.steps is not None:
            return self.dt_max
        return self.t_end / self.n_steps

    @property
    def t_final(self) -> float:
        return self.n_steps * self.dt

    # ------------------------------------------------------------ memory
    def memory_limit(self) -> int | None:
        """Memory a run of this scene may use, bytes: ``memory_limit_bytes``; None where the scene states
        no limit (a scene never reads the machine: the harness, pcabench.machine.memory.bounded, sets the limit
        to what is available before any work)."""
        return self.memory_limit_bytes

    def memory_bytes(self) -> int:
        """Upper bound of the memory the particle arrays need, bytes (a pair list, where used, comes on top)."""
        return self.n_particles * bytes_per_particle(self.precision, self.extra_arrays + self.arrays_3d)

    @property
    def arrays_3d(self) -> int:
        """Arrays per particle a 3D scene holds beyond a 2D one's (FLOAT_ARRAYS_3D, and a PML's parts and rates
        of drho and its zero velocity, PML_ARRAYS_3D; 0 in 2D)."""
        if self.dims != 3:
            return 0
        try:
            split = bool(self.open) and self.edges.absorber_model(self).split
        except ValueError:  # an unknown absorber: refused by the edges' check
            split = False
        return FLOAT_ARRAYS_3D + (PML_ARRAYS_3D if split else 0)

    @property
    def extra_arrays(self) -> int:
        """Arrays per particle the method keeps beyond the standard solver's: its correction's and its
        integrator's (INTEGRATOR_ARRAYS)."""
        try:
            correction = correction_named(self.correction)
            corrected = int(
                getattr(correction, "arrays_3d", correction.arrays) if self.dims == 3 else correction.arrays
            )
        except ValueError:
            corrected = 0
        return corrected + INTEGRATOR_ARRAYS.get(self.integrator, 0)

    def smallest_dx_fitting(self, limit_bytes: float) -> float:
        """The smallest lattice spacing whose arrays fit in ``limit_bytes``, m."""
        extent = (self.x_max - self.x_min) * self.height_span * self.depth_span
        per = bytes_per_particle(self.precision, self.extra_arrays + self.arrays_3d)
        return (
            math.sqrt(extent * per / max(limit_bytes, 1))
            if self.dims == 2
            else math.cbrt(extent * per / max(limit_bytes, 1))
        )

    def dx_for_particles(self, n: float) -> float:
        """The lattice spacing that gives about ``n`` particles on this domain, m."""
        extent = (self.x_max - self.x_min) * self.height_span * self.depth_span
        return math.sqrt(extent / n) if self.dims == 2 else math.cbrt(extent / n)

    @property
    def height_span(self) -> float:
        return self.strip_height if self.strip_height is not None else self.y_max - self.y_min

    @property
    def layers_span(self) -> float:
        """The z layers of a 3D scene's domain, (z_max - z_min) / dx, before rounding; 1 for a 2D scene."""
        return (self.z_max - self.z_min) / self.dx if self.dims == 3 else 1.0

    @property
    def depth_span(self) -> float:
        """z_max - z_min of a 3D scene, m; 1 for a 2D scene (a factor of its particle count)."""
        return self.z_max - self.z_min if self.dims == 3 else 1.0

    # ------------------------------------------------------------ defaults and rules
    @classmethod
    def default(cls, name: str):
        """The default value of the scene parameter ``name`` (the one place defaults live; the domain's
        are the paper's here, a scene kind's own in :meth:`default_of`)."""
        if name in PAPER_DOMAIN:
            return PAPER_DOMAIN[name]
        if name in DEPTH:
            return None  # a 2D scene's; a 3D kind states its own (default_of)
        if name in PAPER_PULSE:
            return PAPER_PULSE[name]
        return cls.keyword_default(name)

    @classmethod
    def keyword_default(cls, name: str):
        """The constructor's default of keyword ``name`` (None where the scene kind's or the paper's is resolved
        when the scene is built: the domain, the pulse, the body)."""
        if name in METHOD_FIELDS:
            return getattr(DEFAULT_METHOD, name)
        if name in Edges.names():
            return getattr(Edges(), name)
        if name in BodyOptions.names():
            return getattr(BodyOptions(), name)
        return cls.__dataclass_fields__[name].default

    def parameters(self) -> dict:
        """{name: value} of :data:`PARAMETERS`: the scene as stored (no derived quantities, no machine limit)."""
        return {name: getattr(self, name) for name in self.PARAMETERS}

    def default_of(self, name: str):
        """The default of parameter ``name`` for this scene's kind (its domain, pulse or edges may differ from the
        paper's)."""
        if name in self.kind.domain:
            return self.kind.domain[name]
        return self.kind.defaults.get(name, self.default(name))

    @classmethod
    def cutoff_ratio(cls, kernel: str | None = None, cutoff_factor: float | None = None) -> float:
        """cutoff / h, the one rule: the kernel's compact support (``Kernel.support``: the Wendland kernels'),
        else the truncation ``cutoff_factor`` (the Gaussian's; None: the defaults)."""
        support = kernel_named(cls.default("kernel") if kernel is None else kernel).support
        if support is not None:
            return support
        return cls.default("cutoff_factor") if cutoff_factor is None else cutoff_factor

    @classmethod
    def thinnest_strip(
        cls, dx: float, cutoff_factor: float | None = None, h_factor: float | None = None, kernel: str | None = None
    ) -> float:
        """The thinnest y-periodic strip height the rules accept at ``dx``, in whole rows, m."""
        h_factor = cls.default("h_factor") if h_factor is None else h_factor
        return math.ceil(STRIP_CUTOFFS * cls.cutoff_ratio(kernel, cutoff_factor) * h_factor * (1 + 1e-9)) * dx

    # ------------------------------------------------------------ helpers
    def replace(self, **changes) -> "Scene":
        """This scene with ``changes``; closing its edges (``open=""``) lets go of the layer's options too (a
        closed scene takes none of them), unless the changes set them."""
        if "open" in changes and not changes["open"]:
            changes = {**LAYER_UNSET, **changes}
        return replace(self, **changes)

    def as_dict(self) -> dict:
        d = self.parameters()
        d.update(
            n_particles=self.n_particles,
            dt=self.dt,
            n_steps=self.n_steps,
            t_final=self.t_final,
            h=self.h,
            cutoff=self.cutoff,
            height=self.height,
            layer=self.layer,
            absorber_used=self.absorber_used if self.open else "",
            boundary_method_used=self.boundary_method_used if self.body is not None else "",
        )
        return d

    def describe(self) -> str:
        scene = "" if self.name == DEFAULT_SCENE else f"{self.name}, "
        if self.body is not None:  # the wall's model, the default's too (it depends on the correction)
            scene += f"{self.boundary_method_used} wall, "
        corrected = "" if self.correction == DEFAULT_CORRECTION else f" ({self.correction}-corrected)"
        edges = (
            f"open {self.open} ({self.absorber_used}, {self.layer:g} m of layer, {self.strength:.3g} 1/s), "
            if self.open
            else ""
        )
        return (
            f"{scene}{edges}{self.n_particles:,} particles ({self.nx} x {self.ny}"
            f"{f' x {self.nz}' if self.dims == 3 else ''}), dx = {self.dx:g} m, "
            f"{self.kernel} kernel{corrected}, "
            f"h = {self.h:.4g} m, cutoff = {self.cutoff:.4g} m, dt = {self.dt:.4g} s, "
            f"{self.n_steps} steps to t = {self.t_final:.4g} s, "
            f"{self.model}/{self.integrator}/{self.precision}, "
            f"arrays <= {self.memory_bytes() / 2**20:.1f} MiB"
        )
