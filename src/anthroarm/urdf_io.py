"""Safe reading and validation of URDF files.

Pinocchio's and yourdfpy's parsers trust their input: an entity bomb hangs them, a cycle or a
missing parent ends in an obscure C++ exception, and ``package://`` URIs are resolved without
asking whether they stay inside their package.  :func:`read_urdf` checks all of that first,
quickly, and raises a typed :mod:`anthroarm.errors` exception naming the file and the problem.

Only after a file passes is its text handed to Pinocchio (``buildModelFromXML``) and yourdfpy,
so neither ever reads the file itself.

**Physical bounds.**  A number that is finite but absurd (an origin of 1e308 m makes forward
kinematics return inf) is refused at load time with :class:`~anthroarm.errors.URDFStructureError`
naming the link or joint and the value.  The bounds, chosen far beyond any arm, hand or humanoid:

- lengths (every ``<origin xyz>``: joints, inertials, visuals, collisions; box sizes, cylinder
  and sphere dimensions, mesh scale factors): ``|x| <= MAX_LENGTH`` = 1e4 (m, or a factor);
  box, cylinder and sphere dimensions must also be >= 0;
- angles (``rpy``) and mimic multipliers / offsets: finite;
- masses: ``0 <= m <= MAX_MASS`` = 1e6 kg; inertia entries: finite, ``|I| <= MAX_INERTIA`` =
  1e12 kg m² (a non-physical, indefinite inertia is kept for kinematics; dynamics refuses it
  with :class:`~anthroarm.errors.InertiaError`);
- joint limits of revolute and prismatic joints: ``|limit| <= MAX_LENGTH`` (rad or m), or
  ``|limit| >= NO_LIMIT`` = 1e100, which means *no limit* (as Pinocchio's ±DBL_MAX defaults;
  :mod:`anthroarm.chain` treats it so); effort and velocity limits finite and >= 0;
- at most ``MAX_MOVABLE_JOINTS`` = 200 movable joints per model, checked before Pinocchio builds it
  (:func:`check_size`): Pinocchio's ``pin.Data`` grows as n³ (0.6 GB at 200 joints, 1.8 GB
  at 300, an out-of-memory kill at 1000).

**Where mesh files may be.**  ``package://NAME/rel`` must name a package (not empty, ``.``,
``..`` or a path) and resolve, after following symlinks, inside that package's root
(:class:`~anthroarm.errors.PackagePathError` otherwise).  ``file://`` URIs and plain paths are
taken as written: relative ones from the URDF's folder, absolute ones anywhere (the policy is
documented in SECURITY.md).
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

from ._io import parse_xml
from .errors import (
    MeshNotFoundError,
    PackagePathError,
    ParameterError,
    URDFNotFoundError,
    URDFSecurityError,
    URDFStructureError,
    URDFSyntaxError,
)

#: Largest URDF we accept (bytes).  The biggest example-robot-data URDF is < 1 MB.
MAX_URDF_BYTES = 32 * 1024 * 1024

JOINT_TYPES = ("revolute", "continuous", "prismatic", "fixed", "floating", "planar")

#: Physical bounds (see the module docstring): lengths in m (and scale factors), masses in kg,
#: inertias in kg m²; a joint limit at least NO_LIMIT in magnitude means no limit.
MAX_LENGTH = 1e4
MAX_MASS = 1e6
MAX_INERTIA = 1e12
NO_LIMIT = 1e100
#: Movable joints a model may have (Pinocchio's ``pin.Data`` grows as n³).
MAX_MOVABLE_JOINTS = 200
MOVABLE = ("revolute", "continuous", "prismatic", "floating", "planar")

#: A DTD or entity declaration, in any case (searched in place: no upper-cased copy of the file).

#: How many names an error message lists before it says "... and N more".
_MAX_NAMES_IN_MESSAGE = 10


class PackageDirs(dict):
    """Where ``package://NAME/...`` URIs are looked up: a dict ``{NAME: root}`` plus
    ``search``, a tuple of folders each of which may hold a package as ``DIR/NAME``
    (Pinocchio's ``package_dirs`` list).  Built by :func:`normalize_package_dirs`."""

    def __init__(self, named: Mapping | None = None, search=()):
        super().__init__(named or {})
        self.search: tuple[Path, ...] = tuple(search)

    def candidate_roots(self, pkg: str) -> list[Path]:
        """The roots package ``pkg`` may live in, in order: the named root, then every
        ``DIR/pkg`` of :attr:`search` that is a folder."""
        roots = [Path(self[pkg])] if pkg in self else []
        roots += [d / pkg for d in self.search if (d / pkg).is_dir()]
        return roots

    def __repr__(self) -> str:
        return f"PackageDirs({dict.__repr__(self)}, search={list(map(str, self.search))!r})"


#: What ``package_dirs`` may be (see :func:`normalize_package_dirs`).
PackageDirsLike = Mapping | list | tuple | str | os.PathLike | None


def _as_folder(value, what: str) -> Path:
    if isinstance(value, (str, os.PathLike)):
        return Path(value)
    raise ParameterError(
        f"package_dirs: {what} must be a folder (str or path), got {type(value).__name__} {value!r}"
    )


def normalize_package_dirs(
    package_dirs: PackageDirsLike = None, *, with_defaults: bool = True
) -> PackageDirs:
    """The one place ``package_dirs`` is interpreted.  Accepted forms:

    - a list (or tuple) of folders, Pinocchio's convention: ``package://NAME/rel`` is looked
      up as ``DIR/NAME/rel`` in each folder ``DIR`` where ``DIR/NAME`` is a folder;
    - a single folder (``str`` or path): the same as a one-element list;
    - a dict ``{NAME: root}``: ``package://NAME/rel`` is ``root/rel``;
    - ``None``: no folders of the user's.

    With ``with_defaults`` the roots of :func:`default_package_dirs` are added (a name the
    user gives wins).  A :class:`PackageDirs` is returned as it is.  Any other type raises
    :class:`~anthroarm.errors.ParameterError` (a :class:`TypeError`), as does a package name
    that is empty, ``.``, ``..`` or contains a path separator.
    """
    if isinstance(package_dirs, PackageDirs):
        return package_dirs
    named: dict[str, Path] = default_package_dirs() if with_defaults else {}
    search: list[Path] = []
    if package_dirs is None:
        pass
    elif isinstance(package_dirs, (str, os.PathLike)):
        search.append(Path(package_dirs))
    elif isinstance(package_dirs, Mapping):
        for name, root in package_dirs.items():
            if not isinstance(name, str):
                raise ParameterError(
                    f"package_dirs: package names must be str, got {type(name).__name__} {name!r}"
                )
            if not _is_package_name(name):
                raise ParameterError(
                    f"package_dirs: {name!r} is not a package name (package://NAME/... needs a "
                    "name that is not empty, '.', '..' or a path)"
                )
            named[name] = _as_folder(root, f"the root of package {name!r}")
    elif isinstance(package_dirs, (list, tuple)):
        search.extend(_as_folder(d, f"entry {i}") for i, d in enumerate(package_dirs))
    else:
        raise ParameterError(
            "package_dirs must be a list of folders (package://NAME/... is looked up as "
            "DIR/NAME/...), a single folder, or a dict {package name: root}; got "
            f"{type(package_dirs).__name__}"
        )
    return PackageDirs(named, search)


def _is_package_name(pkg: str) -> bool:
    return (
        pkg not in ("", ".", "..")
        and os.sep not in pkg
        and not (os.altsep and os.altsep in pkg)
        and "\0" not in pkg
    )


def _name_list(names) -> str:
    names = list(names)
    shown = ", ".join(repr(n) for n in names[:_MAX_NAMES_IN_MESSAGE])
    more = len(names) - _MAX_NAMES_IN_MESSAGE
    return shown + (f", ... and {more} more" if more > 0 else "")


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
    package_dirs: PackageDirs = field(
        default_factory=PackageDirs
    )  # package name -> root, + search folders


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


def _first_children(el) -> dict:
    """``{tag: first child with that tag}`` of an element: one pass over its children instead
    of one ``find`` per tag (which walks them again each time)."""
    first: dict = {}
    for child in el:
        first.setdefault(child.tag, child)
    return first


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
    if not all(map(math.isfinite, vals)):
        raise URDFStructureError(path, f"{what}: non-finite value in {text!r}")
    return vals


def _bounded(
    path,
    vals: list[float],
    what: str,
    bound: float = MAX_LENGTH,
    unit: str = "m",
    nonnegative: bool = False,
) -> list[float]:
    """``vals`` unchanged if every ``|v| <= bound`` (and ``v >= 0`` when asked); else
    :class:`URDFStructureError` naming ``what`` and the value."""
    for v in vals:
        if abs(v) > bound:
            raise URDFStructureError(
                path,
                f"{what}: {v:g} is beyond the physical bound of {bound:.0e} {unit} "
                "(see anthroarm.urdf_io)",
            )
        if nonnegative and v < 0:
            raise URDFStructureError(path, f"{what}: {v:g} is negative")
    return vals


def _check_origin(path, o, what: str) -> None:
    if o is not None:
        _bounded(
            path, _finite_floats(path, o.get("xyz"), f"{what} origin xyz", 3), f"{what} origin xyz"
        )
        _finite_floats(path, o.get("rpy"), f"{what} origin rpy", 3)


#: geometry element -> (attribute, count, nonnegative) checked by :func:`_check_geometry`
_SHAPES = {
    "box": (("size", 3, True),),
    "cylinder": (("radius", 1, True), ("length", 1, True)),
    "sphere": (("radius", 1, True),),
    "capsule": (("radius", 1, True), ("length", 1, True)),
    "mesh": (("scale", 3, False),),
}


def _check_geometry(path, link: str, el) -> None:
    """Origins and shape dimensions of a link's visuals and collisions."""
    for kind in ("visual", "collision"):
        for v in el.findall(kind):
            _check_origin(path, v.find("origin"), f"link {link!r} {kind}")
            g = v.find("geometry")
            for shape in g if g is not None else ():
                for attr, n, nonneg in _SHAPES.get(shape.tag, ()):
                    text = shape.get(attr)
                    if text is None:
                        continue
                    what = f"link {link!r} {kind} {shape.tag} {attr} (line {shape.sourceline})"
                    _bounded(
                        path,
                        _finite_floats(path, text, what, n),
                        what,
                        unit="m" if nonneg else "",
                        nonnegative=nonneg,
                    )


def _check_limit(path, joint: str, jtype: str, which: str, value: float) -> None:
    if jtype in ("revolute", "prismatic") and MAX_LENGTH < abs(value) < NO_LIMIT:
        unit = "m" if jtype == "prismatic" else "rad"
        raise URDFStructureError(
            path,
            f"joint {joint!r} {which} limit {value:g} {unit} is beyond the physical bound of "
            f"{MAX_LENGTH:.0e} {unit}; write a magnitude of at least {NO_LIMIT:.0e} for no limit"
            + (" (or make it a continuous joint)" if jtype == "revolute" else ""),
        )


def check_size(info: "URDFInfo") -> None:
    """:class:`URDFStructureError` if the model has more than :data:`MAX_MOVABLE_JOINTS`
    movable joints (checked before Pinocchio allocates its data, which grows as n³)."""
    n = sum(j["type"] in MOVABLE for j in info.joints.values())
    if n > MAX_MOVABLE_JOINTS:
        raise URDFStructureError(
            info.path,
            f"{n} movable joints; anthroarm takes at most {MAX_MOVABLE_JOINTS} per model "
            "(Pinocchio's data grows as the cube of the joint count: 0.6 GB at 200); split the "
            "model or make joints fixed",
        )


def _finite_float(path, text: str | None, what: str, default: float | None = None) -> float | None:
    if text is None:
        return default
    return _finite_floats(path, text, what, 1)[0]


def resolve_uri(uri: str, urdf_path: Path, package_dirs: PackageDirsLike) -> Path:
    """Resolve a mesh URI to a path.

    ``package://pkg/rel`` is looked up in ``package_dirs`` (any form
    :func:`normalize_package_dirs` accepts: the named root of ``pkg``, then ``DIR/pkg`` for
    each search folder ``DIR``) and in the folders above the URDF named ``pkg``; the result
    must stay inside the package root (:class:`PackagePathError` otherwise).  ``file://`` and
    plain paths are taken relative to the URDF's folder.
    """
    if uri.startswith("package://"):
        dirs = normalize_package_dirs(package_dirs, with_defaults=False)
        rest = uri[len("package://") :]
        pkg, _, rel = rest.partition("/")
        if not _is_package_name(pkg):
            raise PackagePathError(urdf_path, f"mesh {uri!r}: {pkg!r} is not a package name")
        roots = dirs.candidate_roots(pkg)
        for parent in urdf_path.resolve().parents:
            if parent.name == pkg:
                roots.append(parent)
        if not roots:
            searched = (
                f" (not found in package_dirs folders {[str(d) for d in dirs.search]})"
                if dirs.search
                else ""
            )
            raise PackagePathError(
                urdf_path,
                f"mesh {uri!r}: unknown package {pkg!r}{searched}; pass "
                f"package_dirs=['/folder/containing/{pkg}'] or package_dirs={{'{pkg}': "
                f"'/path/to/{pkg}'}}",
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


def read_urdf(path, package_dirs: PackageDirsLike = None, check_meshes: bool = True) -> URDFInfo:
    """Read, parse and validate a URDF file.

    ``package_dirs``: a list of folders holding packages, a single such folder, or a dict
    ``{package name: root}`` (see :func:`normalize_package_dirs`).

    Raises
    ------
    URDFNotFoundError, URDFSyntaxError, URDFSecurityError, URDFStructureError,
    PackagePathError, MeshNotFoundError
    """
    path = Path(path)
    if not path.is_file():
        what = (
            "is a folder, not a URDF file"
            if path.is_dir()
            else "is not a regular file (a device, FIFO or socket)"
            if path.exists()
            else "file does not exist"
        )
        raise URDFNotFoundError(path, what)
    size = path.stat().st_size
    if size > MAX_URDF_BYTES:
        raise URDFSecurityError(
            path, f"file is {size} bytes, larger than the {MAX_URDF_BYTES} accepted"
        )
    raw = path.read_bytes()
    return parse_urdf_bytes(raw, path, package_dirs=package_dirs, check_meshes=check_meshes)


def parse_urdf_bytes(
    raw: bytes, path, package_dirs: PackageDirsLike = None, check_meshes: bool = True
) -> URDFInfo:
    """Validate URDF text already in memory; ``path`` is used for messages and relative URIs."""
    path = Path(path)

    def error(problem: str, line) -> Exception:
        where = f"line {line}: " if line else ""
        cls = URDFSecurityError if problem.startswith("DTD") else URDFSyntaxError
        return cls(path, where + problem)

    root = parse_xml(raw, error, "a URDF")
    if root.tag != "robot":
        raise URDFSyntaxError(path, f"root element is <{root.tag}>, expected <robot>")

    pkgs = normalize_package_dirs(package_dirs)

    links: list[str] = []
    linkset: set[str] = set()
    for el in root.findall("link"):
        name = el.get("name")
        if not name:
            raise URDFStructureError(path, f"<link> without a name (line {el.sourceline})")
        if name in linkset:
            raise URDFStructureError(path, f"link {name!r} defined twice (line {el.sourceline})")
        links.append(name)
        linkset.add(name)
        for inertial in el.findall("inertial"):
            m = inertial.find("mass")
            if m is not None:
                mass = _finite_float(path, m.get("value"), f"link {name!r} mass")
                if mass is None or mass < 0:
                    raise URDFStructureError(
                        path, f"link {name!r}: mass must be >= 0, got {m.get('value')!r}"
                    )
                _bounded(path, [mass], f"link {name!r}: mass", MAX_MASS, "kg")
            _check_origin(path, inertial.find("origin"), f"link {name!r} inertial")
            inertia = inertial.find("inertia")
            if inertia is not None:
                for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"):
                    what = f"link {name!r} inertia {k}"
                    _bounded(
                        path,
                        [_finite_float(path, inertia.get(k, "0"), what)],
                        what,
                        MAX_INERTIA,
                        "kg m^2",
                    )
        if len(el):
            _check_geometry(path, name, el)
    if not links:
        raise URDFStructureError(path, "no <link> elements")

    joints: dict[str, dict] = {}
    parent_of: dict[str, str] = {}  # child link -> parent link
    joint_of: dict[str, str] = {}  # child link -> the joint whose child it is
    for el in root.findall("joint"):
        name = el.get("name")
        jtype = el.get("type")
        if not name:
            raise URDFStructureError(path, f"<joint> without a name (line {el.sourceline})")
        if name in joints:
            raise URDFStructureError(path, f"joint {name!r} defined twice (line {el.sourceline})")
        if jtype not in JOINT_TYPES:
            raise URDFStructureError(
                path,
                f"joint {name!r} has unknown type {jtype!r} (line {el.sourceline}); known: "
                f"{', '.join(JOINT_TYPES)}",
            )
        sub = _first_children(el)
        pe, ce = sub.get("parent"), sub.get("child")
        if pe is None or ce is None:
            raise URDFStructureError(path, f"joint {name!r} needs <parent> and <child>")
        parent, child = pe.get("link"), ce.get("link")
        for role, ln in (("parent", parent), ("child", child)):
            if ln not in linkset:
                raise URDFStructureError(path, f"joint {name!r}: {role} link {ln!r} is not defined")
        if child in parent_of:
            raise URDFStructureError(
                path,
                f"link {child!r} is the child of two joints ({joint_of[child]!r} and {name!r}): a "
                "kinematic loop",
            )
        parent_of[child] = parent
        joint_of[child] = name
        _check_origin(path, sub.get("origin"), f"joint {name!r}")
        ax = sub.get("axis")
        if ax is not None:
            a = _finite_floats(path, ax.get("xyz"), f"joint {name!r} axis", 3, default=0.0)
            if jtype in ("revolute", "continuous", "prismatic") and math.hypot(*a) < 1e-12:
                raise URDFStructureError(path, f"joint {name!r}: zero-length axis")
        lim = sub.get("limit")
        if jtype in ("revolute", "prismatic") and lim is None:
            raise URDFStructureError(path, f"joint {name!r} ({jtype}) has no <limit>")
        if lim is not None:
            lo = _finite_float(path, lim.get("lower"), f"joint {name!r} lower limit", 0.0)
            hi = _finite_float(path, lim.get("upper"), f"joint {name!r} upper limit", 0.0)
            if jtype in ("revolute", "prismatic") and lo > hi:
                raise URDFStructureError(
                    path, f"joint {name!r}: lower limit {lo} > upper limit {hi}"
                )
            _check_limit(path, name, jtype, "lower", lo)
            _check_limit(path, name, jtype, "upper", hi)
            for k in ("effort", "velocity"):
                v = _finite_float(path, lim.get(k), f"joint {name!r} {k} limit")
                if v is not None and v < 0:
                    raise URDFStructureError(path, f"joint {name!r}: negative {k} limit {v}")
        mim = sub.get("mimic")
        mimic = None
        if mim is not None:
            mimic = {
                "joint": mim.get("joint"),
                "multiplier": _finite_float(
                    path, mim.get("multiplier"), f"joint {name!r} mimic multiplier", 1.0
                ),
                "offset": _finite_float(
                    path, mim.get("offset"), f"joint {name!r} mimic offset", 0.0
                ),
            }
        joints[name] = {"type": jtype, "parent": parent, "child": child, "mimic": mimic}
    for name, j in joints.items():
        if j["mimic"] is not None and j["mimic"]["joint"] not in joints:
            raise URDFStructureError(
                path, f"joint {name!r} mimics unknown joint {j['mimic']['joint']!r}"
            )

    root_link = _check_tree(path, links, parent_of, joint_of)

    meshes: dict[str, Path] = {}
    for mesh in root.iter("mesh"):
        uri = mesh.get("filename")
        if not uri:
            raise URDFStructureError(path, f"<mesh> without filename (line {mesh.sourceline})")
        scale = mesh.get("scale")
        if scale is not None:
            _bounded(
                path,
                _finite_floats(path, scale, f"mesh {uri!r} scale", 3),
                f"mesh {uri!r} scale",
                unit="",
            )
        if uri in meshes:  # already resolved and checked (a mesh shared by many links)
            continue
        resolved = resolve_uri(uri, path, pkgs)
        if check_meshes and not resolved.is_file():
            raise MeshNotFoundError(path, f"mesh {uri!r} not found (looked for {resolved})")
        meshes[uri] = resolved

    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise URDFSyntaxError(
            path, f"not UTF-8 text ({exc.reason} at byte {exc.start}); save the URDF as UTF-8"
        ) from None
    return URDFInfo(
        path=path,
        text=text,
        robot_name=root.get("name", path.stem),
        links=links,
        joints=joints,
        root_link=root_link,
        meshes=meshes,
        package_dirs=pkgs,
    )


def _check_tree(path, links: list[str], parent_of: dict[str, str], joint_of: dict[str, str]) -> str:
    """Check that the links form one tree and return its root link, in O(links).

    Each link already has at most one parent (checked while reading the joints).  Then the
    links form one tree exactly when there is one root and every link is reached from it;
    a link not reached lies on, or hangs below, a kinematic cycle.  Iterative, so a chain of
    any depth is fine.
    """
    roots = [ln for ln in links if ln not in parent_of]
    if len(roots) > 1:
        raise URDFStructureError(
            path, f"links are not connected into one tree: {len(roots)} roots ({_name_list(roots)})"
        )
    children: dict[str, list[str]] = {}
    for child, parent in parent_of.items():
        children.setdefault(parent, []).append(child)
    reached: set[str] = set(roots)
    stack = list(roots)
    while stack:
        for child in children.get(stack.pop(), ()):
            if child not in reached:
                reached.add(child)
                stack.append(child)
    if len(reached) == len(links):
        return roots[0]
    # A link not reached: walking up its parents never meets the root, so it meets a cycle.
    cur = next(ln for ln in links if ln not in reached)
    order: dict[str, int] = {}
    while cur not in order:
        order[cur] = len(order)
        cur = parent_of[cur]
    cycle = list(order)[order[cur] :]
    where = "every link has a parent joint; " if not roots else ""
    raise URDFStructureError(
        path,
        f"kinematic cycle through link {cur!r}: {where}links {_name_list(cycle)} "
        f"(joints {_name_list(joint_of[ln] for ln in cycle)})",
    )
