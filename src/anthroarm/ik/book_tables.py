"""Printed data of Chapter 7: Table 7.2 (l. 5111-5124) verbatim, with the corrections of the
ch7 notes §4 E1, and Table 7.3 (l. 5649-5657).

Columns: l = x6, m = y6, n = z6 of the hand frame, p = palm centre C (mm), θ1…θ6 (degrees).
"""

import numpy as np

M_COL = (0.0, 0.0, -1.0)
# row: (l, n, p as printed, printed angles)
PRINTED = {
    1: (
        (-1.0, 0.0, 0.0),
        (0.0, -1.0, 0.0),
        (0.0, -565.8854, -100.0),
        (-126.4318, 72.8953, 1.6652, 84.8053, -17.1830, -47.9230),
    ),
    2: (
        (-0.98, -0.199, 0.0),
        (0.199, -0.98, 0.0),
        (146.4102, -546.4102, -80.0),
        (-110.4301, 78.3910, 1.0464, 85.6839, -13.6483, -53.6524),
    ),
    3: (
        (-0.95, -0.3122, 0.0),
        (0.3122, -0.95, 0.0),
        (232.8427, -489.8980, -60.0),
        (-92.6927, 79.8357, 0.7777, 85.6700, -10.1936, -64.7140),
    ),
    4: (
        (-0.8, -0.6, 0.0),
        (0.6, -0.8, 0.0),
        (400.0, 400.0, -40.0),
        (-78.9997, 83.2436, 0.3729, 86.8549, -6.7665, -80.9632),
    ),
    5: (
        (-0.6, -0.8, 0.0),
        (0.8, -0.6, 0.0),
        (448.7884, -344.3675, -20.0),
        (-74.2914, 86.6277, 0.1343, 87.7209, -3.3749, -50.2954),
    ),
    6: (
        (-0.4, -0.9165, 0.0),
        (0.9165, -0.4, 0.0),
        (489.8980, -232.8427, 0.0),
        (-68.4036, 89.9999, 0.0000, 87.5537, 0.0000, -42.7277),
    ),
    7: (
        (-0.3, -0.9539, 0.0),
        (0.9539, -0.3, 0.0),
        (522.6252, -216.4784, 20.0),
        (-59.9944, 93.3722, -0.1810, 86.9308, 3.3771, -44.3872),
    ),
    8: (
        (-0.2, -0.9798, 0.0),
        (0.9798, -0.2, 0.0),
        (545.4102, -146.4102, 40.0),
        (-52.5904, 96.7563, -0.3263, 87.2475, 6.7641, -46.1749),
    ),
    9: (
        (0.0, -1.0, 0.0),
        (1.0, 0.0, 0.0),
        (585.5854, 0.0, 80.0),
        (-36.5272, 103.6089, -1.0175, 85.8045, 13.6462, -49.1558),
    ),
}

#: corrected target positions (notes §0.2 / §4 E1); rows not listed are as printed
CORRECTED_P = {
    1: (0.0, -565.6854, -100.0),
    3: (282.8427, -489.8980, -60.0),
    4: (400.0, -400.0, -40.0),
    6: (489.8980, -282.8427, 0.0),
    8: (546.4102, -146.4102, 40.0),
    9: (565.5854, 0.0, 80.0),
}
#: corrected printed angles (index, corrected value) — misprints of the output columns
CORRECTED_ANGLE = {1: (3, 84.6054), 2: (1, 76.3910), 4: (5, -60.9633)}
#: tolerances (degrees) of the notes §4 E1: exact rows 5e-4°, rounded-input rows 1e-2°
TOL = {1: 5e-4, 4: 5e-4, 5: 5e-4, 8: 5e-4, 9: 5e-4, 2: 1e-2, 3: 1e-2, 6: 1e-2}


def pose(row: int, corrected: bool = True, si: bool = True) -> np.ndarray:
    """4×4 pose of a row (m if ``si``), rotation columns (l, m, n) as printed (not orthonormalised)."""
    l, n, p, _ = PRINTED[row]
    if corrected:
        p = CORRECTED_P.get(row, p)
    T = np.eye(4)
    T[:3, 0], T[:3, 1], T[:3, 2] = l, M_COL, n
    T[:3, 3] = np.array(p) / (1000.0 if si else 1.0)
    return T


def nearest_rotation(T: np.ndarray) -> np.ndarray:
    """The same pose with its rotation replaced by the nearest rotation matrix (SVD)."""
    U, _, Vt = np.linalg.svd(T[:3, :3])
    out = T.copy()
    out[:3, :3] = U @ np.diag([1, 1, np.linalg.det(U @ Vt)]) @ Vt
    return out


def expected_angles(row: int) -> np.ndarray:
    ang = np.array(PRINTED[row][3], float)
    if row in CORRECTED_ANGLE:
        i, v = CORRECTED_ANGLE[row]
        ang[i] = v
    return ang


# Table 7.3 (l. 5649-5657): two-link mechanism (1 m links), target (y, z) = (1, 0), start (0, π/6);
# iterations 0..4 of θ1, θ2 (rad) as printed.
TABLE_7_3 = {
    "feedback_compensation": (
        (0.0000, -2.000, -0.835, 1.079, -0.882),
        (0.524, 3.752, 3.831, 2.613, 3.908),
    ),
    "steepest_descent": (
        (0.000, -0.134, -0.276, -0.356, -0.763),
        (0.524, 0.524, 0.594, 1.024, 1.377),
    ),
    "conjugate_direction": (
        (0.000, -0.134, -0.276, -0.810, -0.970),
        (0.524, 0.524, 0.594, 1.263, 1.859),
    ),
}
TABLE_7_3_START = (0.0, np.pi / 6)
TABLE_7_3_TARGET = (1.0, 0.0)
TABLE_7_3_SOLUTION = (-np.pi / 3, 2 * np.pi / 3)
