"""Safe reading and validation of URDF files.

Pinocchio's and yourdfpy's parsers trust their input: an entity bomb hangs them, a cycle or a
missing parent ends in an obscure C++ exception, and ``package://`` URIs are resolved without
asking whether they stay inside their package.  :func:`read_urdf` checks all of that first,
quickly, and raises a typed :mod:`anthroarm.errors` exception naming the file and the problem.

Only after a file passes is its text handed to Pinocchio (``buildModelFromXML``) and yourdfpy,
so neither ever reads the file itself.
"""

from __future__ import annotations

import math
import os
import threading
from dataclasses import dataclass, field
from pathlib import Path

from lxml import etree

from .errors import (
    MeshNotFoundError,
    PackagePathError,
    URDFNotFoundError,
    URDFSecurityError,
    URDFStructureError,
    URDFSyntaxError,
)

#: Largest URDF we accept (bytes).  The biggest example-robot-data URDF is < 1 MB.
MAX_URDF_BYTES = 32 * 1024 * 1024

JOINT_TYPES = ("revolute", "continuous", "prismatic", "fixed", "floating", "planar")


@dataclass
class URDFInfo:
    """What :func:`read_urdf` learned about a file."""

    path: Path
    text: str
    robot_name: str
    links: list[str]
    joints: dict[str, dict] = field(default_factory=dict)  # name -> {type, parent, child, mimic}
    root_link: str = ""
    meshes: dict[str, Path] = field(default_factory=dict)  # URI -> resolved path
    package_dirs: dict[str, Path] = field(default_factory=dict)  # package name -> root


def default_package_dirs() -> dict[str, Path]:
    """Package roots known without asking the user: example-robot-data's share folder."""
    dirs: dict[str, Path] = {}
    try:
        import example_robot_data  # noqa: F401
        from example_robot_data import getModelPath

        robots = Path(getModelPath("")).resolve()
        dirs["example-robot-data"] = robots.parent
    except Exception:  # pragma: no cover - the package is a hard dependency
        pass
    return dirs


def _finite_floats(path, text: str | None, what: str, n: int, default: float = 0.0) -> list[float]:
    if text is None:
        return [default] * n
    parts = text.split()
    if len(parts) != n:
        raise URDFStructureError(path, f"{what}: expected {n} numbers, got {text!r}")
    try:
        vals = [float(p) for p in parts]
    except ValueError:
        raise URDFStructureError(path, f"{what}: not a number in {text!r}") from None
    if not all(math.isfinite(v) for v in vals):
        raise URDFStructureError(path, f"{what}: non-finite value in {text!r}")
    return vals


def _finite_float(path, text: str | None, what: str, default: float | None = None) -> float | None:
    if text is None:
        return default
    return _finite_floats(path, text, what, 1)[0]


def resolve_uri(uri: str, urdf_path: Path, package_dirs: dict[str, Path]) -> Path:
    """Resolve a mesh URI to a path.

    ``package://pkg/rel`` is looked up in ``package_dirs`` (name -> root) and in the folders
    above the URDF named ``pkg``; the result must stay inside the package root
    (:class:`PackagePathError` otherwise).  ``file://`` and plain paths are taken relative to
    the URDF's folder.
    """
    if uri.startswith("package://"):
        rest = uri[len("package://") :]
        pkg, _, rel = rest.partition("/")
        roots = []
        if pkg in package_dirs:
            roots.append(Path(package_dirs[pkg]))
        for parent in urdf_path.resolve().parents:
            if parent.name == pkg:
                roots.append(parent)
        if not roots:
            raise PackagePathError(
                urdf_path,
                f"mesh {uri!r}: unknown package {pkg!r}; pass package_dirs={{'{pkg}': '/path/to/{pkg}'}}",
            )
        for root in roots:
            root_r = root.resolve()
            target = (root_r / rel).resolve()
            if root_r != target and root_r not in target.parents:
                raise PackagePathError(urdf_path, f"mesh {uri!r} escapes its package root {root_r}")
            if target.exists():
                return target
        return (roots[0].resolve() / rel).resolve()
    if uri.startswith("file://"):
        uri = uri[len("file://") :]
    p = Path(uri)
    if not p.is_absolute():
        p = urdf_path.resolve().parent / p
    return p.resolve()


