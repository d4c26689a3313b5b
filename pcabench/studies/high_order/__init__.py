"""High-order SPH (``pcabench study --high-order``): the kernel gradient correction, the fourth-order
Laguerre-Gauss kernel and RK4 against standard SPH."""
