"""Cross-check rows of the mechanisms for ``anthroarm check`` (provider ``rows``).

Four-bar, RSSR, RRSS, thumb and finger (``mech:<mechanism>``): loop-closure residual of the closed
form, and position, velocity and acceleration against (a) Pinocchio — the spanning tree + closures
solved by
:class:`~anthroarm.mechanisms.closed_loop.ClosedLoop` — and (b) 8th-order central finite
differences of the closed-form position along a trajectory input(t) = x0 + w t + a t^2 / 2.
Errors are made dimensionless: angles in rad, points divided by the mechanism's length scale,
rates relative (divided by max(input rate scale, |reference|), points first divided by the
length scale).  Random geometry per sample (seeded by ``rng``); the
number of samples per mechanism is capped so the whole provider runs in a few seconds.

Relative motion 002 (4-6)/(4-11)/(4-17) against a Pinocchio chain (frame position, velocity,
classical acceleration), and the RCCC loop (5-152): closure (log6), zero velocity and classical
acceleration of the cut frame of the Pinocchio open chain, joint rates vs finite differences.
"""

from __future__ import annotations

import functools

import numpy as np
import pinocchio as pin

from ..check_rows import CheckRow
from ..spatial.dual import Dual
from ._util import fd_derivative, wrap
from .closed_loop import ClosedLoop
from .finger import FingerGeometry, finger, finger_spec
from .fourbar import fourbar, fourbar_cartesian
from .pin_models import fourbar_spec, rrss_spec, rssr_spec
from .rccc import RCCCGeometry, pinocchio_chain, rccc_acceleration, rccc_position, rccc_velocity
from .relative_motion import (
    RelativeMotionGeometry,
    pinocchio_model,
    relative_acceleration,
    relative_position,
    relative_velocity,
)
from .rrss import RRSSGeometry, rrss, rrss_branch_through, rrss_newton, rrss_position
from .rssr import RSSRGeometry, rssr, rssr_branch_through, rssr_crank_test, rssr_position
from .thumb import ThumbGeometry, thumb, thumb_spec

TOL = 1e-10
MAX_SAMPLES = 6
LWA = pin.LOCAL_WORLD_ALIGNED


class _Acc:
    """Collects the largest error per (model, quantity, oracle)."""

    def __init__(self):
        self.rows = {}

    def add(self, model, quantity, err, oracle, note=""):
        k = (model, quantity, oracle)
        e, n, _ = self.rows.get(k, (0.0, 0, note))
        err = float(err) if np.isfinite(err) else float("inf")
        self.rows[k] = (max(e, err), n + 1, note)

    def out(self):
        return [
            CheckRow(model=m, quantity=q, max_abs_err=e, tol=TOL, samples=n, oracle=o, note=note)
            for (m, q, o), (e, n, note) in self.rows.items()
        ]


def _maxabs(x):
    return float(np.max(np.abs(np.asarray(x, float))))


def _rel(x, ref, rate_scale):
    """Error of a rate, relative to the input rate scale and to the size of the reference."""
    ref = np.asarray(ref, float)
    return _maxabs(np.asarray(x, float) - ref) / max(rate_scale, _maxabs(ref))