def read_urdf(path, package_dirs: dict | None = None, check_meshes: bool = True) -> URDFInfo:
    """Read, parse and validate a URDF file.

    Raises
    ------
    URDFNotFoundError, URDFSyntaxError, URDFSecurityError, URDFStructureError,
    PackagePathError, MeshNotFoundError
    """
    path = Path(path)
    if not path.is_file():
        raise URDFNotFoundError(path, "file does not exist")
    size = path.stat().st_size
    if size > MAX_URDF_BYTES:
        raise URDFSecurityError(path, f"file is {size} bytes, larger than the {MAX_URDF_BYTES} accepted")
    raw = path.read_bytes()
    return parse_urdf_bytes(raw, path, package_dirs=package_dirs, check_meshes=check_meshes)


def parse_urdf_bytes(raw: bytes, path, package_dirs: dict | None = None, check_meshes: bool = True) -> URDFInfo:
    """Validate URDF text already in memory; ``path`` is used for messages and relative URIs."""
    path = Path(path)
    head = raw.upper()
    if b"<!DOCTYPE" in head or b"<!ENTITY" in head:
        raise URDFSecurityError(path, "DTD/entity declarations are not allowed in a URDF (entity expansion or external entity)")
    parser = etree.XMLParser(
        resolve_entities=False, no_network=True, load_dtd=False, huge_tree=False, remove_comments=True
    )
    try:
        root = etree.fromstring(raw, parser)
    except etree.XMLSyntaxError as exc:
        raise URDFSyntaxError(path, f"malformed XML: {exc}") from None
    if root.tag != "robot":
        raise URDFSyntaxError(path, f"root element is <{root.tag}>, expected <robot>")

    pkgs = default_package_dirs()
    pkgs.update({k: Path(v) for k, v in (package_dirs or {}).items()})

    links = []
    for el in root.findall("link"):
        name = el.get("name")
        if not name:
            raise URDFStructureError(path, f"<link> without a name (line {el.sourceline})")
        if name in links:
            raise URDFStructureError(path, f"link {name!r} defined twice (line {el.sourceline})")
        links.append(name)
        for inertial in el.findall("inertial"):
            m = inertial.find("mass")
            if m is not None:
                mass = _finite_float(path, m.get("value"), f"link {name!r} mass")
                if mass is None or mass < 0:
                    raise URDFStructureError(path, f"link {name!r}: mass must be >= 0, got {m.get('value')!r}")
            o = inertial.find("origin")
            if o is not None:
                _finite_floats(path, o.get("xyz"), f"link {name!r} inertial origin xyz", 3)
                _finite_floats(path, o.get("rpy"), f"link {name!r} inertial origin rpy", 3)
            inertia = inertial.find("inertia")
            if inertia is not None:
                for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"):
                    _finite_float(path, inertia.get(k, "0"), f"link {name!r} inertia {k}")
    if not links:
        raise URDFStructureError(path, "no <link> elements")
    linkset = set(links)

    joints: dict[str, dict] = {}
    parent_of: dict[str, str] = {}
    for el in root.findall("joint"):
        name = el.get("name")
        jtype = el.get("type")
        if not name:
            raise URDFStructureError(path, f"<joint> without a name (line {el.sourceline})")
        if name in joints:
            raise URDFStructureError(path, f"joint {name!r} defined twice (line {el.sourceline})")
        if jtype not in JOINT_TYPES:
            raise URDFStructureError(
                path, f"joint {name!r} has unknown type {jtype!r} (line {el.sourceline}); known: {', '.join(JOINT_TYPES)}"
            )
        pe, ce = el.find("parent"), el.find("child")
        if pe is None or ce is None:
            raise URDFStructureError(path, f"joint {name!r} needs <parent> and <child>")
        parent, child = pe.get("link"), ce.get("link")
        for role, ln in (("parent", parent), ("child", child)):
            if ln not in linkset:
                raise URDFStructureError(path, f"joint {name!r}: {role} link {ln!r} is not defined")
        if child in parent_of:
            raise URDFStructureError(
                path, f"link {child!r} is the child of two joints ({joints_child(joints, child)!r} and {name!r}): a kinematic loop"
            )
        parent_of[child] = parent
        o = el.find("origin")
        if o is not None:
            _finite_floats(path, o.get("xyz"), f"joint {name!r} origin xyz", 3)
            _finite_floats(path, o.get("rpy"), f"joint {name!r} origin rpy", 3)
        ax = el.find("axis")
        if ax is not None:
            a = _finite_floats(path, ax.get("xyz"), f"joint {name!r} axis", 3, default=0.0)
            if jtype in ("revolute", "continuous", "prismatic") and math.sqrt(sum(x * x for x in a)) < 1e-12:
                raise URDFStructureError(path, f"joint {name!r}: zero-length axis")
        lim = el.find("limit")
        if jtype in ("revolute", "prismatic") and lim is None:
            raise URDFStructureError(path, f"joint {name!r} ({jtype}) has no <limit>")
        if lim is not None:
            lo = _finite_float(path, lim.get("lower"), f"joint {name!r} lower limit", 0.0)
            hi = _finite_float(path, lim.get("upper"), f"joint {name!r} upper limit", 0.0)
            if jtype in ("revolute", "prismatic") and lo > hi:
                raise URDFStructureError(path, f"joint {name!r}: lower limit {lo} > upper limit {hi}")
            for k in ("effort", "velocity"):
                v = _finite_float(path, lim.get(k), f"joint {name!r} {k} limit")
                if v is not None and v < 0:
                    raise URDFStructureError(path, f"joint {name!r}: negative {k} limit {v}")
        mim = el.find("mimic")
        mimic = None
        if mim is not None:
            mimic = {
                "joint": mim.get("joint"),
                "multiplier": _finite_float(path, mim.get("multiplier"), f"joint {name!r} mimic multiplier", 1.0),
                "offset": _finite_float(path, mim.get("offset"), f"joint {name!r} mimic offset", 0.0),
            }
        joints[name] = {"type": jtype, "parent": parent, "child": child, "mimic": mimic}
    for name, j in joints.items():
        if j["mimic"] is not None and j["mimic"]["joint"] not in joints:
            raise URDFStructureError(path, f"joint {name!r} mimics unknown joint {j['mimic']['joint']!r}")

    roots = [ln for ln in links if ln not in parent_of]
    if len(roots) != 1:
        # every link has a parent -> cycle; several roots -> disconnected
        if not roots:
            raise URDFStructureError(path, "kinematic cycle: every link has a parent joint")
        raise URDFStructureError(path, f"links are not connected into one tree: roots {roots}")
    # cycle detection: walk up from every link
    for ln in links:
        seen = set()
        cur = ln
        while cur in parent_of:
            if cur in seen:
                raise URDFStructureError(path, f"kinematic cycle through link {cur!r}")
            seen.add(cur)
            cur = parent_of[cur]
    meshes: dict[str, Path] = {}
    for mesh in root.iter("mesh"):
        uri = mesh.get("filename")
        if not uri:
            raise URDFStructureError(path, f"<mesh> without filename (line {mesh.sourceline})")
        scale = mesh.get("scale")
        if scale is not None:
            _finite_floats(path, scale, f"mesh {uri!r} scale", 3)
        resolved = resolve_uri(uri, path, pkgs)
        if check_meshes and not resolved.is_file():
            raise MeshNotFoundError(path, f"mesh {uri!r} not found (looked for {resolved})")
        meshes[uri] = resolved

    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise URDFSyntaxError(path, f"not UTF-8 text ({exc.reason} at byte {exc.start}); save the URDF as UTF-8") from None
    return URDFInfo(
        path=path,
        text=text,
        robot_name=root.get("name", path.stem),
        links=links,
        joints=joints,
        root_link=roots[0],
        meshes=meshes,
        package_dirs=pkgs,
    )


def joints_child(joints: dict, child: str) -> str:
    for n, j in joints.items():
        if j["child"] == child:
            return n
    return "?"


def atomic_write_text(path, text: str | bytes) -> None:
    """Write ``text`` (str as UTF-8, or bytes) to ``path`` atomically: a temp file in the same
    folder, then a rename, so a reader sees the old file or the new one, never a partial one;
    the temp file is removed on failure.  The folder must exist (``FileNotFoundError``)."""
    path = Path(path)
    if not path.parent.is_dir():
        raise FileNotFoundError(f"folder {path.parent} does not exist (cannot write {path.name})")
    data = text.encode("utf-8") if isinstance(text, str) else bytes(text)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.{threading.get_ident()}.tmp")
    try:
        tmp.write_bytes(data)
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()
