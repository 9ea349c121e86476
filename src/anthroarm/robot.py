"""Robot: one URDF, its Pinocchio model/data, tool frame and joint limits.

>>> import anthroarm as aa
>>> robot = aa.load("prosthetic_arm")
>>> T = robot.fk(robot.neutral())            # 4x4 world pose of the tool (palm centre)
>>> J = robot.jacobian(robot.neutral())      # 6 x nv, LOCAL_WORLD_ALIGNED, rows (v; w)

The URDF text is validated by :func:`anthroarm.urdf_io.read_urdf` and then given to Pinocchio
(``buildModelFromXML``) and, lazily, to yourdfpy, so both read exactly the same text.  Joints
that a catalog entry does not use (the panda's fingers, the rest of the human body) are locked
with ``pin.buildReducedModel``; ``robot.locked`` records their values.
"""

from __future__ import annotations

import io
from functools import cached_property
from pathlib import Path

import numpy as np
import pinocchio as pin

from .errors import UnknownFrameError, UnsupportedModelError, URDFStructureError
from .urdf_io import URDFInfo, parse_urdf_bytes, read_urdf

LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
_REFERENCES = ("LOCAL", "WORLD", "LOCAL_WORLD_ALIGNED")


def _reference_frame(reference) -> pin.ReferenceFrame:
    """``pin.ReferenceFrame`` from its name; ``ValueError`` listing the names otherwise."""
    if isinstance(reference, pin.ReferenceFrame):
        return reference
    if reference not in _REFERENCES:
        raise ValueError(f"reference must be one of {', '.join(_REFERENCES)}, got {reference!r}")
    return getattr(pin.ReferenceFrame, reference)