# ---------------------------------------------------------------------------------------------
def _fourbar_rows(acc, n, rng):
    m = "mech:fourbar"
    done = 0
    while done < n:
        r2, r3, r4 = rng.uniform(0.3, 1.0), rng.uniform(1.5, 3.0), rng.uniform(1.5, 3.0)
        r1 = rng.uniform(
            max(abs(r3 - r4) + r2, 1.0) + 0.2, min(r3 + r4 - r2, 4.0)
        )  # crank-rocker-ish
        th2, w2, a2 = rng.uniform(-np.pi, np.pi), rng.uniform(0.5, 1.5), rng.uniform(-1, 1)
        br = int(rng.choice([1, -1]))
        s = fourbar(r1, r2, r3, r4, th2, w2, a2, br)
        if s.status != "ok" or abs(np.sin(s.theta3 - s.theta4)) < 0.5:
            continue
        done += 1
        L = r1 + r2 + r3 + r4
        acc.add(m, "loop closure / length", s.residual / L, "math")
        c = fourbar_cartesian([r1, 0.0], r2, r3, r4, th2, w2, a2, br)
        acc.add(
            m,
            "complex (5-12)-(5-22) vs Cartesian §5-3: angles, rates",
            _maxabs(
                [
                    wrap(c.theta3 - s.theta3),
                    wrap(c.theta4 - s.theta4),
                    c.omega3 - s.omega3,
                    c.omega4 - s.omega4,
                    c.alpha3 - s.alpha3,
                    c.alpha4 - s.alpha4,
                ]
            ),
            "math",
        )
        loop = ClosedLoop(fourbar_spec(r1, r2, r3, r4))
        q0 = np.array([th2, s.theta3 - th2 + 0.05, s.theta4 - 0.05])
        st = loop.solve([th2], [w2], [a2], q0=q0)
        acc.add(
            m,
            "pin closure residual (RigidConstraintModel)",
            loop.residual_pin(st.q) / L,
            "pinocchio",
        )
        acc.add(
            m,
            "theta3, theta4",
            _maxabs([wrap(st.q[0] + st.q[1] - s.theta3), wrap(st.q[2] - s.theta4)]),
            "pinocchio",
        )
        acc.add(
            m,
            "omega3, omega4",
            _rel([st.v[0] + st.v[1], st.v[2]], [s.omega3, s.omega4], w2),
            "pinocchio",
        )
        acc.add(
            m,
            "alpha3, alpha4",
            _rel([st.a[0] + st.a[1], st.a[2]], [s.alpha3, s.alpha4], w2**2 + abs(a2)),
            "pinocchio",
        )

        @functools.cache  # one evaluation per stencil time, shared by d1 and d2
        def traj(t):
            return fourbar(r1, r2, r3, r4, th2 + w2 * t + 0.5 * a2 * t * t, w2 + a2 * t, a2, br)

        d1 = fd_derivative(lambda t: np.array([traj(t).theta3, traj(t).theta4]), angular=True)
        d2 = fd_derivative(lambda t: np.array([traj(t).omega3, traj(t).omega4]))
        acc.add(m, "omega3, omega4", _rel(d1, [s.omega3, s.omega4], w2), "finite-diff")
        acc.add(m, "alpha3, alpha4", _rel(d2, [s.alpha3, s.alpha4], w2**2 + abs(a2)), "finite-diff")


def _rand_unit(rng):
    v = rng.normal(size=3)
    return v / np.linalg.norm(v)


def _rssr_rows(acc, n, rng):
    m = "mech:rssr"
    done = 0
    tries = 0
    while done < n and tries < 200:
        tries += 1
        g = RSSRGeometry(
            a0=rng.normal(0, 0.1, 3),
            ua=_rand_unit(rng),
            a1=rng.normal(0, 0.1, 3) + [0.5, 0, 0],
            b0=rng.normal(0, 0.1, 3) + [2.0, 0, 0.5],
            ub=_rand_unit(rng),
            b1=rng.normal(0, 0.1, 3) + [2.0, 0, 1.5],
        )
        ct = rssr_crank_test(g, samples=720)
        if not ct.is_crank or ct.min_discriminant < 1e-3 * g.length_scale**4:
            continue
        br = rssr_branch_through(g)
        al, w, a = rng.uniform(-np.pi, np.pi), rng.uniform(0.5, 1.5), rng.uniform(-1, 1)
        s = rssr(g, al, w, a, br)
        if s.status != "ok":
            continue
        done += 1
        L = g.length_scale
        acc.add(m, "loop closure / length", s.residual / L, "math")
        loop = ClosedLoop(rssr_spec(g))
        Q, ok = loop.track(np.linspace(0.0, al, 1 + int(np.ceil(abs(al) / 0.1)))[:, None])
        st = loop.solve([al], [w], [a], q0=Q[-1])
        ib = loop.joint_q_index("rocker")
        acc.add(
            m,
            "pin closure residual (RigidConstraintModel)",
            loop.residual_pin(st.q) / L,
            "pinocchio",
        )
        acc.add(
            m,
            "beta (branch by continuity from a1, b1)",
            abs(wrap(st.q[ib] - s.beta)) if st.ok else np.inf,
            "pinocchio",
        )
        acc.add(m, "betadot", _rel(st.v[ib], s.betadot, w), "pinocchio")
        acc.add(m, "betaddot", _rel(st.a[ib], s.betaddot, w**2 + abs(a)), "pinocchio")
        d1 = fd_derivative(
            lambda t: rssr_position(g, al + w * t + 0.5 * a * t * t, br).beta, angular=True
        )
        d2 = fd_derivative(
            lambda t: rssr(g, al + w * t + 0.5 * a * t * t, w + a * t, a, br).betadot
        )
        acc.add(m, "betadot", _rel(d1, s.betadot, w), "finite-diff")
        acc.add(m, "betaddot", _rel(d2, s.betaddot, w**2 + abs(a)), "finite-diff")


