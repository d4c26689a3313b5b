"""The asv suite: speed and accuracy of the pcabench solvers across commits (see asv.conf.json)."""
