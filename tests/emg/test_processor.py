"""The signal chain built once (book §9-2 三): sensitivity, codes, streaming, bad input, and
neurokit2's ``emg_simulate``/``emg_process`` as a peer for the envelope and the onsets."""

import numpy as np
import pytest

from anthroarm.emg import (
    AMPUTEE_PP,
    BOTH,
    EXTENSOR,
    FLEXOR,
    REST,
    DifferentialAmplifier,
    EMGProcessor,
    Thresholds,
    electrode_potentials,
    synthesize,
)
from anthroarm.errors import EMGError, SamplingRateError, ThresholdError

FS = 2000.0


def _sine(pp, f=100.0, dur=1.0):
    t = np.arange(int(dur * FS)) / FS
    return 0.5 * pp * np.sin(2 * np.pi * f * t)


@pytest.mark.parametrize(
    "pp, switches", [(50e-6, True), (75e-6, True), (100e-6, True), (20e-6, False)]
)
def test_book_sensitivity_50_to_100_uV_switches(pp, switches):
    """§9-2 三: a 50-100 µV p-p input must operate the hand (default thresholds)."""
    p = EMGProcessor(FS, 1)
    out = p.process(_sine(pp))
    assert out.active[0, -1] == switches
    # the steady envelope reads the sine's p-p (100 Hz is inside the 20-450 Hz band: gain ~1)
    assert out.envelope_pp[0, -1] == pytest.approx(pp, rel=0.01)


def test_amputee_level_noise_bursts_switch_and_rest_does_not():
    rec = synthesize(3.0, FS, [[(0.5, 1.0, 1.0)], [(2.0, 0.6, 1.0)]], pp=AMPUTEE_PP, rng=5)
    out = EMGProcessor(FS).process(rec.emg)
    t = out.t_frames
    code = out.code
    assert np.all(code[(t > 0.75) & (t < 1.45)] == FLEXOR)  # "10": flexor only
    assert np.all(code[(t > 2.25) & (t < 2.55)] == EXTENSOR)  # "01"
    assert np.all(code[t < 0.45] == REST) and np.all(code[(t > 1.7) & (t < 1.95)] == REST)
    on = t[np.argmax(out.active[0])]
    assert 0.5 < on < 0.5 + 0.1  # within the 100 ms window


def test_co_contraction_gives_code_11():
    rec = synthesize(1.5, FS, [[(0.3, 0.8, 1.0)], [(0.32, 0.8, 1.0)]], pp=AMPUTEE_PP * 2, rng=6)
    out = EMGProcessor(FS).process(rec.emg)
    assert np.all(out.code[(out.t_frames > 0.5) & (out.t_frames < 1.05)] == BOTH)


@pytest.mark.parametrize("envelope", ["rms", "lowpass"])
def test_blocks_give_the_result_of_one_piece(envelope):
    rec = synthesize(2.0, FS, [[(0.2, 0.8, 1.0)], [(0.9, 0.6, 1.0)]], pp=80e-6, rng=7)
    p = EMGProcessor(FS, envelope=envelope, notch_hz=50.0)
    whole = p.process(rec.emg)
    rng = np.random.default_rng(0)
    cuts = np.sort(rng.choice(np.arange(1, rec.emg.shape[1]), 9, replace=False))
    parts = [p.process(b, reset=(i == 0)) for i, b in enumerate(np.split(rec.emg, cuts, axis=1))]
    np.testing.assert_allclose(
        np.concatenate([q.envelope_pp for q in parts], axis=1),
        whole.envelope_pp,
        rtol=1e-9,
        atol=1e-15,
    )
    np.testing.assert_array_equal(np.concatenate([q.code for q in parts]), whole.code)
    np.testing.assert_allclose(np.concatenate([q.t_frames for q in parts]), whole.t_frames)
    np.testing.assert_allclose(
        np.concatenate([q.filtered for q in parts], axis=1), whole.filtered, atol=1e-15
    )


def test_schmitt_trigger_hysteresis_definition():
    t = np.arange(int(4 * FS)) / FS
    am = 60e-6 * np.clip(1 - np.abs(t - 2.0) / 1.5, 0, 1)  # slow triangle 0 -> 60 µV -> 0
    x = 0.5 * am * np.sin(2 * np.pi * 100 * t)
    out = EMGProcessor(FS, 1).process(x)
    e, a = out.envelope_pp[0], out.active[0]
    k_on = np.flatnonzero(~a[:-1] & a[1:]) + 1
    k_off = np.flatnonzero(a[:-1] & ~a[1:]) + 1
    assert len(k_on) == 1 and len(k_off) == 1  # no chatter
    assert e[k_on[0]] >= 35e-6 > e[k_on[0] - 1]
    assert e[k_off[0]] <= 25e-6 < e[k_off[0] - 1]
    # between the thresholds the state is held (on while falling from 35 to 25 µV)
    mid = (e < 35e-6) & (e > 25e-6)
    assert np.any(a[mid]) and np.any(~a[mid])


def test_gain_refers_the_amplified_signal_back_to_the_electrodes():
    amp = DifferentialAmplifier(gain=5000.0)
    x = _sine(60e-6)[None]
    out = amp.amplify(x / 2, -x / 2)
    a = EMGProcessor(FS, 1, gain=amp.gain, max_input_pp=amp.max_input_pp).process(out.signal)
    b = EMGProcessor(FS, 1).process(x)
    np.testing.assert_allclose(a.envelope_pp, b.envelope_pp, rtol=1e-9)


