"""The neighbour search: the paper's cell list, the CPU pair list and its stream compaction."""
