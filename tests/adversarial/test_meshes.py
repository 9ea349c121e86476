"""Mesh files that are not meshes (issue 12, item 2).

A URDF's ``<visual><mesh filename=...>`` may name any file on the disk.  Whatever it names —
a text file, random bytes, an empty or truncated STL/OBJ/DAE, a header that promises four
billion triangles, an XML file with entity declarations — the viewer raises
:class:`anthroarm.errors.MeshError` naming the mesh file and the link, never a dependency's
``NotImplementedError`` / ``UnicodeDecodeError``, and never forwards the bytes to the browser
(where three.js would fail, or show another file's contents).  ``anthroarm view`` prints one
line and exits with status 2.  Valid STL (binary and ASCII), OBJ and DAE files still load.
"""

from __future__ import annotations

import os
import shutil
import struct
import subprocess
import sys
from pathlib import Path

import meshcat
import numpy as np
import pytest

import anthroarm as aa
from anthroarm.cli import main as cli_main
from anthroarm.errors import AnthroarmError, MeshError
from anthroarm.viewer import Viewer

URDF = """<robot name="meshy">
  <link name="base"/>
  <link name="forearm"><visual><geometry><mesh filename="{mesh}"/></geometry></visual></link>
  <joint name="elbow" type="revolute"><parent link="base"/><child link="forearm"/><axis
    xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>
"""

MESHCAT_DATA = Path(meshcat.__file__).parent / "tests" / "data"


def _binary_stl(tris: np.ndarray, claimed: int | None = None) -> bytes:
    """A binary STL of triangles (n, 3, 3); ``claimed`` overrides the triangle count."""
    n = len(tris) if claimed is None else claimed
    body = b"".join(
        struct.pack("<3f", 0, 0, 1) + np.asarray(t, "<f4").tobytes() + b"\0\0" for t in tris
    )
    return b"anthroarm test".ljust(80, b" ") + struct.pack("<I", n) + body


TRI = np.array([[0, 0, 0], [0.1, 0, 0], [0, 0.1, 0]], float)
TET = np.array(
    [
        TRI,
        [[0, 0, 0], [0, 0.1, 0], [0, 0, 0.1]],
        [[0, 0, 0], [0, 0, 0.1], [0.1, 0, 0]],
        [[0.1, 0, 0], [0, 0.1, 0], [0, 0, 0.1]],
    ],
    float,
)
ASCII_STL = (
    "solid t\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 0.1 0 0\n"
    "   vertex 0 0.1 0\n  endloop\n endfacet\nendsolid t\n"
)
OBJ = "v 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nv 0 0 0.1\nf 1 2 3\nf 1 3 4\nf 1 4 2\nf 2 4 3\n"


def _valid_dae() -> bytes:
    return (MESHCAT_DATA / "mesh_0_convex_piece_0.dae").read_bytes()


