"""human_upper_limb: the §6-3 arm + five digits (book Fig. 2-2, F = 27 with 20 finger DOF).

Oracles: the book's printed counts (27, 20), Eq. (2-1) through ``design.structure``, Pinocchio
on the generated URDF (FK, mimic joints), the human_arm7 model (its tool), and the published
numbers (Buchholz et al. 1992 coefficients, AAOS ranges, de Leva hand mass) typed here again.
"""

import subprocess
import sys

import numpy as np
import pinocchio as pin
import pytest

import anthroarm as aa
from anthroarm.design import structure
from anthroarm.design.structure import mechanism_of
from anthroarm.errors import AnthropometryError, CouplingError, ParameterError
from anthroarm.models.hand import configuration

deg = np.pi / 180

# Buchholz, Armstrong & Goldstein (1992): segment / hand length (wrist->base, then 3 segments)
BUCHHOLZ = {
    "thumb": (0.118, 0.251, 0.196, 0.158),
    "index": (0.463, 0.245, 0.143, 0.097),
    "middle": (0.446, 0.266, 0.170, 0.108),
    "ring": (0.421, 0.244, 0.165, 0.107),
    "little": (0.414, 0.204, 0.117, 0.093),
}
FINGERS = ("index", "middle", "ring", "little")


@pytest.fixture(scope="module")
def limb():
    return aa.load("human_upper_limb")


def test_mobility_is_the_books_27_and_20():
    spec = aa.models.spec("human_upper_limb")
    m = mechanism_of(spec)
    assert m.loops == 0
    # Eq. (2-1) on the generated model's graph = the book's F = 27 (l. 544) = Fig. 2-2's graph
    assert m.mobility() == 27 == structure.upper_limb_mechanism().mobility()
    # the finger part: 5 two-axis base pairs (IV) + 10 hinges (V) on 15 phalanges: F = 20 (l. 548)
    counts = m.pair_counts()
    n_fingers = 15
    assert (
        structure.spatial_mobility(n_fingers, {4: 5, 5: 10})
        == 20
        == structure.human_fingers().mobility()
    )
    assert (
        counts[5] == 10 and counts[4] == 5 + 2 and counts[3] == 1
    )  # + wrist U, elbow-forearm U, shoulder S
    assert spec.nq == 27 == aa.load("human_upper_limb").nq


def test_mobility_of_the_arm_alone_is_seven():
    # ch. 2 (l. 544): the arm without the fingers, shoulder 3 + elbow/forearm 2 + wrist 2 = 7
    m = mechanism_of(aa.models.spec("human_arm7"))
    assert m.mobility() == 7 and m.pair_counts() == {1: 0, 2: 0, 3: 1, 4: 2, 5: 0}


def test_mimic_coupling_keeps_the_graph_and_drops_four_variables():
    spec = aa.models.spec("human_upper_limb", dip_coupling="2/3")
    assert mechanism_of(spec).mobility() == 27  # the pairs are the same
    r = aa.load("human_upper_limb", dip_coupling="2/3")
    assert r.nq == spec.nq == 27 - 4 == 23  # 4 DIP-PIP couplings (fingers 2-5)
    assert r.has_mimic


def test_q_order_is_pinocchios(limb):
    spec = aa.models.spec("human_upper_limb")
    assert [j.name for j in spec.joints] == list(limb.model.names)[1:]
    assert limb.tool == "hand_point"
    assert set(limb.tips) == {
        "hand_point",
        "thumb_tip",
        "index_tip",
        "middle_tip",
        "ring_tip",
        "little_tip",
    }
    for f in (
        "palm",
        "hand_point",
        "thumb_tip",
        "index_tip",
        "middle_tip",
        "ring_tip",
        "little_tip",
    ):
        assert limb.model.existFrame(f)


def test_arm_part_is_human_arm7(limb):
    arm = aa.load("human_arm7")
    rng = np.random.default_rng(3)
    for q in limb.random_q(20, rng):
        np.testing.assert_allclose(limb.fk(q), arm.fk(q[:7]), atol=1e-14)


