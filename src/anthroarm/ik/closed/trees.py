"""A tree (a humanoid, two arms on a torso, an arm with a hand or a gripper) and frames other than
the tool: the closed form of a tree is that of the joints on the path from the base to the tool
(:class:`Arm`, the robot reduced to them); every other joint keeps its value in ``q_rest``
(default the comfortable posture) — it does not move the tool.  Another frame is solved as the
tool of the same model (:func:`retooled`).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, replace

import numpy as np

from ...errors import UnsupportedModelError
from ...robot import Robot, reduce_model
from ..qp.tasks.posture import comfortable_posture
from .results import AnalyticBatchResult, singular_from


@dataclass(frozen=True)
class Arm:
    """The arm of a tree: ``robot`` reduced to the joints on the path from its base to its tool
    (:func:`anthroarm.robot.reduce_model`, every other joint locked), which the closed form
    solves, and where the arm's configuration sits in the robot's: ``q_idx`` (nq_arm,) the
    robot's q index of each arm q entry, ``th_idx`` (n_arm,) the robot's θ index
    (``chain.independent`` order) of each arm θ entry; ``q_rest`` (nq,) and ``th_rest`` (n,)
    the comfortable posture, the default of the joints off the path."""

    robot: object
    q_idx: np.ndarray
    th_idx: np.ndarray
    q_rest: np.ndarray
    th_rest: np.ndarray

    def configurations(self, Qa, q_rest=None, valid=None) -> np.ndarray:
        """The robot's configurations (..., nq) of the arm's ``Qa`` (..., nq_arm): the joints off
        the path at ``q_rest`` (default :attr:`q_rest`); rows where ``valid`` (...) is False are
        NaN, as the arm's are."""
        rest = self.q_rest if q_rest is None else q_rest
        Q = np.empty(Qa.shape[:-1] + rest.shape)
        Q[...] = rest
        Q[..., self.q_idx] = Qa
        if valid is not None:
            Q[~valid] = np.nan
        return Q


def arm_of(robot):
    """The :class:`Arm` of ``robot`` where some of its joints are off the path to its tool (a
    mimic joint off the path that follows one on it stays in the arm, following it); None where
    every joint is on it; a text saying why where the arm cannot be cut out of the tree (a
    mimic joint on the path following one off it, a model the reduction does not take)."""
    ch = robot.chain
    path = ch.path(robot.tool_id)
    if all(j in path for j in ch.independent):
        return None
    if not path:
        return "no joint moves the frame"
    keep = set(path) | {j.index for j in ch.joints if j.is_mimic and j.mimic.source in path}
    try:
        model, _ = reduce_model(
            robot.model, robot.name, active=[ch.joints[j].name for j in sorted(keep)]
        )
        arm = Robot(model, name=robot.name, tool=robot.tool)
    except Exception as exc:  # noqa: BLE001 - UnsupportedModelError (a mimic pair cut), a model without frames
        return f"the arm on the path to the tool could not be cut out of the tree: {exc}"
    full = robot.model
    starts = [full.joints[full.getJointId(model.names[j])].idx_q for j in range(1, model.njoints)]
    q_idx = np.concatenate(
        [np.arange(i, i + model.joints[j].nq) for j, i in enumerate(starts, 1)]
    ).astype(int)
    pos = {ch.joints[j].name: k for k, j in enumerate(ch.independent)}
    th_idx = np.array([pos[arm.chain.joints[j].name] for j in arm.chain.independent], dtype=int)
    q_rest = comfortable_posture(robot)
    th_rest = ch.angles(q_rest)[list(ch.independent)]
    for a in (q_idx, th_idx, q_rest, th_rest):
        a.setflags(write=False)
    return Arm(arm, q_idx, th_idx, q_rest, th_rest)


def _no_others(robot) -> dict:
    return {}


def retooled(robot, frame):
    """``robot`` itself where ``frame`` (a name or a Pinocchio frame id; None: the tool) is its
    tool, else the same model with ``frame`` as its tool (another tip of a tree: the other
    foot, the other hand; the same spec, so the same comfortable posture), made once per
    (robot, frame) and kept with the robot; None where that frame's name is also an earlier
    frame's (a tool is named, so it would be the other one).  Unknown frames raise
    :class:`~anthroarm.errors.UnknownFrameError`."""
    if frame is None:
        return robot
    f = robot.chain.frame(frame)
    if f.index == robot.tool_id:
        return robot
    others = robot.derived("ik.closed_form.retooled", _no_others)  # frame id -> Robot or None
    if f.index not in others:
        other = Robot(
            robot.model,
            name=robot.name,
            tool=f.name,
            info=robot.info,
            spec=robot.spec,
            locked=robot.locked,
        )
        others[f.index] = other if other.tool_id == f.index else None
    return others[f.index]


def unnamed(robot, frame) -> str:
    f = robot.chain.frame(frame)
    return (
        f"{robot.name}: frame {f.index} shares its name {f.name!r} with frame "
        f"{robot.chain.frame(f.name).index}; the closed form solves for a frame known by its name: "
        "use aa.ik.solve(robot, T, frame=...)"
    )


def frame_robot(robot, frame):
    """:func:`retooled`, or :class:`~anthroarm.errors.UnsupportedModelError` where ``frame`` has
    no closed form of its own (its name is an earlier frame's)."""
    other = retooled(robot, frame)
    if other is None:
        raise UnsupportedModelError(unnamed(robot, frame))
    return other


def q_rest_of(robot, arm, q_rest) -> np.ndarray | None:
    """The configuration (nq,) whose joints off the tool's path a tree's solutions keep:
    ``q_rest`` checked (``robot.check_q``), else the arm's default (its comfortable posture)."""
    if q_rest is None:
        return None if arm is None else arm.q_rest
    q = robot.check_q(q_rest, name="q_rest")
    if q.ndim != 1:
        raise ValueError(
            f"{robot.name}: q_rest is one configuration, shape ({robot.nq},), got shape {q.shape}"
        )
    if arm is not None:
        off = np.setdiff1d(np.arange(robot.nq), arm.q_idx)
        bad = off[(q[off] < robot.lower[off]) | (q[off] > robot.upper[off])]
        if len(bad):
            names = robot.chain.q_names
            raise ValueError(
                f"{robot.name}: q_rest puts {', '.join(names[i] for i in bad)} outside the joint "
                "limits (the solutions keep its joints off the tool's path, and every solution is "
                "inside them)"
            )
    return q


def on_robot(arm: Arm, res, q_rest):
    """A result of the arm of a tree as the robot's: every solution a configuration of the
    robot, the joints off the path at ``q_rest``."""
    if isinstance(res, AnalyticBatchResult):
        return replace(res, solutions=arm.configurations(res.solutions, q_rest, res.valid))
    sing = (
        functools.partial(singular_from, res._singular, res.solutions)
        if callable(res._singular)
        else res._singular
    )
    return replace(res, solutions=arm.configurations(res.solutions, q_rest), _singular=sing)
