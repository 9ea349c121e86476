"""Thresholds from a rest recording (Hodges & Bui 1996: mean + k SD of the rest envelope) and
the book's sensitivity (§9-2 三: 50 µV must operate the hand)."""

import numpy as np
import pytest

from anthroarm.emg import EMGProcessor, synthesize
from anthroarm.emg.processor import BOOK_SENSITIVITY_PP, calibrate_thresholds
from anthroarm.errors import EMGError

FS = 2000.0


def _rest(rms, seconds=3.0, seed=0):
    return rms * np.random.default_rng(seed).standard_normal((2, int(seconds * FS)))


def test_calibrated_thresholds_stay_off_at_rest_and_switch_at_the_book_sensitivity():
    cal = calibrate_thresholds(_rest(2e-6), FS)
    assert cal.status == "ok" and BOOK_SENSITIVITY_PP == 50e-6
    on, off = np.array(cal.thresholds.on_pp), np.array(cal.thresholds.off_pp)
    np.testing.assert_allclose(on, cal.rest_mean_pp + 5 * cal.rest_sd_pp)
    np.testing.assert_allclose(off, cal.rest_mean_pp + 2.5 * cal.rest_sd_pp)
    assert np.all(on < BOOK_SENSITIVITY_PP) and np.all(off < on)
    proc = EMGProcessor(FS, thresholds=cal.thresholds)
    for seed in (1, 2, 3):  # other rest recordings: no false activity
        quiet = proc.process(_rest(2e-6, seed=seed))
        assert not quiet.active[:, quiet.t_frames > 0.3].any()
    burst = synthesize(
        1.5,
        FS,
        [[(0.3, 1.0, 1.0)], [(0.3, 1.0, 1.0)]],
        pp=BOOK_SENSITIVITY_PP,
        noise_rms=2e-6,
        rng=2,
    )
    res = proc.process(burst.emg)
    assert np.all(res.active[:, (res.t_frames > 0.5) & (res.t_frames < 1.25)])


def test_noisy_rest_cannot_meet_the_book_sensitivity():
    cal = calibrate_thresholds(_rest([[30e-6], [2e-6]]), FS)
    assert cal.status.startswith("channel 0") and "channel 1" not in cal.status
    assert cal.thresholds.on_pp[0] > BOOK_SENSITIVITY_PP > cal.thresholds.on_pp[1]


def test_bad_rest_recordings():
    with pytest.raises(EMGError, match="at least 1.3 s"):
        calibrate_thresholds(_rest(2e-6, seconds=1.0), FS)
    r = _rest(2e-6)
    r[1, 100] = np.nan
    with pytest.raises(EMGError, match="NaN"):
        calibrate_thresholds(r, FS)
    with pytest.raises(EMGError, match="silent"):
        calibrate_thresholds(np.zeros((2, 4000)), FS)
    with pytest.raises(EMGError):
        calibrate_thresholds(_rest(2e-6), FS, k=0.0)
    with pytest.raises(EMGError):
        calibrate_thresholds(_rest(2e-6), FS, off_fraction=1.5)