class Robot:
    """A fixed-base kinematic tree loaded from one URDF.

    Parameters
    ----------
    info : URDFInfo
        Validated URDF (see :func:`anthroarm.urdf_io.read_urdf`).
    name : str
        Catalog name or file stem.
    tool : str, optional
        Frame used when ``frame=None``; default: the last frame of the model.
    active : sequence of str, optional
        Joints kept as degrees of freedom; every other joint is locked at ``locked_values``
        (default 0).  ``None`` keeps all joints.
    spec : ChainSpec, optional
        The parameter table a book model was generated from (closed forms use it).
    """

    def __init__(self, info: URDFInfo, name: str | None = None, tool: str | None = None,
                 active=None, locked_values=None, spec=None, description: str = ""):
        self.info = info
        self.name = name or info.robot_name
        self.spec = spec
        self.description = description
        # Mimic joints: Pinocchio models them (mimic=True) as yourdfpy does, as joints driven by
        # the joint they mimic, so both libraries describe the same mechanism.
        self.has_mimic = any(j["mimic"] is not None for j in info.joints.values())
        try:
            full = pin.buildModelFromXML(info.text, mimic=self.has_mimic)
        except Exception as exc:  # pin raises RuntimeError/ValueError from C++
            raise URDFStructureError(info.path, f"Pinocchio cannot build the model: {exc}") from None
        for j in full.joints[1:]:
            if j.shortname() in ("JointModelFreeFlyer", "JointModelSpherical", "JointModelPlanar"):
                raise UnsupportedModelError(f"{self.name}: joint type {j.shortname()} is not supported (fixed-base serial arms only)")
        self.locked: dict[str, float] = {}
        if active is not None:
            missing = [a for a in active if not full.existJointName(a)]
            if missing:
                raise URDFStructureError(info.path, f"active joints {missing} are not in the model")
            locked_values = dict(locked_values or {})
            lock_ids = []
            qref = pin.neutral(full)
            for jid in range(1, full.njoints):
                jname = full.names[jid]
                if jname not in active:
                    lock_ids.append(jid)
                    v = float(locked_values.get(jname, 0.0))
                    jm = full.joints[jid]
                    if jm.nq == 1:
                        qref[jm.idx_q] = v
                    self.locked[jname] = v
            model = pin.buildReducedModel(full, lock_ids, qref) if lock_ids else full
        else:
            model = full
        self.model: pin.Model = model
        self.data: pin.Data = model.createData()
        self.tool = tool or model.frames[len(model.frames) - 1].name
        self.tool_id = self.frame_id(self.tool)

    # ------------------------------------------------------------------ identity
    def __repr__(self) -> str:
        return f"Robot({self.name!r}, nq={self.nq}, tool={self.tool!r})"

    @property
    def nq(self) -> int:
        return self.model.nq

    @property
    def nv(self) -> int:
        return self.model.nv

    @cached_property
    def joint_names(self) -> list[str]:
        """Names of the joints that carry configuration variables, in q order (mimic joints,
        which have none, are left out)."""
        return [self.model.names[i] for i in range(1, self.model.njoints) if self.model.joints[i].nq > 0]

    @cached_property
    def lower(self) -> np.ndarray:
        """Lower joint limits in q order (rad for revolute, m for prismatic joints); read-only."""
        lo = np.array(self.model.lowerPositionLimit, dtype=float)
        lo.setflags(write=False)
        return lo

    @cached_property
    def upper(self) -> np.ndarray:
        """Upper joint limits in q order (rad / m); read-only."""
        hi = np.array(self.model.upperPositionLimit, dtype=float)
        hi.setflags(write=False)
        return hi

    @cached_property
    def velocity_limit(self) -> np.ndarray:
        """Joint velocity limits from the URDF (rad/s or m/s)."""
        return np.array(self.model.velocityLimit, dtype=float)

    @cached_property
    def frame_names(self) -> list[str]:
        return [f.name for f in self.model.frames]

    def frame_id(self, frame: str | None) -> int:
        """Index of a frame; ``None`` means the tool.  Unknown names raise
        :class:`UnknownFrameError` listing the valid ones."""
        if frame is None:
            return self.tool_id
        if isinstance(frame, (int, np.integer)) and not isinstance(frame, bool):
            if not 0 <= frame < len(self.model.frames):
                raise UnknownFrameError(f"{self.name}: frame index {frame} out of range 0..{len(self.model.frames) - 1}")
            return int(frame)
        if not isinstance(frame, str):
            raise UnknownFrameError(f"{self.name}: a frame is a name or an index, got {frame!r}; "
                                    f"valid frames: {', '.join(self.frame_names)}")
        if not self.model.existFrame(frame):
            raise UnknownFrameError(
                f"{self.name}: unknown frame {frame!r}; valid frames: {', '.join(self.frame_names)}"
            )
        return self.model.getFrameId(frame)

    @property
    def length_scale(self) -> float:
        """Sum of the lengths of every joint placement offset and of the tool offset (m), at
        least 1 mm: a bound on the reach (for a serial chain), used as the scale of relative
        position tolerances."""
        total = 0.0
        for jid in range(1, self.model.njoints):
            total += float(np.linalg.norm(self.model.jointPlacements[jid].translation))
        total += float(np.linalg.norm(self.model.frames[self.tool_id].placement.translation))
        return max(total, 1e-3)

    # ------------------------------------------------------------------ configurations
    def neutral(self) -> np.ndarray:
        """Neutral configuration, clipped into the joint limits."""
        q = pin.neutral(self.model)
        return np.clip(q, self.lower, self.upper)

    def check_q(self, q, name: str = "q") -> np.ndarray:
        """Validate a configuration or a batch ``(N, nq)``; returns a float array.

        Raises ``ValueError`` for a wrong shape or a NaN/inf value (naming the joint)."""
        arr = np.asarray(q, dtype=float)
        if arr.ndim not in (1, 2) or arr.shape[-1] != self.nq:
            raise ValueError(
                f"{self.name}: {name} must have shape ({self.nq},) or (N, {self.nq}) "
                f"for joints {self.joint_names}, got shape {arr.shape}"
            )
        bad = ~np.isfinite(arr)
        if bad.any():
            idx = np.argwhere(bad)[0]
            j = int(idx[-1])
            where = f" (row {int(idx[0])})" if arr.ndim == 2 else ""
            raise ValueError(f"{self.name}: {name}[{j}] for joint {self.joint_names[min(j, len(self.joint_names) - 1)]!r} is {arr[tuple(idx)]}{where}")
        return arr

    def within_limits(self, q, tol: float = 0.0) -> np.ndarray | bool:
        """True where ``lower - tol <= q <= upper + tol`` for every joint; one bool for ``(nq,)``,
        an ``(N,)`` array for a batch."""
        q = self.check_q(q)
        ok = (q >= self.lower - tol) & (q <= self.upper + tol)
        return ok.all(axis=-1)

    def random_q(self, n: int | None = None, rng=None, margin: float = 0.0) -> np.ndarray:
        """Uniform random configurations inside the limits (``margin`` rad/m away from them).
        Unbounded joints are drawn in [-π, π]."""
        rng = np.random.default_rng(rng)
        lo = np.where(np.isfinite(self.lower), self.lower, -np.pi) + margin
        hi = np.where(np.isfinite(self.upper), self.upper, np.pi) - margin
        shape = (self.nq,) if n is None else (n, self.nq)
        return lo + (hi - lo) * rng.random(shape)

    # ------------------------------------------------------------------ kinematics
    def fk(self, q, frame=None) -> np.ndarray:
        """World pose (4×4, SE(3) homogeneous) of ``frame`` (default: the tool) at ``q``.

        Accepts ``(nq,)`` -> ``(4, 4)`` or a batch ``(N, nq)`` -> ``(N, 4, 4)``."""
        q = self.check_q(q)
        fid = self.frame_id(frame)
        if q.ndim == 1:
            pin.framesForwardKinematics(self.model, self.data, q)
            return self.data.oMf[fid].homogeneous.copy()
        out = np.empty((q.shape[0], 4, 4))
        for i, qi in enumerate(q):
            pin.framesForwardKinematics(self.model, self.data, qi)
            out[i] = self.data.oMf[fid].homogeneous
        return out

    def jacobian(self, q, frame=None, reference: str = "LOCAL_WORLD_ALIGNED") -> np.ndarray:
        """Frame Jacobian, 6 × nv, rows (v; ω).  Default reference LOCAL_WORLD_ALIGNED: the
        velocity of the frame origin and the angular velocity, both in world axes.
        ``reference`` may be "LOCAL", "WORLD" or "LOCAL_WORLD_ALIGNED".  Batches give (N, 6, nv)."""
        q = self.check_q(q)
        fid = self.frame_id(frame)
        ref = _reference_frame(reference)
        if q.ndim == 1:
            return pin.computeFrameJacobian(self.model, self.data, q, fid, ref).copy()
        out = np.empty((q.shape[0], 6, self.nv))
        for i, qi in enumerate(q):
            out[i] = pin.computeFrameJacobian(self.model, self.data, qi, fid, ref)
        return out

    # ------------------------------------------------------------------ yourdfpy
    @cached_property
    def urdf(self):
        """The same URDF loaded with yourdfpy (lazy; meshes are not loaded)."""
        import yourdfpy

        return yourdfpy.URDF.load(
            io.StringIO(self.info.text) if not self.info.path.is_file() else str(self.info.path),
            build_scene_graph=True, load_meshes=False, build_collision_scene_graph=False,
            load_collision_meshes=False, filename_handler=self._filename_handler,
        )

    def _filename_handler(self, fname: str) -> str:
        from .urdf_io import resolve_uri

        return str(resolve_uri(fname, self.info.path, self.info.package_dirs))

    def yourdfpy_cfg(self, q) -> dict:
        """Map a configuration to yourdfpy's actuated-joint configuration by joint name.

        Locked joints get their locked value; mimic joints are not actuated in yourdfpy, which
        computes them from the joint they mimic, as Pinocchio does (the model is built with
        ``mimic=True`` when the URDF has mimic joints)."""
        q = self.check_q(q)
        u = self.urdf
        values = dict(self.locked)
        for name, v in zip(self.joint_names, q):
            values[name] = float(v)
        return {jn: values.get(jn, 0.0) for jn in u.actuated_joint_names}


