"""Bad input and misuse of the public EMG functions: typed EMGErrors naming the parameter, never
a raw ValueError/TypeError from numpy or scipy, never NaN/inf in a result, never unbounded work,
no state carried from one simulation run into the next."""

import numpy as np
import pytest

from anthroarm import emg
from anthroarm.errors import EMGError, ThresholdError

FS = 2000.0
X = np.random.default_rng(0).standard_normal((2, 4000)) * 1e-4


@pytest.fixture(scope="module")
def spec():
    return emg.spectrum(X, FS)


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda: emg.CodeMachine(0.005, debounce_s="abc"), "debounce_s"),
        (lambda: emg.CodeMachine(0.005, cocontraction_s=None), "cocontraction_s"),
        (lambda: emg.CodeMachine(0.005, modes="elbow"), "sequence of mode names"),
        (lambda: emg.electrode_potentials(X, FS, mains_pp=np.nan), "mains_pp"),
        (lambda: emg.electrode_potentials(X, FS, mains_hz="x"), "mains_hz"),
        (lambda: emg.electrode_potentials(X, FS, offset_v=1e300), "not a voltage"),
        (lambda: emg.activation([0.0, np.nan], [(0, 1, 1)]), "NaN"),
        (lambda: emg.activation([0.0, 1.0], None), "bursts"),
        (lambda: emg.band_limited_noise(10**7, FS, n_channels=10**4), "n_channels"),
        (lambda: emg.band_limited_noise(1000, FS, n_channels=0), "n_channels"),
        (lambda: emg.band_limited_noise(1000, FS, n_channels="2"), "n_channels"),
        (lambda: emg.band_limited_noise(1000, FS, band="ab"), "band"),
        (lambda: emg.synthesize(100.0, FS, [[(0, 1, 1)]] * 10**5), "samples"),
        (lambda: emg.synthesize(1.0, FS, [[(0, 1, 1)]], pp="x"), "pp"),
        (lambda: emg.synthesize(1.0, FS, [[(0, 1, 1)]], pp=[1e-4, 2e-4, 3e-4]), "pp"),
        (lambda: emg.synthesize(1.0, FS, [[(0, 1, 1)]], noise_rms="x"), "noise_rms"),
        (lambda: emg.lowpass_envelope(X, FS, order=0), "order"),
        (lambda: emg.lowpass_envelope(X, FS, order=10**6), "order"),
        (lambda: emg.lowpass_envelope(X, FS, order="a"), "order"),
        (lambda: emg.EMGProcessor(FS, noise_rms="x"), "noise_rms"),
        (lambda: emg.EMGProcessor(FS, noise_rms=np.nan), "noise_rms"),
        (lambda: emg.EMGProcessor(FS, max_input_pp=np.nan), "max_input_pp"),
        (lambda: emg.EMGProcessor(FS, thresholds=(1e-5, 2e-5)), "Thresholds"),
        (lambda: emg.calibrate_thresholds(X, FS, off_fraction="x"), "off_fraction"),
        (lambda: emg.calibrate_thresholds(X, FS, settle_s="x"), "settle_s"),
        (lambda: emg.FilterBank("ab", FS), "centres_hz"),
        (lambda: emg.FilterBank((np.nan,), FS), "centres_hz"),
        (lambda: emg.FilterBank((40.0,), FS).gains([np.nan]), "NaN"),
        (lambda: emg.band_edges(40.0, FS, 1e6), "octaves"),
        (
            lambda: emg.moving_rms(np.zeros(10), 1e12, 0.1),
            "is fs in Hz",
        ),  # a 1e11-sample window: was a MemoryError
        (lambda: emg.EMGProcessor(1e12), "is fs in Hz"),
    ],
)
def test_bad_parameters_are_emg_errors(call, match):
    with pytest.raises(EMGError, match=match):
        call()


def test_a_threshold_object_of_the_wrong_type_is_a_threshold_error():
    with pytest.raises(ThresholdError):
        emg.EMGProcessor(FS, thresholds=(1e-5, 2e-5))


@pytest.mark.parametrize("fn", [emg.mean_frequency, emg.median_frequency])
def test_spectral_descriptors_refuse_nan_psd_and_bad_bands(fn, spec):
    f, p = spec
    with pytest.raises(EMGError, match="NaN"):
        fn(f, np.full_like(p, np.nan))
    with pytest.raises(EMGError, match="low < high"):
        fn(f, p, band=(300.0, 30.0))
    with pytest.raises(EMGError, match="band"):
        fn(f, p, band="ab")
    with pytest.raises(EMGError, match="one bin per entry"):
        fn(f[:3], p)


def test_band_powers_refuse_nan_psd_and_mismatched_shapes(spec):
    f, p = spec
    with pytest.raises(EMGError, match="NaN"):
        emg.band_powers(f, np.full_like(p, np.nan), [(30.0, 60.0)])
    with pytest.raises(EMGError, match="one bin per entry"):
        emg.band_powers(f[:3], p, [(30.0, 60.0)])
    with pytest.raises(EMGError, match="bands"):
        emg.band_powers(f, p, "x")


@pytest.fixture(scope="module")
def arm():
    import anthroarm as aa

    return aa.load("prosthetic_arm")


@pytest.mark.parametrize(
    "kw, match",
    [
        (dict(dt=np.nan), "dt"),
        (dict(dt=0.0), "dt"),
        (dict(dt="x"), "dt"),
        (dict(dt=10.0), "control frame"),
        (dict(dt=1e-7), "integration steps"),  # 5e6 steps for 0.5 s: refused, not run for minutes
        (dict(speeds={"fingers": "x"}), "speeds"),
        (dict(hand="x"), "HandModel"),
        (dict(servos={"fingers": 3}), "PositionServo"),
    ],
)
def test_simulate_bad_parameters_are_parameter_errors(arm, kw, match):
    from anthroarm.emg.simulate import simulate_powered_hand
    from anthroarm.errors import ParameterError

    rec = emg.synthesize(0.5, FS, [[(0.1, 0.2, 1.0)], [(0.3, 0.1, 1.0)]], pp=1e-4, rng=0)
    with pytest.raises(ParameterError, match=match):
        simulate_powered_hand(arm, rec.emg, FS, {"elbow": "elbow_flexion", "fingers": None}, **kw)


def test_a_reused_code_machine_starts_each_run_from_rest(arm):
    """The machine is reset per run: a second run with the same machine (left in another mode
    by the first) gives the first run's trace and motion, not a continuation."""
    from anthroarm.emg.simulate import simulate_powered_hand

    rec = emg.synthesize(
        1.5, FS, [[(0.2, 0.3, 1.0), (0.8, 0.4, 1.0)], [(0.2, 0.3, 1.0)]], pp=1e-4, rng=3
    )
    machine = emg.CodeMachine(0.005, modes=("elbow", "fingers"))
    joints = {"elbow": "elbow_flexion", "fingers": None}
    a = simulate_powered_hand(arm, rec.emg, FS, joints, machine=machine)
    assert a.trace.mode[-1] == 1  # the co-contraction at 0.2 s switched to the fingers
    b = simulate_powered_hand(arm, rec.emg, FS, joints, machine=machine)
    np.testing.assert_array_equal(b.trace.mode, a.trace.mode)
    np.testing.assert_array_equal(b.trace.command, a.trace.command)
    np.testing.assert_allclose(b.angle, a.angle)
