"""Sound in the open (``pcabench study --open``): what an open edge leaves behind, what its layer costs,
whether it is stable."""