def load(name_or_path, *, tool: str | None = None, package_dirs: dict | None = None,
         check_meshes: bool = True, **params) -> Robot:
    """Load a catalog model by name (with optional builder ``params``, e.g. ``height=1.62``)
    or a URDF file by path.

    Raises :class:`~anthroarm.errors.UnknownModelError` (listing the catalog) for an unknown
    name, and the typed URDF errors of :func:`~anthroarm.urdf_io.read_urdf` for a bad file.
    """
    from . import models

    s = str(name_or_path)
    if s in models.BOOK_MODELS:
        spec = models.spec(s, **params)
        text = models.to_urdf(spec)
        path = models.REPO_URDF_DIR / f"{s}.urdf"
        info = parse_urdf_bytes(text.encode(), path, package_dirs=package_dirs, check_meshes=check_meshes)
        if params or not path.is_file() or path.read_text(encoding="utf-8") != text:
            # not the committed default file: keep the text only (yourdfpy reads from memory)
            info.path = Path(f"<generated>/{s}.urdf")
        return Robot(info, name=s, tool=tool or spec.tool_name, spec=spec, description=spec.description)
    if s in models.ERD_ARMS:
        if params:
            raise ValueError(f"{s}: example-robot-data arms take no parameters, got {params}")
        arm = models.ERD_ARMS[s]
        info = read_urdf(arm.urdf_path(), package_dirs=package_dirs, check_meshes=check_meshes)
        return Robot(info, name=s, tool=tool or arm.tool, active=arm.active, locked_values=arm.locked_values,
                     description=arm.description)
    looks_like_path = s.endswith(".urdf") or "/" in s or Path(s).exists()
    if not looks_like_path:
        raise models._unknown(s)
    info = read_urdf(s, package_dirs=package_dirs, check_meshes=check_meshes)
    return Robot(info, name=Path(s).stem, tool=tool)
