"""Trajectories: via-point polynomials, gradual approach, resolved-rate motion (book Ch. 7)."""
