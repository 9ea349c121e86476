"""Mesh files for the viewer: read once, checked, and sent as they are or packed.

:func:`load_mesh` reads a .stl (binary or ASCII), .obj, .dae or any format trimesh reads, checks
the bytes (a file that is not a mesh, truncated, with non-finite coordinates, too large, or a
.dae with a DTD raises :class:`~anthroarm.errors.MeshError`), and returns meshcat geometry: the
file as it is, or, with a triangle budget, a compact :class:`PackedMesh` (:func:`pack_mesh`:
16-bit vertex grid, vertex clustering above the budget).

Function-local import (a heavy dependency, ~1 s, only paid for by a mesh that needs it):
trimesh, in ``_trimesh()`` (used by ``_packed`` and ``_via_trimesh``).
"""

from __future__ import annotations

import io
import numbers
import re
import stat
from pathlib import Path

import meshcat.geometry as mg
import numpy as np
import umsgpack
from lxml import etree
from meshcat.geometry import threejs_type

from .._io import parse_xml
from ..errors import MeshError, ParameterError

#: Largest mesh file the viewer reads (bytes).  Its contents go to the browser in one message.
MAX_MESH_BYTES = 256 * 2**20
#: The mesh formats read directly (checked here, parsed by three.js in the browser); any other
#: extension goes through trimesh and is sent as a binary STL.
DIRECT_FORMATS = (".stl", ".obj", ".dae")

_STL_RECORD = np.dtype([("normal", "<f4", 3), ("v", "<f4", 9), ("attr", "<u2")])


def load_mesh(path, link: str | None = None, max_triangles: int | None = None):
    """A meshcat mesh geometry from a mesh file: .stl (binary or ASCII), .obj, .dae, or any
    format trimesh reads (sent as STL).  With ``max_triangles`` the file is parsed here and
    sent as a :class:`PackedMesh` of at most that many triangles (:func:`pack_mesh`) instead.

    The file is read once, checked, and only the checked bytes are sent: a file that is not a
    mesh (a text file, random bytes), empty, truncated, with non-finite coordinates, larger than
    :data:`MAX_MESH_BYTES`, or a .dae with a DTD raises :class:`~anthroarm.errors.MeshError`
    naming the file and ``link`` (the link or geometry object that uses it)."""
    path = Path(path)
    try:
        st = path.stat()
    except OSError as exc:
        raise MeshError(path, f"cannot be read ({exc.strerror or exc})", link) from None
    if not stat.S_ISREG(st.st_mode):
        raise MeshError(path, "is not a regular file", link)
    if st.st_size > MAX_MESH_BYTES:
        raise MeshError(
            path,
            f"is {st.st_size} bytes, larger than the viewer's bound of {MAX_MESH_BYTES} bytes "
            f"(anthroarm.viewer.meshes.MAX_MESH_BYTES); decimate the mesh",
            link,
        )
    try:
        with open(path, "rb") as f:
            data = f.read(MAX_MESH_BYTES + 1)
    except OSError as exc:
        raise MeshError(path, f"cannot be read ({exc.strerror or exc})", link) from None
    if len(data) > MAX_MESH_BYTES:  # grew since stat
        raise MeshError(path, f"is larger than the viewer's bound of {MAX_MESH_BYTES} bytes", link)
    if not data:
        raise MeshError(path, "is empty", link)
    ext = path.suffix.lower()
    try:
        if ext == ".stl":
            _check_stl(data)
            geom, fmt, body = _stl_geometry(data), "stl", data
        elif ext == ".obj":
            body = _check_obj(data)
            geom, fmt = mg.MeshGeometry(body, "obj"), "obj"
        elif ext == ".dae":
            body = _check_dae(data)
            geom, fmt = mg.MeshGeometry(body, "dae"), "dae"
        else:
            body = _via_trimesh(data, ext)
            geom, fmt = _stl_geometry(body), "stl"
        if max_triangles is None:
            return geom
        return _packed(
            body, fmt, _check_budget(max_triangles), (str(path), st.st_mtime_ns, st.st_size)
        )
    except _NotAMesh as exc:
        raise MeshError(path, str(exc), link) from None


#: Default triangle budget of one mesh file in the viewer (``Viewer(mesh_triangles=...)``): the
#: Franka Panda's 10 visual mesh files (134 000 triangles, 10.5 MB of COLLADA text) become 44 000
#: triangles in 0.39 MB, so a Jupyter cell embeds well under 2 MB.
MESH_TRIANGLES = 5000


