"""Closed-form kinematics of the book's arms, vectorised over batches of configurations."""
