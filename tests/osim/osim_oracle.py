"""OpenSim itself as the oracle of the .osim import (issue 32): poses of bodies and markers,
the mass matrix, gravity and inverse dynamics, from the ``opensim`` package (PyPI 4.6).

Coordinates and mobilities: OpenSim's ``SimbodyMatterSubsystem.calcM`` and
``InverseDynamicsSolver`` work in Simbody's mobility order (u), which need not be the
coordinate order; each coordinate's u index is found by setting its speed alone to 1 and
reading ``state.getU()``.  A dependent coordinate (a ``CoordinateCouplerConstraint``) is a
mobility of its own in OpenSim: its value, rate and acceleration follow from OpenSim's own
coupler function (``Function.calcValue`` / ``calcDerivative``), and the mobility-space
quantities are projected onto the independent coordinates with C = du/dq̇ (Mᵢ = Cᵀ M C,
τᵢ = Cᵀ τ): the constraint's forces do no work along C.
"""

from __future__ import annotations

import numpy as np


class OpenSimOracle:
    def __init__(self, path, names, forces: bool = False):
        import opensim as osim

        osim.Logger.setLevelString("error")
        osim.Logger.removeFileSink()  # no opensim.log beside the model (OpenSim loads from its folder)
        self.osim = osim
        self.model = model = osim.Model(str(path))
        if not forces:
            fs = model.getForceSet()
            for i in range(fs.getSize()):
                fs.get(i).set_appliesForce(False)
        self.state = model.initSystem()
        cs = model.getCoordinateSet()
        self.coords = {cs.get(i).getName(): cs.get(i) for i in range(cs.getSize())}
        self.names = list(names)  # the independent coordinates, in the Robot's q order
        self.couplers = {}
        cons = model.getConstraintSet()
        for i in range(cons.getSize()):
            c = osim.CoordinateCouplerConstraint.safeDownCast(cons.get(i))
            if c is not None and c.get_isEnforced():
                ind = c.getIndependentCoordinateNames()
                self.couplers[c.getDependentCoordinateName()] = (
                    ind.get(0),
                    c.getFunction(),
                    osim.PropertyHelper.getValueDouble(c.getPropertyByName("scale_factor")),
                )
        self.nu = self.state.getNU()
        self.u_index = {}
        for n, c in self.coords.items():
            for m in self.coords.values():
                m.setSpeedValue(self.state, 0.0)
            c.setSpeedValue(self.state, 1.0)
            u = np.array([self.state.getU().get(k) for k in range(self.nu)])
            self.u_index[n] = int(np.argmax(u))
        for m in self.coords.values():
            m.setSpeedValue(self.state, 0.0)
        self.bodies = model.getBodySet()
        self.markers = model.getMarkerSet()
        self.ids = osim.InverseDynamicsSolver(model)

    def _fun(self, f, x, order):
        v = self.osim.Vector(1, float(x))
        if order == 0:
            return f.calcValue(v)
        # a list, converted by SWIG's sequence typemap: an opensim.StdVectorInt (moco's class) was
        # refused with a TypeError by common's Function.calcDerivative in some test processes
        return f.calcDerivative([0] * order, v)

    def kinematics(self, q, qd=None, qdd=None):
        """Every coordinate's (value, rate, acceleration) and C = du/dq̇, from the
        independent ones."""
        n = len(self.names)
        val = dict(zip(self.names, q))
        rate = dict(zip(self.names, np.zeros(n) if qd is None else qd))
        acc = dict(zip(self.names, np.zeros(n) if qdd is None else qdd))
        row = {nm: np.eye(n)[i] for i, nm in enumerate(self.names)}
        todo = [d for d in self.couplers if d not in val]
        while todo:
            for d in list(todo):
                src, f, s = self.couplers[d]
                if src not in val:
                    continue
                x = val[src]
                f0, f1, f2 = (self._fun(f, x, k) for k in range(3))
                val[d] = s * f0
                rate[d] = s * f1 * rate[src]
                acc[d] = s * (f1 * acc[src] + f2 * rate[src] ** 2)
                row[d] = s * f1 * row[src]
                todo.remove(d)
        C = np.zeros((self.nu, n))
        for nm, r in row.items():
            C[self.u_index[nm]] = r
        return val, rate, acc, C

    def set_state(self, q, qd=None, qdd=None):
        val, rate, acc, C = self.kinematics(q, qd, qdd)
        for nm, c in self.coords.items():
            if nm not in val:  # a locked coordinate: OpenSim keeps its default value
                continue
            c.setValue(self.state, float(val[nm]), False)
            c.setSpeedValue(self.state, float(rate[nm]))
        self.model.realizeVelocity(self.state)
        udot = np.zeros(self.nu)
        for nm in self.coords:
            udot[self.u_index[nm]] = acc.get(nm, 0.0)
        return C, udot

    def body_poses(self):
        out = {}
        for i in range(self.bodies.getSize()):
            b = self.bodies.get(i)
            T = b.getTransformInGround(self.state)
            R, p = T.R(), T.p()
            H = np.eye(4)
            H[:3, :3] = [[R.get(r, c) for c in range(3)] for r in range(3)]
            H[:3, 3] = [p.get(k) for k in range(3)]
            out[b.getName()] = H
        return out

    def marker_positions(self):
        out = {}
        for i in range(self.markers.getSize()):
            mk = self.markers.get(i)
            p = mk.getLocationInGround(self.state)
            out[mk.getName()] = np.array([p.get(k) for k in range(3)])
        return out

    def mass_matrix(self, C):
        M = self.osim.Matrix()
        self.model.getMatterSubsystem().calcM(self.state, M)
        Mn = np.array([[M.get(r, c) for c in range(self.nu)] for r in range(self.nu)])
        return C.T @ Mn @ C

    def inverse_dynamics(self, C, udot):
        tau = self.ids.solve(self.state, self.osim.Vector(udot.tolist()))
        return C.T @ np.array([tau.get(k) for k in range(self.nu)])