def _rrss_rows(acc, n, rng):
    m = "mech:rrss"
    done = 0
    tries = 0
    while done < n and tries < 200:
        tries += 1
        u0 = np.array([0.0, 0.0, 1.0]) + rng.normal(0, 0.2, 3)
        u1 = np.array([0.0, 1.0, 1.0]) + rng.normal(0, 0.3, 3)
        g = RRSSGeometry(
            a0=rng.normal(0, 0.1, 3),
            u0=u0 / np.linalg.norm(u0),
            a1=[1.0, 0, 0] + rng.normal(0, 0.1, 3),
            u1=u1 / np.linalg.norm(u1),
            b0=[1.0, 1.0, 5.0] + rng.normal(0, 0.3, 3),
            b1=[2.0, 0.5, -0.5] + rng.normal(0, 0.2, 3),
        )
        br = rrss_branch_through(g)
        th = rng.uniform(-1.2, 1.2)
        w, a = rng.uniform(0.5, 1.5), rng.uniform(-1, 1)
        path = np.linspace(0.0, th, 13)
        sp = rrss_position(g, path, br)
        if not np.all(np.asarray(sp.status) == "ok"):
            continue
        s = rrss(g, th, w, a, br)
        den = abs(np.dot(s.b - g.b0, np.cross(s.u_a, s.b - s.a))) / (
            g.bar_length * np.linalg.norm(s.b - s.a)
        )
        if den < 0.2:
            continue
        done += 1
        L = g.length_scale
        acc.add(m, "loop closure / length", s.residual / L, "math")
        nw = rrss_newton(g, th, w, a, steps=6)
        acc.add(
            m,
            "002 Newton (rotation vector) vs closed form (6-99)/(6-105)/(6-111)",
            _maxabs(
                [
                    wrap(nw.theta2 - s.theta2),
                    (nw.theta2dot - s.theta2dot) / w,
                    (nw.theta2ddot - s.theta2ddot) / (w**2 + abs(a)),
                    *((nw.b - s.b) / L),
                ]
            )
            if nw.status == "ok"
            else np.inf,
            "math",
        )
        loop = ClosedLoop(rrss_spec(g))
        Q, ok = loop.track(path[:, None])
        st = loop.solve([th], [w], [a], q0=Q[-1])
        i2 = loop.joint_q_index("r2")
        acc.add(
            m,
            "pin closure residual (RigidConstraintModel)",
            loop.residual_pin(st.q) / L,
            "pinocchio",
        )
        acc.add(
            m,
            "theta2, b",
            max(
                abs(wrap(st.q[i2] - s.theta2)), _maxabs(loop.frame_position(st.q, "b_R2") - s.b) / L
            )
            if st.ok
            else np.inf,
            "pinocchio",
        )
        acc.add(
            m,
            "theta2dot, bdot",
            _rel(
                np.r_[st.v[i2], loop.frame_velocity(st.q, st.v, "b_R2") / L],
                np.r_[s.theta2dot, s.bdot / L],
                w,
            ),
            "pinocchio",
        )
        acc.add(
            m,
            "theta2ddot, bddot (classical)",
            _rel(
                np.r_[st.a[i2], loop.frame_acceleration(st.q, st.v, st.a, "b_R2") / L],
                np.r_[s.theta2ddot, s.bddot / L],
                w**2 + abs(a),
            ),
            "pinocchio",
        )

        @functools.cache  # one evaluation per stencil time, shared by d1 and d2
        def traj(t):
            return rrss(g, th + w * t + 0.5 * a * t * t, w + a * t, a, br)

        d1 = fd_derivative(lambda t: np.r_[traj(t).theta2, traj(t).b / L], angular=False)
        d2 = fd_derivative(lambda t: np.r_[traj(t).theta2dot, traj(t).bdot / L])
        acc.add(m, "theta2dot, bdot", _rel(d1, np.r_[s.theta2dot, s.bdot / L], w), "finite-diff")
        acc.add(
            m,
            "theta2ddot, bddot (classical)",
            _rel(d2, np.r_[s.theta2ddot, s.bddot / L], w**2 + abs(a)),
            "finite-diff",
        )


