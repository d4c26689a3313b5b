"""The physics every solver shares: the SPH rates per pair, the integrators, their CPU compilation."""
