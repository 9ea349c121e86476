"""The EMG test-signal generator (book §9-2): synthesized amplitudes and envelopes, activation
ramps, bad input.

Oracles: the book's amplitudes (p-p of the synthesized signal against the requested one) and
the closed form of its raised-cosine ramp."""

import numpy as np
import pytest

from anthroarm.emg import (
    PP_PER_RMS,
    activation,
    band_limited_noise,
    rms,
    synthesize,
)
from anthroarm.errors import EMGError

FS = 2000.0


def test_synthesized_amplitude_and_envelope():
    rec = synthesize(
        3.0, FS, [[(0.5, 2.0, 1.0)], [(1.0, 1.0, 0.5)]], pp=[1e-3, 3e-3], noise_rms=0.0, rng=2
    )
    assert rec.emg.shape == (2, 6000)
    on = (rec.t > 0.6) & (rec.t < 2.4)
    assert PP_PER_RMS * rms(rec.emg[0, on])[0] == pytest.approx(1e-3, rel=0.05)
    on1 = (rec.t > 1.1) & (rec.t < 1.9)
    assert PP_PER_RMS * rms(rec.emg[1, on1])[0] == pytest.approx(0.5 * 3e-3, rel=0.05)
    assert np.all(rec.emg[:, rec.t < 0.5] == 0.0)
    np.testing.assert_allclose(rec.envelope_rms, rec.activation * (rec.pp / PP_PER_RMS)[:, None])


def test_activation_ramps():
    t = np.linspace(0, 1, 1001)
    a = activation(t, [(0.2, 0.5, 0.8)], ramp_s=0.1)
    assert a[t < 0.2].max() == 0 and a[t > 0.7].max() == 0
    np.testing.assert_allclose(a[(t >= 0.3) & (t <= 0.6)], 0.8)
    assert a[250] == pytest.approx(0.4, abs=1e-9)  # half-way up the raised cosine


def test_synth_bad_input():
    with pytest.raises(EMGError):
        band_limited_noise(1000, 500.0, (30.0, 300.0))  # band above Nyquist
    with pytest.raises(EMGError):
        synthesize(1.0, FS, [[(0.1, 0.2, 2.0)]])  # level > 1
    with pytest.raises(EMGError):
        synthesize(1.0, FS, [[(0.1, 0.2, 1.0)]], pp=-1e-6)
    with pytest.raises(EMGError):
        synthesize(1.0, FS, [])
