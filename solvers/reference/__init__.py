"""What runs are scored against: the exact and reference solutions, and the dispersion prediction."""
