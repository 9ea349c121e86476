r"""The differential front end: a bipolar surface-electrode pair and a high-CMRR amplifier.

Book §9-2 (二 1, 三): paired silver surface electrodes 2–3 cm apart over the motor point pick
up microvolt EMG; the amplifier needs a gain of **thousands to tens of thousands**, a
DC-coupled **double-ended differential** first stage, and a high **common-mode rejection
ratio** against 50 Hz mains, which reaches both electrodes almost equally.  The book gives no
CMRR figure; the default 100 dB is an assumption in the range surface-EMG amplifier designs
aim for (Merletti & Parker 2004, *Electromyography*, ch. 5).

A linear differential amplifier with differential gain :math:`G_d` and CMRR
:math:`\rho = G_d / G_c` outputs

.. math:: v_o = G_d\,(v_+ - v_-) + G_c\,\frac{v_+ + v_-}{2},\qquad
          G_c = G_d\,10^{-\mathrm{CMRR}_{dB}/20},

clipped at the supply rails :math:`\pm V_{rail}` (the output saturates; the result says so).
Volts in, volts out; time along the last axis.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import EMGError
from ._checks import positive, signal


@dataclass(frozen=True)
class AmplifierOutput:
    """What :meth:`DifferentialAmplifier.amplify` returns.

    ``signal``: (channels, samples) output volts (clipped at the rails); ``saturated``: number
    of clipped samples per channel; ``status``: ``"ok"`` or ``"saturated: ..."`` naming the
    channels, so a clipped recording is never taken for a clean one."""

    signal: np.ndarray
    saturated: np.ndarray
    status: str


@dataclass(frozen=True)
class DifferentialAmplifier:
    """A differential EMG amplifier (book §9-2 三: gain 10³–10⁴, differential, high CMRR).

    Parameters
    ----------
    gain
        Differential gain :math:`G_d` (V/V); default 5000 (the book's "thousands to tens of
        thousands").
    cmrr_db
        Common-mode rejection ratio, dB (assumption: 100 dB).
    rail
        Output saturation, ±V (default 5 V); ``None`` for an ideal amplifier.
    """

    gain: float = 5000.0
    cmrr_db: float = 100.0
    rail: float | None = 5.0

    def __post_init__(self):
        positive(self.gain, "gain", "V/V")
        positive(self.cmrr_db, "cmrr_db", "dB")
        if self.rail is not None:
            positive(self.rail, "rail", "V")

    @property
    def common_mode_gain(self) -> float:
        """:math:`G_c = G_d / 10^{\\mathrm{CMRR}/20}` (V/V)."""
        return self.gain * 10.0 ** (-self.cmrr_db / 20.0)

    @property
    def max_input_pp(self) -> float:
        """The largest differential input peak-to-peak (V) that passes unclipped: 2 rail / gain
        (``inf`` without a rail)."""
        return float("inf") if self.rail is None else 2.0 * self.rail / self.gain

    def amplify(self, v_plus, v_minus) -> AmplifierOutput:
        """Amplify the electrode potentials ``v_plus``, ``v_minus`` (V, (channels, samples),
        same shape) against the reference; returns :class:`AmplifierOutput`."""
        a = signal(v_plus, "v_plus")
        b = signal(v_minus, "v_minus")
        if a.shape != b.shape:
            raise EMGError(
                f"v_plus and v_minus must have the same shape, got {a.shape} and {b.shape}"
            )
        with np.errstate(over="ignore", invalid="ignore"):
            out = self.gain * (a - b) + self.common_mode_gain * 0.5 * (a + b)
        if not np.all(np.isfinite(out)):
            raise EMGError(
                f"gain {self.gain:g} times the input overflows the float range: lower the gain"
            )
        if self.rail is None:
            return AmplifierOutput(out, np.zeros(out.shape[0], dtype=int), "ok")
        clipped = np.abs(out) > self.rail
        np.clip(out, -self.rail, self.rail, out=out)
        n = clipped.sum(axis=1)
        status = "ok"
        if n.any():
            which = ", ".join(f"channel {i}: {k} samples" for i, k in enumerate(n) if k)
            status = f"saturated at ±{self.rail:g} V ({which}): lower the gain"
        return AmplifierOutput(out, n, status)

    def input_referred(self, v_out) -> np.ndarray:
        """Output volts divided by the differential gain: the EMG at the electrodes (V)."""
        return signal(v_out, "v_out") / self.gain
