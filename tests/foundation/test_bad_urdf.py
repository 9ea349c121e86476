"""Hostile and malformed URDF files: each raises a typed anthroarm exception naming the file."""

import pytest

import anthroarm as aa
from anthroarm import errors

GOOD_JOINT = """
  <joint name="j1" type="revolute">
    <parent link="base"/><child link="l1"/>
    <origin xyz="0 0 0.1" rpy="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/>
  </joint>"""


def write(tmp_path, body, name="robot.urdf", head='<?xml version="1.0"?>\n'):
    p = tmp_path / name
    p.write_text(head + body)
    return p


def robot_xml(links="<link name='base'/><link name='l1'/>", joints=GOOD_JOINT, extra=""):
    return f"<robot name='t'>{links}{joints}{extra}</robot>"


def assert_structure_error(tmp_path, match, **robot_xml_kw):
    """Loading ``robot_xml(**robot_xml_kw)`` raises URDFStructureError matching ``match``; returns
    it."""
    with pytest.raises(errors.URDFStructureError, match=match) as exc:
        aa.load(str(write(tmp_path, robot_xml(**robot_xml_kw))))
    return exc.value


def test_minimal_good_file_loads(tmp_path):
    r = aa.load(str(write(tmp_path, robot_xml())))
    assert r.nq == 1 and r.joint_names == ["j1"]


def test_missing_file():
    with pytest.raises(errors.URDFNotFoundError, match="does_not_exist.urdf"):
        aa.load("/nonexistent/does_not_exist.urdf")


def test_malformed_xml(tmp_path):
    p = write(tmp_path, "<robot name='t'><link name='a'></robot>")
    with pytest.raises(errors.URDFSyntaxError, match="robot.urdf.*malformed XML"):
        aa.load(str(p))


def test_not_utf8_names_the_file(tmp_path):
    p = tmp_path / "latin1.urdf"
    text = '<?xml version="1.0" encoding="ISO-8859-1"?>\n'
    text += '<robot name="café"><link name="base"/></robot>'
    p.write_bytes(text.encode("latin-1"))
    with pytest.raises(errors.URDFSyntaxError, match="latin1.urdf.*UTF-8"):
        aa.load(str(p))


def test_not_a_robot(tmp_path):
    with pytest.raises(errors.URDFSyntaxError, match="expected <robot>"):
        aa.load(str(write(tmp_path, "<sdf/>")))


def test_entity_expansion_bomb_is_rejected_before_parsing(tmp_path):
    bomb = (
        '<!DOCTYPE lolz [<!ENTITY lol "lol">'
        + "".join(
            f'<!ENTITY lol{i} "{("&lol%s;" % (i - 1 if i else "")) * 10}">' for i in range(1, 10)
        )
        + "]>"
    )
    p = write(tmp_path, bomb + "<robot name='t'><link name='&lol9;'/></robot>")
    with pytest.raises(errors.URDFSecurityError, match="entity"):
        aa.load(str(p))


def test_external_entity_is_rejected(tmp_path):
    secret = tmp_path / "secret.txt"
    secret.write_text("top secret")
    p = write(
        tmp_path,
        f'<!DOCTYPE r [<!ENTITY xxe SYSTEM "file://{secret}">]>'
        "<robot name='t'><link name='&xxe;'/></robot>",
    )
    with pytest.raises(errors.URDFSecurityError):
        aa.load(str(p))


def test_kinematic_cycle(tmp_path):
    joints = (
        GOOD_JOINT
        + """
  <joint name="j2" type="revolute"><parent link="l1"/><child link="base"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>"""
    )
    assert_structure_error(tmp_path, "cycle|two joints", joints=joints)


def test_closed_loop_child_with_two_parents(tmp_path):
    links = "<link name='base'/><link name='l1'/><link name='l2'/>"
    joints = (
        GOOD_JOINT
        + """
  <joint name="j2" type="fixed"><parent link="base"/><child link="l2"/></joint>
  <joint name="j3" type="fixed"><parent link="l2"/><child link="l1"/></joint>"""
    )
    assert_structure_error(tmp_path, "child of two joints", links=links, joints=joints)