def test_thresholds_that_can_never_switch_are_refused():
    amp = DifferentialAmplifier(gain=20_000.0, rail=1.0)  # passes at most 100 µV p-p
    with pytest.raises(ThresholdError, match="never switch on"):
        EMGProcessor(
            FS, thresholds=Thresholds(150e-6, 100e-6), gain=amp.gain, max_input_pp=amp.max_input_pp
        )
    with pytest.raises(ThresholdError, match="never switch off"):
        EMGProcessor(FS, thresholds=Thresholds(35e-6, 2e-6), noise_rms=1e-6)
    with pytest.raises(ThresholdError, match="hysteresis"):
        Thresholds(20e-6, 30e-6).arrays(2)
    for bad in (float("nan"), 0.0, -1e-6, float("inf")):
        with pytest.raises(ThresholdError):
            EMGProcessor(FS, thresholds=Thresholds(bad, 1e-6))
    with pytest.raises(ThresholdError):
        EMGProcessor(
            FS, thresholds=Thresholds((35e-6, 35e-6, 35e-6), 25e-6)
        )  # 3 values, 2 channels
    EMGProcessor(FS, thresholds=Thresholds((35e-6, 50e-6), (25e-6, 40e-6)), noise_rms=1e-6)


def test_bad_signals_and_rates():
    p = EMGProcessor(FS)
    with pytest.raises(EMGError, match="NaN"):
        p.process(np.array([[0.0, np.nan, 0.0], [0.0, 0.0, 0.0]]))
    with pytest.raises(EMGError, match=r"emg.T"):
        p.process(np.zeros((100, 2)))
    with pytest.raises(EMGError, match="2 channels"):
        p.process(np.zeros((3, 100)))
    with pytest.raises(EMGError, match="shape"):
        p.process(np.zeros(100))
    with pytest.raises(SamplingRateError, match="fs > 900"):
        EMGProcessor(800.0)
    with pytest.raises(EMGError):
        EMGProcessor(FS, envelope="hilbert")
    with pytest.raises(EMGError):
        EMGProcessor(FS, frame_s=0.0)
    with pytest.raises(EMGError, match="band"):
        EMGProcessor(FS, band=(20.0,))
    with pytest.raises(EMGError, match="low < high"):
        EMGProcessor(FS, band=(450.0, 20.0))


def test_envelope_and_onsets_against_neurokit2():
    """neurokit2 as a peer: its simulated bursts (1 s each, quiet 1.75 s between) processed by
    ``nk.emg_process`` and by ours.  Our envelope is causal (100 ms RMS), theirs zero-phase."""
    nk = pytest.importorskip("neurokit2")
    x = nk.emg_simulate(duration=10, sampling_rate=1000, burst_number=3, random_state=42)
    sig, info = nk.emg_process(x, sampling_rate=1000)
    out = EMGProcessor(1000.0, 1, frame_s=0.001, thresholds=Thresholds(0.5, 0.3)).process(x)
    e = out.envelope_pp[0]
    assert np.corrcoef(e, sig["EMG_Amplitude"].to_numpy())[0, 1] > 0.9
    a = out.active[0].astype(int)
    on = out.t_frames[np.flatnonzero(np.diff(a) == 1) + 1]
    off = out.t_frames[np.flatnonzero(np.diff(a) == -1) + 1]
    truth_on = np.array([1.75, 4.5, 7.25])
    assert len(on) == 3 and len(off) == 3
    assert np.all((on >= truth_on) & (on <= truth_on + 0.1))  # causal: never early, < window late
    assert np.all((off >= truth_on + 1.0) & (off <= truth_on + 1.1))
    np.testing.assert_allclose(on, np.asarray(info["EMG_Onsets"]) / 1000.0, atol=0.1)
    np.testing.assert_allclose(off, np.asarray(info["EMG_Offsets"]) / 1000.0, atol=0.1)


@pytest.mark.parametrize(
    "cmrr_db, notch, switches", [(100.0, None, False), (60.0, None, True), (60.0, 50.0, False)]
)
def test_mains_hum_and_the_cmrr(cmrr_db, notch, switches):
    """1 V p-p of 50 Hz common-mode hum, no EMG: the differential front end leaves
    1 V * 10**(-CMRR/20) at its input (10 µV p-p at 100 dB, under the 25 µV off-threshold;
    1 mV at 60 dB, which would move the hand); a 50 Hz notch removes it again."""
    amp = DifferentialAmplifier(gain=1000.0, cmrr_db=cmrr_db, rail=None)
    vp, vm = electrode_potentials(np.zeros((2, int(2 * FS))), FS, mains_pp=1.0)
    out = amp.amplify(vp, vm)
    res = EMGProcessor(FS, gain=amp.gain, notch_hz=notch).process(out.signal)
    residual = 1.0 * 10 ** (-cmrr_db / 20)
    if notch is None:
        assert res.envelope_pp[0, -1] == pytest.approx(
            residual, rel=0.02
        )  # 50 Hz: gain ~1 in 20-450 Hz
    assert res.active[:, -1].tolist() == [switches, switches]
