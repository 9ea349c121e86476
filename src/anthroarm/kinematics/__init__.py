"""Kinematics: the book's printed forward-kinematics forms (:mod:`.book_fk`), the H-D chain
(:mod:`.dh`), the batched FK/Jacobian of any robot (:mod:`.batched`), §6-6 error propagation
(:mod:`.error_propagation`) and their ``anthroarm check`` rows (:mod:`.checks`)."""
