"""Envelopes, FFT features and the test-signal generator (book §9-2 二 3).

Oracles: closed forms for a sine (RMS = A/sqrt 2, mean rectified value 2A/pi), the direct
definition of a moving RMS (a brute-force sum), Parseval, the flat spectrum of band-limited
noise (mean and median frequency at the band's middle), and neurokit2's ``signal_psd`` as a
peer for the spectral centroid."""

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
    activation,
    band_limited_noise,
    band_powers,
    lowpass_envelope,
    mean_frequency,
    median_frequency,
    moving_rms,
    peak_to_peak,
    rms,
    spectral_features,
    spectrum,
    synthesize,
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


def test_spectrum_of_a_sine_peaks_at_its_frequency_and_keeps_parseval():
    t = np.arange(int(2 * FS)) / FS
    x = np.sin(2 * np.pi * 123.0 * t)
    f, p = spectrum(x, FS)
    assert abs(f[np.argmax(p[0])] - 123.0) <= (f[1] - f[0])
    assert p[0].sum() * (f[1] - f[0]) == pytest.approx(x.var(), rel=0.01)


@pytest.mark.parametrize("band", [EMG_BAND, (10.0, 200.0), (100.0, 400.0)])
def test_band_limited_noise_has_a_flat_spectrum_in_its_band(band):
    x = band_limited_noise(int(20 * FS), FS, band, n_channels=2, rng=1)
    np.testing.assert_allclose(x.std(axis=1), 1.0, rtol=1e-12)
    feats = spectral_features(x, FS)
    mid = 0.5 * (band[0] + band[1])
    np.testing.assert_allclose(feats.mean_hz, mid, rtol=0.02)
    np.testing.assert_allclose(feats.median_hz, mid, rtol=0.02)
    assert np.all((feats.peak_hz >= band[0] - 5) & (feats.peak_hz <= band[1] + 5))
    np.testing.assert_allclose(feats.power, 1.0, rtol=0.02)
    inside = band_powers(feats.freqs, feats.psd, [band])[:, 0]
    np.testing.assert_allclose(inside, 1.0, rtol=0.03)


def test_mean_frequency_agrees_with_neurokit2():
    nk = pytest.importorskip("neurokit2")
    x = band_limited_noise(int(10 * FS), FS, (30.0, 300.0), rng=4)[0] + 0.5 * np.sin(
        2 * np.pi * 60 * np.arange(int(10 * FS)) / FS
    )
    f, p = spectrum(x, FS, segment_s=0.5)
    psd = nk.signal_psd(
        x, sampling_rate=FS, method="welch", min_frequency=1.0, max_frequency=1000.0
    )
    theirs = float(np.sum(psd["Frequency"] * psd["Power"]) / np.sum(psd["Power"]))
    ours = mean_frequency(f, p, band=(1.0, 1000.0))[0]
    assert ours == pytest.approx(theirs, rel=0.03)
    assert median_frequency(f, p)[0] < ours  # the 60 Hz line pulls the median down


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
