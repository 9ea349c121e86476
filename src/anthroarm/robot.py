"""Robot: a Pinocchio model, its kinematic description ``chain``, tool frame and limits.

>>> import anthroarm as aa
>>> robot = aa.load("prosthetic_arm")
>>> T = robot.fk(robot.neutral())            # 4x4 world pose of the tool (palm centre)
>>> J = robot.jacobian(robot.neutral())      # 6 x nv, LOCAL_WORLD_ALIGNED, rows (v; w)
>>> T_batch = robot.fk(robot.random_q(1000, rng=0))   # (1000, 4, 4) through the batched chain

:func:`load` takes a catalog name, any example-robot-data robot by name, a URDF path, a
``pin.Model`` or a ``pin.RobotWrapper``.  URDF text is validated by
:func:`anthroarm.urdf_io.read_urdf` and then given to Pinocchio (``buildModelFromXML``) and,
lazily, to yourdfpy, so both read exactly the same text.  Joints a user does not want (a
gripper, the rest of a humanoid) are locked with ``pin.buildReducedModel`` (``locked=`` /
``active=``); ``robot.locked`` records their values.

Thread safety: a Robot may be used from several threads at once.  ``robot.data`` is a
``pin.Data`` of the calling thread (one per thread, made on first use), ``robot.chain`` is
immutable, and the batched path keeps no state between calls.
"""

from __future__ import annotations

import io
import threading
from functools import cached_property
from pathlib import Path

import numpy as np
import pinocchio as pin

from . import models
from .chain import Chain
from .errors import ParameterError, UnknownFrameError, UnsupportedModelError, URDFStructureError
from .urdf_io import URDFInfo, check_size, parse_urdf_bytes, read_urdf, resolve_uri

LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
_REFERENCES = ("LOCAL", "WORLD", "LOCAL_WORLD_ALIGNED")


def _short(x, n: int = 80) -> str:
    """``repr(x)`` cut to ``n`` characters, for error messages."""
    r = repr(x)
    return r if len(r) <= n else r[: n - 3] + "..."


def _has_text(x) -> bool:
    """True for a str/bytes, a numpy array of text, or a list/tuple holding a str/bytes/None."""
    if isinstance(x, (str, bytes)):
        return True
    if isinstance(x, np.ndarray):
        return x.dtype.kind in "US"
    if isinstance(x, (list, tuple)):
        return any(v is None or _has_text(v) for v in x)
    return False


def _reference_frame(reference) -> pin.ReferenceFrame:
    """``pin.ReferenceFrame`` from its name; :class:`~anthroarm.errors.ParameterError` (a
    ``ValueError``) listing the names otherwise."""
    if isinstance(reference, pin.ReferenceFrame):
        return reference
    if not isinstance(reference, str) or reference not in _REFERENCES:
        raise ParameterError(
            f"reference must be one of {', '.join(_REFERENCES)} (or a pin.ReferenceFrame), "
            f"got {reference!r}"
        )
    return getattr(pin.ReferenceFrame, reference)


def build_model(info: URDFInfo):
    """``pin.Model`` of a validated URDF (mimic joints modelled, as yourdfpy does).  Pinocchio's
    C++ errors become :class:`~anthroarm.errors.URDFStructureError` naming the file, as does a
    model too large for Pinocchio's data (:func:`~anthroarm.urdf_io.check_size`)."""
    check_size(info)
    has_mimic = any(j["mimic"] is not None for j in info.joints.values())
    try:
        return pin.buildModelFromXML(info.text, mimic=has_mimic)
    except Exception as exc:  # pin raises RuntimeError/ValueError from C++
        raise URDFStructureError(info.path, f"Pinocchio cannot build the model: {exc}") from None


