"""Small Pinocchio models built in code for the dynamics tests (not from the catalog)."""

import numpy as np
import pinocchio as pin


def rot(axis, angle):
    return pin.exp3(np.asarray(axis, float) / np.linalg.norm(axis) * angle)


JOINTS = {
    "RX": pin.JointModelRX,
    "RY": pin.JointModelRY,
    "RZ": pin.JointModelRZ,
    "PX": pin.JointModelPX,
    "PY": pin.JointModelPY,
    "PZ": pin.JointModelPZ,
}


def random_spd(rng, scale=0.05):
    A = rng.standard_normal((3, 3))
    U, _ = np.linalg.qr(A)
    d = rng.uniform(0.3, 1.0, 3)
    d[2] = min(d[2], d[0] + d[1] - 0.01)  # physically consistent principal moments
    return scale * U @ np.diag(d) @ U.T


def chain(types, rng, gravity=(0, 0, -9.81)):
    """Serial chain with random placements, CoM offsets and full inertia tensors.

    ``types``: list of "RX".."PZ" or ("RU", axis) for an unaligned revolute joint.
    Returns (model, params) where params lists (R0, p0, kind, axis, m, c, I) per joint."""
    model = pin.Model()
    model.gravity.linear = np.asarray(gravity, float)
    parent = 0
    params = []
    for k, t in enumerate(types):
        R0 = rot(rng.standard_normal(3), rng.uniform(-2, 2))
        p0 = rng.uniform(-0.3, 0.3, 3)
        if isinstance(t, tuple):
            axis = np.asarray(t[1], float) / np.linalg.norm(t[1])
            jm = pin.JointModelRevoluteUnaligned(axis)
            kind = "R"
        else:
            jm = JOINTS[t]()
            axis = np.eye(3)["XYZ".index(t[1])]
            kind = t[0]
        jid = model.addJoint(parent, jm, pin.SE3(R0, p0), f"j{k}")
        m = rng.uniform(0.5, 2.0)
        c = rng.uniform(-0.2, 0.2, 3)
        I = random_spd(rng)
        model.appendBodyToJoint(jid, pin.Inertia(m, c, I), pin.SE3.Identity())
        model.lowerPositionLimit[jid - 1] = -np.pi
        model.upperPositionLimit[jid - 1] = np.pi
        params.append((R0, p0, kind, axis, m, c, I))
        parent = jid
    return model, params
