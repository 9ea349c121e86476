"""Activities of daily living (ADL) as parametric tasks, turned into joint trajectories.

The library holds the activities of the book's Table 9.2 (ADL 评价, the evaluation of the
Tokyo Denki simplified powered hand: dressing 穿脱衣服, washing the face 洗脸, eating 饮食,
general actions such as opening a door 一般动作 (门开关), desk work such as writing 桌面动作,
hygiene (toilet) 卫生动作) and the activities of the upper-limb ADL literature that issue 17
lists: hand to mouth, combing hair, reaching to a shelf at shoulder height, reaching to the
opposite shoulder, lifting a 1 kg object to a table and pouring from a jug (Magermans et al.
2005, "Requirements for upper extremity motions during activities of daily living", Clin.
Biomech. 20(6), 591–599: combing hair, washing the contralateral axilla, eating with a spoon,
perineal care; Murray & Johnson 2004, Clin. Biomech. 19(6), 586–594, loads at the shoulder and
elbow in everyday tasks).

An activity is a list of **keyframes**: a target of the hand point (the model's tool, the head
of the 3rd metacarpal) relative to the body, the time to move there, a hold, and whether the
held object is in the hand.  Targets are built from the person's stature H with the segment
proportions of Drillis & Contini (1966) as drawn in Winter, *Biomechanics and Motor Control of
Human Movement* (4th ed., 2009, Fig. 4.1): shoulder height 0.818 H, chin 0.870 H, eyes 0.936 H,
vertex 1.000 H, shoulder (biacromial) width 0.259 H; the sitting shoulder height above the
seat is taken as 0.34 H (sitting height ≈ 0.52 H minus the head and neck 0.182 H).  The face
is put 0.055 H in front of the shoulder joint centres and the mouth at 0.890 H.  These
placements and the furniture (a 0.72 m table, a 0.45 m seat) are this module's estimates for a
generic person, not values printed in the papers above: every one of them is a parameter.

Frame: the right shoulder joint centre, x to the person's right, y forward, z up (the human arm
model's base frame, :mod:`anthroarm.models.human`), metres.

:func:`activity_trajectory` solves each keyframe with the project's IK (``aa.ik.solve`` in
position mode with the comfortable-posture phase: the hand reaches the target and the redundant
freedom goes to the posture closest to :func:`~anthroarm.ik.qp.comfortable_posture`), seeded
with the previous keyframe's solution, then joins the keyframe postures with rest-to-rest
minimum-jerk segments in joint space (:mod:`anthroarm.motion.timing`, Flash & Hogan 1985).  A
keyframe the arm cannot reach gets status ``"unreachable"`` and the closest posture found
(``strict=True`` raises :class:`~anthroarm.errors.ActivityError` instead); the rest of the
activity is still built.
"""

from __future__ import annotations

import inspect
from dataclasses import dataclass, field

import numpy as np

from .. import ik
from ..errors import ActivityError
from ..ik.qp import comfortable_posture
from .timing import keyframe_trajectory

#: the most samples :func:`activity_trajectory` makes (a bound on the memory a bad rate or duration
#: takes)
MAX_SAMPLES = 1e7

#: stature fractions (Drillis & Contini 1966, Winter 2009 Fig. 4.1) and this module's estimates
BODY_PROPORTIONS = {
    "shoulder_height": 0.818,
    "chin_height": 0.870,
    "mouth_height": 0.890,
    "eye_height": 0.936,
    "vertex_height": 1.000,
    "shoulder_width": 0.259,
    "face_front": 0.055,
    "head_back": 0.055,
    "sitting_shoulder": 0.34,
    "back_depth": 0.07,
}


@dataclass(frozen=True)
class Keyframe:
    """A target of the hand point: ``position`` (3,) m in the shoulder frame, reached ``move`` s
    after the previous keyframe, held ``hold`` s; ``holding``: the object is in the hand from
    this keyframe until the next keyframe that says otherwise."""

    name: str
    position: tuple
    move: float = 1.0
    hold: float = 0.0
    holding: bool = False