class PackedMesh(mg.Geometry):
    """An indexed triangle mesh in a compact form: vertex positions on a 16-bit grid over the
    mesh's bounding cube (``placement`` maps grid units to the mesh file's metres), indices as
    16-bit integers below 65 536 vertices.  No normals are sent: the page computes smooth
    vertex normals (``anthroarm_normals`` in :data:`~anthroarm.viewer._store.JS_PATCH`)."""

    def __init__(self, grid: np.ndarray, faces: np.ndarray, placement: np.ndarray):
        super().__init__()
        self.grid = np.ascontiguousarray(grid, dtype=np.uint16)
        self.faces = np.ascontiguousarray(
            faces, dtype=np.uint16 if len(self.grid) <= 65536 else np.uint32
        )
        self.placement = np.asarray(placement, float)

    @property
    def vertices(self) -> np.ndarray:
        """(N, 3) vertex positions in the mesh file's frame (m)."""
        return self.grid.astype(float) @ self.placement[:3, :3].T + self.placement[:3, 3]

    def lower(self, object_data):
        def attr(a, size):
            code, name = (20, "Uint16Array") if a.dtype == np.uint16 else (22, "Uint32Array")
            return {
                "itemSize": size,
                "type": name,
                "array": umsgpack.Ext(code, a.tobytes()),
                "normalized": False,
            }

        return {
            "uuid": self.uuid,
            "type": "BufferGeometry",
            "data": {
                "attributes": {"position": attr(self.grid, 3)},
                "index": attr(self.faces.ravel(), 1),
            },
        }


def _check_budget(max_triangles) -> int:
    if (
        isinstance(max_triangles, bool)
        or not isinstance(max_triangles, numbers.Integral)
        or int(max_triangles) < 12
    ):
        raise ParameterError(
            f"max_triangles (mesh_triangles) must be an integer >= 12 or None (the mesh files "
            f"as they are), got {max_triangles!r}"
        )
    return int(max_triangles)


def _cluster(V: np.ndarray, F: np.ndarray, n: int, count_only: bool = False):
    """Vertex clustering on a grid of ``n`` cells along the bounding cube's side: the vertices
    of a cell merge into their mean; triangles that collapse, or repeat, are dropped.
    ``count_only``: just the number of triangles that do not collapse (an upper bound)."""
    lo = V.min(0)
    side = float((V.max(0) - lo).max()) or 1.0
    key = np.minimum(np.floor((V - lo) / side * n).astype(np.int64), n - 1)
    flat = (key[:, 0] * n + key[:, 1]) * n + key[:, 2]
    if count_only:
        G = flat[F]
        return int(
            np.count_nonzero((G[:, 0] != G[:, 1]) & (G[:, 1] != G[:, 2]) & (G[:, 0] != G[:, 2]))
        )
    _, inv = np.unique(flat, return_inverse=True)
    inv = inv.ravel()
    cnt = np.bincount(inv)
    W = np.stack([np.bincount(inv, V[:, k]) for k in range(3)], 1) / cnt[:, None]
    G = inv[F]
    G = G[(G[:, 0] != G[:, 1]) & (G[:, 1] != G[:, 2]) & (G[:, 0] != G[:, 2])]
    if len(G):
        r = np.argmin(
            G, 1
        )  # rotate each triangle to start at its smallest index: repeats become equal rows
        G = np.unique(np.stack([G[np.arange(len(G)), (r + k) % 3] for k in range(3)], 1), axis=0)
    used = np.unique(G)
    remap = np.full(len(W), -1, np.int64)
    remap[used] = np.arange(len(used))
    return W[used], remap[G]


def pack_mesh(vertices, faces, max_triangles: int = MESH_TRIANGLES) -> PackedMesh:
    """A :class:`PackedMesh` of at most ``max_triangles`` triangles: coincident vertices merged
    (a 16-bit grid: 1/65535 of the bounding cube), then, above the budget, vertex clustering on
    the finest grid that meets it (Rossignac & Borrel 1993, "Multi-resolution 3D approximations
    for rendering complex scenes")."""
    V = np.asarray(vertices, float)
    F = np.asarray(faces, np.int64).reshape(-1, 3)
    W, G = _cluster(V, F, 65535)
    if len(G) > max_triangles:
        lo, hi = 2, 4096
        while lo < hi:  # the finest grid whose surviving triangles fit (they grow with n)
            mid = (lo + hi + 1) // 2
            if _cluster(V, F, mid, count_only=True) <= max_triangles:
                lo = mid
            else:
                hi = mid - 1
        W, G = _cluster(V, F, lo)
    if len(W) == 0:
        W, G = np.zeros((1, 3)), np.zeros((0, 3), np.int64)
    lo = W.min(0)
    step = max(float((W.max(0) - lo).max()), 1e-12) / 65535.0
    grid = np.clip(np.round((W - lo) / step), 0, 65535)
    placement = np.diag([step, step, step, 1.0])
    placement[:3, 3] = lo
    return PackedMesh(grid, G, placement)


