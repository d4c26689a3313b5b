"""Speed against accuracy (``pcabench study --front``): time to solution against error at t = 10 s, the fronts
of the fastest methods, on the paper's scene and on every other scene kind (scenes.py)."""
