"""OpenSim models written for the tests: every joint type the import reads (Pin, Slider,
Universal, Gimbal, Planar, Weld, CustomJoint with a 6-coordinate free base), offset frames
with rotations, bodies with off-centre masses and products of inertia, a CustomJoint with
Linear (slope -0.5), Constant, Polynomial, Multiplier(SimmSpline) and NaturalCubicSpline axes,
a coordinate coupled by a SimmSpline coupler, a locked coordinate, markers; and, with
``walker=True``, a joint where one coordinate drives three rotations (Rajagopal's walker
knee).  OpenSim reads the same file: it is the oracle, the text only the input."""

from __future__ import annotations

import numpy as np


def _v(a) -> str:
    return " ".join(repr(float(x)) for x in a)


def _frame(name, parent, rng):
    return f"""<PhysicalOffsetFrame name="{name}">
<socket_parent>{parent}</socket_parent>
<translation>{_v(rng.uniform(-0.2, 0.2, 3))}</translation>
<orientation>{_v(rng.uniform(-0.7, 0.7, 3))}</orientation>
</PhysicalOffsetFrame>"""


def _coord(name, locked=False, default=0.0, lo=-1.2, hi=1.2):
    return f"""<Coordinate name="{name}"><default_value>{default}</default_value>
<range>{lo} {hi}</range><clamped>false</clamped><locked>{str(locked).lower()}</locked></Coordinate>"""


def _joint(kind, name, parent, child, coords, rng, extra=""):
    p = "/ground" if parent == "ground" else f"/bodyset/{parent}"
    return f"""<{kind} name="{name}">
<socket_parent_frame>{parent}_offset</socket_parent_frame>
<socket_child_frame>{child}_offset</socket_child_frame>
<coordinates>{"".join(coords)}</coordinates>
<frames>{_frame(parent + "_offset", p, rng)}{_frame(child + "_offset", "/bodyset/" + child, rng)}</frames>
{extra}</{kind}>"""


def _axis(name, coord, axis, function):
    return f"""<TransformAxis name="{name}"><coordinates>{coord}</coordinates>
<axis>{_v(axis)}</axis>{function}</TransformAxis>"""


def _spline(xs, ys, tag="SimmSpline", name=' name="function"'):
    return f"<{tag}{name}><x>{_v(xs)}</x><y>{_v(ys)}</y></{tag}>"


def _linear(a, b):
    return f'<LinearFunction name="function"><coefficients>{a} {b}</coefficients></LinearFunction>'


def _const(c):
    return f'<Constant name="function"><value>{c}</value></Constant>'


