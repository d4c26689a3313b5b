"""asv across commits: the machine description asv records and its smoke run."""
