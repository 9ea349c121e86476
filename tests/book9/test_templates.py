"""Table 2.3 motion forms as catalog generators, Table 2.4 as data.  Oracles: the coordinates
of each form (mathematics) against Pinocchio FK, workspace extents from the strokes, and the
printed table cells."""

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import anthroarm as aa
from anthroarm.errors import ParameterError
from anthroarm.models import book_tables
from anthroarm.models.templates import TEMPLATES

REPO = Path(__file__).resolve().parents[2]
RNG = np.random.default_rng(7)


def tool_positions(name, n=200, **params):
    r = aa.load(name, **params) if params else aa.load(name)
    Q = r.random_q(n, RNG)
    return r, Q, r.fk(Q)[:, :3, 3]


def test_templates_are_in_the_catalog_in_table_order():
    assert [f.form for f in book_tables.robot_forms()] == [
        "cartesian",
        "cylindrical",
        "spherical",
        "articulated",
    ]
    assert list(TEMPLATES) == [f"{f.form}_robot" for f in book_tables.robot_forms()]
    assert set(TEMPLATES) <= set(aa.models.names())


@pytest.mark.parametrize("name", list(TEMPLATES))
def test_committed_urdf(name):
    assert (REPO / "urdf" / f"{name}.urdf").read_text() == aa.models.urdf_text(name)


def test_cartesian_is_a_translation_by_q():
    r, Q, p = tool_positions("cartesian_robot")
    np.testing.assert_allclose(p, np.array([0.3, 0.0, 0.5]) + Q, atol=1e-14)
    assert (r.fk(Q)[:, :3, :3] == np.eye(3)).all()


def test_cylindrical_coordinates():
    r, Q, p = tool_positions("cylindrical_robot")
    np.testing.assert_allclose(np.arctan2(p[:, 1], p[:, 0]), Q[:, 0], atol=1e-12)
    np.testing.assert_allclose(np.hypot(p[:, 0], p[:, 1]), Q[:, 2], atol=1e-12)
    np.testing.assert_allclose(p[:, 2], 0.3 + Q[:, 1], atol=1e-12)


def test_spherical_coordinates_about_the_shoulder():
    r, Q, p = tool_positions("spherical_robot")
    d = p - np.array([0, 0, 0.8])
    np.testing.assert_allclose(np.linalg.norm(d, axis=1), Q[:, 2], atol=1e-12)
    np.testing.assert_allclose(np.arcsin(d[:, 2] / Q[:, 2]), Q[:, 1], atol=1e-12)
    np.testing.assert_allclose(np.arctan2(d[:, 1], d[:, 0]), Q[:, 0], atol=1e-12)
    # Table 2.3 remark "能提取地面上的物体" (can pick objects off the floor): boom down 45° at full
    # reach puts the tool 0.8 - 1.0 sin 45° = 0.093 m above the base plane
    low = r.fk(np.array([0.0, r.lower[1], r.upper[2]]))[:3, 3]
    assert low[2] == pytest.approx(0.8 - np.sin(np.pi / 4), abs=1e-12) and low[2] < 0.1


def test_articulated_two_link_formula():
    r, Q, p = tool_positions("articulated_robot")
    q1, q2, q3 = Q.T
    rad = 0.5 * np.cos(q2) + 0.5 * np.cos(q2 + q3)
    np.testing.assert_allclose(p[:, 0], rad * np.cos(q1), atol=1e-12)
    np.testing.assert_allclose(p[:, 1], rad * np.sin(q1), atol=1e-12)
    np.testing.assert_allclose(p[:, 2], 0.5 + 0.5 * np.sin(q2) + 0.5 * np.sin(q2 + q3), atol=1e-12)


def test_parameters_change_the_model():
    r = aa.load("articulated_robot", l2=0.3, l3=0.2, h0=0.1)
    np.testing.assert_allclose(r.fk(np.zeros(3))[:3, 3], [0.5, 0, 0.1], atol=1e-14)
    r = aa.load("cylindrical_robot", reach=(0.2, 0.4))
    np.testing.assert_allclose([r.lower[2], r.upper[2]], [0.2, 0.4])


@pytest.mark.parametrize(
    "name,params,match",
    [
        ("cylindrical_robot", {"reach": (1.0, 0.5)}, "reach"),
        ("cylindrical_robot", {"reach": (-0.1, 0.5)}, "reach"),
        ("spherical_robot", {"elevation": (-2.0, 1.0)}, "elevation"),
        ("articulated_robot", {"l2": 0.0}, "l2"),
        ("articulated_robot", {"l3": float("nan")}, "l3"),
        ("cartesian_robot", {"x_stroke": (0, float("inf"))}, "x_stroke"),
        ("cartesian_robot", {"h0": -1}, "h0"),
        ("spherical_robot", {"base": "wide"}, "base"),
        ("articulated_robot", {"l2": 1e300}, "l2"),  # was an 'inf' link mass blamed on the URDF
        ("cylindrical_robot", {"reach": (0.0, 1e300)}, "reach"),
    ],
)
def test_parameters_out_of_range_are_typed(name, params, match):
    with pytest.raises(ParameterError, match=match):
        aa.models.spec(name, **params)


def test_crba_positive_definite_and_mass():
    for name in TEMPLATES:
        r = aa.load(name)
        q = r.random_q(None, RNG)
        M = pin.crba(r.model, r.model.createData(), q)
        assert np.linalg.eigvalsh(0.5 * (M + M.T)).min() > 0


# ---------------------------------------------------------------- Table 2.4 and 2.3 data


def test_table_2_4_as_printed():
    rows = book_tables.lower_limb_rom()
    got = [(r.joint, r.motion, r.range_deg) for r in rows]
    assert got == [
        ("hip", "flexion", 120.0),
        ("hip", "extension", 30.0),
        ("hip", "internal_external_rotation", 45.0),
        ("knee", "flexion", 120.0),
        ("knee", "extension", None),
        ("ankle", "dorsiflexion", 45.0),
        ("ankle", "plantarflexion", 45.0),
    ]
    assert rows[0].joint_zh == "股关节" and rows[0].printed == "约 120°"
    lim = book_tables.lower_limb_limits()
    np.testing.assert_allclose(np.degrees(lim["hip_flexion"]), [-30, 120])
    np.testing.assert_allclose(np.degrees(lim["knee_flexion"]), [0, 120])
    np.testing.assert_allclose(np.degrees(lim["ankle_flexion"]), [-45, 45])
    np.testing.assert_allclose(np.degrees(lim["hip_rotation"]), [-45, 45])


def test_table_2_3_as_printed():
    f = {r.form: r for r in book_tables.robot_forms()}
    assert [
        f[k].workspace_shape_zh for k in ("cartesian", "cylindrical", "spherical", "articulated")
    ] == ["立方体", "圆柱体", "球体", "球多球体"]
    assert [f[k].footprint_zh for k in f] == ["大", "较小", "小", "最小"]
    assert [f[k].relative_workspace_zh for k in f] == ["小", "较大", "大", "最大"]
    assert [f[k].intuitiveness_zh for k in f] == ["强", "较强", "一般", "差"]
    assert [f[k].use_zh for k in f] == ["较多", "多", "较少", "少"]
    assert [f[k].remark_zh for k in f] == ["", "", "能提取地面上的物体", "能绕过障碍物进行工作"]
    assert [f[k].form_zh for k in f] == ["直角坐标式", "圆柱坐标式", "球坐标式", "多关节式"]