@dataclass
class Activity:
    """A parametric activity for one person: ``keyframes`` (the first is the start posture's
    hand position), the held ``object_mass`` (kg), where it comes from (``source``, ``book``:
    the Table 9.2 row it stands for) and the parameters it was built with."""

    name: str
    title: str
    keyframes: list
    object_mass: float = 0.0
    source: str = ""
    book: str = ""
    params: dict = field(default_factory=dict)


@dataclass
class ActivityTrajectory:
    """Joint trajectory of an activity.

    Attributes
    ----------
    t : (K,) s
    q, qd, qdd : (K, nq)
        rad, rad/s, rad/s² (minimum-jerk in joint space between keyframes).
    hand : (K, 3)
        Hand point by forward kinematics, m (shoulder frame).
    holding : (K,) bool
        The object is in the hand.
    object_mass : float
        kg.
    keyframe_names, keyframe_times, keyframe_q, keyframe_status, keyframe_error :
        Per keyframe: name, arrival time (s), IK posture, ``"ok"`` or ``"unreachable"``, and the
        distance of the hand from its target (m).
    """

    activity: Activity
    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    hand: np.ndarray
    holding: np.ndarray
    object_mass: float
    keyframe_names: tuple
    keyframe_times: np.ndarray
    keyframe_q: np.ndarray
    keyframe_status: tuple
    keyframe_error: np.ndarray
    joint_names: tuple = ()

    @property
    def reachable(self) -> bool:
        """Every keyframe was reached."""
        return all(s == "ok" for s in self.keyframe_status)

    @property
    def payload(self) -> np.ndarray:
        """(K,) mass in the hand, kg."""
        return np.where(self.holding, self.object_mass, 0.0)

    @property
    def duration(self) -> float:
        return float(self.t[-1])


# ---------------------------------------------------------------------------------- the body
@dataclass(frozen=True)
class Body:
    """Landmarks of a person relative to the right shoulder joint centre (m): built from the
    stature ``height`` and the arm length ``arm`` (shoulder to hand point)."""

    height: float
    arm: float
    props: dict

    def f(self, key: str) -> float:
        return self.props[key] * self.height

    @property
    def midline_x(self) -> float:
        return -0.5 * self.f("shoulder_width")

    def above_shoulder(self, frac_key: str) -> float:
        return self.f(frac_key) - self.f("shoulder_height")

    @property
    def mouth(self) -> np.ndarray:
        return np.array([self.midline_x, self.f("face_front"), self.above_shoulder("mouth_height")])

    def seated_table(self, table_height: float, seat_height: float) -> float:
        """Height of a table top above the shoulder of the seated person (m, negative below)."""
        return (table_height - seat_height) - self.f("sitting_shoulder")

    def standing(self, height_above_floor: float) -> float:
        return height_above_floor - self.f("shoulder_height")


def _rest(B: Body) -> tuple:
    """The hand at rest beside the body: arm hanging, elbow slightly bent."""
    return (0.02, 0.08, -0.92 * B.arm)


def _lap(B: Body, seat_height) -> tuple:
    """Hand resting on the thigh of the seated person."""
    return (-0.02, 0.22, max(-0.85 * B.arm, -(B.f("sitting_shoulder") - 0.10)))


def _hand_to_mouth(
    B, *, move=1.0, hold=1.0, seat_height=0.45, table_height=0.72, object_mass=0.0, **_
):
    m = B.mouth + [0.0, 0.07, -0.02]  # the grip of a cup or spoon, in front of the mouth
    return [
        Keyframe("rest", _lap(B, seat_height)),
        Keyframe("mouth", tuple(m), move, hold),
        Keyframe("rest_again", _lap(B, seat_height), move),
    ], object_mass