def reduce_model(model, name: str, active=None, locked=None):
    """Lock joints of ``model``: every joint not in ``active`` (when given) and every joint in
    ``locked`` (a list of names, locked at 0 / the neutral value, or a dict name → value: an
    angle in rad or a displacement in m; for a joint with several coordinates its q slice).

    Returns ``(reduced model, {name: value})``.  Unknown names raise
    :class:`~anthroarm.errors.UnknownFrameError` listing the joints."""
    if active is None and not locked:
        return model, {}
    names = [model.names[i] for i in range(1, model.njoints)]
    if isinstance(locked, (str, bytes)) or (locked is not None and not hasattr(locked, "__iter__")):
        raise ParameterError(
            f"{name}: locked= is a list of joint names or a dict name -> value, got {locked!r}"
        )
    locked = dict(locked) if isinstance(locked, dict) else {n: None for n in (locked or ())}
    if isinstance(active, (str, bytes)) or (active is not None and not hasattr(active, "__iter__")):
        raise ParameterError(f"{name}: active= is a list of joint names, got {active!r}")
    active = list(active) if active is not None else None
    for what, given in (("active", active or ()), ("locked", locked)):
        bad = [a for a in given if not isinstance(a, str)]
        if bad:
            raise ParameterError(f"{name}: {what}= takes joint names (str), got {bad!r}")
    for what, given in (("active", active or ()), ("locked", locked)):
        missing = [a for a in given if a not in names]
        if missing:
            raise UnknownFrameError(
                f"{name}: {what} joints {missing} are not in the model; joints: {', '.join(names)}"
            )
    qref = pin.neutral(model)
    lock_ids, values = [], {}
    mimic_source = {
        int(m): int(s)
        for m, s in zip(
            getattr(model, "mimicking_joints", ()), getattr(model, "mimicked_joints", ())
        )
    }
    for jid in range(1, model.njoints):
        jname = model.names[jid]
        if jname in locked or (active is not None and jname not in active):
            jm = model.joints[jid]
            v = locked.get(jname)
            if jid in mimic_source:  # follows its source: locked with it (checked below)
                lock_ids.append(jid)
                continue
            if v is not None:
                try:
                    v = np.atleast_1d(np.asarray(v, dtype=float))
                except (TypeError, ValueError):
                    raise ParameterError(
                        f"{name}: locked value of joint {jname!r} must be a number (rad or m), "
                        f"got {v!r}"
                    ) from None
                if jm.nq == 2 and jm.nv == 1 and v.size == 1:  # a continuous joint: an angle
                    v = np.array([np.cos(v[0]), np.sin(v[0])])
                if v.size != jm.nq or not np.all(np.isfinite(v)):
                    raise ParameterError(
                        f"{name}: locked value of joint {jname!r} must be {jm.nq} finite "
                        f"number(s), got {v}"
                    )
                qref[jm.idx_q : jm.idx_q + jm.nq] = v
            val = qref[jm.idx_q : jm.idx_q + jm.nq].copy()
            values[jname] = float(val[0]) if val.size == 1 else val
            lock_ids.append(jid)
    for m, src in mimic_source.items():
        if (m in lock_ids) != (src in lock_ids):
            raise UnsupportedModelError(
                f"{name}: mimic joint {model.names[m]!r} follows {model.names[src]!r}: lock both "
                "or neither"
            )
        if m in lock_ids:
            e = model.joints[m].extract()
            values[model.names[m]] = float(
                e.scaling * np.atleast_1d(values[model.names[src]])[0] + e.offset
            )
    if not lock_ids:
        return model, {}
    framed = {int(f.parentJoint) for f in model.frames if f.type == pin.FrameType.JOINT}
    missing = [model.names[j] for j in range(1, model.njoints) if j not in framed]
    if missing:  # buildReducedModel dereferences each joint's frame: it would crash the process
        raise UnsupportedModelError(
            f"{name}: joints {missing} have no joint frame (model.addJointFrame); "
            "Pinocchio cannot lock joints of such a model"
        )
    try:
        return pin.buildReducedModel(model, lock_ids, qref), values
    except Exception as exc:
        raise UnsupportedModelError(
            f"{name}: Pinocchio cannot lock joints {list(values)}: {exc}"
        ) from None


