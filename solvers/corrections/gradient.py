"""The kernel gradient correction (Bonet & Lok 1999; Randles & Libersky 1996), in its energy-keeping form.

The corrected gradient of a field f at particle i is

    grad f_i = L_i sum_j V_j (f_j - f_i) grad_i W_ij,   L_i = M_i^-1,   M_i = sum_j V_j (x_j - x_i) (x) grad_i W_ij

(M is symmetric, grad_i W_ij being G_ij r_ij): exact for linear fields, so the phase-speed error a kernel
keeps at fixed h/dx (its lattice moment's departure from 1) is gone and the operator is second order, fourth
with the Laguerre-Gauss kernel at h >= 1.5 dx cut at 4 h (design.md, 1c). In the lattice's interior L_i is the
scalar 1 / M_xx, so the dispersion prediction is the standard symbol divided by its long-wave slope.

The momentum equation takes that gradient of p = c0^2 drho: du_i/dt = -L_i (grad p)_i / rho_i. The
continuity equation takes its negative adjoint in the volume-weighted inner product,

    d(drho_i)/dt = -rho_i sum_j V_j (L_i u_i + L_j u_j) . grad_i W_ij,

so that for fixed particles the linear system keeps the discrete energy sum_i V_i (rho0 |u_i|^2 +
c0^2 drho_i^2 / rho0) / 2 exactly in time-continuous form: the pair of operators is skew-adjoint, whatever
L_i does near a wall, a body or the lattice's edge (the corrected gradient in both equations, the other
choice, is not: where L_i varies it has growing modes). Both sums are the solver's own sweeps: with
Gamma_i = sum_j V_j grad_i W_ij,

    sum_j V_j (f_j - f_i) grad_i W_ij = sum_j V_j (f_i + f_j) grad_i W_ij - 2 f_i Gamma_i   (the momentum sweep)
    sum_j V_j (w_i + w_j) . grad_i W_ij = -sum_j V_j (w_i - w_j) . grad_i W_ij + 2 w_i . Gamma_i   (continuity)

with w = L u, so the correction is the standard sweeps over other arrays plus one pass per particle. M and
Gamma come from one more sweep (``Solver.moments``): once per run for particles that stay on their sites
(linear, fixed), at each search for moving ones (with the CPU pair list, a stream over its listed factors and
the positions, no kernel evaluation: solvers/loops/pairlist.py). A fluid particle whose M is singular or
near it (too few neighbours: h below the lattice, an isolated particle near a body or a layer) fails the run
at that step, naming where.
"""

from __future__ import annotations

import math

import numpy as np

from solvers.corrections.base import Correction, SingularMoments

SMALLEST_MOMENT = 0.05  # the smallest eigenvalue of M a fluid particle may have (1 in the lattice's interior)