def _eating(
    B, *, move=1.0, hold=0.5, seat_height=0.45, table_height=0.72, object_mass=0.05, repeats=2, **_
):
    zt = B.seated_table(table_height, seat_height)
    plate = (-0.05, 0.35, zt + 0.05)
    m = tuple(B.mouth + [0.0, 0.07, -0.02])
    kf = [Keyframe("plate", plate, hold=0.5, holding=True)]
    for i in range(int(repeats)):
        kf += [
            Keyframe(f"mouth{i + 1}", m, move, hold, True),
            Keyframe(f"plate{i + 1}", plate, move, 0.5, True),
        ]
    return kf, object_mass


def _comb_hair(B, *, move=1.0, hold=0.0, strokes=2, object_mass=0.05, **_):
    top = (
        B.midline_x + 0.04 * B.height,
        0.03 * B.height,
        B.above_shoulder("vertex_height") - 0.02 * B.height,
    )
    back = (
        B.midline_x + 0.05 * B.height,
        -B.f("head_back"),
        B.above_shoulder("eye_height") - 0.02 * B.height,
    )
    kf = [
        Keyframe("rest", _rest(B), holding=True),
        Keyframe("head_front_top", top, 1.5 * move, 0.0, True),
    ]
    for i in range(int(strokes)):
        kf += [
            Keyframe(f"head_back{i + 1}", back, move, hold, True),
            Keyframe(f"head_top{i + 1}", top, move, 0.0, True),
        ]
    kf.append(Keyframe("rest_again", _rest(B), 1.5 * move, 0.0, True))
    return kf, object_mass


def _reach_shelf(
    B, *, move=1.2, hold=0.5, reach_fraction=0.85, shelf_height=None, object_mass=0.0, **_
):
    z = 0.0 if shelf_height is None else B.standing(shelf_height)
    shelf = (0.02, reach_fraction * np.sqrt(max(B.arm**2 - z**2, 0.0)), z)
    return [
        Keyframe("rest", _rest(B)),
        Keyframe("shelf", shelf, move, hold),
        Keyframe("rest_again", _rest(B), move),
    ], object_mass


def _opposite_shoulder(B, *, move=1.0, hold=0.5, object_mass=0.0, **_):
    target = (-B.f("shoulder_width") + 0.03, 0.04, 0.02)
    return [
        Keyframe("rest", _rest(B)),
        Keyframe("opposite_shoulder", target, move, hold),
        Keyframe("rest_again", _rest(B), move),
    ], object_mass


def _lift_to_table(
    B, *, move=1.2, hold=0.5, seat_height=0.45, table_height=0.72, object_mass=1.0, **_
):
    zt = B.seated_table(table_height, seat_height)
    start = (0.12, 0.15, -0.80 * B.arm)  # the object beside the chair, low
    table = (-0.02, 0.38, zt + 0.06)
    return [
        Keyframe("rest", _rest(B)),
        Keyframe("grasp_low", start, move, 0.3, True),
        Keyframe("on_table", table, move, hold, False),
        Keyframe("rest_again", _rest(B), move),
    ], object_mass


def _pour(B, *, move=1.2, hold=1.0, seat_height=0.45, table_height=0.72, object_mass=1.0, **_):
    zt = B.seated_table(table_height, seat_height)
    jug = (0.05, 0.35, zt + 0.08)
    over_cup = (-0.12, 0.36, zt + 0.22)
    return [
        Keyframe("lap", _lap(B, seat_height)),
        Keyframe("grasp_jug", jug, move, 0.3, True),
        Keyframe("over_cup", over_cup, move, hold, True),
        Keyframe("jug_down", jug, move, 0.3, False),
        Keyframe("lap_again", _lap(B, seat_height), move),
    ], object_mass


