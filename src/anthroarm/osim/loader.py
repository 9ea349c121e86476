"""``aa.load("model.osim")``: an OpenSim model as a :class:`~anthroarm.robot.Robot`.

:class:`OsimRobot` is a Robot whose configuration is the model's independent coordinates
(named after them).  When every moving transform axis of the model is exactly one coordinate
(arm26, Tug_of_War) the Pinocchio model's q *is* that configuration and ``robot.coupling`` is
None; otherwise (splines, couplers, scaled axes: gait2392's knees) ``robot.coupling`` maps q to
the Pinocchio configuration (:class:`~anthroarm.osim.coupling.Coupling`) and ``fk``,
``jacobian`` and the dynamics (:meth:`OsimRobot.mass_matrix`, :meth:`~OsimRobot.gravity`,
:meth:`~OsimRobot.bias`, :meth:`~OsimRobot.inverse_dynamics`) work in q by the chain rule.
"""

from __future__ import annotations

import tempfile
from functools import cached_property
from pathlib import Path

import numpy as np
import pinocchio as pin

from ..errors import OsimStrictError, OsimUnsupportedError, ParameterError
from ..robot import Robot, reduce_model
from . import xmlread
from .build import build
from .reader import OsimModel, read_model
from .report import KEPT

LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


class OsimRobot(Robot):
    """A :class:`~anthroarm.robot.Robot` read from an OpenSim model (see the module docstring).

    Extra attributes: ``coupling`` (None or the coupling map), ``report`` (the
    :class:`~anthroarm.osim.report.ImportReport`), ``osim`` (the
    :class:`~anthroarm.osim.reader.OsimModel` read: coordinates with their ranges, defaults,
    locked and clamped flags; bodies; markers; credits), ``markers`` (marker frame names)."""

    def __init__(self, model, *, coupling=None, osim: OsimModel, **kw):
        super().__init__(model, **kw)
        self.coupling = coupling
        self.osim = osim
        self.report = osim.report

    # ------------------------------------------------------------------ configuration
    @property
    def nq(self) -> int:
        return self.coupling.nq if self.coupling is not None else self.model.nq

    @property
    def nv(self) -> int:
        return self.nq

    @cached_property
    def joint_names(self) -> list[str]:
        """The independent coordinates, in q order."""
        if self.coupling is None:
            return super().joint_names
        return list(self.coupling.names)

    @property
    def lower(self) -> np.ndarray:
        return self.coupling.lower if self.coupling is not None else super().lower

    @property
    def upper(self) -> np.ndarray:
        return self.coupling.upper if self.coupling is not None else super().upper

    @property
    def velocity_limit(self) -> np.ndarray:
        return np.full(self.nq, np.inf) if self.coupling is not None else super().velocity_limit

    @cached_property
    def markers(self) -> list[str]:
        """The marker frames' names (the model's MarkerSet)."""
        return [mk.name for mk in self.osim.markers]

    @property
    def osim_markers(self) -> list[str]:
        """:attr:`markers` (the name :func:`anthroarm.motion.osim_marker_set` reads)."""
        return self.markers

    @cached_property
    def osim_coordinates(self) -> dict:
        """name -> the OpenSim coordinate (range, default, locked, clamped, dependent)."""
        return {c.name: c for c in self.osim.coordinates}

    def default_q(self) -> np.ndarray:
        """The model's default pose: each coordinate's ``default_value``, in q order."""
        c = self.osim_coordinates
        return np.array([c[n].default for n in self.joint_names])

    def neutral(self) -> np.ndarray:
        if self.coupling is None:
            return super().neutral()
        return np.clip(np.zeros(self.nq), self.lower, self.upper)

    def check_q(self, q, name: str = "q") -> np.ndarray:
        if self.coupling is None:
            return super().check_q(q, name)
        try:
            arr = np.asarray(q, dtype=float)
            if isinstance(q, (str, bytes)) or arr.dtype.kind not in "fiu":
                raise TypeError("not numbers")
        except (TypeError, ValueError) as exc:
            raise ParameterError(
                f"{self.name}: {name} must be real numbers, shape ({self.nq},) or (N, {self.nq}) "
                f"for coordinates {self.joint_names}; got {q!r:.80} ({exc})"
            ) from None
        if arr.ndim not in (1, 2) or arr.shape[-1] != self.nq:
            raise ParameterError(
                f"{self.name}: {name} must have shape ({self.nq},) or (N, {self.nq}) for "
                f"coordinates {self.joint_names}, got shape {arr.shape}"
            )
        if not np.all(np.isfinite(arr)):
            idx = np.argwhere(~np.isfinite(arr))[0]
            raise ParameterError(
                f"{self.name}: {name}[{int(idx[-1])}] for coordinate "
                f"{self.joint_names[int(idx[-1])]!r} is not finite"
            )
        return arr

    def random_q(self, n: int | None = None, rng=None, margin: float = 0.0) -> np.ndarray:
        if self.coupling is None:
            return super().random_q(n, rng, margin)
        rng = np.random.default_rng(rng)
        lo, hi = self.lower + margin, self.upper - margin
        shape = (self.nq,) if n is None else (int(n), self.nq)
        return lo + (hi - lo) * rng.random(shape)

    def angles(self, q) -> np.ndarray:
        """The value of every Pinocchio joint (rad or m): φ(q) with a coupling (one per moving
        transform axis, in Pinocchio's joint order), :meth:`Robot.angles
        <anthroarm.robot.Robot.angles>` without."""
        if self.coupling is None:
            return super().angles(q)
        return self.coupling.full(self.check_q(q))

    def full_q(self, q) -> np.ndarray:
        """The Pinocchio configuration φ(q) (q itself without a coupling)."""
        q = self.check_q(q)
        return q.copy() if self.coupling is None else self.coupling.full(q)

    # ------------------------------------------------------------------ kinematics
    def fk(self, q, frame=None) -> np.ndarray:
        if self.coupling is None:
            return super().fk(q, frame)
        qf = self.coupling.full(self.check_q(q))
        fid = self.frame_id(frame)
        if qf.ndim == 1:
            pin.framesForwardKinematics(self.model, self.data, qf)
            return self.data.oMf[fid].homogeneous.copy()
        return self.chain.serial(fid).fk(qf)

    def jacobian(self, q, frame=None, reference: str = "LOCAL_WORLD_ALIGNED") -> np.ndarray:
        """Frame Jacobian in the independent coordinates, J(φ(q)) · G(q) (chain rule), 6 × nq,
        rows (v; ω); references as :meth:`anthroarm.robot.Robot.jacobian`."""
        if self.coupling is None:  # Pinocchio gives (6,) for one joint: always (6, nv)
            J = super().jacobian(q, frame, reference)
            return J.reshape(J.shape[:-1] + (6, self.nv)) if J.shape[-1] != self.nv else J
        q = self.check_q(q)
        fid = self.frame_id(frame)
        qf, G = self.coupling.jacobian(q)
        if q.ndim == 2 and reference == "LOCAL_WORLD_ALIGNED":
            return np.einsum("nij,njk->nik", self.chain.serial(fid).jacobian(qf), G)
        ref = getattr(pin.ReferenceFrame, reference) if isinstance(reference, str) else reference
        if q.ndim == 1:
            return pin.computeFrameJacobian(self.model, self.data, qf, fid, ref) @ G
        return np.stack(
            [
                pin.computeFrameJacobian(self.model, self.data, a, fid, ref) @ g
                for a, g in zip(qf, G)
            ]
        )

    # ------------------------------------------------------------------ dynamics
    def mass_matrix(self, q) -> np.ndarray:
        """M(q) in the independent coordinates: Gᵀ M_pin(φ(q)) G (``pin.crba``), nq × nq."""
        q = self.check_q(q)
        qf, G = self._phi_G(q)
        M = pin.crba(self.model, self.data, qf)
        M = np.triu(M) + np.triu(M, 1).T
        return G.T @ M @ G

    def gravity(self, q) -> np.ndarray:
        """Generalized gravity g(q) = Gᵀ g_pin(φ(q)) (``pin.computeGeneralizedGravity``), the
        torques that hold the model still against gravity (N m or N)."""
        q = self.check_q(q)
        qf, G = self._phi_G(q)
        return G.T @ pin.computeGeneralizedGravity(self.model, self.data, qf)

    def bias(self, q, qd) -> np.ndarray:
        """Velocity and gravity terms h(q, q̇) = Gᵀ (M_pin Ġq̇ + b_pin(φ, G q̇)) so that
        τ = M(q) q̈ + h (``pin.rnea`` with the acceleration Ġq̇)."""
        return self.inverse_dynamics(q, qd, np.zeros(self.nq))

    def inverse_dynamics(self, q, qd, qdd) -> np.ndarray:
        """τ = Gᵀ rnea(φ(q), G q̇, G q̈ + Ġq̇): the generalized forces in the independent
        coordinates that produce the motion (q, q̇, q̈) (N m or N)."""
        q = self.check_q(q)
        qd = self.check_q(qd, "qd")
        qdd = self.check_q(qdd, "qdd")
        if self.coupling is None:
            return pin.rnea(self.model, self.data, q, qd, qdd).copy()
        qf, G, b = self.coupling.second(q, qd)
        tau = pin.rnea(self.model, self.data, qf, G @ qd, G @ qdd + b)
        return G.T @ tau

    def _phi_G(self, q):
        if q.ndim != 1:
            raise ParameterError(f"{self.name}: one configuration ({self.nq},) at a time")
        if self.coupling is None:
            return q, np.eye(self.nq)
        return self.coupling.jacobian(q)


