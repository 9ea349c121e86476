"""EMG control of powered hands (book §9-2): the signal chain and the 4-code state machine.

>>> from anthroarm import emg
>>> bursts = [[(0.3, 0.6, 1.0)], [(1.2, 0.5, 1.0)]]        # (start s, length s, level) per channel
>>> rec = emg.synthesize(2.0, 2000.0, bursts, pp=emg.AMPUTEE_PP, rng=0)
>>> out = emg.EMGProcessor(2000.0).process(rec.emg)       # envelopes, thresholds, codes 00/01/10/11
>>> trace = emg.CodeMachine(out.frame_s).run(out.code)    # modes, commands, vibrators

Modules:

* :mod:`.frontend` — differential amplifier with gain, CMRR and rails;
* :mod:`.filters` — Butterworth conditioning band and the book's filter banks (Table 9.1);
* :mod:`.envelope` — rectification, moving RMS, linear envelope, sine-equivalent p-p;
* :mod:`.features` — FFT spectrum, mean/median/peak frequency, band powers;
* :mod:`.synth` — amplitude-modulated band-limited test EMG at the book's amplitudes;
* :mod:`.processor` — the chain built once: filter, envelope, frames, Schmitt thresholds, codes;
* :mod:`.codes` — the 10/01/11/00 state machine with debouncing, co-contraction, vibrators;
* :mod:`.simulate` — EMG → codes → servo set-points → the elbow, wrist and hand of an arm.
"""

from __future__ import annotations

from .codes import MODES, VIBRATOR_OF_MODE, VIBRATORS, CodeMachine, CodeTrace, vibrators_with_grasp
from .envelope import (
    PP_PER_MAV,
    PP_PER_RMS,
    lowpass_envelope,
    moving_rms,
    peak_to_peak,
    rectify,
    rms,
)
from .features import (
    SpectralFeatures,
    band_powers,
    mean_frequency,
    median_frequency,
    peak_frequency,
    spectral_features,
    spectrum,
)
from .filters import (
    BOOK_BANK_2CH,
    BOOK_BANK_3CH,
    CONDITIONING_BAND,
    FilterBank,
    band_edges,
    bandpass_sos,
    check_sampling_rate,
    notch_sos,
)
from .frontend import AmplifierOutput, DifferentialAmplifier
from .processor import (
    BOOK_SENSITIVITY_PP,
    BOTH,
    CODE_NAMES,
    EXTENSOR,
    FLEXOR,
    REST,
    Calibration,
    EMGProcessor,
    ProcessedEMG,
    Thresholds,
    calibrate_thresholds,
)
from .synth import (
    AMPUTEE_PP,
    AMPUTEE_TRAINED_PP,
    EMG_BAND,
    HEALTHY_PP,
    TYPICAL_PP,
    SyntheticEMG,
    activation,
    band_limited_noise,
    electrode_potentials,
    synthesize,
)

__all__ = [
    "AMPUTEE_PP",
    "AMPUTEE_TRAINED_PP",
    "AmplifierOutput",
    "BOOK_BANK_2CH",
    "BOOK_BANK_3CH",
    "BOOK_SENSITIVITY_PP",
    "BOTH",
    "CODE_NAMES",
    "Calibration",
    "calibrate_thresholds",
    "CONDITIONING_BAND",
    "CodeMachine",
    "CodeTrace",
    "DifferentialAmplifier",
    "EMGProcessor",
    "EMG_BAND",
    "EXTENSOR",
    "FLEXOR",
    "FilterBank",
    "HEALTHY_PP",
    "MODES",
    "PP_PER_MAV",
    "PP_PER_RMS",
    "ProcessedEMG",
    "REST",
    "SpectralFeatures",
    "SyntheticEMG",
    "TYPICAL_PP",
    "Thresholds",
    "VIBRATORS",
    "VIBRATOR_OF_MODE",
    "activation",
    "band_edges",
    "band_limited_noise",
    "band_powers",
    "bandpass_sos",
    "check_sampling_rate",
    "electrode_potentials",
    "lowpass_envelope",
    "mean_frequency",
    "median_frequency",
    "moving_rms",
    "notch_sos",
    "peak_frequency",
    "peak_to_peak",
    "rectify",
    "rms",
    "spectral_features",
    "spectrum",
    "synthesize",
    "vibrators_with_grasp",
]