def test_unknown_joint_type(tmp_path):
    joints = GOOD_JOINT.replace('type="revolute"', 'type="ball"')
    assert_structure_error(tmp_path, "unknown type 'ball'", joints=joints)


@pytest.mark.parametrize("role, old, new", [("child", "l1", "l9"), ("parent", "base", "nowhere")])
def test_unknown_link(tmp_path, role, old, new):
    joints = GOOD_JOINT.replace(f'{role} link="{old}"', f'{role} link="{new}"')
    assert_structure_error(tmp_path, f"j1.*{role} link '{new}' is not defined", joints=joints)


@pytest.mark.parametrize("bad", ["nan", "inf", "1e400", "abc"])
def test_bad_numbers(tmp_path, bad):
    joints = GOOD_JOINT.replace('xyz="0 0 0.1"', f'xyz="0 0 {bad}"')
    assert_structure_error(tmp_path, "j1.*origin xyz", joints=joints)


def test_inverted_limits(tmp_path):
    joints = GOOD_JOINT.replace('lower="-1" upper="1"', 'lower="1" upper="-1"')
    assert_structure_error(tmp_path, "lower limit", joints=joints)


def test_negative_mass(tmp_path):
    links = "<link name='base'/><link name='l1'><inertial><mass value='-2'/></inertial></link>"
    assert_structure_error(tmp_path, "mass", links=links)


def mesh_link(uri):
    return (
        "<link name='base'/><link name='l1'><visual><geometry>"
        f"<mesh filename='{uri}'/></geometry></visual></link>"
    )


def test_missing_mesh_names_the_file(tmp_path):
    p = write(tmp_path, robot_xml(links=mesh_link("meshes/arm.stl")))
    with pytest.raises(errors.MeshNotFoundError, match="meshes/arm.stl"):
        aa.load(str(p))
    # opting out of the mesh check still loads the kinematics
    assert aa.load(str(p), check_meshes=False).nq == 1


def test_package_uri_escaping_its_package(tmp_path):
    pkg = tmp_path / "my_pkg"
    (pkg / "urdf").mkdir(parents=True)
    outside = tmp_path / "outside.stl"
    outside.write_text("solid x\nendsolid x\n")
    p = write(pkg / "urdf", robot_xml(links=mesh_link("package://my_pkg/../outside.stl")))
    with pytest.raises(errors.PackagePathError, match="escapes"):
        aa.load(str(p))


def test_package_uri_inside_package_resolves(tmp_path):
    pkg = tmp_path / "my_pkg"
    (pkg / "urdf").mkdir(parents=True)
    (pkg / "meshes").mkdir()
    (pkg / "meshes" / "a.stl").write_text("solid x\nendsolid x\n")
    p = write(pkg / "urdf", robot_xml(links=mesh_link("package://my_pkg/meshes/a.stl")))
    r = aa.load(str(p))
    assert r.info.meshes["package://my_pkg/meshes/a.stl"] == (pkg / "meshes" / "a.stl").resolve()


def test_unknown_package(tmp_path):
    p = write(tmp_path, robot_xml(links=mesh_link("package://nowhere/a.stl")))
    with pytest.raises(errors.PackagePathError, match="unknown package 'nowhere'"):
        aa.load(str(p))


def test_huge_file_is_refused(tmp_path, monkeypatch):
    import anthroarm.urdf_io as io

    monkeypatch.setattr(io, "MAX_URDF_BYTES", 100)
    with pytest.raises(errors.URDFSecurityError, match="larger than"):
        aa.load(str(write(tmp_path, robot_xml())))


def test_errors_are_anthroarm_errors():
    for cls in (
        errors.URDFNotFoundError,
        errors.URDFSyntaxError,
        errors.URDFSecurityError,
        errors.URDFStructureError,
        errors.MeshNotFoundError,
        errors.PackagePathError,
    ):
        assert issubclass(cls, errors.AnthroarmError)


def test_two_roots(tmp_path):
    links = "<link name='base'/><link name='l1'/><link name='loose'/>"
    assert_structure_error(
        tmp_path, r"not connected into one tree: 2 roots \('base', 'loose'\)", links=links
    )


