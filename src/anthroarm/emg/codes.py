r"""The 4-code switching state machine of the 3-DOF EMG upper-arm hand (book §9-2 三 2).

Printed (Shanghai Institute of Physiology, 1981, Fig. 9-25): two upper-arm EMG channels with
thresholds form four codes.  **10** (flexor) closes the fingers, pronates the wrist or flexes
the elbow; **01** (extensor) opens the fingers, supinates the wrist or extends the elbow;
**11** switches the controlled joint; **00** is rest.  Three vibrators on the chest tell the
wearer the state: **left** when the circuit switches to the elbow, **right** when it switches
to the wrist, **neither** for the fingers, and the **middle** one when the fingers grip or
have grasped an object.

Not printed, chosen here (assumptions, each a parameter):

* **mode cycle order** elbow → wrist → fingers → elbow, starting at the elbow: the order in
  which the book describes the vibrators, and the joint the book calls the key function of an
  upper-arm prosthesis;
* **debouncing**: a code is accepted once it has persisted ``debounce_s`` (default 50 ms);
  with the 100 ms envelope window the controller's delay stays near the 100–125 ms that
  Farrell & Weir 2007 (*IEEE TNSRE* 15:111) found best for myoelectric prostheses;
* **co-contraction**: an accepted 11 switches the mode only when it is a deliberate
  co-contraction: it comes straight from rest, or the second muscle joined within
  ``cocontraction_s`` (default 150 ms) of the first one's onset (two muscles never start
  exactly together).  A slow 11 (antagonist tension while moving) stops the joint without
  switching ("hold");
* **lock-out**: after a switch, commands stay off until the code returns to 00, so the
  relaxation of a co-contraction (one muscle letting go first) does not drive the newly
  selected joint;
* **vibrator timing**: the left/right vibrator pulses ``vibrate_s`` (default 0.3 s) after a
  switch; the middle one is on while the hand reports a grasp.

Codes are integers ``2·flexor + extensor`` (:data:`~anthroarm.emg.processor.REST` = 0 …
:data:`~anthroarm.emg.processor.BOTH` = 3); commands are +1 (flexor direction: close,
pronate, flex), −1 (extensor direction) or 0.  The machine is run on blocks of frames and
keeps its state between calls, so blocks of any length give the result of one piece.  Like
:class:`~anthroarm.emg.processor.EMGProcessor` it is not thread-safe: one machine per stream.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import EMGError
from ._checks import nonnegative, positive
from .processor import BOTH, EXTENSOR, FLEXOR, REST

#: mode cycle (an assumption, the order in which the book lists the vibrators)
MODES = ("elbow", "wrist", "fingers")
#: the chest vibrator that signals a switch to each mode, book §9-2 (None means no vibrator)
VIBRATOR_OF_MODE = {"elbow": "left", "wrist": "right", "fingers": None}
#: the columns of ``CodeTrace.vibrators``
VIBRATORS = ("left", "right", "middle")
#: the longest debounce, co-contraction or vibrator time in frames (2**40 frames of 1 ms are
#: 35 years; frame indices are int64, so sums of them never overflow)
MAX_FRAMES = float(2**40)


@dataclass(frozen=True)
class CodeTrace:
    """Per control frame (``frame_s`` seconds each): ``code`` the accepted (debounced) code
    0..3, ``mode`` the index into ``modes`` of the controlled joint, ``command`` −1/0/+1,
    ``switched`` True on the frame a mode switch happens, ``hold`` True on frames where an
    accepted 11 did not switch (slow co-contraction), ``vibrators`` (frames, 3) bool for
    :data:`VIBRATORS` (the middle column is False here; see :func:`vibrators_with_grasp`)."""

    code: np.ndarray
    mode: np.ndarray
    command: np.ndarray
    switched: np.ndarray
    hold: np.ndarray
    vibrators: np.ndarray
    modes: tuple
    frame_s: float

    @property
    def mode_names(self) -> list[str]:
        """The controlled joint's name at every frame."""
        return [self.modes[i] for i in self.mode]


