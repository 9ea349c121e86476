"""The rows of ``anthroarm check model.osim``: the import against Pinocchio and mathematics
(always) and against OpenSim itself (when the ``opensim`` package is installed).

Pinocchio rows: the batched FK of every body equal to Pinocchio's one-configuration FK at φ(q);
the Jacobian J·G equal to central differences of the FK; the mass matrix Gᵀ M G equal to the
columns of the inverse dynamics (``pin.rnea``); G and Ġq̇ of the coupling equal to central
differences of φ.

OpenSim rows (``opensim`` 4.x): every body's pose (``Body.getTransformInGround``), every marker
(``Marker.getLocationInGround``), the mass matrix (``SimbodyMatterSubsystem.calcM``), gravity
and inverse dynamics (``InverseDynamicsSolver``), in the independent coordinates.  OpenSim works
in mobility order and keeps a coupled coordinate as a mobility of its own: a coordinate's
mobility is found by giving it alone a speed, and mobility quantities are projected with
C = du/dq̇ built from OpenSim's own coupler functions (Mᵢ = Cᵀ M C, τᵢ = Cᵀ τ).

The muscles' rows (lengths and moment arms against OpenSim's ``getLength`` /
``computeMomentArm`` and against central differences of our lengths) are made by
:func:`anthroarm.muscles.checks.rows` with :class:`OpenSimModel` below, and added by
``anthroarm check`` after these: this model-layer module does not import the algorithms.
"""

from __future__ import annotations

import numpy as np

from ..check_rows import CheckRow
from ..errors import OsimError


def rows(robot, samples: int, rng) -> list[CheckRow]:
    """Pinocchio rows, and OpenSim rows when ``opensim`` imports, for an imported OpenSim
    model (``[]`` for any other robot)."""
    if getattr(robot, "osim", None) is None:
        return []
    out = pinocchio_rows(robot, samples, rng)
    try:
        import opensim  # noqa: F401  (optional: the oracle)
    except ImportError:
        return out
    return out + opensim_rows(robot, min(int(samples), 200), rng)


def nonlinear(f) -> bool:
    """A function that is neither constant nor linear (a spline, a polynomial ...)."""
    if f.kind == "MultiplierFunction":
        return nonlinear(f.inner)
    return f.kind not in ("Constant", "LinearFunction")


def has_splines(robot) -> bool:
    """The issue's test of tolerance: poses to 1e-12 where every transform is constant or
    linear, 1e-9 where one is nonlinear (splines)."""
    c = robot.coupling
    if c is None:
        return False
    return any(nonlinear(s.function) for s in (*c.joint_steps, *c.dependent_steps))


def _bodies(robot) -> list[str]:
    return [b for b in robot.osim.bodies]