def test_segment_lengths_are_buchholz(limb):
    p = limb.spec.params
    HL = p["hand_length"]
    # default hand length: the middle MCP at the end of de Leva's hand segment (86.2 mm at 1741 mm)
    assert HL == pytest.approx(0.0862 * 1.75 / 1.741 / 0.446, rel=1e-12)
    assert p["hand_breadth"] == pytest.approx(0.45 * HL, rel=1e-12)
    q = np.zeros(limb.nq)
    pin.framesForwardKinematics(limb.model, limb.data, q)
    pos = {n: limb.data.oMi[limb.model.getJointId(n)].translation for n in limb.model.names[1:]}
    tip = {d: limb.fk(q, frame=f"{d}_tip")[:3, 3] for d in BUCHHOLZ}
    wrist = pos["wrist_flexion"]
    for d, c in BUCHHOLZ.items():
        j = (
            ("thumb_cmc_flexion", "thumb_mcp", "thumb_ip")
            if d == "thumb"
            else (f"{d}_mcp_flexion", f"{d}_pip", f"{d}_dip")
        )
        pts = [pos[n] for n in j] + [tip[d]]
        lengths = [np.linalg.norm(b - a) for a, b in zip(pts, pts[1:])]
        np.testing.assert_allclose(lengths, np.array(c[1:]) * HL, rtol=1e-12)
        # wrist -> base (MCP, thumb CMC) along the hand axis: Buchholz's first coefficient, up to
        # the one offset that puts the middle MCP at de Leva's l_hand (0 at the default)
        assert wrist[2] - pts[0][2] == pytest.approx(c[0] * HL, abs=1e-12)
    # at q = 0 the middle finger is straight below the hand point: its tip 0.544 HL below it
    np.testing.assert_allclose(
        tip["middle"] - limb.fk(q)[:3, 3], [0, 0, -(0.266 + 0.170 + 0.108) * HL], atol=1e-14
    )


def test_flexion_moves_fingers_palmar_and_abduction_toward_thumb(limb):
    q0 = np.zeros(limb.nq)
    names = list(limb.model.names)[1:]
    for f in FINGERS:
        for j, (axis, sign) in (
            (f"{f}_mcp_flexion", (1, +1)),
            (f"{f}_pip", (1, +1)),
            (f"{f}_mcp_abduction", (0, +1)),
        ):
            q = q0.copy()
            q[names.index(j)] = 0.2
            d = limb.fk(q, frame=f"{f}_tip")[:3, 3] - limb.fk(q0, frame=f"{f}_tip")[:3, 3]
            assert sign * d[axis] > 1e-3, (j, d)  # +y palmar, +x radial (thumb side)
    q = q0.copy()
    q[names.index("thumb_cmc_abduction")] = 0.3
    d = limb.fk(q, frame="thumb_tip")[:3, 3] - limb.fk(q0, frame="thumb_tip")[:3, 3]
    assert d[1] > 1e-3  # palmar abduction
    q = q0.copy()
    q[names.index("thumb_mcp")] = 0.5
    d = limb.fk(q, frame="thumb_tip")[:3, 3] - limb.fk(q0, frame="thumb_tip")[:3, 3]
    assert d[0] < -1e-3  # thumb flexion sweeps across the palm (ulnar)


def test_thumb_reaches_the_index_tip_within_the_ranges(limb):
    """Opposition (tip pinch) is possible inside the joint ranges: a bounded local minimisation
    (scipy, independent of the model code) brings the thumb tip onto the index tip."""
    from scipy.optimize import minimize

    names = list(limb.model.names)[1:]
    idx = [i for i, n in enumerate(names) if n.startswith(("thumb", "index"))]

    def gap(x):
        q = np.zeros(limb.nq)
        q[idx] = x
        return np.linalg.norm(
            limb.fk(q, frame="thumb_tip")[:3, 3] - limb.fk(q, frame="index_tip")[:3, 3]
        )

    lo, hi = limb.lower[idx], limb.upper[idx]
    res = minimize(gap, (lo + hi) / 2, bounds=list(zip(lo, hi)))
    assert res.fun < 1e-6
    assert np.all(res.x >= lo - 1e-12) and np.all(res.x <= hi + 1e-12)


