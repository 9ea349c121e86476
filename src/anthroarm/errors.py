"""Typed exceptions of anthroarm.

Every error a user can cause (a bad file, a bad array, an unknown name) raises one of these,
with a message that names the file, the joint or the value at fault.  Value errors on arrays
derive from :class:`ValueError` so that ``except ValueError`` keeps working.
"""

from __future__ import annotations


class AnthroarmError(Exception):
    """Base class of every exception raised on purpose by anthroarm."""


class URDFError(AnthroarmError):
    """A URDF file cannot be used.  ``path`` names the file."""

    def __init__(self, path, problem: str):
        self.path = str(path)
        self.problem = problem
        super().__init__(f"{self.path}: {problem}")


class URDFNotFoundError(URDFError, FileNotFoundError):
    """The URDF path does not exist."""


class URDFSyntaxError(URDFError):
    """The file is not well-formed XML, or not a URDF ``<robot>``."""


class URDFSecurityError(URDFError):
    """The file uses a DTD / entity declarations (entity bombs, external entities)."""


class URDFStructureError(URDFError):
    """Kinematic structure is invalid: cycles, unknown links, unknown joint types, bad numbers."""


class MeshNotFoundError(URDFError, FileNotFoundError):
    """A mesh referenced by the URDF cannot be found."""


class PackagePathError(URDFError):
    """A ``package://`` URI names an unknown package or escapes its package directory."""


class UnknownModelError(AnthroarmError, KeyError):
    """A catalog name that does not exist.  The message lists the catalog."""

    def __str__(self) -> str:  # KeyError would quote the message
        return str(self.args[0]) if self.args else ""


class UnknownFrameError(AnthroarmError, KeyError):
    """A frame name that does not exist in the model.  The message lists valid frames."""

    def __str__(self) -> str:
        return str(self.args[0]) if self.args else ""


class UnsupportedModelError(AnthroarmError):
    """The model has a feature an algorithm does not support (e.g. a free-flyer joint)."""


class ViewerError(AnthroarmError):
    """The meshcat viewer cannot do what was asked (server not running, no answer, ...)."""


class ViewerPortInUseError(ViewerError, OSError):
    """The requested viewer port on 127.0.0.1 is already taken."""


class InertiaError(UnsupportedModelError, ValueError):
    """A link inertia cannot be used for dynamics: negative or non-finite mass, an indefinite
    or non-symmetric inertia tensor, or a chain without mass (M(q) singular)."""


class SolverNotAvailableError(AnthroarmError, ValueError):
    """A QP solver name that is unknown or not installed.  The message lists the installed ones."""


class EulerSingularityError(AnthroarmError, ValueError):
    """Euler angles at a singular posture (gimbal lock), e.g. sin ψ = 0 for X–Y–X angles."""


class AmbiguousToolError(UnknownFrameError):
    """A robot with several tips was loaded without ``tool=``; the message lists the tip frames."""


class ParameterError(AnthroarmError, TypeError, ValueError):
    """A keyword a loader or builder does not take, or a bad builder parameter.  A
    :class:`TypeError` (like any unknown keyword) and, for old callers, a :class:`ValueError`."""


class AnthropometryError(AnthroarmError, ValueError):
    """Body or hand measurements outside human ranges (:mod:`anthroarm.models.hand`): a hand
    longer than the forearm, a negative or implausible breadth, a hand length out of
    proportion to the stature.  ``name`` is the parameter, ``value`` its value (SI)."""

    def __init__(self, message: str, name: str | None = None, value=None):
        self.name = name
        self.value = value
        super().__init__(message)


class MeshError(AnthroarmError, ValueError):
    """A mesh file a robot's visuals name is not a usable mesh: not a mesh at all (a text file,
    random bytes), empty, truncated, non-finite, beyond the size bound, or a format the viewer
    does not read.  ``path`` names the mesh file, ``link`` the link (or geometry object) that
    uses it."""

    def __init__(self, path, problem: str, link: str | None = None):
        self.path = str(path)
        self.link = link
        self.problem = problem
        where = f" (mesh of link {link!r})" if link is not None else ""
        super().__init__(f"{self.path}{where}: {problem}")