def _dressing(B, *, move=1.2, hold=0.5, object_mass=0.0, **_):
    opp = (-B.f("shoulder_width") + 0.03, 0.04, 0.02)
    neck = (B.midline_x + 0.03, -0.03, 0.05)
    return [
        Keyframe("rest", _rest(B)),
        Keyframe("opposite_shoulder", opp, move, hold),
        Keyframe("back_of_neck", neck, move, hold),
        Keyframe("rest_again", _rest(B), move),
    ], object_mass


def _wash_face(B, *, move=1.0, hold=0.5, object_mass=0.0, **_):
    face = B.mouth + [0.0, 0.05, 0.03]
    left = face + [-0.05, 0.0, 0.02]
    right = face + [0.05, 0.0, 0.02]
    return [
        Keyframe("rest", _rest(B)),
        Keyframe("face", tuple(face), move, hold),
        Keyframe("left_cheek", tuple(left), 0.5),
        Keyframe("right_cheek", tuple(right), 0.5),
        Keyframe("rest_again", _rest(B), move),
    ], object_mass


def _open_door(B, *, move=1.2, hold=0.5, handle_height=1.0, pull=0.15, object_mass=0.0, **_):
    z = B.standing(handle_height)
    handle = (0.10, 0.65 * np.sqrt(max(B.arm**2 - z**2, 0.0)), z)
    pulled = (handle[0], handle[1] - pull, z)
    return [
        Keyframe("rest", _rest(B)),
        Keyframe("handle", handle, move, hold),
        Keyframe("pull", pulled, move, hold),
        Keyframe("rest_again", _rest(B), move),
    ], object_mass


def _writing(
    B,
    *,
    move=1.0,
    seat_height=0.45,
    table_height=0.72,
    stroke=0.08,
    strokes=3,
    object_mass=0.02,
    **_,
):
    zt = B.seated_table(table_height, seat_height)
    p0 = np.array([0.0, 0.33, zt + 0.04])
    kf = [Keyframe("paper", tuple(p0), holding=True)]
    for i in range(int(strokes)):
        kf.append(
            Keyframe(
                f"stroke{i + 1}",
                tuple(p0 + [-(i + 1) * stroke / strokes, 0.0, 0.0]),
                0.6,
                0.2,
                True,
            )
        )
    kf.append(Keyframe("paper_again", tuple(p0), move, 0.0, True))
    return kf, object_mass


def _toileting(B, *, move=1.2, hold=0.5, object_mass=0.0, **_):
    behind = (0.0, -B.f("back_depth") - 0.03, -0.85 * B.arm)
    return [
        Keyframe("rest", _rest(B)),
        Keyframe("behind_hip", behind, move, hold),
        Keyframe("rest_again", _rest(B), move),
    ], object_mass


_MAGERMANS = "Magermans et al. 2005, Clin. Biomech. 20(6) 591-599"
_MURRAY = "Murray & Johnson 2004, Clin. Biomech. 19(6) 586-594"

#: name -> (title, builder, source, Table 9.2 row)
ACTIVITIES = {
    "hand_to_mouth": (
        "hand to mouth (drinking), seated",
        _hand_to_mouth,
        f"{_MURRAY}; issue 17",
        "",
    ),
    "comb_hair": (
        "combing hair (hand to the top and back of the head)",
        _comb_hair,
        _MAGERMANS,
        "",
    ),
    "reach_shelf": ("reach to a shelf at shoulder height", _reach_shelf, "issue 17", ""),
    "reach_opposite_shoulder": (
        "reach to the opposite shoulder",
        _opposite_shoulder,
        f"{_MAGERMANS} (contralateral axilla)",
        "",
    ),
    "lift_to_table": (
        "lift a 1 kg object from beside the chair to the table",
        _lift_to_table,
        f"{_MURRAY}; issue 17",
        "",
    ),
    "pour": ("pour from a 1 kg jug into a cup, seated", _pour, f"{_MURRAY}; issue 17", ""),
    "eating": ("eating with a spoon: plate to mouth, twice", _eating, _MAGERMANS, "饮食 eating"),
    "dressing": (
        "dressing: hand to the opposite shoulder and behind the neck",
        _dressing,
        "book Table 9.2",
        "穿脱衣服 dressing",
    ),
    "wash_face": ("washing the face", _wash_face, "book Table 9.2", "洗脸 washing the face"),
    "open_door": (
        "opening a door: reach the handle at 1 m and pull",
        _open_door,
        "book Table 9.2",
        "一般动作 general (opening doors)",
    ),
    "writing": (
        "writing at a table, seated",
        _writing,
        "book Table 9.2",
        "桌面动作 desk work (writing)",
    ),
    "toileting": (
        "hygiene: hand behind the hip (perineal care)",
        _toileting,
        f"book Table 9.2; {_MAGERMANS}",
        "卫生动作 hygiene (toilet)",
    ),
}