_PACKED: dict = {}


def _packed(body, fmt: str, max_triangles: int, key) -> PackedMesh:
    """The checked mesh bytes/text parsed with trimesh and packed; the last 64 results are kept
    (key: file, modification time, size, budget), so a second Viewer of a robot is quick."""
    trimesh = _trimesh()
    k = (*key, max_triangles)
    if k in _PACKED:
        return _PACKED[k]
    data = body.encode("utf-8") if isinstance(body, str) else body
    try:
        m = trimesh.load(io.BytesIO(data), file_type=fmt, force="mesh")
        V, F = np.asarray(m.vertices, float), np.asarray(m.faces, np.int64)
    except Exception as exc:  # noqa: BLE001 - trimesh/pycollada raise anything
        raise _NotAMesh(
            f"cannot be parsed for the viewer ({type(exc).__name__}: {' '.join(str(exc).split())[:200]})"
        ) from None
    if len(F) and not np.all(np.isfinite(V)):
        raise _NotAMesh("has non-finite vertex coordinates")
    packed = (
        pack_mesh(V, F, max_triangles)
        if len(F)
        else PackedMesh(np.zeros((1, 3)), np.zeros((0, 3)), np.eye(4))
    )
    if len(_PACKED) >= 64:
        _PACKED.pop(next(iter(_PACKED)))
    _PACKED[k] = packed
    return packed


def mesh_placement(geom) -> np.ndarray:
    """Where a mesh geometry's own coordinates sit in the mesh file's frame (a
    :class:`PackedMesh`'s grid; the identity for a file sent as it is)."""
    return geom.placement if isinstance(geom, PackedMesh) else np.eye(4)


def _trimesh():
    """The trimesh module (imported on first use: it is heavy)."""
    import trimesh

    return trimesh


class _NotAMesh(Exception):
    """What is wrong with the bytes (turned into a MeshError naming the file and the link)."""


def _stl_geometry(data: bytes):
    _, extcode = threejs_type(np.uint8)
    return mg.MeshGeometry(umsgpack.Ext(extcode, bytes(data)), "stl")


def _check_stl(data: bytes) -> None:
    """A binary STL whose size matches its triangle count, or an ASCII STL of complete facets
    ending in 'endsolid'; every coordinate finite.  A well-formed STL without triangles (an
    empty solid) is accepted: it draws nothing."""
    n = len(data)
    if n >= 84:
        count = int.from_bytes(data[80:84], "little")
        expected = 84 + 50 * count
        if expected <= n and not (expected < n and data[:5].lower() == b"solid"):
            rec = np.frombuffer(data, dtype=_STL_RECORD, count=count, offset=84)
            bad = ~np.isfinite(rec["v"]).all(axis=1)
            if bad.any():
                raise _NotAMesh(
                    f"is a binary STL with non-finite vertex coordinates (triangle {int(np.argmax(bad))})"
                )
            return
    if data.lstrip()[:5].lower() == b"solid":
        _check_ascii_stl(data)
        return
    if n >= 84:
        count = int.from_bytes(data[80:84], "little")
        raise _NotAMesh(
            f"is not an STL file: as a binary STL its header promises {count} triangles "
            f"({84 + 50 * count} bytes) but the file has {n} bytes (truncated, or not a mesh), "
            "and it is not an ASCII STL ('solid ... endsolid')"
        )
    raise _NotAMesh(
        f"is not an STL file ({n} bytes: shorter than a binary STL header, and not an ASCII STL)"
    )