def test_finger_ranges_are_aaos(limb):
    names = list(limb.model.names)[1:]
    lo, hi = np.rad2deg(limb.lower), np.rad2deg(limb.upper)
    aaos = {"mcp_flexion": (-45, 90), "pip": (0, 100), "dip": (-10, 90), "mcp_abduction": (-20, 20)}
    for f in FINGERS:
        for k, (a, b) in aaos.items():
            i = names.index(f"{f}_{k}")
            assert (lo[i], hi[i]) == pytest.approx((a, b), abs=1e-12)
    thumb = {
        "thumb_cmc_flexion": (-20, 15),
        "thumb_cmc_abduction": (0, 70),
        "thumb_mcp": (0, 50),
        "thumb_ip": (-20, 80),
    }
    for n, (a, b) in thumb.items():
        i = names.index(n)
        assert (lo[i], hi[i]) == pytest.approx((a, b), abs=1e-12)
    # the arm keeps Table 2.2: elbow +145 / -5 (theta_4), forearm +-90 (theta_5)
    assert (lo[3], hi[3]) == pytest.approx((-5, 145), abs=1e-12)
    assert (lo[4], hi[4]) == pytest.approx((-90, 90), abs=1e-12)


def test_hand_mass_is_de_levas_and_phalanges_are_cylinders(limb):
    m = limb.model
    ids = {m.names[i]: i for i in range(1, m.njoints)}
    hand_joints = ["wrist_flexion"] + [n for n in ids if n.split("_")[0] in BUCHHOLZ]
    total = sum(m.inertias[ids[n]].mass for n in hand_joints)
    assert total == pytest.approx(
        0.0061 * 75.0, rel=1e-12
    )  # de Leva 1996: hand 0.61 % of body mass
    HL = limb.spec.params["hand_length"]
    r = limb.spec.params["hand_breadth"] / 8
    # index middle phalanx: solid cylinder, 1160 kg/m^3, radius 0.925 r, length 0.143 HL
    Y = m.inertias[ids["index_pip"]]
    L, rr = 0.143 * HL, 0.925 * r
    mass = 1160 * np.pi * rr**2 * L
    assert Y.mass == pytest.approx(mass, rel=1e-12)
    np.testing.assert_allclose(Y.lever, [0, 0, -L / 2], atol=1e-15)
    np.testing.assert_allclose(
        np.diag(Y.inertia), [mass * (3 * rr**2 + L**2) / 12] * 2 + [mass * rr**2 / 2], rtol=1e-12
    )
    for i in range(1, m.njoints):
        assert m.inertias[i].mass > 0 and np.linalg.eigvalsh(m.inertias[i].inertia).min() > 0


def test_dip_mimic_equals_the_coupled_tree():
    free = aa.load("human_upper_limb")
    coupled = aa.load("human_upper_limb", dip_coupling="2/3")
    names_c = list(coupled.model.names)[1:]
    names_f = [n for n in list(free.model.names)[1:]]
    rng = np.random.default_rng(5)
    for qc in coupled.random_q(10, rng):
        qf = np.zeros(free.nq)
        indep = [n for n in names_f if not (n.endswith("_dip") and n.split("_")[0] in FINGERS)]
        for n, v in zip(indep, qc):
            qf[names_f.index(n)] = v
        for f in FINGERS:
            qf[names_f.index(f"{f}_dip")] = 2.0 / 3.0 * qf[names_f.index(f"{f}_pip")]
        for frame in ("index_tip", "little_tip", "thumb_tip", "hand_point"):
            np.testing.assert_allclose(
                coupled.fk(qc, frame=frame), free.fk(qf, frame=frame), atol=1e-14
            )
    assert len(names_c) == 27  # the mimic joints stay joints of the model


def test_configuration_rejects_an_inconsistent_dip():
    spec = aa.models.spec("human_upper_limb", dip_coupling="2/3")
    q = configuration(spec, {"index_pip": 0.9, "index_dip": 0.6, "elbow_flexion": 1.0})
    assert q.shape == (23,)
    names = [j.name for j in spec.joints if j.mimic is None]
    assert q[names.index("index_pip")] == 0.9 and q[names.index("elbow_flexion")] == 1.0
    with pytest.raises(CouplingError) as e:
        configuration(spec, {"index_pip": 0.9, "index_dip": 0.2})
    assert e.value.joint == "index_dip" and e.value.expected == pytest.approx(0.6)
    with pytest.raises(ParameterError):
        configuration(spec, {"index_knuckle": 0.1})
    with pytest.raises(ParameterError):
        configuration(spec, {"index_pip": float("nan")})
    with pytest.raises(ParameterError, match="dict"):
        configuration(spec, [0.9, 0.6])