def model_text(walker: bool = False, seed: int = 7, const_first: bool = False) -> str:
    """The model's text; ``const_first=True`` puts a constant rotation (0.3 rad) before the
    moving 'twist' axis of the CustomJoint (``rotation2``), where Simbody's H ignores it."""
    rng = np.random.default_rng(seed)
    bodies = []
    for i in range(10):
        m = rng.uniform(0.5, 3.0)
        inertia = [0.1, 0.12, 0.09, 0.01, -0.005, 0.002]
        bodies.append(
            f"""<Body name="b{i}"><mass>{m}</mass><mass_center>{_v(rng.uniform(-0.1, 0.1, 3))}</mass_center>
<inertia>{_v(inertia)}</inertia></Body>"""
        )
    xs = np.linspace(-1.5, 1.5, 9)
    free = "".join(
        _axis(n, c, a, _linear(1, 0))
        for n, c, a in [
            ("rotation1", "free_rz", (0, 0, 1)),
            ("rotation2", "free_rx", (1, 0, 0)),
            ("rotation3", "free_ry", (0, 1, 0)),
            ("translation1", "free_tx", (1, 0, 0)),
            ("translation2", "free_ty", (0, 1, 0)),
            ("translation3", "free_tz", (0, 0, 1)),
        ]
    )
    const_rotation = 0.3
    if walker:
        rot = _axis("rotation2", "flex", (1, 0, 0), _spline(xs, 0.2 * np.sin(xs)))
        rot += _axis("rotation3", "flex", (0, 1, 0), _spline(xs, 0.1 * xs**2))
        custom_coords = [_coord("flex")]
    else:
        rot = _axis("rotation2", "twist", (0.1, 0.99, 0.05), _spline(xs, xs, "NaturalCubicSpline"))
        rot += _axis("rotation3", "", (1, 0, 0), _const(const_rotation))
        custom_coords = [_coord("flex"), _coord("twist")]
        if const_first:
            rot = _axis("rotation2", "", (1, 0, 0), _const(const_rotation))
            rot += _axis(
                "rotation3", "twist", (0.1, 0.99, 0.05), _spline(xs, xs, "NaturalCubicSpline")
            )
    custom = (
        _axis("rotation1", "flex", (0.2, 0.1, 0.97), _linear(-0.5, 0.1))
        + rot
        + _axis(
            "translation1",
            "flex",
            (1, 0, 0),
            '<PolynomialFunction name="function"><coefficients>0.01 -0.02 0.03 0.05'
            "</coefficients></PolynomialFunction>",
        )
        + _axis(
            "translation2",
            "flex",
            (0, 1, 0),
            '<MultiplierFunction name="function"><function>'
            + _spline(xs, 0.05 * np.cos(xs), name="")
            + "</function><scale>1.3</scale></MultiplierFunction>",
        )
        + _axis("translation3", "", (0, 0, 1), _const(0.02))
    )
    joints = [
        _joint(
            "CustomJoint",
            "ground_b0",
            "ground",
            "b0",
            [_coord(c) for c in ("free_rz", "free_rx", "free_ry", "free_tx", "free_ty", "free_tz")],
            rng,
            f"<SpatialTransform>{free}</SpatialTransform>",
        ),
        _joint("PinJoint", "pin", "b0", "b1", [_coord("pin_rz")], rng),
        _joint("SliderJoint", "slider", "b1", "b2", [_coord("slide_tx")], rng),
        _joint("UniversalJoint", "universal", "b0", "b3", [_coord("u_rx"), _coord("u_ry")], rng),
        _joint(
            "GimbalJoint", "gimbal", "b3", "b4", [_coord(c) for c in ("g_rx", "g_ry", "g_rz")], rng
        ),
        _joint(
            "PlanarJoint", "planar", "b4", "b5", [_coord(c) for c in ("p_rz", "p_tx", "p_ty")], rng
        ),
        _joint("WeldJoint", "weld", "b5", "b6", [], rng),
        _joint(
            "CustomJoint",
            "custom",
            "b6",
            "b7",
            custom_coords,
            rng,
            f"<SpatialTransform>{custom}</SpatialTransform>",
        ),
        _joint("PinJoint", "pat", "b7", "b8", [_coord("pat_rz", lo=-3, hi=3)], rng),
        _joint("PinJoint", "held", "b2", "b9", [_coord("held_rz", locked=True, default=0.4)], rng),
    ]
    coupler = f"""<CoordinateCouplerConstraint name="pat_coupler"><isEnforced>true</isEnforced>
<coupled_coordinates_function>{_spline(xs, 0.4 * np.tanh(xs), name="")}</coupled_coordinates_function>
<independent_coordinate_names>flex</independent_coordinate_names>
<dependent_coordinate_name>pat_rz</dependent_coordinate_name><scale_factor>1.5</scale_factor>
</CoordinateCouplerConstraint>"""
    markers = "".join(
        f"""<Marker name="m{i}"><socket_parent_frame>/bodyset/b{i}</socket_parent_frame>
<location>{_v(rng.uniform(-0.1, 0.1, 3))}</location></Marker>"""
        for i in range(10)
    )
    return f"""<?xml version="1.0" encoding="UTF-8" ?>
<OpenSimDocument Version="40000">
<Model name="{"walker" if walker else "synthetic"}">
<Ground name="ground" />
<gravity>0.3 -9.81 0.2</gravity>
<BodySet name="bodyset"><objects>{"".join(bodies)}</objects></BodySet>
<JointSet name="jointset"><objects>{"".join(joints)}</objects></JointSet>
<ConstraintSet name="constraintset"><objects>{coupler}</objects></ConstraintSet>
<MarkerSet name="markerset"><objects>{markers}</objects></MarkerSet>
</Model>
</OpenSimDocument>
"""