def read(path) -> OsimModel:
    """Parse and read ``path`` (typed errors as :func:`load_osim`).  A 3.x model (document
    version below 40000) is first brought to 4.x by OpenSim's own updater when the ``opensim``
    package is installed (:func:`upgrade`); without it, the error names the remedy."""
    model_el, version = xmlread.parse(path)
    if version >= 40000:
        return read_model(model_el, version, path)
    text = upgrade(path, version)
    model_el, new_version = xmlread.parse_bytes(text, path)
    m = read_model(model_el, new_version, path)
    m.report.add(
        "/",
        "OpenSimDocument",
        KEPT,
        f"a {version // 10000}.x model (version {version}) read after OpenSim's updater "
        "(opensim.Model(path).printToXML): line numbers are those of the updated text",
        1,
    )
    return m


def upgrade(path, version: int) -> bytes:
    """The 4.x text of a 3.x model, written by OpenSim's updater (``opensim.Model(path)``, then
    ``printToXML``) into a temporary folder.  Without ``opensim``:
    :class:`~anthroarm.errors.OsimUnsupportedError` naming the remedy."""
    remedy = (
        f"an OpenSim {version // 10000}.x model (document version {version}); the import reads "
        "4.x models: open and save it in OpenSim 4, or run "
        "opensim.Model(path).printToXML(new_path) (OpenSim's updater; with the opensim package "
        "installed, aa.load does this itself)"
    )
    try:
        import opensim
    except ImportError:
        raise OsimUnsupportedError(path, remedy, "<OpenSimDocument>", 1) from None
    opensim.Logger.setLevelString("error")
    opensim.Logger.removeFileSink()
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "updated.osim"
        try:
            opensim.Model(str(Path(path).resolve())).printToXML(str(out))
            return out.read_bytes()
        except Exception as exc:  # OpenSim's C++ exceptions arrive as RuntimeError
            raise OsimUnsupportedError(
                path,
                f"{remedy}; OpenSim's updater failed: {' '.join(str(exc).split())[:300]}",
                "<OpenSimDocument>",
                1,
            ) from None


