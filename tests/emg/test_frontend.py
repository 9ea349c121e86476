"""The differential front end of the EMG chain (book §9-2): CMRR, saturation at the rails, bad
input.

Oracle: the linear amplifier equation (differential gain times the difference plus the
common-mode gain times the mean, clipped at the rails)."""

import numpy as np
import pytest

from anthroarm.emg import (
    DifferentialAmplifier,
    electrode_potentials,
)
from anthroarm.errors import EMGError


def test_cmrr_of_the_differential_amplifier():
    fs, amp = 2000.0, DifferentialAmplifier(gain=5000.0, cmrr_db=100.0, rail=None)
    t = np.arange(2000) / fs
    emg = 100e-6 * np.sin(2 * np.pi * 120 * t)  # 200 µV p-p differential
    vp, vm = electrode_potentials(emg, fs, mains_pp=1.0, mains_hz=50.0, offset_v=0.2)
    out = amp.amplify(vp, vm)
    assert out.status == "ok"
    gc = 5000.0 * 10 ** (-100 / 20)
    cm = 0.5 * np.sin(2 * np.pi * 50 * t) + 0.2
    np.testing.assert_allclose(out.signal[0], 5000.0 * emg + gc * cm, rtol=0, atol=1e-12)
    # the common-mode hum (1 V p-p, 74 dB above the EMG) leaves 0.05 V p-p beside 1 V p-p of EMG
    assert amp.common_mode_gain == pytest.approx(0.05)
    np.testing.assert_allclose(
        amp.input_referred(out.signal), (emg + gc / 5000.0 * cm)[None], atol=1e-15
    )


def test_amplifier_saturation_is_reported():
    amp = DifferentialAmplifier(gain=10_000.0, rail=5.0)
    assert amp.max_input_pp == pytest.approx(1e-3)
    x = np.array([[0.0, 4e-4, 6e-4, -7e-4]])
    out = amp.amplify(x / 2, -x / 2)
    np.testing.assert_allclose(out.signal[0], [0.0, 4.0, 5.0, -5.0])
    assert out.saturated.tolist() == [2] and out.status.startswith("saturated")


def test_amplifier_bad_input():
    with pytest.raises(EMGError):
        DifferentialAmplifier(gain=-1)
    with pytest.raises(EMGError):
        DifferentialAmplifier(cmrr_db=float("nan"))
    amp = DifferentialAmplifier()
    with pytest.raises(EMGError, match="same shape"):
        amp.amplify(np.zeros((2, 10)), np.zeros((2, 11)))
    with pytest.raises(EMGError, match="NaN"):
        amp.amplify(np.array([[0.0, np.nan]]), np.zeros((1, 2)))