class CodeMachine:
    """Debounced 4-code → mode/command state machine (see the module text).

    Parameters
    ----------
    frame_s
        Frame period of the codes (s), e.g. ``EMGProcessor.frame_s``.
    debounce_s
        A code must persist this long (s) to be accepted (at least one frame).
    cocontraction_s
        Largest onset asynchrony (s) of the two muscles for an 11 to count as a switch.
    modes
        The cycle of controlled joints (names; the vibrator of each from
        :data:`VIBRATOR_OF_MODE`, ``None`` for unknown names).
    start_mode
        Index of the first controlled joint.
    vibrate_s
        Length of the switch pulse of the left/right vibrator (s).
    """

    def __init__(
        self,
        frame_s: float,
        debounce_s: float = 0.05,
        cocontraction_s: float = 0.15,
        modes=MODES,
        start_mode: int = 0,
        vibrate_s: float = 0.3,
    ):
        self.frame_s = positive(frame_s, "frame_s", "s")
        self.n_db = max(1, self._frames(nonnegative(debounce_s, "debounce_s", "s"), "debounce_s"))
        self.n_cc = self._frames(
            nonnegative(cocontraction_s, "cocontraction_s", "s"), "cocontraction_s"
        )
        self.n_vib = max(1, self._frames(positive(vibrate_s, "vibrate_s", "s"), "vibrate_s"))
        try:
            if isinstance(modes, (str, bytes)):
                raise TypeError
            self.modes = tuple(str(m) for m in modes)
        except TypeError:
            raise EMGError(
                f"modes is a sequence of mode names, e.g. ('elbow', 'wrist', 'fingers'), got "
                f"{type(modes).__name__} {modes!r}"
            ) from None
        if len(self.modes) < 1:
            raise EMGError("modes needs at least one joint name")
        if not (
            isinstance(start_mode, (int, np.integer))
            and not isinstance(start_mode, bool)
            and 0 <= start_mode < len(self.modes)
        ):
            raise EMGError(
                f"start_mode must be an index 0..{len(self.modes) - 1}, got {start_mode!r}"
            )
        self.start_mode = int(start_mode)
        vib = [VIBRATOR_OF_MODE.get(m) for m in self.modes]
        self._vib_col = np.array([-1 if v is None else VIBRATORS.index(v) for v in vib])
        self.reset()

    def _frames(self, seconds: float, name: str) -> int:
        """``seconds`` as a whole number of frames, at most :data:`MAX_FRAMES` (else
        :class:`~anthroarm.errors.EMGError`: a ratio that overflows a float or the frame
        counters is a unit mistake, not a setting)."""
        ratio = seconds / self.frame_s
        if not ratio <= MAX_FRAMES:  # also catches inf (a subnormal frame_s)
            raise EMGError(
                f"{name} = {seconds:g} s is {ratio:.3g} frames of frame_s = {self.frame_s:g} s, "
                f"more than {MAX_FRAMES:.3g}: are both in seconds?"
            )
        return int(round(ratio))

    def reset(self) -> None:
        """Back to rest: code 00, the start mode, no lock-out, no pulse, frame 0."""
        self._frame = 0  # global index of the next frame
        self._raw = REST  # raw code of the current run
        self._raw_start = 0  # global frame where the current raw run began
        self._code = REST  # accepted code
        self._mode = self.start_mode
        self._locked = False
        self._hold = False  # the accepted 11 is a slow one (no switch)
        self._onset = 0  # raw start of the single-muscle activity that left rest
        self._vib_until = 0  # global frame (exclusive) until which a switch pulse lasts
        self._vib_mode = self.start_mode

    def run(self, raw_codes) -> CodeTrace:
        """Feed raw codes (frames,) int 0..3 (``ProcessedEMG.code``); returns the
        :class:`CodeTrace` of these frames and keeps the state for the next block."""
        try:
            r = np.asarray(raw_codes)
        except (TypeError, ValueError):
            raise EMGError(
                "raw_codes must be a 1-D integer array of codes 0..3, got "
                f"{type(raw_codes).__name__} (ragged?)"
            ) from None
        if r.ndim != 1 or (
            r.size and (not np.issubdtype(r.dtype, np.integer) or r.min() < 0 or r.max() > 3)
        ):
            raise EMGError(
                f"raw_codes must be a 1-D integer array of codes 0..3, got shape {r.shape}, "
                f"dtype {r.dtype}"
            )
        m, g0 = r.size, self._frame
        state0 = (self._code, self._mode, self._locked)
        hold0 = self._hold
        vib0 = (self._vib_until, self._vib_mode)
        events = []  # (global frame, code, mode, locked, switched, hold)
        if m:
            change = np.flatnonzero(r[1:] != r[:-1]) + 1
            starts = np.concatenate([[0], change])
            ends = np.concatenate([change, [m]])
            for s, e in zip(starts, ends):
                c = int(r[s])
                if s == 0 and c == self._raw:
                    start = self._raw_start
                else:
                    start = g0 + int(s)
                    self._raw, self._raw_start = c, start
                if c == self._code or g0 + int(e) - start < self.n_db:
                    continue
                a = start + self.n_db - 1  # frame on which the run has lasted n_db frames
                switched = hold = False
                if c == BOTH:
                    if self._code == REST or start - self._onset <= self.n_cc:
                        self._mode = (self._mode + 1) % len(self.modes)
                        self._locked = switched = True
                        self._vib_until, self._vib_mode = a + self.n_vib, self._mode
                    else:
                        hold = True
                elif c == REST:
                    self._locked = False
                elif self._code == REST:
                    self._onset = start
                self._code, self._hold = c, hold
                events.append((a, c, self._mode, self._locked, switched, hold))
        self._frame = g0 + m
        return self._trace(m, g0, state0, hold0, vib0, events)

    def _trace(self, m, g0, state0, hold0, vib0, events) -> CodeTrace:
        frames = g0 + np.arange(m)
        ev_f = np.array([e[0] for e in events], dtype=np.int64)
        table = np.array([state0] + [(e[1], e[2], e[3]) for e in events], dtype=np.int64).reshape(
            -1, 3
        )
        k = np.searchsorted(ev_f, frames, side="right")  # 0 = before the first event
        code, mode, locked = table[k, 0], table[k, 1], table[k, 2].astype(bool)
        command = np.where(
            locked, 0, np.where(code == FLEXOR, 1, np.where(code == EXTENSOR, -1, 0))
        ).astype(np.int8)
        switched = np.zeros(m, dtype=bool)
        hold = np.zeros(m, dtype=bool)
        for f, *_, sw, hd in events:
            switched[f - g0] |= sw
        hold_code = np.array([hold0] + [e[5] for e in events], dtype=bool)[k]
        hold[:] = hold_code & (code == BOTH)
        vib = np.zeros((m, len(VIBRATORS)), dtype=bool)
        until0, mode0 = vib0
        pulses = [(until0 - self.n_vib, until0, mode0)] if until0 > g0 else []
        pulses += [(f, f + self.n_vib, md) for f, _, md, _, sw, _ in events if sw]
        for i, (f0, f1, md) in enumerate(pulses):
            if i + 1 < len(pulses):
                f1 = min(f1, pulses[i + 1][0])  # a new switch ends the previous pulse
            col = self._vib_col[md]
            lo, hi = max(f0, g0) - g0, min(f1, g0 + m) - g0
            if col >= 0 and hi > lo:
                vib[lo:hi, col] = True
        return CodeTrace(
            code=code.astype(np.int8),
            mode=mode.astype(np.int8),
            command=command,
            switched=switched,
            hold=hold,
            vibrators=vib,
            modes=self.modes,
            frame_s=self.frame_s,
        )


def vibrators_with_grasp(trace: CodeTrace, grasped) -> np.ndarray:
    """The vibrator pattern of ``trace`` with the middle vibrator on while ``grasped``
    ((frames,) bool: the fingers grip or hold an object, book §9-2 三 2)."""
    g = np.asarray(grasped, dtype=bool)
    if g.shape != trace.code.shape:
        raise EMGError(f"grasped must have one entry per frame {trace.code.shape}, got {g.shape}")
    v = trace.vibrators.copy()
    v[:, VIBRATORS.index("middle")] = g
    return v