class SingularMassMatrixError(InertiaError):
    """M(q) is singular or too ill-conditioned for forward dynamics at this configuration: a
    joint moves (almost) no mass or inertia there (e.g. a point mass on the axis of the joint
    above it).  ``q`` is the configuration (robot layout), ``cond`` the condition number of
    M(q) (``inf`` when it is exactly singular), ``joint`` the joint that moves least.  Forward
    dynamics has no unique answer there; Pinocchio's ``aba`` returns accelerations of ~1e30
    without a warning."""

    def __init__(self, message: str, q=None, cond: float = float("inf"), joint: str | None = None):
        self.q = q
        self.cond = cond
        self.joint = joint
        super().__init__(message)


class DualDivisionError(AnthroarmError, ValueError):
    """Division by a dual number whose real part is zero (a + ε b with a = 0 has no inverse)."""


class ObjectiveError(AnthroarmError, ValueError):
    """An optimiser's objective never returned a finite value: NaN or ±inf at every point it
    was evaluated, so there is no best point to report.  ``x`` is the last point evaluated,
    ``value`` the value there (NaN or ±inf), ``nfev`` the number of evaluations."""

    def __init__(self, message: str, x=None, value: float = float("nan"), nfev: int = 0):
        self.x = x
        self.value = value
        self.nfev = nfev
        super().__init__(message)


class MotionDataError(AnthroarmError, ValueError):
    """Recorded motion that cannot be used as given (:mod:`anthroarm.motion`): a C3D or CSV file
    that is missing, unreadable or malformed, unknown units, marker trajectories of the wrong
    shape.  ``path`` names the file (``None`` for arrays)."""

    def __init__(self, problem: str, path=None):
        self.path = None if path is None else str(path)
        self.problem = problem
        super().__init__(problem if path is None else f"{self.path}: {problem}")


class C3DError(MotionDataError):
    """A C3D file ezc3d cannot read or write, or one without usable POINT data (labels, rate,
    units)."""


class MarkerSetError(AnthroarmError, ValueError):
    """A marker set that does not fit the robot: an unknown body frame (the message lists the
    frames), duplicate marker names, a non-finite position or weight, or no marker of the set in
    a trial."""


class UnconstrainedJointError(MarkerSetError):
    """The markers cannot determine some joints: no marker on a body downstream of the joint,
    or a marker Jacobian whose rank is below the number of joints.  ``joints`` lists them."""

    def __init__(self, message: str, joints=()):
        self.joints = tuple(joints)
        super().__init__(message)


class ActivityError(AnthroarmError, ValueError):
    """A daily-living activity that cannot be built: a bad parameter (duration, mass, a target
    that is not finite), or, with ``strict=True``, a target outside the arm's reach
    (``keyframe`` names it, ``distance`` is the remaining hand error in m)."""

    def __init__(self, message: str, keyframe: str | None = None, distance: float = 0.0):
        self.keyframe = keyframe
        self.distance = distance
        super().__init__(message)


class ControlError(AnthroarmError, ValueError):
    """A bad input to :mod:`anthroarm.control` (servo, motor, teach/playback, DDA, gripper): a
    non-finite or out-of-range parameter, a malformed program.  The message names the value."""


class PlaybackError(ControlError):
    """A teach/playback program that cannot run: a jump or call to a label, subroutine or address
    that does not exist (the message lists the valid ones), or a duplicate label."""


class DegenerateArcError(ControlError):
    """A circular arc through three points that are collinear or coincident (no unique circle)."""


class EMGError(AnthroarmError, ValueError):
    """An EMG recording or signal-chain setting that cannot be processed: NaN/inf samples, the
    wrong array shape or channel count, a bad window or gain (:mod:`anthroarm.emg`)."""


class SamplingRateError(EMGError):
    """The sampling rate cannot represent a filter band: it must exceed twice the highest band
    edge (Nyquist).  ``fs`` is the rate (Hz), ``required`` the smallest usable rate (Hz)."""

    def __init__(self, message: str, fs: float = float("nan"), required: float = float("nan")):
        self.fs = fs
        self.required = required
        super().__init__(message)


class ThresholdError(EMGError):
    """EMG amplitude thresholds that can never switch: not finite or not > 0, an off-threshold
    above the on-threshold, an on-threshold no input reaches (beyond the amplifier's rail) or
    an off-threshold at or below the noise floor (never switches off)."""


class GraspError(AnthroarmError, ValueError):
    """A grasp that cannot be posed: an object larger than the hand's span, a bad object
    (non-finite centre, radius <= 0), a wrong number of contacts."""