class Robot:
    """A fixed-base kinematic tree: a Pinocchio model and its kinematic description.

    Use :func:`load`; the constructor takes an already built (and reduced) model.

    Parameters
    ----------
    model : pin.Model
        Fixed-base model with revolute, continuous, prismatic and mimic joints only.
    name : str
        Catalog name, example-robot-data name or file stem.
    tool : str, optional
        Frame used when ``frame=None``.  Default: the only tip of a serial chain; a tree with
        several tips raises :class:`~anthroarm.errors.AmbiguousToolError` listing them.
    info : URDFInfo, optional
        The validated URDF the model was built from (yourdfpy and the viewer read it).
    spec : ChainSpec, optional
        The parameter table a book model was generated from.
    locked : dict, optional
        Joints locked out of the model and their values (record only).
    visual_model, collision_model : pin.GeometryModel, optional
        Geometry of a model given as a ``pin.Model`` / ``RobotWrapper``.
    """

    #: the map from q to the Pinocchio configuration of a model whose joints are coupled by
    #: nonlinear functions (an OpenSim model: :class:`anthroarm.osim.coupling.Coupling`, with
    #: ``fk``/``jacobian`` by the chain rule); None for every other robot
    coupling = None

    def __init__(
        self,
        model,
        *,
        name: str | None = None,
        tool: str | None = None,
        info: URDFInfo | None = None,
        spec=None,
        description: str = "",
        locked: dict | None = None,
        visual_model=None,
        collision_model=None,
    ):
        self.info = info
        self.name = name or (info.robot_name if info is not None else "") or model.name or "robot"
        self.spec = spec
        self.description = description
        self.locked: dict = dict(locked or {})
        self.model: pin.Model = model
        self.visual_model = visual_model
        self.collision_model = collision_model
        self.chain: Chain = Chain.from_model(model, tool=tool, name=self.name)
        self.tool = self.chain.tool
        self.tool_id = self.chain.tool_frame
        self._local = threading.local()
        self._derived: dict = {}  # key -> (chain, tool, value): see derived()

    @property
    def data(self) -> pin.Data:
        """``pin.Data`` of the calling thread (one per thread, created on first use)."""
        d = getattr(self._local, "data", None)
        if d is None:
            d = self._local.data = self.model.createData()
        return d

    def derived(self, key: str, make):
        """What an algorithm derives from this robot once — a closed-form plan, a solver, a
        workspace — made by ``make(robot)`` on first use and kept on the robot: dropped with it
        (no module-level table outlives a robot) and made again when ``robot.chain`` or
        ``robot.tool`` change.  ``key`` names the owner (``"ik.geometric.plan"``).

        Thread-safe without a lock: two threads asking at once may both make it; the last one
        made is kept and each caller gets a valid value (``make`` must be pure)."""
        hit = self._derived.get(key)
        if hit is not None and hit[0] is self.chain and hit[1] == self.tool:
            return hit[2]
        value = make(self)
        self._derived[key] = (self.chain, self.tool, value)
        return value

    # ------------------------------------------------------------------ identity
    def __repr__(self) -> str:
        return f"Robot({self.name!r}, nq={self.nq}, tool={self.tool!r})"

    @property
    def nq(self) -> int:
        return self.model.nq

    @property
    def nv(self) -> int:
        return self.model.nv

    @property
    def tips(self) -> tuple[str, ...]:
        """One frame per leaf of the kinematic tree (see :func:`anthroarm.chain.leaf_frames`)."""
        return self.chain.tips

    @property
    def has_mimic(self) -> bool:
        return self.chain.has_mimic

    @cached_property
    def joint_names(self) -> list[str]:
        """Names of the joints that carry configuration variables, in q order (mimic joints,
        which have none, are left out; a continuous joint is named once for its two entries)."""
        return [self.chain.joints[i].name for i in self.chain.independent]

    @property
    def lower(self) -> np.ndarray:
        """Lower joint limits in q order (rad for revolute, m for prismatic joints; −1 for a
        continuous joint's (cos, sin) entries); read-only."""
        return self.chain.lower

    @property
    def upper(self) -> np.ndarray:
        """Upper joint limits in q order (rad / m; +1 for (cos, sin) entries); read-only."""
        return self.chain.upper

    @property
    def velocity_limit(self) -> np.ndarray:
        """Joint velocity limits (nv,) from the model (rad/s or m/s); read-only."""
        return self.chain.velocity_limit

    @cached_property
    def frame_names(self) -> list[str]:
        return [f.name for f in self.chain.frames]

    def frame_id(self, frame: str | None) -> int:
        """Index of a frame; ``None`` means the tool.  Unknown names raise
        :class:`UnknownFrameError` listing the valid ones."""
        if frame is None:
            return self.tool_id
        return self.chain.frame(frame).index

    @property
    def length_scale(self) -> float:
        """A bound on the reach of the tool (m, :meth:`anthroarm.chain.Chain.reach`), at least
        1 mm: the scale of relative position tolerances."""
        return max(self.chain.reach(), 1e-3)

    # ------------------------------------------------------------------ configurations
    def neutral(self) -> np.ndarray:
        """Neutral configuration (θ = 0 for every joint), clipped into the joint limits."""
        q = pin.neutral(self.model)
        return np.clip(q, self.lower, self.upper)

    def check_q(self, q, name: str = "q") -> np.ndarray:
        """Validate a configuration or a batch ``(N, nq)``; returns a float array.

        Raises :class:`~anthroarm.errors.ParameterError` (a ``ValueError`` and a ``TypeError``)
        for entries that are not real numbers, a wrong shape, a NaN/inf value (naming the joint)
        or a continuous joint whose (cos, sin) pair is not a unit vector."""
        names = list(self.chain.q_names)
        if q is None:
            raise ParameterError(
                f"{self.name}: {name} is None; give {self.nq} joint values (rad or m) "
                f"for q entries {names}"
            )
        try:
            if _has_text(q):  # numpy would parse "0.1" and turn None into NaN
                raise TypeError("holds text or None")
            arr = np.asarray(q, dtype=float)
        except (TypeError, ValueError) as exc:
            raise ParameterError(
                f"{self.name}: {name} must be real numbers (rad or m), shape ({self.nq},) or "
                f"(N, {self.nq}) for q entries {names}; got {_short(q)} ({exc})"
            ) from None
        if arr.ndim not in (1, 2) or arr.shape[-1] != self.nq:
            raise ParameterError(
                f"{self.name}: {name} must have shape ({self.nq},) or (N, {self.nq}) "
                f"for q entries {names}, got shape {arr.shape}"
            )
        bad = ~np.isfinite(arr)
        if bad.any():
            idx = np.argwhere(bad)[0]
            j = int(idx[-1])
            where = f" (row {int(idx[0])})" if arr.ndim == 2 else ""
            raise ParameterError(
                f"{self.name}: {name}[{j}] for joint {names[j]!r} is {arr[tuple(idx)]}{where}; "
                f"joint values must be finite (rad or m)"
            )
        if self.chain.has_continuous:
            try:
                self.chain.check_unit(arr, name)
            except ParameterError:
                raise
            except ValueError as exc:  # Chain.check_unit names the robot, the joint and the norm
                raise ParameterError(str(exc)) from None
        return arr

    def within_limits(self, q, tol: float = 0.0) -> np.ndarray | bool:
        """True where ``lower - tol <= q <= upper + tol`` for every joint; one bool for ``(nq,)``,
        an ``(N,)`` array for a batch."""
        q = self.check_q(q)
        ok = (q >= self.lower - tol) & (q <= self.upper + tol)
        return ok.all(axis=-1)

    def random_q(self, n: int | None = None, rng=None, margin: float = 0.0) -> np.ndarray:
        """Uniform random configurations inside the limits (``margin`` rad/m away from them).
        Unbounded joints are drawn in [-π, π] (a continuous joint: the angle, then its
        (cos, sin))."""
        return self.chain.random_q(n, rng, margin)

    def angles(self, q) -> np.ndarray:
        """Joint positions θ of every joint (rad or m), mimic joints included: see
        :meth:`anthroarm.chain.Chain.angles`."""
        return self.chain.angles(self.check_q(q))

    # ------------------------------------------------------------------ kinematics
    def fk(self, q, frame=None) -> np.ndarray:
        """World pose (4×4, SE(3) homogeneous) of ``frame`` (default: the tool) at ``q``.

        ``(nq,)`` -> ``(4, 4)`` through Pinocchio; a batch ``(N, nq)`` -> ``(N, 4, 4)`` through
        the batched chain (:meth:`anthroarm.chain.Chain.serial`, equal to Pinocchio to 1e-15)."""
        q = self.check_q(q)
        fid = self.frame_id(frame)
        if q.ndim == 1:
            data = self.data
            pin.framesForwardKinematics(self.model, data, q)
            return data.oMf[fid].homogeneous.copy()
        return self.chain.serial(fid).fk(q)

    def jacobian(self, q, frame=None, reference: str = "LOCAL_WORLD_ALIGNED") -> np.ndarray:
        """Frame Jacobian, 6 × nv, rows (v; ω).  Default reference LOCAL_WORLD_ALIGNED: the
        velocity of the frame origin and the angular velocity, both in world axes.
        ``reference`` may be "LOCAL", "WORLD" or "LOCAL_WORLD_ALIGNED".  Batches ``(N, nq)``
        give ``(N, 6, nv)``; LOCAL_WORLD_ALIGNED batches go through the batched chain."""
        q = self.check_q(q)
        fid = self.frame_id(frame)
        ref = _reference_frame(reference)
        if q.ndim == 1:
            return pin.computeFrameJacobian(self.model, self.data, q, fid, ref).copy()
        if ref == LWA:
            return self.chain.serial(fid).jacobian(q)
        data = self.data
        out = np.empty((q.shape[0], 6, self.nv))
        for i, qi in enumerate(q):
            out[i] = pin.computeFrameJacobian(self.model, data, qi, fid, ref)
        return out

    # ------------------------------------------------------------------ yourdfpy
    @cached_property
    def urdf(self):
        """The same URDF loaded with yourdfpy (lazy; meshes are not loaded).  Robots loaded
        from a ``pin.Model`` have no URDF: :class:`UnsupportedModelError`."""
        import yourdfpy

        if self.info is None:
            raise UnsupportedModelError(
                f"{self.name} was loaded from a pin.Model: it has no URDF for yourdfpy"
            )
        # the validated text, never the file again (it may have changed since it was validated);
        # mesh URIs go through the same resolution as the loader's (filename_handler)
        return yourdfpy.URDF.load(
            io.BytesIO(self.info.text.encode("utf-8")),
            build_scene_graph=True,
            load_meshes=False,
            build_collision_scene_graph=False,
            load_collision_meshes=False,
            filename_handler=self._filename_handler,
        )

    def _filename_handler(self, fname: str) -> str:
        return str(resolve_uri(fname, self.info.path, self.info.package_dirs))

    def yourdfpy_cfg(self, q) -> dict:
        """Map a configuration to yourdfpy's actuated-joint configuration by joint name.

        Locked joints get their locked value; a continuous joint its angle; mimic joints are
        not actuated in yourdfpy, which computes them from the joint they mimic, as Pinocchio
        does (the model is built with ``mimic=True`` when the URDF has mimic joints)."""
        q = self.check_q(q)
        theta = self.chain.angles(q)
        u = self.urdf
        values = {}
        for name, v in self.locked.items():
            v = np.atleast_1d(v)
            values[name] = float(np.arctan2(v[1], v[0])) if v.size == 2 else float(v[0])
        for j in self.chain.joints:
            if not j.is_mimic:
                values[j.name] = float(theta[j.index])
        return {jn: values.get(jn, 0.0) for jn in u.actuated_joint_names}