def load_osim(
    path,
    *,
    tool: str | None = None,
    name: str | None = None,
    strict: bool = False,
    active=None,
    locked=None,
) -> OsimRobot:
    """Read an OpenSim 4.x model (``.osim``) into an :class:`OsimRobot`.

    ``tool=`` the default frame (default: the last body of the BodySet); ``strict=True``
    raises :class:`~anthroarm.errors.OsimStrictError` when the import report lists anything
    as dropped or approximated (muscles, wrap objects, geometry ...).  ``active=`` /
    ``locked=`` are for models without a coupling (see :func:`anthroarm.load`).

    Raises :class:`~anthroarm.errors.OsimError` (naming the element and its line) for a
    malformed or inconsistent model, :class:`~anthroarm.errors.OsimSecurityError` for DTDs /
    entities, :class:`~anthroarm.errors.OsimUnsupportedError` for a construct the import does not
    represent (naming the remedy).
    """
    m = read(path)
    if strict:
        bad = [r for r in m.report.rows if r.status != KEPT]
        if bad:
            r = bad[0]
            raise OsimStrictError(
                path,
                f"strict=True and the import report lists {len(bad)} component(s) as not kept, "
                f"first {r.component} ({r.type}: {r.status}, {r.why})",
                r.component,
                r.line,
            )
    model, coupling, _ = build(m)
    bodies = [b for b in m.bodies if b != m.ground]
    tool = tool or (bodies[-1] if bodies else m.ground)
    name = name or Path(str(path)).stem
    desc = f"OpenSim model {m.name} ({Path(str(path)).name})"
    if coupling is not None:
        if active is not None or locked:
            raise ParameterError(
                f"{name}: active=/locked= are not available for a model with coupled "
                "coordinates; fix coordinates by their values in q instead"
            )
        return OsimRobot(model, coupling=coupling, osim=m, name=name, tool=tool, description=desc)
    model, values = reduce_model(model, name, active, locked)
    out = OsimRobot(
        model,
        coupling=None,
        osim=m,
        name=name,
        tool=tool,
        description=desc,
        locked=values,
    )
    return out