@pytest.mark.parametrize(
    "kw, match",
    [
        ({"hand_length": 0.30}, "forearm"),  # longer than the forearm (0.270 m at 1.75 m)
        ({"hand_breadth": -0.08}, "positive"),
        ({"hand_breadth": 0.0}, "positive"),
        ({"hand_length": float("nan")}, "finite"),
        ({"hand_length": 0.10}, "stature"),  # 0.057 x stature: not a human hand
        ({"hand_breadth": 0.15}, "hand length"),  # broader than 0.65 x its length
        ({"hand_length": "long"}, "finite"),
        (
            {"hand_breadth": 1e300},
            r"hand_breadth 1e\+300 m is 5.15e\+300 × the hand length",
        ),  # short, readable
    ],
)
def test_bad_anthropometry_raises(kw, match):
    with pytest.raises(AnthropometryError, match=match):
        aa.models.spec("human_upper_limb", **kw)


@pytest.mark.parametrize("bad", ["abc", "0", "-2/3", "5", "1/0", True, [2, 3]])
def test_bad_coupling_raises(bad):
    with pytest.raises(ParameterError):
        aa.models.spec("human_upper_limb", dip_coupling=bad)


def test_user_hand_length_scales_the_hand():
    s = aa.models.spec(
        "human_upper_limb", height=1.62, mass=55, sex="female", hand_length=0.17, hand_breadth=0.075
    )
    r = aa.load(
        "human_upper_limb", height=1.62, mass=55, sex="female", hand_length=0.17, hand_breadth=0.075
    )
    q = np.zeros(r.nq)
    wrist = r.fk(q, frame="palm")[:3, 3] + [0, 0, 0.446 * 0.17 / 2]
    np.testing.assert_allclose(r.fk(q)[:3, 3] - wrist, [0, 0, -0.446 * 0.17], atol=1e-14)
    np.testing.assert_allclose(
        r.fk(q, frame="index_tip")[:3, 3] - r.fk(q, frame="middle_tip")[:3, 3],
        [0.075 / 4, 0, (0.446 - 0.463 + 0.266 + 0.170 + 0.108 - 0.245 - 0.143 - 0.097) * 0.17],
        atol=1e-14,
    )
    assert s.params["hand_length"] == 0.17


CLI = "import sys; from anthroarm.cli import main; sys.exit(main(sys.argv[1:]))"


def test_cli_writes_the_model(tmp_path):
    out = tmp_path / "limb.urdf"
    res = subprocess.run(
        [
            sys.executable,
            "-c",
            CLI,
            "urdf",
            "human_upper_limb",
            "--param",
            "height=1.62",
            "-o",
            str(out),
        ],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert res.returncode == 0, res.stderr
    assert out.read_text() == aa.models.urdf_text("human_upper_limb", height=1.62)
    r = aa.load(str(out), tool="index_tip")
    assert r.nq == 27
    res = subprocess.run(
        [
            sys.executable,
            "-c",
            CLI,
            "urdf",
            "human_upper_limb",
            "--param",
            "hand_length=0.5",
            "-o",
            str(tmp_path / "bad.urdf"),
        ],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert res.returncode != 0 and "forearm" in res.stderr and "Traceback" not in res.stderr
    from anthroarm import cli

    out2 = tmp_path / "coupled.urdf"
    assert cli.main(["urdf", "human_upper_limb", "--dip_coupling", "2/3", "-o", str(out2)]) == 0
    text = out2.read_text()
    assert text.count("<mimic ") == 4 and 'multiplier="0.6666666666666666"' in text


def test_crosscheck_rows_pass():
    from anthroarm import crosscheck

    rows = crosscheck.run(
        ["human_upper_limb"],
        samples=10,
        tool="index_tip",
        providers=["anthroarm.kinematics.checks:rows", "anthroarm.dynamics.checks:model_rows"],
    )
    assert len(rows) >= 8
    bad = [(r.quantity, r.max_abs_err, r.note) for r in rows if not r.ok]
    assert not bad, bad


def test_a_visual_shape_urdf_cannot_draw_is_a_parameter_error():
    from anthroarm.models.spec import Shape, to_urdf

    spec = aa.models.spec("human_upper_limb")
    spec.joints[-1].link.shapes = (Shape("cone", (0.01,)),)
    with pytest.raises(ParameterError, match="box, cylinder or sphere"):
        to_urdf(spec)