def _as_model_source(obj):
    """(model, visual, collision) of a pin.Model / RobotWrapper / (model, collision, visual)
    tuple as ``pin.buildModelsFromUrdf`` returns it, or None."""
    if isinstance(obj, pin.Model):
        return obj, None, None
    if hasattr(obj, "model") and isinstance(getattr(obj, "model"), pin.Model):  # RobotWrapper
        return obj.model, getattr(obj, "visual_model", None), getattr(obj, "collision_model", None)
    return None


def load(
    source,
    *,
    tool: str | None = None,
    active=None,
    locked=None,
    package_dirs=None,
    check_meshes: bool = True,
    name: str | None = None,
    visual_model=None,
    collision_model=None,
    **params,
) -> Robot:
    """Load a robot.

    ``source`` is one of

    * a catalog name (:func:`anthroarm.models.names`); a book model takes its builder's
      parameters as keywords (``height=1.62, sex="female"`` ...);
    * any example-robot-data robot by name (``"ur10"``, ``"xarm7"``, ``"kinova"``, ``"baxter"``;
      :func:`anthroarm.models.erd_names`), read offline from the installed package;
    * a URDF path;
    * an OpenSim model path ``*.osim`` (:func:`anthroarm.osim.load_osim`; ``strict=True``
      refuses a model whose import report drops anything);
    * a ``pin.Model`` (with ``visual_model=`` / ``collision_model=`` if you have them) or a
      ``pin.RobotWrapper``.

    Keywords: ``tool=`` the default frame (a tree with several tips needs it: the error lists
    ``robot.tips``); ``active=`` joints to keep (all others locked); ``locked=`` joints to
    freeze (a list of names, or a dict name → value in rad / m); ``package_dirs=`` where
    ``package://`` URIs are found, a list of folders (Pinocchio's convention) or a dict
    package name → root; ``name=`` the robot's name.  Any other keyword raises
    :class:`TypeError` unless a book model's builder takes it.

    Raises :class:`~anthroarm.errors.UnknownModelError` (listing the catalog) for an unknown
    name, the typed URDF errors of :func:`~anthroarm.urdf_io.read_urdf` for a bad file and
    :class:`~anthroarm.errors.UnsupportedModelError` for a joint no algorithm here handles
    (free-flyer, spherical, planar: lock it or pick a sub-chain).
    """

    def no_params(what):
        if params:
            raise ParameterError(
                f"{what} takes no parameters; unknown keyword(s): {', '.join(sorted(params))}"
            )

    if tool is not None and not isinstance(tool, str):
        raise ParameterError(f"tool= is a frame name (str), got {type(tool).__name__} {tool!r}")
    if name is not None and not isinstance(name, str):
        raise ParameterError(f"name= is a str, got {type(name).__name__} {name!r}")
    if not isinstance(check_meshes, bool):
        raise ParameterError(f"check_meshes= is True or False, got {check_meshes!r}")
    common = dict(tool=tool, active=active, locked=locked)
    src = _as_model_source(source)
    if src is not None:
        no_params("a pin.Model")
        if package_dirs is not None:
            raise ParameterError("package_dirs= applies to URDF files, not to a pin.Model")
        model, vis, col = src
        return make_robot(
            model,
            name=name or model.name or "robot",
            info=None,
            visual_model=visual_model or vis,
            collision_model=collision_model or col,
            **common,
        )
    if visual_model is not None or collision_model is not None:
        raise ParameterError("visual_model= / collision_model= go with a pin.Model source")
    if not isinstance(source, (str, Path)):
        raise ParameterError(
            f"load() takes a catalog or example-robot-data name, a URDF path, a pin.Model or a "
            f"RobotWrapper, got {type(source).__name__}"
        )
    s = str(source)
    if s in models.BOOK_MODELS:
        spec = models.spec(s, **params)
        text = models.to_urdf(spec)
        path = models.REPO_URDF_DIR / f"{s}.urdf"
        info = parse_urdf_bytes(
            text.encode(), path, package_dirs=package_dirs, check_meshes=check_meshes
        )
        if params or not path.is_file() or path.read_text(encoding="utf-8") != text:
            # not the committed default file: keep the text only (yourdfpy reads from memory)
            info.path = Path(f"<generated>/{s}.urdf")
        return make_robot(
            build_model(info),
            name=name or s,
            info=info,
            spec=spec,
            description=spec.description,
            tool=tool or spec.tool_name,
            active=active,
            locked=locked,
        )
    if s in models.ERD_ARMS:
        no_params(f"{s} (example-robot-data)")
        arm = models.ERD_ARMS[s]
        info = read_urdf(arm.urdf_path(), package_dirs=package_dirs, check_meshes=check_meshes)
        if active is None and locked is None:
            active, locked = arm.active, arm.locked_values
        return make_robot(
            build_model(info),
            name=name or s,
            info=info,
            tool=tool or arm.tool,
            active=active,
            locked=locked,
            description=arm.description,
        )
    if s in models.erd_names():
        no_params(f"{s} (example-robot-data)")
        info = read_urdf(
            models.erd_urdf_path(s), package_dirs=package_dirs, check_meshes=check_meshes
        )
        return make_robot(
            build_model(info),
            name=name or s,
            info=info,
            description=f"{s} (example-robot-data)",
            **common,
        )
    if s.lower().endswith(".osim"):  # read by anthroarm.load (anthroarm.loading), above osim
        raise ParameterError(f"{s} is an OpenSim model: load it with anthroarm.load")
    looks_like_path = s.endswith(".urdf") or "/" in s or Path(s).exists()
    if not looks_like_path:
        raise models._unknown(s)
    no_params(f"the URDF file {s}")
    info = read_urdf(s, package_dirs=package_dirs, check_meshes=check_meshes)
    return make_robot(build_model(info), name=name or Path(s).stem, info=info, **common)


def make_robot(model, *, name, active=None, locked=None, **kw) -> Robot:
    """The :class:`Robot` of ``model`` (a ``pin.Model``) with only the joints ``active`` kept or
    the joints ``locked`` frozen (:func:`reduce_model`); the other keywords go to
    :class:`Robot`.  No validation of a source: :func:`load` is the way in for a user."""
    model, values = reduce_model(model, name, active, locked)
    return Robot(model, name=name, locked=values, **kw)
