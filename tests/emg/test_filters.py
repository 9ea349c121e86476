"""Filters of the EMG chain (book §9-2, Table 9.1), and the chain's refusal of numbers beyond
any voltage and of sizes that would exhaust memory.  The differential front end is tested in
``test_frontend.py``.

Oracles: Butterworth mathematics (unit gain at the centre, 1/sqrt(2) at the -3 dB edges, from
``scipy.signal.sosfreqz`` of the designed sections), the steady-state response of an LTI filter
to a sine (amplitude times |H(f)|) and the Wiener-Khinchin relation for white noise."""

import numpy as np
import pytest
from scipy import signal as sps

from anthroarm.emg import (
    BOOK_BANK_2CH,
    BOOK_BANK_3CH,
    CONDITIONING_BAND,
    DifferentialAmplifier,
    FilterBank,
    band_edges,
    bandpass_sos,
    notch_sos,
)
from anthroarm.errors import EMGError, SamplingRateError


def test_book_centre_frequencies_are_the_printed_ones():
    assert BOOK_BANK_2CH == (40.0, 100.0, 160.0, 360.0)  # Table 9.1, 方式1
    assert BOOK_BANK_3CH == (70.0, 160.0, 360.0)  # Table 9.1, 方式2


@pytest.mark.parametrize("fs", [1000.0, 2000.0, 4000.0])
@pytest.mark.parametrize("centres", [BOOK_BANK_2CH, BOOK_BANK_3CH])
def test_bank_unit_gain_at_centre_and_minus_3db_at_edges(fs, centres):
    bank = FilterBank(centres, fs)
    for k, fc in enumerate(centres):
        lo, hi = bank.edges[k]
        g = bank.gains([fc, lo, hi])[k]
        assert g[0] == pytest.approx(1.0, abs=1e-9)
        assert g[1] == pytest.approx(1 / np.sqrt(2), abs=1e-9)
        assert g[2] == pytest.approx(1 / np.sqrt(2), abs=1e-9)
        # half an octave apart in the pre-warped axis, symmetric about fc there
        w = np.tan(np.pi * np.array([lo, fc, hi]) / fs)
        assert np.log2(w[2] / w[0]) == pytest.approx(0.5, abs=1e-12)
        assert w[1] ** 2 == pytest.approx(w[0] * w[2], rel=1e-12)
        assert lo < fc < hi


def test_bank_bands_do_not_overlap_and_are_the_documented_ones():
    bank = FilterBank(BOOK_BANK_2CH, 2000.0)
    assert np.all(bank.edges[1:, 0] > bank.edges[:-1, 1])
    # module docstring: 40 -> 33.6-47.6, 360 -> 303-428 Hz (nominal fc * 2**(+-1/4))
    np.testing.assert_allclose(bank.edges[0], [40 * 2**-0.25, 40 * 2**0.25], rtol=2e-3)
    np.testing.assert_allclose(
        bank.edges[3], [312.1, 411.6], atol=0.05
    )  # documented values at 2 kHz


def test_conditioning_band_edges_minus_3db():
    sos = bandpass_sos(*CONDITIONING_BAND, 2000.0)
    _, h = sps.sosfreqz(sos, worN=np.array(CONDITIONING_BAND), fs=2000.0)
    np.testing.assert_allclose(np.abs(h), 1 / np.sqrt(2), atol=1e-9)


def test_bank_separates_tones_with_the_gain_of_its_frequency_response():
    fs = 2000.0
    bank = FilterBank(BOOK_BANK_2CH, fs)
    t = np.arange(int(2 * fs)) / fs
    for f in BOOK_BANK_2CH:
        x = np.sin(2 * np.pi * f * t)
        y = bank.apply(x)[0]  # (bands, samples)
        amp = np.sqrt(2) * np.sqrt(np.mean(y[:, int(fs) :] ** 2, axis=1))  # steady second half
        np.testing.assert_allclose(amp, bank.gains([f])[:, 0], rtol=2e-3)
        assert BOOK_BANK_2CH[int(np.argmax(amp))] == f


def test_white_noise_through_a_band_has_the_wiener_khinchin_variance():
    fs = 2000.0
    bank = FilterBank(BOOK_BANK_3CH, fs)
    x = np.random.default_rng(3).standard_normal(200_000)
    y = bank.apply(x)[0][:, 2000:]
    f = np.linspace(0, fs / 2, 200_001)
    h2 = bank.gains(f) ** 2
    expected = np.trapezoid(h2, f, axis=1) * 2 / fs  # sigma^2 = 1: one-sided PSD 2/fs
    np.testing.assert_allclose(y.var(axis=1), expected, rtol=0.03)


def test_notch_removes_mains():
    sos = notch_sos(50.0, 2000.0)
    _, h = sps.sosfreqz(sos, worN=np.array([50.0, 150.0]), fs=2000.0)
    assert abs(h[0]) < 1e-9 and abs(h[1]) > 0.95


@pytest.mark.parametrize("fs", [800.0, 856.0, 100.0])
def test_sampling_rate_below_twice_the_highest_band_is_refused(fs):
    with pytest.raises(SamplingRateError) as e:
        FilterBank(BOOK_BANK_2CH, fs)
    assert e.value.required == pytest.approx(2 * 360 * 2**0.25)
    assert "360" in str(e.value) and "fs >" in str(e.value)
    FilterBank(BOOK_BANK_2CH, 860.0)  # just above: fine


@pytest.mark.parametrize("bad", [float("nan"), float("inf"), 0.0, -2000.0, "fast"])
def test_bad_sampling_rates(bad):
    with pytest.raises(EMGError):
        bandpass_sos(20.0, 450.0, bad)


def test_bad_bands():
    with pytest.raises(EMGError):
        bandpass_sos(450.0, 20.0, 2000.0)
    with pytest.raises(EMGError):
        band_edges(-40.0, 2000.0)
    with pytest.raises(EMGError):
        FilterBank([], 2000.0)


def test_numbers_beyond_any_voltage_are_refused_not_overflowed():
    from anthroarm.emg import EMGProcessor, moving_rms, spectrum

    huge = np.full((2, 400), 1e200)
    for call in (
        lambda: EMGProcessor(2000.0).process(huge),
        lambda: moving_rms(huge, 2000.0),
        lambda: spectrum(huge, 2000.0),
    ):
        with pytest.raises(EMGError, match="not a voltage"):
            call()
    with pytest.raises(EMGError, match="overflows"):
        DifferentialAmplifier(gain=1e308, rail=None).amplify(np.full((1, 4), 1e5), np.zeros((1, 4)))
    # the largest accepted voltage goes through without inf/NaN
    out = EMGProcessor(2000.0).process(
        np.full((2, 400), 1e6) * np.sign(np.sin(np.arange(400)))[None]
    )
    assert np.all(np.isfinite(out.envelope_pp)) and np.all(np.isfinite(out.filtered))


def test_sizes_that_would_exhaust_memory_or_never_switch_are_refused():
    from anthroarm.emg import EMGProcessor, Thresholds, synthesize
    from anthroarm.errors import ThresholdError

    with pytest.raises(EMGError, match="not an envelope window"):
        EMGProcessor(2000.0, window_s=1e9)
    with pytest.raises(EMGError, match="samples"):
        synthesize(1e9, 2000.0, [[(0.0, 1.0, 1.0)]])
    with pytest.raises(ThresholdError, match="never switch on"):  # no voltage reaches 1e300 V p-p
        EMGProcessor(2000.0, thresholds=Thresholds(1e300, 1e-6))
