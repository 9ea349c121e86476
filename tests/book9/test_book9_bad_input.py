"""Bad input to the knee, the vector loop and the inertia-force functions: ParameterErrors (a
ValueError) naming what is wrong, never a raw numpy/LinAlg/Index error, never unbounded work."""

import numpy as np
import pytest

import anthroarm as aa
from anthroarm.dynamics import inertia_forces as inf
from anthroarm.errors import ParameterError
from anthroarm.kinematics import vector_loop as vl
from anthroarm.mechanisms import knee as kn
from anthroarm.models.templates import tensor6r_loop


@pytest.fixture(scope="module")
def loop():
    return tensor6r_loop()[0]


def test_icr_path_sample_count_is_bounded():
    # n = 1e9 allocated tens of GB (the process was OOM-killed); now refused at once
    with pytest.raises(ParameterError, match="n must be an integer"):
        kn.icr_path(kn.default_knee(), n=10**9)
    with pytest.raises(ParameterError, match="n must be an integer"):
        kn.icr_path(kn.default_knee(), n=10.0)


def test_knee_flexion_of_nothing_is_refused():
    with pytest.raises(ParameterError, match="non-empty"):
        kn.knee_flexion(kn.default_knee(), [])


def test_inertia_force_bad_mass_and_vectors():
    for m in ("x", np.nan, -1.0, None):
        with pytest.raises(ParameterError, match="mass"):
            inf.inertia_force(m, [0.0, 0.0, 0.0])
    with pytest.raises(ParameterError, match="p1"):
        inf.joint_frame("abc", [0.0, 1.0, 0.0])


def test_oblique_decomposition_on_dependent_axes_is_refused():
    axes = np.column_stack([[1.0, 0, 0], [0, 1.0, 0], [1.0, 1.0, 0]])  # p3 in the plane of p1, p2
    for fn in (inf.oblique_components, inf.oblique_components_printed):
        with pytest.raises(ParameterError, match="not independent"):
            fn([1.0, 2.0, 3.0], axes)


def test_vector_loop_bad_input(loop):
    with pytest.raises(ParameterError, match="q must be 6"):
        vl.nested_pose(loop, "abcdef")
    with pytest.raises(ParameterError, match="G must be 3"):
        vl.VectorLoop((("R", (1.0, 0, 0)),), G="abc")
    with pytest.raises(ParameterError, match="no joint"):
        vl.loop_spec(vl.VectorLoop((("C", (1.0, 0, 0)),), G=(0, 0, 0)))
    with pytest.raises(ParameterError, match="one \\(lower, upper\\) per joint"):
        vl.loop_spec(loop, limits=[(0.0, 1.0)])


def test_dalembert_wrong_velocity_shape():
    r = aa.load("care_robot")
    with pytest.raises(ParameterError, match="v must be"):
        inf.dalembert_torques(r, np.zeros(6), np.zeros(5), np.zeros(6))