def _thumb_rows(acc, n, rng):
    m = "mech:thumb"
    g = ThumbGeometry.book()
    loop = ClosedLoop(thumb_spec(g))
    L = g.length_scale
    i2, i3 = loop.joint_q_index("r2"), loop.joint_q_index("r3")
    for th in rng.uniform(0.15, 0.5, n):  # theta1 in ~[9, 29] deg: f2 is matched; the literal upper
        # four-bar is close to its toggle below ~5 deg (rates of tens of rad/s)
        w, a = rng.uniform(0.5, 1.5), rng.uniform(-1, 1)
        s = thumb(g, th, w, a)
        acc.add(
            m,
            "loop closure / length",
            s.residual / L,
            "math",
            note="Ch.4 geometry, theta1 in [9, 29] deg",
        )
        Q, ok = loop.track(np.linspace(0.0, th, 9)[:, None])
        st = loop.solve([th], [w], [a], q0=Q[-1])
        acc.add(
            m,
            "pin closure residual (RigidConstraintModel)",
            loop.residual_pin(st.q) / L,
            "pinocchio",
        )
        acc.add(
            m,
            "theta2, theta3, fingertip S",
            max(
                abs(wrap(st.q[i2] - s.theta2)),
                abs(wrap(st.q[i3] - s.theta3)),
                _maxabs(loop.frame_position(st.q, "S") - s.S) / L,
            )
            if st.ok
            else np.inf,
            "pinocchio",
        )
        acc.add(
            m,
            "theta2dot, theta3dot, Sdot",
            _rel(
                np.r_[st.v[i2], st.v[i3], loop.frame_velocity(st.q, st.v, "S") / L],
                np.r_[s.theta2dot, s.theta3dot, s.Sdot / L],
                w,
            ),
            "pinocchio",
        )
        acc.add(
            m,
            "theta2ddot, theta3ddot, Sddot (classical)",
            _rel(
                np.r_[st.a[i2], st.a[i3], loop.frame_acceleration(st.q, st.v, st.a, "S") / L],
                np.r_[s.theta2ddot, s.theta3ddot, s.Sddot / L],
                w**2 + abs(a),
            ),
            "pinocchio",
        )

        @functools.cache  # one evaluation per stencil time, shared by d1 and d2
        def traj(t):
            return thumb(g, th + w * t + 0.5 * a * t * t, w + a * t, a)

        d1 = fd_derivative(lambda t: np.r_[traj(t).theta2, traj(t).theta3, traj(t).S / L])
        d2 = fd_derivative(lambda t: np.r_[traj(t).theta2dot, traj(t).theta3dot, traj(t).Sdot / L])
        acc.add(
            m,
            "theta2dot, theta3dot, Sdot",
            _rel(d1, np.r_[s.theta2dot, s.theta3dot, s.Sdot / L], w),
            "finite-diff",
        )
        acc.add(
            m,
            "theta2ddot, theta3ddot, Sddot (classical)",
            _rel(d2, np.r_[s.theta2ddot, s.theta3ddot, s.Sddot / L], w**2 + abs(a)),
            "finite-diff",
        )