def test_cycle_apart_from_the_root_names_its_links_and_joints(tmp_path):
    links = "<link name='base'/><link name='l1'/><link name='a'/><link name='b'/>"
    joints = (
        GOOD_JOINT
        + """
  <joint name="ab" type="fixed"><parent link="a"/><child link="b"/></joint>
  <joint name="ba" type="fixed"><parent link="b"/><child link="a"/></joint>"""
    )
    exc = assert_structure_error(
        tmp_path, "kinematic cycle through link '[ab]'", links=links, joints=joints
    )
    assert all(f"'{name}'" in str(exc) for name in ("a", "b", "ab", "ba"))


@pytest.fixture
def pkg_tree(tmp_path):
    """tmp_path/my_pkg/meshes/a.stl, and a URDF outside the package using package://my_pkg."""
    mesh = tmp_path / "my_pkg" / "meshes" / "a.stl"
    mesh.parent.mkdir(parents=True)
    mesh.write_text("solid x\nendsolid x\n")
    (tmp_path / "robots").mkdir()
    return (
        tmp_path,
        write(tmp_path / "robots", robot_xml(links=mesh_link("package://my_pkg/meshes/a.stl"))),
        mesh,
    )


@pytest.mark.parametrize("form", ["list", "tuple", "str", "path", "dict", "dict_path"])
def test_package_dirs_forms(pkg_tree, form):
    root, p, mesh = pkg_tree
    package_dirs = {
        "list": [str(root / "empty_or_missing"), str(root)],
        "tuple": (root,),
        "str": str(root),
        "path": root,
        "dict": {"my_pkg": str(root / "my_pkg")},
        "dict_path": {"my_pkg": root / "my_pkg"},
    }[form]
    r = aa.load(str(p), package_dirs=package_dirs)
    assert r.info.meshes["package://my_pkg/meshes/a.stl"] == mesh.resolve()
    # the robot keeps the folders: later look-ups (yourdfpy, viewer) resolve the same way
    from anthroarm.urdf_io import resolve_uri

    assert (
        resolve_uri("package://my_pkg/meshes/a.stl", r.info.path, r.info.package_dirs)
        == mesh.resolve()
    )


def test_package_dirs_list_without_the_package(pkg_tree):
    root, p, _ = pkg_tree
    with pytest.raises(errors.PackagePathError, match="unknown package 'my_pkg'.*robots"):
        aa.load(str(p), package_dirs=[str(root / "robots")])
    with pytest.raises(errors.PackagePathError, match="unknown package 'my_pkg'"):
        aa.load(str(p))


def test_package_dirs_list_keeps_escape_protection(tmp_path):
    (tmp_path / "my_pkg").mkdir()
    (tmp_path / "outside.stl").write_text("solid x\nendsolid x\n")
    (tmp_path / "robots").mkdir()
    p = write(tmp_path / "robots", robot_xml(links=mesh_link("package://my_pkg/../outside.stl")))
    with pytest.raises(errors.PackagePathError, match="escapes"):
        aa.load(str(p), package_dirs=[str(tmp_path)])
    # '..' as the package name would make the search folder's parent a package root
    sub = tmp_path / "search"
    sub.mkdir()
    p = write(
        tmp_path / "robots",
        robot_xml(links=mesh_link("package://../outside.stl")),
        name="dots.urdf",
    )
    with pytest.raises(errors.PackagePathError, match="'..' is not a package name"):
        aa.load(str(p), package_dirs=[str(sub)])


@pytest.mark.parametrize(
    "bad, what",
    [
        (42, "got int"),
        (b"/tmp", "got bytes"),
        ([1], "entry 0"),
        ({"p": 3}, "root of package 'p'"),
        ({1: "/tmp"}, "package names must be str"),
    ],
)
def test_package_dirs_wrong_type(tmp_path, bad, what):
    from anthroarm.urdf_io import normalize_package_dirs

    with pytest.raises(TypeError, match=what):
        normalize_package_dirs(bad)
    with pytest.raises(TypeError, match="package_dirs"):
        aa.load(str(write(tmp_path, robot_xml())), package_dirs=bad)
