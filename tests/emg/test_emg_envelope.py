"""Envelopes of the EMG chain (book §9-2 二 3): the book's amplitudes, peak to peak, moving RMS,
the linear envelope, window sizes.  The FFT features are tested in ``test_features.py``, the
test-signal generator in ``test_synth.py``.

Oracles: closed forms for a sine (RMS = A/sqrt 2, mean rectified value 2A/pi) and the direct
definition of a moving RMS (a brute-force sum)."""

import numpy as np
import pytest

from anthroarm.emg import (
    AMPUTEE_PP,
    AMPUTEE_TRAINED_PP,
    EMG_BAND,
    HEALTHY_PP,
    PP_PER_MAV,
    PP_PER_RMS,
    TYPICAL_PP,
    lowpass_envelope,
    moving_rms,
    peak_to_peak,
    rms,
)
from anthroarm.errors import EMGError, SamplingRateError

FS = 2000.0


def test_book_amplitudes():
    assert HEALTHY_PP == (1e-3, 3e-3)  # 1-3 mV p-p, healthy
    assert TYPICAL_PP == 100e-6  # typical moderate contraction
    assert AMPUTEE_PP == 50e-6 and AMPUTEE_TRAINED_PP == 100e-6
    assert EMG_BAND == (30.0, 300.0)  # main spectral power


def test_sine_equivalent_peak_to_peak_of_a_sine():
    t = np.arange(4000) / FS
    A = 37e-6
    x = A * np.sin(2 * np.pi * 100 * t)
    assert PP_PER_RMS * rms(x)[0] == pytest.approx(2 * A, rel=1e-9)
    # sampled at N = 20 points a period, the mean of |sin| is 2 cot(pi/N)/N (-> 2/pi as N grows)
    N = 20
    assert np.mean(np.abs(x)) == pytest.approx(A * 2 / np.tan(np.pi / N) / N, rel=1e-9)
    assert PP_PER_MAV * A * 2 / np.pi == pytest.approx(2 * A, rel=1e-15)
    assert peak_to_peak(x)[0] == pytest.approx(2 * A, rel=1e-6)


def test_moving_rms_matches_its_definition_and_a_sine():
    rng = np.random.default_rng(0)
    x = rng.standard_normal((2, 700))
    w = 60  # 30 ms at 2 kHz
    got = moving_rms(x, FS, 0.03)
    pad = np.concatenate([np.zeros((2, w - 1)), x], axis=1)
    brute = np.array(
        [[np.sqrt(np.sum(pad[c, k : k + w] ** 2) / w) for k in range(700)] for c in range(2)]
    )
    np.testing.assert_allclose(got, brute, rtol=1e-10, atol=1e-14)
    t = np.arange(4000) / FS
    s = 5.0 * np.sin(2 * np.pi * 50 * t)  # 100 ms window = 5 periods
    np.testing.assert_allclose(moving_rms(s, FS, 0.1)[0, 400:], 5.0 / np.sqrt(2), rtol=1e-9)


def test_linear_envelope_of_a_sine_is_its_mean_rectified_value():
    t = np.arange(8000) / FS
    s = 2.0 * np.sin(2 * np.pi * 150 * t)
    e = lowpass_envelope(s, FS, cutoff_hz=5.0)[0, 4000:]
    # 150 Hz at 2 kHz: 3 periods in 40 samples; the sampled mean of |sin| is 2 cot(pi/40)/40
    assert np.mean(e) == pytest.approx(2.0 * 2 / np.tan(np.pi / 40) / 40, rel=2e-3)
    assert np.ptp(e) < 0.01 * np.mean(e)  # the 300 Hz ripple is filtered out
    with pytest.raises(SamplingRateError):
        lowpass_envelope(s, 8.0, cutoff_hz=5.0)


def test_window_shorter_than_a_sample_and_bad_arrays():
    with pytest.raises(EMGError, match="shorter than one sample"):
        moving_rms(np.zeros(10), FS, 1e-4)
    with pytest.raises(EMGError, match="NaN"):
        moving_rms(np.array([0.0, np.inf]), FS, 0.1)
    with pytest.raises(EMGError, match="shape"):
        moving_rms(np.zeros((2, 3, 4)), FS, 0.1)
