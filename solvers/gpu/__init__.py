"""The GPU backend: the device (or numba's simulator), its kernels, the step as a CUDA graph."""
