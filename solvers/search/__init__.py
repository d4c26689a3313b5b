"""The neighbour search: the paper's cell list (in 3D also one cell a site for particles that stay on their
sites), the CPU pair list and its stream compaction."""
