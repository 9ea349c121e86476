"""Dynamics (book Ch. 8): symbolic Lagrange equations, the book's formulations, simulation."""