def names() -> list[str]:
    """Names of the activities in the library."""
    return list(ACTIVITIES)


def _person(robot, height):
    if height is None:
        params = getattr(getattr(robot, "spec", None), "params", None) or {}
        height = params.get("height")
        if height is None:
            raise ActivityError(f"{robot.name} does not say the person's height: pass height= (m)")
    if not (
        isinstance(height, (int, float, np.floating))
        and np.isfinite(height)
        and 0.5 <= height <= 2.6
    ):
        raise ActivityError(f"height must be a number of metres in 0.5 ... 2.6, got {height!r}")
    arm = float(np.linalg.norm(robot.fk(robot.neutral())[:3, 3]))
    return Body(float(height), arm, dict(BODY_PROPORTIONS))


def activity(name: str, robot, *, height: float | None = None, **params) -> Activity:
    """The activity ``name`` (:func:`~anthroarm.motion.activities.names`) for the person of
    ``robot`` (stature from ``robot.spec.params["height"]`` or ``height=``, arm length from the
    model).  ``params`` override the builder's parameters: ``move`` (s per movement), ``hold`` (s),
    ``object_mass`` (kg), ``table_height``/``seat_height``/``shelf_height``/``handle_height`` (m
    above the floor), ``repeats``/``strokes`` ...; an unknown parameter
    raises :class:`~anthroarm.errors.ActivityError`."""
    if name not in ACTIVITIES:
        raise ActivityError(f"unknown activity {name!r}; the library has: {', '.join(ACTIVITIES)}")
    title, builder, source, book = ACTIVITIES[name]

    accepted = [p for p in inspect.signature(builder).parameters if p not in ("B", "_")]
    unknown = sorted(set(params) - set(accepted))
    if unknown:
        raise ActivityError(f"activity {name!r} takes parameters {accepted}; unknown: {unknown}")
    for k, v in params.items():
        if v is None:
            continue
        if not (
            isinstance(v, (int, float, np.floating, np.integer))
            and not isinstance(v, bool)
            and np.isfinite(v)
        ):
            raise ActivityError(f"activity {name!r}: parameter {k}={v!r} must be a finite number")
        if k in ("move", "repeats", "strokes") and v <= 0:
            raise ActivityError(f"activity {name!r}: {k} must be > 0, got {v}")
        if k in ("hold", "object_mass") and v < 0:
            raise ActivityError(f"activity {name!r}: {k} must be >= 0, got {v}")
    B = _person(robot, height)
    keyframes, mass = builder(B, **params)
    return Activity(
        name,
        title,
        keyframes,
        float(mass),
        source,
        book,
        {"height": B.height, "arm": B.arm, **params},
    )


