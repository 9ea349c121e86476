"""The one code generator: :mod:`.graph` (exact expression graph, differentiation, Python/numpy
and C emitters), used by the Lagrange dynamics and the generated FK of the closed-form IK."""
