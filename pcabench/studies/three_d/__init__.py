"""Sound in three dimensions (``pcabench study --three-d``): the 3D pulse's error against dx with the standard and
the high-order methods, and what a pair costs in 3D against 2D."""