def activity_trajectory(
    robot,
    act,
    *,
    rate: float = 100.0,
    strict: bool = False,
    tol: float = 1e-3,
    height: float | None = None,
    q_start=None,
    **params,
) -> ActivityTrajectory:
    """Joint trajectory of an activity (an :class:`Activity` or a library name, built with
    :func:`activity` and ``params``) for ``robot``, sampled at ``rate`` Hz.

    Each keyframe is solved by ``aa.ik.solve(robot, target, mode="position", posture="auto")``
    seeded with the previous keyframe's posture (the first with ``q_start``, default the
    comfortable posture); a keyframe whose hand error stays above ``tol`` (m) is
    ``"unreachable"`` (or raises :class:`~anthroarm.errors.ActivityError` with ``strict``).
    """
    if isinstance(act, str):
        act = activity(act, robot, height=height, **params)
    elif params or height is not None:
        raise ActivityError("parameters go with an activity name, not with a built Activity")
    if not isinstance(act, Activity):
        raise ActivityError(f"expected an Activity or a name, got {type(act).__name__}")
    if not act.keyframes:
        raise ActivityError(f"activity {act.name!r} has no keyframes")
    if not (
        isinstance(rate, (int, float, np.floating, np.integer)) and np.isfinite(rate) and rate > 0
    ):
        raise ActivityError(f"rate must be a positive number of samples per second, got {rate!r}")
    for kf in act.keyframes:
        try:
            ok = (
                np.asarray(kf.position, float).shape == (3,)
                and np.isfinite(kf.position).all()
                and np.isfinite(kf.move)
                and kf.move > 0
                and np.isfinite(kf.hold)
                and kf.hold >= 0
            )
        except (TypeError, ValueError):
            ok = False
        if not ok:
            raise ActivityError(
                f"activity {act.name!r}: keyframe {kf.name!r} needs a target of 3 finite numbers "
                f"(m), move > 0 s and hold >= 0 s; got {kf.position!r}, {kf.move!r}, {kf.hold!r}",
                keyframe=kf.name,
            )
    total = sum(kf.move for kf in act.keyframes[1:]) + sum(kf.hold for kf in act.keyframes)
    if total * rate > MAX_SAMPLES:
        raise ActivityError(
            f"activity {act.name!r}: {total:g} s at {rate:g} Hz is more than {MAX_SAMPLES:g} "
            "samples; lower the rate or the durations"
        )
    q_prev = (
        comfortable_posture(robot) if q_start is None else robot.check_q(q_start, name="q_start")
    )
    Qk, status, err = [], [], []
    for kf in act.keyframes:
        p = np.asarray(kf.position, float)
        res = ik.solve(robot, p, q0=q_prev, mode="position", posture="auto")
        e = float(np.linalg.norm(robot.fk(res.q)[:3, 3] - p))
        ok = e <= tol
        if not ok and strict:
            raise ActivityError(
                f"activity {act.name!r}: keyframe {kf.name!r} at {np.round(p, 3).tolist()} m is "
                f"out of the arm's reach (closest hand position {e * 1000:.0f} mm away; "
                f"{res.status})",
                keyframe=kf.name,
                distance=e,
            )
        Qk.append(res.q)
        status.append("ok" if ok else "unreachable")
        err.append(e)
        q_prev = res.q
    Qk = np.array(Qk)
    durations = np.array([kf.move for kf in act.keyframes], float)
    holds = np.array([kf.hold for kf in act.keyframes], float)
    t, q, qd, qdd, arrival = keyframe_trajectory(Qk, durations, holds, rate)
    # the object is in the hand from a keyframe flagged holding until the next keyframe not flagged
    holding = np.zeros(len(t), dtype=bool)
    flags = [kf.holding for kf in act.keyframes]
    for k, fl in enumerate(flags):
        start = arrival[k]
        end = arrival[k + 1] if k + 1 < len(flags) else np.inf
        if fl:
            holding |= (t >= start) & (t < end)
    hand = robot.fk(q)[:, :3, 3]
    return ActivityTrajectory(
        act,
        t,
        q,
        qd,
        qdd,
        hand,
        holding,
        act.object_mass,
        tuple(kf.name for kf in act.keyframes),
        arrival,
        Qk,
        tuple(status),
        np.array(err),
        tuple(robot.chain.q_names),
    )
