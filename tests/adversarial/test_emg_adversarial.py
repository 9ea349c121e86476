"""Hostile input to :mod:`anthroarm.emg` (issue 30): every case is refused with an
:class:`~anthroarm.errors.EMGError` naming the value at fault (never a numpy or Python error, a
warning, a silent conversion, NaN output or an exhausted memory), or answered correctly.

Before the fixes of issue 30 these failed: complex samples (the imaginary part dropped with a
ComplexWarning), masked samples (the gap read as data), boolean/string/date arrays (converted),
10**8 samples (several GB of working memory), the code machine's extreme durations
(OverflowError), a mode list that is not a sequence (TypeError), ragged codes (ValueError), a
band at an extreme rate (NaN edges), a band with no FFT bin (NaN test signal), a processor of
10**12 channels (MemoryError), a mains frequency whose phase overflows (a wrong message).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from anthroarm import emg
from anthroarm.emg import features
from anthroarm.emg._checks import MEMORY_BUDGET
from anthroarm.errors import EMGError

FS = 2000.0
X = np.random.default_rng(0).standard_normal((2, 4000)) * 1e-4


@pytest.fixture(autouse=True)
def _warnings_are_errors():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        yield


@pytest.mark.parametrize(
    "call",
    [
        lambda x: emg.rms(x),
        lambda x: emg.moving_rms(x, FS),
        lambda x: emg.spectrum(x, FS),
        lambda x: emg.EMGProcessor(FS).process(x),
        lambda x: emg.DifferentialAmplifier().amplify(x, x),
    ],
    ids=["rms", "moving_rms", "spectrum", "processor", "amplifier"],
)
def test_complex_samples_are_refused_not_truncated(call):
    with pytest.raises(EMGError, match="complex samples"):
        call(X + 1e-5j)


def test_complex_python_numbers_in_a_list_are_refused():
    with pytest.raises(EMGError, match="complex"):
        emg.rms([1e-4, 2e-4 + 1e-5j, 0.0])


def test_masked_samples_are_a_gap_not_data():
    m = np.ma.masked_array(X, mask=np.zeros_like(X, bool))
    m.mask[1, 17] = True
    with pytest.raises(EMGError, match=r"masked samples .*\(1, 17\)"):
        emg.EMGProcessor(FS).process(m)
    # a masked array without a masked sample is plain data
    assert np.allclose(emg.rms(np.ma.masked_array(X)), emg.rms(X))


def test_nan_gap_names_channel_and_sample():
    y = X.copy()
    y[0, 100:140] = np.nan
    with pytest.raises(EMGError, match="channel 0, sample 100"):
        emg.EMGProcessor(FS).process(y)


@pytest.mark.parametrize(
    "x",
    [
        np.ones((2, 100), bool),
        np.array([["1e-4", "2e-4"], ["0", "1"]]),
        np.arange(10).astype("datetime64[s]"),
    ],
    ids=["bool", "str", "datetime"],
)
def test_non_numeric_dtypes_are_refused(x):
    with pytest.raises(EMGError, match="real numbers"):
        emg.rms(x)


def test_ragged_rows_and_no_channel():
    with pytest.raises(EMGError, match="ragged"):
        emg.rms([[1e-4, 2e-4], [1e-4]])
    with pytest.raises(EMGError, match="no channel"):
        emg.rms(np.zeros((0, 10)))


def test_1e8_samples_are_refused_by_the_memory_budget_before_any_copy():
    # a broadcast view: 10**8 values of zero bytes, so the test itself allocates nothing
    big = np.broadcast_to(np.float64(0.0), (2, 5 * 10**7))
    for call in (emg.rms, lambda x: emg.EMGProcessor(FS).process(x)):
        with pytest.raises(EMGError, match="budget.*reset=False"):
            call(big)
    with pytest.raises(EMGError, match="generator makes"):
        emg.synthesize(10**8 / FS, FS, [[(0.0, 1.0, 1.0)]])
    assert MEMORY_BUDGET == 2 * 2**30


def test_blocks_give_the_result_of_one_piece():
    # the remedy the budget's message names
    p = emg.EMGProcessor(FS)
    whole = p.process(X)
    parts = [p.process(X[:, a : a + 1000], reset=(a == 0)) for a in range(0, 4000, 1000)]
    np.testing.assert_allclose(
        np.concatenate([o.envelope_pp for o in parts], 1), whole.envelope_pp, rtol=1e-12
    )


@pytest.mark.parametrize(
    "kw",
    [
        dict(frame_s=5e-324),
        dict(frame_s=1e-3, debounce_s=1e306),
        dict(frame_s=1e-3, cocontraction_s=1e306),
        dict(frame_s=1e-3, vibrate_s=1e300),
        dict(frame_s=1e-300),
    ],
)
def test_code_machine_extreme_durations_are_typed(kw):
    with pytest.raises(EMGError, match="frames of frame_s"):
        emg.CodeMachine(**kw)


@pytest.mark.parametrize(
    "kw, match",
    [
        (dict(modes=5), "sequence of mode names"),
        (dict(modes=None), "sequence of mode names"),
        (dict(modes="elbow"), "sequence of mode names"),
        (dict(start_mode=True), "start_mode"),
    ],
)
def test_code_machine_bad_modes(kw, match):
    with pytest.raises(EMGError, match=match):
        emg.CodeMachine(0.005, **kw)


def test_code_machine_ragged_codes():
    with pytest.raises(EMGError, match="raw_codes"):
        emg.CodeMachine(0.005).run([[0], [1, 2]])


def test_code_machine_long_stream_keeps_int64_frames():
    m = emg.CodeMachine(1e-3, vibrate_s=1e6)  # 1e9 frames: within the bound
    m._frame = 2**62  # a stream that has run for a very long time
    tr = m.run(np.array([0] * 10 + [3] * 100 + [0] * 10))
    assert tr.switched.sum() == 1 and tr.vibrators[:, 1].any()


def test_band_edges_at_extreme_rates_are_finite():
    lo, hi = emg.band_edges(1e307, 1e308)
    assert np.isfinite(lo) and np.isfinite(hi) and lo < 1e307 < hi
    # and the same numbers as at an ordinary rate, scaled
    lo2, hi2 = emg.band_edges(100.0, 1000.0)
    np.testing.assert_allclose([lo / 1e305, hi / 1e305], [lo2, hi2], rtol=1e-12)


def test_band_without_a_frequency_bin_is_refused_not_nan():
    with pytest.raises(EMGError, match="no frequency bin"):
        emg.band_limited_noise(16, 1e6, band=(30.0, 300.0))


def test_processor_with_1e12_channels_is_refused():
    with pytest.raises(EMGError, match="n_channels"):
        emg.EMGProcessor(FS, n_channels=10**12)


def test_mains_phase_overflow_is_named():
    with pytest.raises(EMGError, match="mains_hz"):
        emg.electrode_potentials(X, 1e308, mains_pp=1.0, mains_hz=1e308)


def test_activation_at_extreme_times_has_no_warning():
    a = emg.activation(np.array([1e308, -1e308]), [(1e308, 1e308, 1.0)], ramp_s=1e-300)
    assert np.all((a >= 0) & (a <= 1))


def test_spectrum_at_a_rate_at_the_end_of_the_float_range_is_refused():
    """fs = 1e308 Hz overflowed Welch's scaling inside scipy (a warning and a spectrum of zeros)."""
    x = np.random.default_rng(0).normal(size=(1, 512))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(EMGError, match="fs = 1e"):
            features.spectrum(x, 1e308)