class FingertipError(AnthroarmError, ValueError):
    """A fingertip task or grasp contact on a frame that is not a fingertip of the hand (not a
    tip of ``robot.chain`` moved by finger joints).  The message lists the fingertips."""


class CouplingError(AnthroarmError, ValueError):
    """Coupled joints given inconsistent values: a mimic joint's value that is not
    multiplier · source + offset, or a start configuration that breaks a hard coupling."""


class CatalogueError(AnthroarmError, ValueError):
    """A motor or gearbox catalogue (CSV, :mod:`anthroarm.prosthesis.catalogue`) that cannot be
    used: a missing column, a value that is not a number, a negative or zero constant, a
    duplicate name.  ``path`` names the file, ``line`` the line (1-based) and ``column`` the
    column at fault (``None`` when the whole file is at fault)."""

    def __init__(self, problem: str, path=None, line: int | None = None, column: str | None = None):
        self.path = None if path is None else str(path)
        self.line = line
        self.column = column
        self.problem = problem
        where = (
            ""
            if path is None
            else f"{self.path}" + (f", line {line}" if line is not None else "") + ": "
        )
        super().__init__(where + problem)


class UnknownCodeError(AnthroarmError, KeyError):
    """A code or key that a book table does not hold (e.g. a display code of Table 9.6); the
    message lists the valid ones."""

    def __str__(self) -> str:
        return str(self.args[0]) if self.args else ""


class UnsafeCacheError(AnthroarmError, PermissionError):
    """The disk cache folder (:mod:`anthroarm.cache`) is not safe to use: it is a symbolic
    link, not a folder, owned by another user, or writable by group or others.  Raised by
    operations that act on that folder on purpose (``anthroarm cache clear``); everyday use
    warns with :class:`UnsafeCacheWarning` and runs without it.  ``path`` is the folder."""

    def __init__(self, message: str, path=None):
        self.path = None if path is None else str(path)
        super().__init__(message)

    def __str__(self) -> str:  # PermissionError would format (errno, strerror)
        return str(self.args[0]) if self.args else ""


class UnsafeCacheWarning(UserWarning):
    """The disk cache folder is not safe to use (see :class:`UnsafeCacheError`); anthroarm runs
    without it, keeping generated code in a private temporary folder for this process."""


class CollisionError(AnthroarmError, ValueError):
    """A collision model, obstacle or collision limit that cannot be used: a missing or corrupt
    collision mesh (``link`` and ``path`` name it), a degenerate shape (radius or size <= 0,
    non-finite pose), too many obstacles, a safety distance not below the detection distance."""

    def __init__(self, message: str, link: str | None = None, path=None):
        self.link = link
        self.path = None if path is None else str(path)
        super().__init__(message)


class NoCollisionBodiesError(CollisionError):
    """A robot with no collision bodies: its URDF has no ``<collision>`` elements and it has no
    links to wrap in capsules (a Cartesian gantry of bare prismatic joints)."""


class OsimError(AnthroarmError, ValueError):
    """An OpenSim model (``.osim``) that cannot be imported.  ``path`` names the file,
    ``element`` the XML element at fault (``<SimmSpline>`` of ``knee_r/translation1``) and
    ``line`` its line in the file (None when unknown)."""

    def __init__(self, path, problem: str, element: str | None = None, line: int | None = None):
        self.path = str(path)
        self.problem = problem
        self.element = element
        self.line = line
        where = ""
        if element:
            where += f" {element}"
        if line is not None:
            where += f" (line {line})"
        super().__init__(f"{self.path}:{where}: {problem}" if where else f"{self.path}: {problem}")


class OsimSecurityError(OsimError):
    """The file uses a DTD / entity declarations (entity bombs, external entities), or is too
    large to be a model."""


class OsimUnsupportedError(OsimError):
    """A valid OpenSim construct the import does not represent (a joint or function type, a
    format version): the message names the remedy."""


class OsimStrictError(OsimError):
    """``strict=True`` and the import report lists a component as dropped or approximated."""


class MuscleError(AnthroarmError, ValueError):
    """A muscle that cannot be evaluated: a non-positive optimal fibre length or maximum
    isometric force, a path whose consecutive points coincide, activations outside [0, 1]
    (``anthroarm.muscles``)."""
