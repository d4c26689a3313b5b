"""What a scene is: the problem, its boundaries, its initial fields and what it is scored against.

A scene kind is one class (one file in solvers/scenes/, or a plug-in through
the entry-point group ``pcabench.scenes``) with a ``name``. It states

* ``summary``: one line for --help;
* ``dims``: 2 (a plane) or 3 (a volume: z too, ``periodic-z`` for a solver);
* ``periodic``: the axes that are periodic ("x", "y", "z"); the others have free
  edges, except the x edges named in ``walls`` ("x_min", "x_max"), which are
  rigid walls (mirror particles, solvers/physics/pairs.py). :meth:`boundaries` turns
  them into the boundary kinds a solver must support (``free-x``,
  ``periodic-x``, ``wall-x``, ``free-y``, ``periodic-y``); ``images`` names the
  periodic axes whose seams are images of an open problem, which ``--open``
  may open (a free edge of the lattice beyond an absorbing layer);
* ``domain``: its default domain (x_min, x_max, y_min, y_max, m), where it
  differs from the paper's; ``defaults``: its other defaults where they
  differ (the pulse's width and centre, a body's radius; ``open``: the edges
  an open problem always opens);
* ``body``: whether it holds a rigid body (:meth:`body_of`: a cylinder's axis
  and radius), whose curved wall a boundary method models (solvers/boundaries/bodies/;
  the boundary kind ``body``);
* ``fields``: the fields its error measures name; ``primary`` the one the
  headline error (a record's ``mse`` and ``me``) measures;
* its initial fields (:meth:`initial_fields`), its exact linear reference
  and error measures (:meth:`errors`), the isothermal reference where it has
  one (:meth:`isothermal_errors`), the linear prediction (:meth:`predict`),
  and its own parameter checks (:meth:`check`, one line each).

The numerical method (kernel, h/dx, CFL, integrator, precision, model) is
the Scene's, not the kind's: every kind runs with every method.
"""

from __future__ import annotations

import math

BOUNDARY_KINDS = ("free-x", "periodic-x", "wall-x", "free-y", "periodic-y", "periodic-z", "free-z", "body")
MACH_RANGE = (1e-6, 0.3)  # amplitudes a scene accepts: acoustic (linear) to weakly nonlinear
PULSE_WIDTH_RANGE = (0.1, 20.0)  # m
# Pulse widths about a peak that count as the pulse: beyond them a Gaussian pulse is below 1e-4 of its peak
# (exp(-9), and exp(-9 ln 2) for the 2D pulse's half-width); the headline switches once they reach an open edge.
PULSE_REACH = 3.0


def wall_measures(scene, x, diff, ref, amplitude: float) -> dict:
    """The error near the walls apart from the error in the bulk: ``wall_rms`` over the particles within a
    cutoff of a wall (those with mirror neighbours), ``bulk_rms`` over the others, each the RMS of ``diff``
    there over the RMS of ``ref`` over the whole domain (their squares, weighted by each band's share of the
    particles, add up to the whole's square). NaN (undefined) where ``ref`` holds no pulse: its RMS below
    QUIET of the pulse's ``amplitude`` (solvers/reference/analytic.py)."""
    import numpy as np

    from solvers.reference.analytic import QUIET

    x, diff, ref = (np.asarray(a, dtype=np.float64) for a in (x, diff, ref))
    gap = np.min([np.abs(x - xw) for xw in scene.walls.values()], axis=0)
    band = gap < scene.cutoff
    scale = float(np.mean(ref**2))
    if not (scale > (QUIET * amplitude) ** 2 and np.all(np.isfinite(diff))):
        return {"wall_rms": float("nan"), "bulk_rms": float("nan")}
    n = diff.size
    return {
        "wall_rms": float(np.sqrt(np.sum(diff[band] ** 2) / max(band.sum(), 1) / scale)),
        "bulk_rms": float(np.sqrt(np.sum(diff[~band] ** 2) / max(n - band.sum(), 1) / scale)),
    }