class GradientCorrection(Correction):
    """L_i (the inverse moment matrix) on the momentum gradient, its negative adjoint in continuity."""

    name = "gradient"
    summary = "kernel gradient correction (Bonet & Lok): exact for linear fields, energy-keeping form"
    arrays = 14  # M's inverse (3), Gamma (2), w (2), and the moments sweep's and inversion's temporaries
    moments = True  # M and Gamma, at every search where particles move
    allocates = True  # its per-particle passes make their arrays inside the step
    arrays_3d = 24  # in 3D: M's inverse (6), Gamma (3), w (3), and the temporaries

    def coefficients(self, continuity: bool, momentum: bool) -> tuple:
        """Both sweeps need the volumes (momentum sums drho itself, c0^2 after)."""
        return True, False

    def sweep(self, solver, continuity: bool, momentum: bool) -> None:
        if solver.scene.dims == 3:
            return self.sweep_3d(solver, continuity, momentum)
        a, k = solver.arrays, solver.k
        lxx, lxy, lyy, gx, gy = self.factors(solver)
        wx, wy = self.scratch(solver)
        if continuity:
            solver.launch("corrected_velocity", a["u"], a["v"], lxx, lxy, lyy, wx, wy)
            with solver.swapped(u=wx, v=wy):
                solver._sweep(True, False)
                if solver.split:
                    solver.continuity_parts()
            # the x part: w's x terms (in the interior, L u_x's); without a split absorber an array never written (the
            # same array twice is two copies in numba's CUDA simulator, the second written back last)
            ddx = a["ddx"] if solver.split else self.unused(solver)
            solver.launch("corrected_continuity", a["dd"], ddx, a["drho"], wx, wy, gx, gy, solver.split, k)
        if momentum:  # the sweep sums drho; c0^2 (p = c0^2 drho) comes in the pass after
            with solver.swapped(mass=a["vol"], pr=a["drho"]):
                solver._sweep(False, True)
            solver.launch("corrected_momentum", a["ax"], a["ay"], a["drho"], lxx, lxy, lyy, gx, gy, k)

    def sweep_3d(self, solver, continuity: bool, momentum: bool) -> None:
        """:meth:`sweep` in 3D: L (six components) and Gamma (three) from :meth:`factors_3d`; a split absorber's
        parts of the rate each w's own component's terms (the sweep's and the pass's, the others zero)."""
        a, k = solver.arrays, solver.k
        lxx, lxy, lxz, lyy, lyz, lzz, gx, gy, gz = factors = self.factors_3d(solver)
        wx, wy, wz = self.scratch(solver, 3)
        if continuity:
            solver.launch("corrected_velocity", a["u"], a["v"], a["w"], *factors[:6], wx, wy, wz)
            with solver.swapped(u=wx, v=wy, w=wz):
                solver._sweep(True, False)
                if solver.split:
                    solver.continuity_parts()
            solver.launch("corrected_continuity", a["dd"], a["drho"], wx, wy, wz, gx, gy, gz, k)
            for axis, rate in enumerate(solver.layer.rates if solver.split else ()):
                w = tuple(c if i == axis else solver.no_velocity for i, c in enumerate((wx, wy, wz)))
                solver.launch("corrected_continuity", a[rate], a["drho"], *w, gx, gy, gz, k)
        if momentum:
            with solver.swapped(mass=a["vol"], pr=a["drho"]):
                solver._sweep(False, True)
            solver.launch("corrected_momentum", a["ax"], a["ay"], a["az"], a["drho"], *factors, k)

    def factors_3d(self, solver) -> tuple:
        """(L_xx, L_xy, L_xz, L_yy, L_yz, L_zz, Gamma_x, Gamma_y, Gamma_z) at the current positions, kept as in 2D
        (:meth:`factors`): L = M^-1 by its adjugate, M's smallest eigenvalue checked first."""
        key = (solver.reordered, solver.moves)
        kept = getattr(solver, "correction_factors", None)
        if kept is not None and kept[0] == key:
            return kept[1]
        solver.correction_factors = None
        xx, xy, xz, yy, yz, zz, gx, gy, gz = solver.moments()
        xp = solver.xp
        m = xp.stack([xp.stack([xx, xy, xz], -1), xp.stack([xy, yy, yz], -1), xp.stack([xz, yz, zz], -1)], -2)
        smallest = xp.linalg.eigvalsh(m.astype(xp.float64))[:, 0]
        del m
        bad = ~(smallest >= SMALLEST_MOMENT)
        body = solver.arrays["role"] != 0 if "role" in solver.arrays else None
        fluid_bad = bad & ~body if body is not None else bad
        if bool(fluid_bad.any()):
            self.refuse(solver, int(xp.argmax(fluid_bad)), float(smallest[int(xp.argmax(fluid_bad))]))
        if body is not None:  # a body's inert particles lend nothing: where their M is poor, no correction
            one, zero = solver.dtype.type(1.0), solver.dtype.type(0.0)
            for arr, value in ((xx, one), (xy, zero), (xz, zero), (yy, one), (yz, zero), (zz, one)):
                arr[bad] = value
        cxx, cxy, cxz = yy * zz - yz * yz, xz * yz - xy * zz, xy * yz - xz * yy  # the adjugate's (symmetric)
        cyy, cyz, czz = xx * zz - xz * xz, xy * xz - xx * yz, xx * yy - xy * xy
        det = xx * cxx + xy * cxy + xz * cxz
        factors = (cxx / det, cxy / det, cxz / det, cyy / det, cyz / det, czz / det, gx, gy, gz)
        solver.correction_factors = (key, factors)
        return factors

    def unused(self, solver):
        """A one-element array of the solver's type: the x part's slot where there is none."""
        kept = getattr(solver, "correction_unused", None)
        if kept is None or kept.dtype != solver.dtype:
            kept = solver.xp.zeros(1, solver.dtype)
            solver.correction_unused = kept
        return kept

    def scratch(self, solver, count: int = 2) -> tuple:
        """(w_x, w_y) (and w_z: ``count`` 3): what the corrected continuity sweep sums, made anew from the state at
        every PI (so never reordered), kept from one PI to the next."""
        kept = getattr(solver, "correction_scratch", None)
        n = solver.scene.n_particles
        if kept is None or len(kept) != count or kept[0].shape[0] != n or kept[0].dtype != solver.dtype:
            kept = tuple(solver.xp.zeros(n, solver.dtype) for _ in range(count))
            solver.correction_scratch = kept
        return kept

    def factors(self, solver) -> tuple:
        """(L_xx, L_xy, L_yy, Gamma_x, Gamma_y) at the current positions: computed when the particles have moved
        or been put in a new order since (``Solver.reordered``, ``Solver.moves``), else kept."""
        key = (solver.reordered, solver.moves)
        kept = getattr(solver, "correction_factors", None)
        if kept is not None and kept[0] == key:
            return kept[1]
        solver.correction_factors = None  # the old factors go before the new are made (the memory's peak)
        mxx, mxy, myy, gx, gy = solver.moments()
        xp = solver.xp
        smallest = 0.5 * (mxx + myy) - xp.sqrt((0.5 * (mxx - myy)) ** 2 + mxy * mxy)
        bad = ~(smallest >= SMALLEST_MOMENT)  # NaN too
        ghost = solver.arrays["role"] != 0 if "role" in solver.arrays else None
        fluid_bad = bad & ~ghost if ghost is not None else bad
        if bool(fluid_bad.any()):
            self.refuse(solver, int(xp.argmax(fluid_bad)), float(smallest[int(xp.argmax(fluid_bad))]))
        if ghost is not None:  # a body's ghosts only lend their values: where their M is poor, no correction
            one, zero = solver.dtype.type(1.0), solver.dtype.type(0.0)
            for arr, value in ((mxx, one), (mxy, zero), (myy, one)):
                arr[bad] = value
        del smallest, bad, ghost, fluid_bad
        det = mxx * myy
        det -= mxy * mxy
        lxx = myy / det  # then L in place of M: L_yy in M_xx's array, L_xy in M_xy's
        lyy = xp.divide(mxx, det, out=mxx)
        lxy = xp.divide(mxy, det, out=mxy)
        lxy *= solver.dtype.type(-1.0)
        factors = (lxx, lxy, lyy, gx, gy)
        solver.correction_factors = (key, factors)
        return factors

    def refuse(self, solver, i: int, smallest: float) -> None:
        s, a = solver.scene, solver.arrays
        x = s.x_lo + (float(a["lx"][i]) + 0.5) * s.dx + float(a["sx"][i])
        y = s.y_lo + (float(a["ly"][i]) + 0.5) * s.dx + float(a["sy"][i])
        z = f", {s.z_lo + (float(a['lz'][i]) + 0.5) * s.dx + float(a['sz'][i]):.6g}" if s.dims == 3 else ""
        raise SingularMoments(
            f"--correction gradient: the particle at ({x:.6g}, {y:.6g}{z}) m has a moment matrix with smallest "
            f"eigenvalue {smallest:.3g} (at least {SMALLEST_MOMENT:g}; 1 inside the lattice): too few neighbours "
            f"within the cutoff ({s.cutoff / s.dx:.3g} dx at h = {s.h_factor:g} dx) to correct its gradient"
        )

    def lattice_factor(self, scene) -> float:
        """1 / M_xx of a particle inside the lattice (square in 2D, cubic in 3D, by the scene's dimension): the
        symbol's long-wave slope divided out (D(k) / D'(0)); M_xx = -dx^d sum_j G(r_j) x_j^2 over the lattice
        neighbours within the cutoff."""
        reach = int(math.ceil(scene.cutoff / scene.dx))
        offsets = np.arange(-reach, reach + 1, dtype=np.float64) * scene.dx
        axes = np.meshgrid(*(offsets,) * scene.dims, indexing="ij")
        r = np.hypot(*axes) if scene.dims == 2 else np.sqrt(sum(a * a for a in axes))
        keep = (r < scene.cutoff) & (r > 0)
        dims = {"dims": 3} if scene.dims == 3 else {}  # a 2D-only kernel takes no dims
        g = scene.sph_kernel.gradient(r[keep], scene.h, **dims)
        moment = -(scene.dx**scene.dims) * float((g * axes[0][keep] ** 2).sum())
        return 1.0 / moment if math.isfinite(moment) and moment > 0 else 1.0