def _cases() -> dict[str, tuple[str, bytes]]:
    dae = _valid_dae()
    nan_tri = TRI.copy()
    nan_tri[1, 0] = np.nan
    return {
        "text_file_as_stl": (
            "passwd.stl",
            b"root:x:0:0:root:/root:/bin/bash\ndaemon:x:1:1::/:/usr/sbin/nologin\n",
        ),
        "text_file_without_extension": ("passwd", b"root:x:0:0:root:/root:/bin/bash\n"),
        "binary_dae": (
            "random.dae",
            np.random.default_rng(0).integers(0, 256, 4096, dtype=np.uint8).tobytes(),
        ),
        "empty_stl": ("empty.stl", b""),
        "empty_obj": ("empty.obj", b""),
        "empty_dae": ("empty.dae", b""),
        "empty_ply": ("empty.ply", b""),
        "truncated_binary_stl": ("trunc.stl", _binary_stl(TET)[:-70]),
        "stl_triangle_count_bomb": ("bomb.stl", _binary_stl(TET, claimed=2**32 - 1)),
        "stl_nan_vertex": ("nan.stl", _binary_stl(np.array([nan_tri]))),
        "truncated_ascii_stl": ("trunc_ascii.stl", ASCII_STL[:70].encode()),
        "ascii_stl_facet_of_two_vertices": (
            "two.stl",
            ASCII_STL.replace("   vertex 0 0.1 0\n", "").encode(),
        ),
        "truncated_obj": ("trunc.obj", b"v 0 0 0\nv 0.1 0 0\nv 0 0.1"),
        "obj_without_faces": ("nofaces.obj", b"v 0 0 0\nv 0.1 0 0\nv 0 0.1 0\n"),
        "obj_face_index_out_of_range": ("range.obj", b"v 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nf 1 2 9\n"),
        "obj_nan_vertex": ("nan.obj", b"v nan 0 0\nv 0.1 0 0\nv 0 0.1 0\nf 1 2 3\n"),
        "obj_not_utf8": ("latin.obj", b"# \xff\xfe\xfa\nv 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nf 1 2 3\n"),
        "truncated_dae": ("trunc.dae", dae[: len(dae) // 2]),
        "dae_not_collada": ("page.dae", b"<html><body>not a mesh</body></html>"),
        "dae_with_external_entity": (
            "xxe.dae",
            b'<?xml version="1.0"?>\n<!DOCTYPE c [<!ENTITY e SYSTEM '
            b'"file:///etc/passwd">]>\n<COLLADA>&e;</COLLADA>\n',
        ),
        "garbage_ply": ("garbage.ply", b"this is not a ply file\n" * 10),
        "unknown_extension": ("shape.xyz", b"1 2 3\n4 5 6\n"),
    }


CASES = _cases()


def _robot_with_mesh(tmp_path: Path, mesh: Path):
    urdf = tmp_path / "meshy.urdf"
    urdf.write_text(URDF.format(mesh=mesh))
    return aa.load(urdf), urdf


@pytest.mark.parametrize("case", sorted(CASES))
def test_not_a_mesh_is_a_mesh_error(tmp_path, case):
    fname, data = CASES[case]
    mesh = tmp_path / fname
    mesh.write_bytes(data)
    robot, _ = _robot_with_mesh(tmp_path, mesh)
    with pytest.raises(MeshError) as ei:
        Viewer(robot)
    msg = str(ei.value)
    assert str(mesh) in msg and "forearm" in msg, msg
    assert (
        isinstance(ei.value, AnthroarmError)
        and ei.value.link == "forearm"
        and ei.value.path == str(mesh)
    )
    assert "\n" not in msg


def test_etc_passwd_as_mesh(tmp_path):
    """The file of the report: an absolute path to /etc/passwd (a text file, no extension)."""
    target = Path("/etc/passwd")
    if not target.is_file():  # pragma: no cover - every Linux has it
        pytest.skip("no /etc/passwd")
    robot, _ = _robot_with_mesh(tmp_path, target)
    with pytest.raises(MeshError, match="/etc/passwd.*forearm|forearm.*/etc/passwd"):
        Viewer(robot)


def test_mesh_larger_than_the_bound_is_refused_without_reading_it(tmp_path):
    """A sparse file just over the size bound (no disk space used): refused by its size."""
    from anthroarm.viewer.visuals import MAX_MESH_BYTES

    mesh = tmp_path / "huge.stl"
    with open(mesh, "wb") as f:
        f.truncate(MAX_MESH_BYTES + 1)
    robot, _ = _robot_with_mesh(tmp_path, mesh)
    with pytest.raises(MeshError, match="larger than"):
        Viewer(robot)


@pytest.mark.parametrize(
    "kind",
    [
        "binary_stl",
        "ascii_stl",
        "obj",
        "dae",
        "meshcat_stl_binary",
        "meshcat_obj",
        "empty_binary_solid",
        "empty_ascii_solid",
    ],
)
def test_valid_meshes_still_load(tmp_path, kind):
    files = {
        "binary_stl": ("tet.stl", _binary_stl(TET)),
        "ascii_stl": ("tri.stl", ASCII_STL.encode()),
        "obj": ("tet.obj", OBJ.encode()),
        "dae": ("piece.dae", _valid_dae()),
        "meshcat_stl_binary": (
            "piece.stl",
            (MESHCAT_DATA / "mesh_0_convex_piece_0.stl_binary").read_bytes(),
        ),
        "meshcat_obj": ("piece.obj", (MESHCAT_DATA / "mesh_0_convex_piece_0.obj").read_bytes()),
        # well-formed STL without triangles: an empty solid draws nothing, and is not an error
        "empty_binary_solid": ("zero.stl", _binary_stl(TET[:0])),
        "empty_ascii_solid": ("nofacet.stl", b"solid t\nendsolid t\n"),
    }
    fname, data = files[kind]
    mesh = tmp_path / fname
    mesh.write_bytes(data)
    robot, _ = _robot_with_mesh(tmp_path, mesh)
    v = Viewer(robot)
    assert any(p.group == "mesh" for b in v.bodies for p in b.pieces)
    assert "_meshfile" in v.static_html() or len(v.static_html()) > 1000


def test_geometry_model_mesh_error_names_the_object(tmp_path):
    """A robot loaded from a pin.Model with a visual_model whose mesh file is not a mesh."""
    import coal
    import pinocchio as pin

    bad = tmp_path / "bad.stl"
    bad.write_bytes(b"")
    model = aa.load("planar2r").model
    gm = pin.GeometryModel()
    go = pin.GeometryObject(
        "upper_arm_0",
        1,
        model.frames[model.getFrameId(model.names[1])].parentFrame,
        pin.SE3.Identity(),
        coal.Sphere(0.1),
    )
    go.meshPath = str(bad)
    gm.addGeometryObject(go)
    robot = aa.load(model, visual_model=gm)
    with pytest.raises(MeshError, match="upper_arm_0") as ei:
        Viewer(robot, style="visual_model")
    assert str(bad) in str(ei.value)


def test_cli_view_prints_one_line_and_exits_2(tmp_path, capsys):
    mesh = tmp_path / "passwd.stl"
    mesh.write_bytes(CASES["text_file_as_stl"][1])
    _, urdf = _robot_with_mesh(tmp_path, mesh)
    rc = cli_main(["view", str(urdf), "--html", str(tmp_path / "out.html")])
    err = capsys.readouterr().err
    assert rc == 2
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1 and str(mesh) in lines[0] and "forearm" in lines[0], err
    assert not (tmp_path / "out.html").exists()


def test_cli_view_subprocess_no_traceback(tmp_path):
    """The real console entry point on the binary .dae of the report."""
    fname, data = CASES["binary_dae"]
    mesh = tmp_path / fname
    mesh.write_bytes(data)
    _, urdf = _robot_with_mesh(tmp_path, mesh)
    exe = shutil.which("anthroarm", path=os.path.dirname(sys.executable)) or shutil.which(
        "anthroarm"
    )
    cmd = [exe] if exe else [sys.executable, "-m", "anthroarm.cli"]
    r = subprocess.run(
        [*cmd, "view", str(urdf), "--html", str(tmp_path / "o.html")],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert r.returncode == 2, r.stderr
    assert "Traceback" not in r.stderr and len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert str(mesh) in r.stderr
