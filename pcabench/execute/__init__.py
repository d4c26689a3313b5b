"""Running: the stage clock, one run, its child process, the sweep of many (forked warm, or on Dask)."""
