"""The 4-code state machine of the 3-DOF upper-arm hand (book §9-2 三 2, Fig. 9-25).

Expected values are the book's printed mapping (10 flexor: close / pronate / flex; 01
extensor: open / supinate / extend; 11 switch; 00 rest; left vibrator = elbow, right =
wrist, none = fingers, middle = grasp) and the documented assumptions (cycle order, debounce,
co-contraction window, lock-out), frame by frame."""

import numpy as np
import pytest

from anthroarm.emg import MODES, VIBRATOR_OF_MODE, VIBRATORS, CodeMachine, vibrators_with_grasp
from anthroarm.errors import EMGError

F = 0.005  # 5 ms frames: debounce 50 ms = 10 frames, co-contraction 150 ms = 30 frames


def seq(*runs):
    return np.concatenate([np.full(n, c, dtype=np.int8) for c, n in runs])


def test_book_vibrator_mapping():
    assert MODES == ("elbow", "wrist", "fingers")
    assert VIBRATOR_OF_MODE == {"elbow": "left", "wrist": "right", "fingers": None}
    assert VIBRATORS == ("left", "right", "middle")


def test_flexor_and_extensor_commands_after_the_debounce():
    tr = CodeMachine(F).run(seq((0, 20), (2, 40), (0, 20), (1, 40), (0, 20)))
    assert np.all(tr.mode == 0)  # starts at the elbow
    cmd = tr.command
    assert np.all(cmd[:29] == 0) and np.all(cmd[29:69] == 1)  # accepted on the 10th frame of "10"
    assert np.all(cmd[69:89] == 0) and np.all(cmd[89:129] == -1)  # every change is 10 frames late
    assert np.all(cmd[129:] == 0)
    assert not tr.switched.any()


def test_a_glitch_shorter_than_the_debounce_is_ignored():
    tr = CodeMachine(F).run(seq((0, 20), (2, 9), (0, 20), (3, 5), (0, 10)))
    assert np.all(tr.code == 0) and np.all(tr.command == 0) and not tr.switched.any()


def test_co_contraction_cycles_the_modes_with_the_book_vibrators():
    m = CodeMachine(F)
    tr = m.run(seq((0, 10), (3, 20), (0, 30), (3, 20), (0, 30), (3, 20), (0, 30)))
    sw = np.flatnonzero(tr.switched)
    assert sw.tolist() == [19, 69, 119]
    assert (
        tr.mode[18] == 0 and tr.mode[19] == 1 and tr.mode[69] == 2 and tr.mode[119] == 0
    )  # elbow->wrist->fingers->elbow
    assert [tr.mode_names[k] for k in sw] == ["wrist", "fingers", "elbow"]
    assert np.all(tr.command == 0)  # 11 never drives a joint
    left, right, middle = tr.vibrators.T
    assert np.flatnonzero(right).tolist() == list(
        range(19, 69)
    )  # wrist: right; cut short by the next switch
    assert not left[:119].any()  # fingers (69..118): no vibrator
    n_vib = round(0.3 / F)
    assert np.flatnonzero(left).tolist() == list(
        range(119, min(119 + n_vib, tr.code.size))
    )  # elbow: left
    assert not middle.any()


def test_lock_out_after_a_switch_until_rest():
    """Relaxing a co-contraction one muscle first leaves a "10": it must not drive the new joint."""
    tr = CodeMachine(F).run(seq((0, 10), (3, 20), (2, 30), (0, 20), (2, 30), (0, 5)))
    assert tr.switched.sum() == 1
    assert np.all(tr.command[:80] == 0)  # 10 after the switch: locked out
    assert np.all(tr.command[89:110] == 1) and np.all(
        tr.mode[89:] == 1
    )  # after rest: drives the wrist


def test_asynchronous_onsets_within_the_window_still_switch():
    tr = CodeMachine(F).run(seq((0, 10), (2, 20), (3, 20), (0, 20)))  # 100 ms flexor lead
    assert tr.switched.sum() == 1
    assert np.all(tr.command[29:39] == 1)  # the lead moved the elbow briefly
    assert np.all(tr.command[39:] == 0)


def test_slow_co_contraction_holds_without_switching():
    tr = CodeMachine(F).run(
        seq((0, 10), (2, 60), (3, 30), (2, 20), (0, 20))
    )  # 300 ms > 150 ms window
    assert not tr.switched.any()
    assert np.all(tr.command[19:79] == 1)
    assert np.all(tr.command[79:99] == 0) and np.all(tr.hold[79:99])
    assert np.all(tr.command[109:120] == 1)  # flexor alone again: moves again
    assert np.all(tr.mode == 0)


@pytest.mark.parametrize("seed", range(6))
def test_blocks_of_any_length_give_the_result_of_one_piece(seed):
    rng = np.random.default_rng(seed)
    runs = [(int(rng.integers(0, 4)), int(rng.integers(1, 40))) for _ in range(60)]
    raw = seq(*runs)
    m = CodeMachine(F, debounce_s=0.03, vibrate_s=0.2)
    whole = m.run(raw)
    m.reset()
    cuts = np.sort(rng.choice(np.arange(1, raw.size), 15, replace=False))
    parts = [m.run(b) for b in np.split(raw, cuts)]
    for name in ("code", "mode", "command", "switched", "hold", "vibrators"):
        np.testing.assert_array_equal(
            np.concatenate([getattr(p, name) for p in parts]), getattr(whole, name), err_msg=name
        )
    assert whole.switched.any()


def test_middle_vibrator_follows_the_grasp():
    tr = CodeMachine(F).run(seq((0, 50)))
    g = np.zeros(50, dtype=bool)
    g[20:30] = True
    v = vibrators_with_grasp(tr, g)
    np.testing.assert_array_equal(v[:, 2], g)
    with pytest.raises(EMGError):
        vibrators_with_grasp(tr, g[:10])


def test_bad_codes_and_settings():
    m = CodeMachine(F)
    with pytest.raises(EMGError):
        m.run(np.array([0, 4]))
    with pytest.raises(EMGError):
        m.run(np.array([0.0, 1.0]))
    with pytest.raises(EMGError):
        m.run(np.zeros((2, 3), dtype=int))
    with pytest.raises(EMGError):
        CodeMachine(F, debounce_s=-0.01)
    with pytest.raises(EMGError):
        CodeMachine(0.0)
    with pytest.raises(EMGError):
        CodeMachine(F, start_mode=3)
    assert m.run(np.array([], dtype=int)).code.size == 0