def _finger_rows(acc, n, rng):
    m = "mech:finger"
    g = FingerGeometry.default()
    loop = ClosedLoop(finger_spec(g))
    L = g.length_scale
    p0, p1 = g.phi_range
    for u in rng.uniform(0.05, 0.95, n):
        ph = p0 + u * (p1 - p0)
        w, a = rng.uniform(0.5, 1.5), rng.uniform(-1, 1)
        s = finger(g, ph, w, a)
        acc.add(
            m,
            "loop closure / length",
            s.residual / L,
            "math",
            note="our bar lengths (fitted to Ch.3 f(x))",
        )
        Q, ok = loop.track(np.linspace(0.0, ph - p0, 7)[:, None])
        st = loop.solve([ph - p0], [w], [a], q0=Q[-1])
        acc.add(
            m,
            "pin closure residual (RigidConstraintModel)",
            loop.residual_pin(st.q) / L,
            "pinocchio",
        )
        acc.add(
            m,
            "fingertip P8",
            _maxabs(loop.frame_position(st.q, "P8")[:2] - s.tip) / L if st.ok else np.inf,
            "pinocchio",
        )
        acc.add(
            m,
            "fingertip velocity",
            _rel(loop.frame_velocity(st.q, st.v, "P8")[:2] / L, s.velocities["P8"] / L, w),
            "pinocchio",
        )
        acc.add(
            m,
            "fingertip acceleration (classical)",
            _rel(
                loop.frame_acceleration(st.q, st.v, st.a, "P8")[:2] / L,
                s.accelerations["P8"] / L,
                w**2 + abs(a),
            ),
            "pinocchio",
        )

        @functools.cache  # one evaluation per stencil time, shared by d1 and d2
        def traj(t):
            return finger(g, ph + w * t + 0.5 * a * t * t, w + a * t, a)

        h = 2.5e-4  # the DIP rate grows fast near the end of the range: small steps
        d1 = fd_derivative(lambda t: traj(t).tip / L, h)
        d2 = fd_derivative(lambda t: traj(t).velocities["P8"] / L, h)
        acc.add(m, "fingertip velocity", _rel(d1, s.velocities["P8"] / L, w), "finite-diff")
        acc.add(
            m,
            "fingertip acceleration (classical)",
            _rel(d2, s.accelerations["P8"] / L, w**2 + abs(a)),
            "finite-diff",
        )


# ---------------------------------------------------------------------------------------------
# relative motion (002 §4-1) and the RCCC mechanism (§5-6): rows of their own, checked against
# Pinocchio chains; ``n`` samples each (capped separately, these are cheap)
def _relative_rows(n, rng):
    e = np.zeros(3)
    for _ in range(n):
        u0, u1 = _rand_unit(rng), _rand_unit(rng)
        g = RelativeMotionGeometry(
            u0, rng.normal(size=3), u1, rng.normal(size=3), rng.normal(size=3)
        )
        x = rng.normal(size=9)
        th, thd, thdd, ph, phd, phdd, s, sd, sdd = x
        model, fid = pinocchio_model(g)
        data = model.createData()
        pin.forwardKinematics(
            model,
            data,
            np.array([th, s, ph]),
            np.array([thd, sd, phd]),
            np.array([thdd, sdd, phdd]),
        )
        pin.updateFramePlacements(model, data)
        scale = max(1.0, np.abs(np.r_[g.p0, g.p1, g.q1]).max())
        e[0] = max(
            e[0],
            np.abs(relative_position(g, th, ph, s).q - data.oMf[fid].translation).max() / scale,
        )
        e[1] = max(
            e[1],
            np.abs(
                relative_velocity(g, th, thd, ph, phd, s, sd).total
                - pin.getFrameVelocity(model, data, fid, LWA).linear
            ).max()
            / scale,
        )
        e[2] = max(
            e[2],
            np.abs(
                relative_acceleration(g, th, thd, thdd, ph, phd, phdd, s, sd, sdd).total
                - pin.getFrameClassicalAcceleration(model, data, fid, LWA).linear
            ).max()
            / scale,
        )
    return [
        CheckRow("relative_motion", "position 002 (4-6) vs pin FK (rel.)", float(e[0]), 1e-10, n),
        CheckRow(
            "relative_motion", "velocity 002 (4-11) vs frame velocity (rel.)", float(e[1]), 1e-10, n
        ),
        CheckRow(
            "relative_motion",
            "acceleration 002 (4-17) vs classical acc (rel.)",
            float(e[2]),
            1e-10,
            n,
        ),
    ]