def _check_ascii_stl(data: bytes) -> None:
    try:
        text = data.decode("ascii")
    except UnicodeDecodeError as exc:
        raise _NotAMesh(
            f"starts like an ASCII STL but has a non-ASCII byte at offset {exc.start}"
        ) from None
    facets = 0
    in_loop = 0
    for lineno, line in enumerate(text.splitlines(), 1):
        parts = line.split()
        if not parts:
            continue
        key = parts[0].lower()
        if key == "vertex":
            try:
                xyz = [float(x) for x in parts[1:]]
            except ValueError:
                xyz = []
            if len(xyz) != 3 or not all(map(np.isfinite, xyz)):
                raise _NotAMesh(
                    f"is an ASCII STL with a bad vertex at line {lineno}: {line.strip()[:60]!r}"
                )
            in_loop += 1
        elif key == "outer":
            in_loop = 0
        elif key == "endloop":
            if in_loop != 3:
                raise _NotAMesh(
                    f"is an ASCII STL with a facet of {in_loop} vertices at line {lineno} (3 expected)"
                )
            facets += 1
    if not re.search(r"^\s*endsolid\b", text, re.MULTILINE | re.IGNORECASE):
        raise _NotAMesh("is an ASCII STL without 'endsolid' (truncated)")


def _utf8(data: bytes, what: str) -> str:
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise _NotAMesh(
            f"is not UTF-8 text (a {what} file is text): byte {data[exc.start]:#04x} at offset "
            f"{exc.start}"
        ) from None


def _check_obj(data: bytes) -> str:
    """Wavefront OBJ text: finite vertices, faces of >= 3 vertices that refer to vertices
    defined before them; at least one face."""
    text = _utf8(data, "Wavefront .obj")
    nv = faces = 0
    for lineno, line in enumerate(text.splitlines(), 1):
        parts = line.split()
        if not parts or parts[0].startswith("#"):
            continue
        if parts[0] == "v":
            try:
                xyz = [float(x) for x in parts[1:4]]
            except ValueError:
                xyz = []
            if len(xyz) != 3 or not all(map(np.isfinite, xyz)):
                raise _NotAMesh(
                    f"is an OBJ with a bad vertex at line {lineno}: {line.strip()[:60]!r}"
                )
            nv += 1
        elif parts[0] == "f":
            if len(parts) < 4:
                raise _NotAMesh(f"is an OBJ with a face of fewer than 3 vertices at line {lineno}")
            for tok in parts[1:]:
                try:
                    i = int(tok.split("/")[0])
                except ValueError:
                    raise _NotAMesh(
                        f"is an OBJ with a bad face at line {lineno}: {line.strip()[:60]!r}"
                    ) from None
                if not (1 <= i <= nv or -nv <= i <= -1):
                    raise _NotAMesh(
                        f"is an OBJ whose face at line {lineno} refers to vertex {i}, but {nv} "
                        "vertices are defined before it (truncated, or not a mesh)"
                    )
            faces += 1
    if faces == 0:
        raise _NotAMesh(f"is not an OBJ mesh: no faces ({nv} vertices)")
    return text


def _check_dae(data: bytes) -> str:
    """COLLADA XML without a DTD, with at least one <geometry>; returned as text."""

    def error(problem: str, line) -> Exception:
        if problem.startswith("DTD"):
            return _NotAMesh(f"declares a DTD or entity (line {line}); refused: {problem}")
        return _NotAMesh(f"is not well-formed XML (a COLLADA .dae file is XML): {problem}")

    root = parse_xml(data, error, "a mesh", keep_comments=True)
    name = etree.QName(root).localname if isinstance(root.tag, str) else str(root.tag)
    if name != "COLLADA":
        raise _NotAMesh(f"is XML but not COLLADA (root element <{name}>)")
    if next(root.iter("{*}geometry", "geometry"), None) is None:
        raise _NotAMesh("is a COLLADA file without any <geometry>")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:  # another declared encoding: send lxml's Unicode text
        return etree.tostring(root, encoding="unicode")


def _via_trimesh(data: bytes, ext: str) -> bytes:
    """Any other format trimesh reads, as a binary STL."""
    if not ext:
        raise _NotAMesh(
            "has no file extension; the viewer reads .stl, .obj, .dae and the formats trimesh "
            "reads (.ply, .glb, .off, ...)"
        )
    trimesh = _trimesh()
    try:
        mesh = trimesh.load(io.BytesIO(data), file_type=ext[1:], force="mesh")
        faces = len(mesh.faces)
        finite = bool(np.isfinite(np.asarray(mesh.vertices)).all())
        out = mesh.export(file_type="stl") if faces and finite else b""
    except Exception as exc:  # noqa: BLE001 - trimesh raises anything (NotImplementedError, KeyError, ...)
        raise _NotAMesh(
            f"cannot be read as a {ext} mesh ({type(exc).__name__}: {' '.join(str(exc).split())[:200]})"
        ) from None
    if not faces:
        raise _NotAMesh(f"is a {ext} file without triangles")
    if not finite:
        raise _NotAMesh(f"is a {ext} mesh with non-finite vertex coordinates")
    _check_stl(out)
    return out
