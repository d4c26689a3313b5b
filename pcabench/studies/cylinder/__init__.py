"""Sound around an object (``pcabench study --cylinder``): the CAA workshop's pulse scattered by a rigid
cylinder, each boundary method against the exact solution."""