def scored_axes(scene) -> tuple:
    """(x (nx,), y (ny,)): the coordinates of the scored domain's lattice columns and rows, m (an open edge's
    layer left out), in the order of a run's output (row by row)."""
    import numpy as np

    columns = np.arange(scene.layer_columns, scene.nx - scene.layer_columns)
    rows = np.arange(scene.layer_rows, scene.ny - scene.layer_rows)
    return scene.x_lo + (columns + 0.5) * scene.dx, scene.y_lo + (rows + 0.5) * scene.dx


def left_behind(scene, fields, exact) -> dict:
    """What a run with open edges leaves in its domain, against the open problem's exact solution ``exact``
    ((drho, u, v) at the run's points): ``left_amplitude``, the largest error of the primary field over the
    initial pulse's peak, and ``left_energy``, the acoustic energy of the error, sum of 0.5 rho0 |du|^2 +
    0.5 c0^2 ddrho^2 / rho0 per scored site, over the initial pulse's. After the pulse has left, this is
    what the edges sent back (with the method's own dispersive tail: the dispersion prediction's same
    measures, a perfect absorber's, say how much)."""
    import numpy as np

    r_drho, r_u, r_v = (np.asarray(a, dtype=np.float64) for a in exact)
    d = {"drho": np.asarray(fields.drho) - r_drho, "u": np.asarray(fields.u) - r_u, "v": np.asarray(fields.v) - r_v}
    x, y = scored_axes(scene)
    gx, gy = np.meshgrid(x, y)
    u0, v0, drho0 = scene.kind.initial_fields(scene, gx.ravel(), gy.ravel(), np)
    start = {"drho": np.asarray(drho0, float), "u": np.asarray(u0, float), "v": np.asarray(v0, float)}

    def energy(f):  # per site: a plane scene's prediction is one row of its strip
        return float(
            np.mean(0.5 * scene.rho0 * (f["u"] ** 2 + f["v"] ** 2) + 0.5 * scene.c0**2 * f["drho"] ** 2 / scene.rho0)
        )

    primary = "drho" if scene.kind.primary == "drho" else "u"
    if not all(np.all(np.isfinite(a)) for a in d.values()):
        return {"left_amplitude": float("nan"), "left_energy": float("nan")}
    return {
        "left_amplitude": float(np.max(np.abs(d[primary])) / np.max(np.abs(start[primary]))),
        "left_energy": energy(d) / energy(start),
    }


def window_probe_errors(scene, probes, window: tuple, exact) -> dict:
    """The relative RMS of p = c0^2 drho at each probe over ``window`` (t0, t1) s (to the run's end; NaN before
    it), ``probe_<name>``, over all probes together, ``probe_rms``, and the largest error, ``probe_max``.
    ``exact(names, t)``: the exact drho at those probes and times, an array (len(names), len(t)), kg/m^3. A
    probe the sound has not reached (its reference below 1e-6 of the pulse's amplitude) has none (NaN)."""
    import numpy as np

    t = np.asarray(probes["t"], dtype=np.float64)
    inside = (t >= window[0] - 1e-9) & (t <= window[1] + 1e-9)
    names = [k for k in probes if k != "t"]
    nan = float("nan")
    if inside.sum() < 2 or not names:
        return {"probe_rms": nan, "probe_max": nan, **{f"probe_{k}": nan for k in names}}
    out, num, den, worst = {}, 0.0, 0.0, 0.0
    for name, ref in zip(names, exact(names, t[inside])):
        d = np.asarray(probes[name], dtype=np.float64)[inside] - ref
        quiet = np.sqrt(np.mean(ref**2)) < 1e-6 * scene.rho0 * scene.mach  # no sound there yet
        out[f"probe_{name}"] = nan if quiet else float(np.sqrt(np.sum(d**2) / np.sum(ref**2)))
        num, den = num + float(np.sum(d**2)), den + float(np.sum(ref**2))
        worst = max(worst, float(np.max(np.abs(d))))
    out["probe_rms"] = float(np.sqrt(num / den)) if np.isfinite(num) and den > 0 else nan
    out["probe_max"] = worst if np.isfinite(num) else nan
    return out


PLANE_MOST = 64  # sites a side of a stored plane at most (every k-th site beyond: about 50 kB a record)


