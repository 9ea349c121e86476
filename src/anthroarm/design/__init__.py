"""Mechanism design (book Ch. 2-4): mobility, grasp error, motion curves, synthesis, optimisers."""