def pinocchio_rows(robot, samples: int, rng) -> list[CheckRow]:
    n = max(2, min(int(samples), 200))
    name, Q = robot.name, robot.random_q(n, rng)
    e_fk = 0.0
    for b in _bodies(robot):
        Tb = robot.fk(Q, b)
        for i in range(0, n, max(1, n // 10)):
            e_fk = max(e_fk, float(np.abs(Tb[i] - robot.fk(Q[i], b)).max()))
    h, e_j, e_m, e_g, e_b = 1e-6, 0.0, 0.0, 0.0, 0.0
    frames = _bodies(robot)[-3:] + robot.markers[:3]
    for q in Q[: min(n, 10)]:
        for f in frames:
            J = robot.jacobian(q, f)
            cols = [
                (robot.fk(q + h * e, f)[:3, 3] - robot.fk(q - h * e, f)[:3, 3]) / (2 * h)
                for e in np.eye(robot.nq)
            ]
            e_j = max(e_j, float(np.abs(J[:3] - np.column_stack(cols)).max()))
        z = np.zeros(robot.nq)
        g = robot.inverse_dynamics(q, z, z)
        Mr = np.column_stack([robot.inverse_dynamics(q, z, e) - g for e in np.eye(robot.nq)])
        M = robot.mass_matrix(q)
        e_m = max(e_m, float(np.abs(M - Mr).max() / max(1.0, np.abs(M).max())))
        if robot.coupling is not None:
            qd = rng.normal(size=robot.nq)
            _, G, b = robot.coupling.second(q, qd)
            fd = [
                (robot.coupling.full(q + h * e) - robot.coupling.full(q - h * e)) / (2 * h)
                for e in np.eye(robot.nq)
            ]
            e_g = max(e_g, float(np.abs(G - np.column_stack(fd)).max()))
            Gp = robot.coupling.jacobian(q + h * qd)[1]
            Gm = robot.coupling.jacobian(q - h * qd)[1]
            e_b = max(e_b, float(np.abs(b - (Gp - Gm) / (2 * h) @ qd).max()))
    out = [
        CheckRow(name, "osim FK batched = pin FK(phi(q))", e_fk, 1e-12, n),
        CheckRow(name, "osim J G = dFK/dq (central diff.)", e_j, 1e-6, 10, "mathematics"),
        CheckRow(name, "osim M = columns of rnea (rel.)", e_m, 1e-9, 10),
    ]
    if robot.coupling is not None:
        out += [
            CheckRow(name, "osim G = dphi/dq (central diff.)", e_g, 1e-6, 10, "mathematics"),
            CheckRow(name, "osim Gdot qd (central diff.)", e_b, 1e-5, 10, "mathematics"),
        ]
    return out


class OpenSimModel:
    """OpenSim's side of every comparison with OpenSim (this module's rows, the muscle rows of
    :mod:`anthroarm.muscles.checks`, the tests): the model read by ``opensim.Model``, its forces
    switched off (``set_appliesForce(False)``: gravity and inertia only in the dynamics; a
    muscle's path is geometry and stays), set to states given in the robot's independent
    coordinates ``names``.

    :meth:`set_state` gives every coordinate its value, rate and acceleration: a dependent
    coordinate of a ``CoordinateCouplerConstraint`` y = s f(x) gets ẏ = s f'(x) ẋ and
    ÿ = s (f'(x) ẍ + f''(x) ẋ²) from OpenSim's own function, and its row of C = du/dq̇ is
    s f'(x) times that of x (module docstring); a locked coordinate keeps its default value.
    The readers (:meth:`poses`, :meth:`markers`, :meth:`mass_matrix`, :meth:`inverse_dynamics`,
    :meth:`lengths`, :meth:`moment_arm`, :meth:`current_path`) then read OpenSim at that state.

    Attributes: ``osim`` (the module), ``model``, ``state``, ``coords`` (name -> Coordinate, all
    of the model's), ``names``, ``couplers``, ``nu`` (Simbody's mobilities), ``u_index``
    (coordinate name -> mobility), ``muscles`` (the model's muscles, in its order).
    """

    def __init__(self, path, names):
        import opensim as osim

        osim.Logger.setLevelString("error")
        osim.Logger.removeFileSink()  # no opensim.log beside the model (OpenSim loads from its folder)
        self.osim = osim
        self.model = model = osim.Model(str(path))
        fs = model.getForceSet()
        for i in range(fs.getSize()):
            fs.get(i).set_appliesForce(False)
        self.state = s = model.initSystem()
        cs = model.getCoordinateSet()
        self.coords = {cs.get(i).getName(): cs.get(i) for i in range(cs.getSize())}
        self.names = list(names)
        missing = [nm for nm in self.names if nm not in self.coords]
        if missing:
            raise OsimError(path, f"coordinates not in the model: {', '.join(missing)}")
        self.couplers = {}
        cons = model.getConstraintSet()
        for i in range(cons.getSize()):
            c = osim.CoordinateCouplerConstraint.safeDownCast(cons.get(i))
            if c is not None and c.get_isEnforced():
                scale = osim.PropertyHelper.getValueDouble(c.getPropertyByName("scale_factor"))
                ind = c.getIndependentCoordinateNames().get(0)
                self.couplers[c.getDependentCoordinateName()] = (ind, c.getFunction(), scale)
        self.nu = s.getNU()
        self.u_index = {}
        for nm, c in self.coords.items():
            for other in self.coords.values():
                other.setSpeedValue(s, 0.0)
            c.setSpeedValue(s, 1.0)
            self.u_index[nm] = int(np.argmax([s.getU().get(k) for k in range(self.nu)]))
        for c in self.coords.values():
            c.setSpeedValue(s, 0.0)
        self.ids = osim.InverseDynamicsSolver(model)
        ms = model.getMuscles()
        self.muscles = [ms.get(i) for i in range(ms.getSize())]

    def _f(self, f, x, order):
        v = self.osim.Vector(1, float(x))
        if order == 0:
            return f.calcValue(v)
        # a list, converted by SWIG's sequence typemap: an opensim.StdVectorInt (moco's class) was
        # refused with a TypeError by common's Function.calcDerivative in some test processes
        return f.calcDerivative([0] * order, v)

    def set_state(self, q, qd=None, qdd=None):
        """Set the state to coordinates ``q``, rates ``qd`` and accelerations ``qdd`` (zero
        when None) and realize it to velocity: (C = du/dq̇ of shape (nu, n), the mobility
        accelerations u̇)."""
        n = len(self.names)
        z = np.zeros(n)
        val, rate, acc = (
            dict(zip(self.names, q)),
            dict(zip(self.names, z if qd is None else qd)),
            dict(zip(self.names, z if qdd is None else qdd)),
        )
        row = {nm: np.eye(n)[i] for i, nm in enumerate(self.names)}
        todo = [d for d in self.couplers if d not in val]
        for _ in range(len(todo) + 1):
            for d in [d for d in todo if self.couplers[d][0] in val]:
                src, f, sc = self.couplers[d]
                f0, f1, f2 = (self._f(f, val[src], k) for k in range(3))
                val[d], rate[d] = sc * f0, sc * f1 * rate[src]
                acc[d] = sc * (f1 * acc[src] + f2 * rate[src] ** 2)
                row[d] = sc * f1 * row[src]
                todo.remove(d)
        for nm, c in self.coords.items():
            if nm in val:  # a locked coordinate keeps its default value
                c.setValue(self.state, float(val[nm]), False)
                c.setSpeedValue(self.state, float(rate[nm]))
        self.model.realizeVelocity(self.state)
        C = np.zeros((self.nu, n))
        udot = np.zeros(self.nu)
        for nm, r in row.items():
            C[self.u_index[nm]] = r
        for nm in self.coords:
            udot[self.u_index[nm]] = acc.get(nm, 0.0)
        return C, udot

    def poses(self) -> dict:
        """Every body's pose in ground (``Body.getTransformInGround``): name -> 4×4."""
        bs, out = self.model.getBodySet(), {}
        for i in range(bs.getSize()):
            T = bs.get(i).getTransformInGround(self.state)
            H = np.eye(4)
            H[:3, :3] = [[T.R().get(r, c) for c in range(3)] for r in range(3)]
            H[:3, 3] = [T.p().get(k) for k in range(3)]
            out[bs.get(i).getName()] = H
        return out

    def markers(self) -> dict:
        """Every marker's position in ground (``Marker.getLocationInGround``): name -> (3,)."""
        ms, out = self.model.getMarkerSet(), {}
        for i in range(ms.getSize()):
            p = ms.get(i).getLocationInGround(self.state)
            out[ms.get(i).getName()] = np.array([p.get(k) for k in range(3)])
        return out

    def mass_matrix(self, C) -> np.ndarray:
        """The mass matrix in the independent coordinates, Cᵀ M C (M by
        ``SimbodyMatterSubsystem.calcM`` in mobility order)."""
        M = self.osim.Matrix()
        self.model.getMatterSubsystem().calcM(self.state, M)
        return C.T @ np.array([[M.get(r, c) for c in range(self.nu)] for r in range(self.nu)]) @ C

    def inverse_dynamics(self, C, udot) -> np.ndarray:
        """The generalized forces in the independent coordinates, Cᵀ τ (τ by
        ``InverseDynamicsSolver.solve`` at mobility accelerations ``udot``)."""
        tau = self.ids.solve(self.state, self.osim.Vector(udot.tolist()))
        return C.T @ np.array([tau.get(k) for k in range(self.nu)])

    def lengths(self) -> np.ndarray:
        """Every muscle's musculotendon length (``Muscle.getLength``, m), in the model's order."""
        return np.array([m.getLength(self.state) for m in self.muscles])

    def moment_arm(self, i: int, k: int) -> float:
        """Muscle ``i``'s moment arm about the independent coordinate ``names[k]``
        (``Muscle.computeMomentArm``, m)."""
        return self.muscles[i].computeMomentArm(self.state, self.coords[self.names[k]])

    def current_path(self, i: int):
        """Muscle ``i``'s path as OpenSim has it at this state: (points (k, 3) of
        ``GeometryPath.getCurrentPath`` in ground by ``getLocationInGround``, m; their names,
        ``pwpt1``/``pwpt2`` for a wrap's ``PathWrapPoint``\\ s; ``getLength``, m)."""
        gp = self.muscles[i].getGeometryPath()
        cp = gp.getCurrentPath(self.state)
        pts = [cp.get(k) for k in range(cp.getSize())]
        xyz = [p.getLocationInGround(self.state) for p in pts]
        X = np.array([[x[j] for j in range(3)] for x in xyz]).reshape(-1, 3)
        return X, [p.getName() for p in pts], gp.getLength(self.state)

    def moment_arms(self) -> np.ndarray:
        """Every muscle's moment arm about every independent coordinate: (muscles, n), m."""
        n = len(self.names)
        return np.array(
            [[self.moment_arm(i, k) for k in range(n)] for i in range(len(self.muscles))]
        )


def opensim_rows(robot, n: int, rng) -> list[CheckRow]:
    """The OpenSim rows (module docstring) on ``n`` random states."""
    o = OpenSimModel(robot.osim.path, robot.joint_names)
    Q = robot.random_q(n, rng)
    QD, QDD = rng.normal(size=Q.shape), rng.normal(size=Q.shape)
    z = np.zeros(robot.nq)
    err = dict(pose=0.0, marker=0.0, M=0.0, g=0.0, tau=0.0)
    for q, qd, qdd in zip(Q, QD, QDD):
        C, _ = o.set_state(q, z, z)
        for b, H in o.poses().items():
            err["pose"] = max(err["pose"], float(np.abs(robot.fk(q, b) - H).max()))
        for mk, p in o.markers().items():
            err["marker"] = max(err["marker"], float(np.abs(robot.fk(q, mk)[:3, 3] - p).max()))
        Mo, go = o.mass_matrix(C), o.inverse_dynamics(C, np.zeros(o.nu))
        err["M"] = max(
            err["M"], float(np.abs(robot.mass_matrix(q) - Mo).max() / max(1, np.abs(Mo).max()))
        )
        err["g"] = max(
            err["g"], float(np.abs(robot.gravity(q) - go).max() / max(1, np.abs(go).max()))
        )
        C, udot = o.set_state(q, qd, qdd)
        to = o.inverse_dynamics(C, udot)
        tau = robot.inverse_dynamics(q, qd, qdd)
        err["tau"] = max(err["tau"], float(np.abs(tau - to).max() / max(1, np.abs(to).max())))
    tol = 1e-9 if has_splines(robot) else 1e-12
    name, osim = robot.name, "opensim"
    return [
        CheckRow(name, "osim body poses = OpenSim", err["pose"], tol, n, osim),
        CheckRow(name, "osim markers = OpenSim", err["marker"], tol, n, osim),
        CheckRow(name, "osim M = OpenSim calcM (rel.)", err["M"], 1e-9, n, osim),
        CheckRow(name, "osim g = OpenSim ID (rel.)", err["g"], 1e-9, n, osim),
        CheckRow(name, "osim tau = OpenSim ID (rel.)", err["tau"], 1e-9, n, osim),
    ]
