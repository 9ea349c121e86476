"""FFT features of the EMG chain (book §9-2 二 3): the spectrum, mean / median / peak frequency,
band powers.

Oracles: Parseval for a sine, the flat spectrum of band-limited noise (mean and median
frequency at the band's middle), and neurokit2's ``signal_psd`` as a peer for the spectral
centroid."""

import numpy as np
import pytest

from anthroarm.emg import (
    EMG_BAND,
    band_limited_noise,
    band_powers,
    mean_frequency,
    median_frequency,
    spectral_features,
    spectrum,
)

FS = 2000.0


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