def _rccc_rows(n, rng):
    e = np.zeros(4)
    count = checked = fd_checked = 0  # assembled geometries, branches with rates, FD comparisons
    tries = 0
    while (count < n or not fd_checked) and tries < 20 * n + 20:
        tries += 1
        tw = rng.uniform(0.2, np.pi - 0.2, 4)
        ln = rng.uniform(-2, 2, 5)
        g = RCCCGeometry(*(Dual(a, b) for a, b in zip(tw, ln[:4])), s1=ln[4])
        th1, w1, a1 = rng.uniform(-np.pi, np.pi), rng.normal(), rng.normal()
        r = rccc_position(g, th1)
        if not r.ok:
            continue
        model, fid = pinocchio_chain(g)
        data = model.createData()
        for sol in r.solutions:
            v = rccc_velocity(g, sol, w1)
            a = rccc_acceleration(g, sol, w1, a1, v)
            if v.status != "ok":
                continue
            checked += 1
            pin.forwardKinematics(model, data, sol.q, v.rates, a.rates)
            pin.updateFramePlacements(model, data)
            err6 = pin.log6(data.oMf[fid]).vector
            vmag = max(1.0, np.abs(v.rates).max())  # rates grow without bound near a dead point
            amag = max(1.0, np.abs(v.rates).max() ** 2, np.abs(a.rates).max())
            V = pin.getFrameVelocity(model, data, fid, LWA).vector
            A = pin.getFrameClassicalAcceleration(model, data, fid, LWA).vector
            e[0] = max(e[0], np.abs(err6[:3]).max() / g.scale, np.abs(err6[3:]).max())
            e[1] = max(e[1], np.abs(V[:3]).max() / (g.scale * vmag), np.abs(V[3:]).max() / vmag)
            e[2] = max(e[2], np.abs(A[:3]).max() / (g.scale * amag), np.abs(A[3:]).max() / amag)
            h = 1e-6
            rp, rm = rccc_position(g, th1 + h), rccc_position(g, th1 - h)
            v1 = rccc_velocity(g, sol, 1.0).rates
            if (
                rp.ok and rm.ok and np.abs(v1).max() < 100.0
            ):  # away from dead points (FD is meaningless there)
                dq = (rp.solutions[sol.branch].q - rm.solutions[sol.branch].q) / (2 * h)
                e[3] = max(e[3], np.abs(dq - v1).max() / max(1.0, np.abs(v1).max()))
                fd_checked += 1
        count += 1
    # a row that compared nothing must not pass: NaN fails the check
    e[:3] = e[:3] if checked else np.nan
    e[3] = e[3] if fd_checked else np.nan
    note = f"{checked} branches of {count} assembled geometries"
    return [
        CheckRow(
            "rccc", "loop closure (5-152) log6 (rel.)", float(e[0]), 1e-10, checked, note=note
        ),
        CheckRow("rccc", "cut-frame velocity = 0 (rel.)", float(e[1]), 1e-10, checked, note=note),
        CheckRow(
            "rccc", "cut-frame classical acc = 0 (rel.)", float(e[2]), 1e-10, checked, note=note
        ),
        CheckRow(
            "rccc",
            "joint rates vs finite differences (rel.)",
            float(e[3]),
            1e-6,
            fd_checked,
            "finite differences",
        ),
    ]


def rows(models, samples, rng) -> list[CheckRow]:
    """Provider for :func:`anthroarm.crosscheck.run` (mechanisms are not catalog models: the rows
    are always produced, named ``mech:<mechanism>``)."""
    n = max(1, min(int(samples), MAX_SAMPLES))
    acc = _Acc()
    for f in (_fourbar_rows, _rssr_rows, _rrss_rows, _thumb_rows, _finger_rows):
        f(acc, n, rng)
    k = max(1, min(int(samples), 50))
    return acc.out() + _relative_rows(k, rng) + _rccc_rows(max(1, k // 2), rng)