def plane_z(fields, dx: float, z0: float, most: int = PLANE_MOST) -> dict:
    """drho on the lattice plane nearest ``z0`` (m) of 3D ``fields``, every k-th site along x and y so that at most
    ``most`` are kept a side: {"z": the plane's z, "t", "x0", "y0": its first site, m, "step": the kept sites'
    spacing, m, "drho": rows along y of drho along x, kg/m^3, 6 significant digits}; {} without a third axis or
    sites there. The report's z = 0 slice (pcabench/studies/three_d/section.py)."""
    import numpy as np

    z = getattr(fields, "z", None)
    if z is None or len(z) == 0:
        return {}
    x, y, z = (np.asarray(a, dtype=np.float64) for a in (fields.x, fields.y, z))
    zs = np.round((z - z.min()) / dx)  # each lattice plane's index
    nearest = zs[np.argmin(np.abs(z - z0))]
    on = zs == nearest
    if not on.any():
        return {}
    ix = np.round((x[on] - x[on].min()) / dx).astype(np.int64)
    iy = np.round((y[on] - y[on].min()) / dx).astype(np.int64)
    grid = np.full((iy.max() + 1, ix.max() + 1), np.nan)
    grid[iy, ix] = np.asarray(fields.drho, dtype=np.float64)[on]
    k = max(1, -(-max(grid.shape) // most))
    kept = grid[::k, ::k]
    return {
        "z": float(np.mean(z[on])),
        "t": float(fields.t),
        "x0": float(x[on].min()),
        "y0": float(y[on].min()),
        "step": float(k * dx),
        "drho": [[float(f"{v:.6g}") if np.isfinite(v) else None for v in row] for row in kept],
    }


class NoPrediction(ValueError):
    """A scene kind with no prediction of its errors (``accuracy`` and ``advise`` refuse it in one line)."""


class SceneKind:
    """Base class of the scene kinds: a problem with an exact reference. Subclasses set ``name``."""

    name: str = ""
    summary: str = ""
    dims: int = 2  # the dimension of its space: 2, or 3 (z_min, z_max, a z lattice coordinate and velocity)
    periodic: tuple = ("y",)
    walls: tuple = ()  # the x edges that are rigid walls: "x_min", "x_max" (the others free, or periodic)
    domain: dict = {}  # {x_min, x_max, y_min, y_max}: where the kind's default domain differs from Scene's
    defaults: dict = {}  # the kind's other defaults where they differ from Scene's (solvers.scene.PER_KIND, open)
    body: bool = False  # whether the scene holds a rigid body (body_of), modelled by a boundary method
    fields: tuple = ("u",)
    primary: str = "u"
    has_isothermal: bool = False  # scored against the isothermal solution too (the lagrangian model's physics)
    strip: bool = False  # whether a y-periodic strip gives the same answer (the fields do not depend on y)
    t_end: float = 10.0  # s: the physical time ``accuracy`` and ``advise`` ask about when --t-end is not given

    # the periodic axes whose seams are the images of an open problem (a square of images), so that an open
    # edge there gives the open problem itself; a strip's y is a slice of a plane wave and stays periodic
    images: tuple = ()

    # Where every solver is checked on this kind (Scene fields over the kind's defaults), so that a new kind is
    # checked everywhere without a list to edit: ``smallest``, a few hundred particles with its boundaries acting
    # from the first step, for the conformance suite (pcabench/conformance.py) and the GPU check's rehearsal;
    # ``smallest_open`` the same with open edges (None: none to open); ``card`` and ``card_open`` the GPU check's
    # comparison of the GPU solver with the CPU one on a card (the walls, open-edges and cylinder studies' gpu.py).
    smallest: dict = {"dx": 1.0}
    smallest_open: dict | None = None
    card: dict = {"dx": 0.5}
    card_open: dict | None = None

    def boundaries(self, scene=None) -> frozenset:
        """The boundary kinds this scene needs of a solver (with ``scene``'s open edges, which are free edges
        of the lattice beyond the layer)."""
        open_edges = scene.open if scene is not None else ""
        if "x" in self.periodic and "x" not in open_edges:
            x = {"periodic-x"}
        else:
            x = {"wall-x"} if self.walls else set()
            if len(self.walls) < 2:
                x.add("free-x")
        periodic_y = "y" in self.periodic and "y" not in open_edges
        z = set() if self.dims == 2 else {"periodic-z" if "z" in self.periodic and "z" not in open_edges else "free-z"}
        return frozenset(x | {"periodic-y" if periodic_y else "free-y"} | z | ({"body"} if self.body else set()))

    def headline(self, t_end: float) -> str:
        """What the headline error (``mse``) of a run to ``t_end`` (s) measures, in words."""
        return f"relative RMS error of {self.primary} at t = {t_end:.4g} s"

    def pulse_inside(self, scene, t: float) -> bool:
        """Whether the whole pulse (its peaks and :data:`PULSE_REACH` widths about them) is still inside the scored
        domain at ``t`` (s), so that an error against the exact solution measures the run: always by default (walls
        and periodic seams keep the sound in); a kind whose pulse leaves (by an open edge, or the plane pulse's free
        end) says when it reaches the edge."""
        return True

    def measure(self, scene, t: float) -> str:
        """The name of the headline measure of a run of ``scene`` to ``t`` (s), the one error that means
        something at that time: ``rms_<primary>`` (the record's ``mse``: the relative RMS error of the primary field
        against the exact solution) while the pulse is inside the scored domain; once it has reached an edge it
        leaves by, ``left_energy`` (the error's acoustic energy over the initial pulse's: what the edges sent back
        and the method left behind; :func:`left_behind`)."""
        if not self.pulse_inside(scene, t):
            return "left_energy"
        return f"rms_{self.primary}"

    def measure_words(self, name: str, t: float) -> str:
        """What the headline measure ``name`` (:meth:`measure`) of a run to ``t`` (s) is, in words."""
        if name == "left_energy":
            return f"energy of the error left in the domain at t = {t:.4g} s over the pulse's (the pulse has left)"
        return self.headline(t)

    @staticmethod
    def measure_value(name: str, mse, errors: dict):
        """The value of the headline measure ``name`` among a run's ``mse`` and its other ``errors`` (None where
        the run did not measure it)."""
        return mse if name.startswith(("rms_", "probes_")) else errors.get(name)

    def probe_points(self, scene) -> dict:
        """{name: (x, y)} (m) where every run of this kind records drho: none by default (``--probe`` adds)."""
        return {}

    def probe_errors(self, scene, probes) -> dict:
        """Error measures of the probes' readings ``probes`` ({"t": times, name: drho, ...}) against the exact
        solution: none by default."""
        return {}

    def body_of(self, scene) -> tuple:
        """(x0, y0, radius) of the body, m (a kind with ``body``)."""
        raise NotImplementedError

    def tiny(self, scene):
        """A few hundred particles of this kind with ``scene``'s method, for the JIT warm-up (None: the
        interface's generic tiny scene)."""
        return None

    def openable_edges(self) -> tuple:
        """The axes whose edges ``--open`` may open: free x edges without walls, and periodic axes whose seams
        are images (``images``)."""
        if self.walls:
            return tuple(axis for axis in ("y",) if axis in self.images)
        free_x = "x" not in self.periodic
        axes = ("x", "y", "z")[: self.dims]
        return tuple(axis for axis in axes if (axis == "x" and free_x) or axis in self.images)

    def closed_reason(self, axis: str) -> str:
        """Why the ``axis`` edges of this scene cannot be opened, one clause."""
        if axis == "x" and self.walls:
            return f"the x edge {', '.join(self.walls)} of {self.name} is a wall"
        if axis in self.periodic:
            what = (
                "its exact reference is a plane wave's" if self.strip else "its exact reference is the periodic images'"
            )
            return f"the {axis} edges of {self.name} are periodic by the scene's nature ({what})"
        return f"the {axis} edges of {self.name} cannot be opened"

    def check(self, scene) -> list[str]:
        """Problems with ``scene``'s parameters for this kind, one line each naming the option and range."""
        out = []
        lo, hi = MACH_RANGE
        if not lo <= scene.mach <= hi:
            out.append(f"--mach must be in [{lo:g}, {hi:g}] (got {scene.mach:g})")
        lo, hi = PULSE_WIDTH_RANGE
        if not lo <= scene.pulse_width <= hi:
            out.append(f"--pulse-width must be in [{lo:g}, {hi:g}] m (got {scene.pulse_width:g})")
        if not scene.x_min <= scene.pulse_center <= scene.x_max:
            out.append(
                f"--pulse-center must be inside the domain, in [{scene.x_min:g}, {scene.x_max:g}] m "
                f"(got {scene.pulse_center:g})"
            )
        if scene.strip_height is not None and not self.strip:
            out.append(f"--strip-height: the {self.name} scene depends on y, a strip would change it")
        return out

    def initial_fields(self, scene, x, y, xp):
        """(u, v, drho) at the lattice positions ``x``, ``y`` (m, float64 arrays of module ``xp``) at t = 0."""
        raise NotImplementedError

    def errors(self, scene, fields) -> dict:
        """Error measures of ``fields`` (solvers.interface.Fields) against the exact linear solution:
        ``mse`` (relative RMS of the primary field) and ``me`` (its max error) at least."""
        raise NotImplementedError

    def isothermal_errors(self, scene, fields) -> float | None:
        """Relative RMS error of the primary field against the isothermal (nonlinear) solution, or None."""
        return None

    def exact_fields(self, scene, t: float):
        """The exact linear solution on the scene's lattice at ``t`` as solvers.interface.Fields."""
        raise NotImplementedError

    def linear_floor(self, scene) -> float | None:
        """The `linear` model's error against the isothermal physics as dx -> 0, at the scene's amplitude and
        end: the relative RMS distance between the exact linear and the isothermal solutions (None where the
        scene has no isothermal reference)."""
        if not self.has_isothermal:
            return None
        return self.isothermal_errors(scene, self.exact_fields(scene, scene.t_final))

    def predict(self, scene):
        """The linear model's predicted errors from the dispersion relation (solvers/reference/dispersion.py);
        NoPrediction where the kind has none."""
        raise NoPrediction(f"the {self.name} scene has no prediction from the dispersion relation")

    def predicted_stable_cfl(self, scene) -> float | None:
        """The largest stable CFL of ``scene``'s method where this kind's lattice is not the square one (a 3D
        kind's cube); None: the square lattice's (solvers/reference/dispersion.py ``predicted_stable_cfl``). A
        plug-in kind written before the name (its ``stable_cfl``) is asked by that."""
        legacy = getattr(self, "stable_cfl", None)
        return legacy(scene) if callable(legacy) else None

    def predict_headline(self, scene):
        """:meth:`predict` where only its headline error is wanted (advise's search): a kind may skip the rest."""
        return self.predict(scene)

    def mirror_extension(self, scene, u, v, drho) -> tuple:
        """(u, v, drho, keep): the initial fields (arrays with x the last axis) on the lattice whose periodic
        solution is this scene's, and the slice of its columns that is the scene's lattice. With rigid walls,
        the even extension across them: the mirror image beside the fields, the normal velocity reversed (with
        walls at both x edges the doubled lattice is periodic: its seam is the other wall); without, the
        fields themselves (the prediction's lattice, solvers/reference/dispersion.py)."""
        import numpy as np

        nx = u.shape[-1]
        if not self.walls:
            return u, v, drho, slice(0, nx)
        images = (-u[..., ::-1], v[..., ::-1], drho[..., ::-1])
        if "x_max" in self.walls:
            out = [np.concatenate((a, b), axis=-1) for a, b in zip((u, v, drho), images)]
            return (*out, slice(0, nx))
        out = [np.concatenate((b, a), axis=-1) for a, b in zip((u, v, drho), images)]
        return (*out, slice(nx, 2 * nx))

    def sized_domain(self, size: float) -> dict:
        """The domain of side ``size`` (m) for ``--domain-size``; ValueError where the kind's domain is fixed."""
        raise ValueError(f"--domain-size: the {self.name} scene's domain is fixed (it applies to square scenes)")

    def breaking_time(self, scene) -> float:
        """When the pulse steepens into a shock under the isothermal equations, s (inf: never)."""
        return math.inf
