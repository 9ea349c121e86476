"""Hypothesis strategies shared by the tests of anthroarm.spatial (random geometry)."""

import numpy as np
from hypothesis import strategies as st

angle = st.floats(-np.pi, np.pi, allow_nan=False)
small = st.floats(-2.0, 2.0, allow_nan=False)
rate = st.floats(-3.0, 3.0, allow_nan=False)
vec3 = st.tuples(small, small, small).map(np.array)
unit3 = (
    st.tuples(small, small, small)
    .filter(lambda v: np.linalg.norm(v) > 0.2)
    .map(lambda v: np.array(v) / np.linalg.norm(v))
)


@st.composite
def rotation(draw):
    import pinocchio as pin

    u = draw(unit3)
    return pin.exp3(draw(angle) * u)
