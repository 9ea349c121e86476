"""The batch jobs: one calling convention, local (``client=None``) or on Dask.

Every job takes the robot (a :class:`~anthroarm.robot.Robot`, a catalog name or a
:class:`~anthroarm.batch.describe.RobotDescription`), its own parameters, and the keywords

* ``client``: ``None`` (vectorised numpy in this process, chunked, with a tqdm bar) or a
  :class:`distributed.Client` (:func:`anthroarm.batch.connect`);
* ``chunk_size``: work items per task (configurations, samples, targets, lattice slices);
  the result depends on it for random jobs, never on the number of workers;
* ``seed``: root of the per-task :class:`numpy.random.SeedSequence` children (random jobs);
* ``progress``: a tqdm bar; ``callback(done, total)`` after each task (raise to cancel);

and returns a :class:`~anthroarm.batch.result.BatchResult`.  The local and the Dask run of
the same call return bitwise identical results (see :mod:`anthroarm.batch.engine`).  Jobs
never read or write files: save the result with ``result.save(path)`` (atomic).

Frames and units: positions are in the robot's base frame, metres; voxel grids are axis
aligned in the base frame, coordinates are voxel centres (m); angles in rad.
"""

from __future__ import annotations

import numpy as np

from ..ik import solve
from ..ik.cells import MAX_LATTICE, CellTable, lattice
from ..ik.qp.tasks.posture import comfortable_posture
from ..kinematics.error_propagation import (
    PerturbedChain,
    draw_errors,
    length_jacobian,
    log3_batch,
    tolerance_vector,
)
from ..models import PERSON_ARM
from . import engine
from .describe import RobotDescription, describe, robot_from
from .errors import BatchParameterError, JobTooLargeError
from .limits import MEMORY_BUDGET as MEMORY_BUDGET  # its old home
from .limits import _check_memory, _positive_int, _voxel, _voxels_per_side
from .result import BatchResult

#: configurations per task of the map jobs: ~0.3 s of work per task.  Measured on a 1-worker
#: LocalCluster, a task's CPU time equals the local one, and the wall time adds ~10 ms a task
#: (worker idle between tasks, scheduler round trips): 13-16 % of the work at 2**18, ~5 % at
#: 2**20, which is also 7 % faster locally (fewer per-task histograms)
MAP_CHUNK = 1 << 20
#: configurations per vectorised block inside a task: each (B,) float temporary is 64 KiB, under
#: glibc's 128 KiB mmap threshold.  Dask's nanny sets ``MALLOC_TRIM_THRESHOLD_``, which pins that
#: threshold, so 128 KiB blocks would be fresh page-faulting mmaps: 4x slower on a worker.
BLOCK = 1 << 13
#: Monte Carlo samples per task
MC_CHUNK = 1 << 15
#: IK targets per task
IK_CHUNK = 256
#: z slices of a cell table per task
CELL_SLICES = 2


def _robot_and_desc(robot, client):
    """(local robot, description): the description only where a worker needs it, so that the
    local path also runs robots made from a pin.Model."""
    if isinstance(robot, RobotDescription):
        return robot_from(robot), robot
    if isinstance(robot, str):
        d = describe(robot)
        return robot_from(d), d
    if client is None:
        return robot, _LocalOnly(robot)
    return robot, describe(robot)


class _LocalOnly:
    """Stands for the caller's robot on the local path (never shipped)."""

    def __init__(self, robot):
        self.robot = robot


def _tasks(fn, desc, payloads):
    """:class:`~anthroarm.batch.engine.Tasks` of ``fn`` over ``payloads = (count, make)``
    (``make()`` a fresh generator of the payloads): made as they are submitted."""
    n, make = payloads
    if isinstance(desc, _LocalOnly):
        return engine.Tasks(n, lambda: ((_local_call, None, (fn, desc.robot, p)) for p in make()))
    return engine.Tasks(n, lambda: ((fn, desc, p) for p in make()))


def _run(tasks, consume, client, robot, progress, desc, callback):
    engine.run(tasks, consume, client=client, progress=progress, desc=desc, callback=callback)


def _local_call(_, payload):
    fn, robot, p = payload
    return fn(robot, p)


# ============================================================================ voxel grids
def voxel_grid(robot, voxel: float, frame=None):
    """(lo (3,), shape (3,)) of the axis-aligned grid of cubes of side ``voxel`` (m) that
    contains every position ``frame`` can reach: ±(chain.reach + one voxel) about the base."""
    voxel = _voxel(voxel)
    m = _voxels_per_side(robot.chain.reach(frame), voxel) + 1
    return np.full(3, -m * voxel), (2 * m,) * 3


def _voxel_coords(lo, shape, voxel):
    return {ax: lo[i] + voxel * (np.arange(shape[i]) + 0.5) for i, ax in enumerate("xyz")}


def _positions_blocks(robot, p):
    """The task's random configurations in cache-sized blocks: yields (Q (B, nq), [x, y, z])
    with x, y, z (B,) the positions (m, base frame) of ``p["frame"]`` by the batched FK
    (:meth:`~anthroarm.kinematics.batched.SerialChain.positions`: no 4×4 matrices)."""
    rng = np.random.default_rng(p["seed"])
    ser = robot.chain.serial(p["frame"])
    n = p["n"]
    for a in range(0, n, BLOCK):
        Q = robot.chain.random_q(min(BLOCK, n - a), rng=rng)
        xyz = ser.positions(Q)
        yield Q, [xyz[:, 0], xyz[:, 1], xyz[:, 2]]


def _flat_index(xyz, lo, voxel, shape):
    """Flat voxel index (into ``shape``, C order) of the positions inside the grid, and the
    mask of those inside: voxel i along an axis holds lo + i·voxel <= x < lo + (i+1)·voxel."""
    flat = np.zeros(xyz[0].shape[0], np.int64)
    inside = np.ones(xyz[0].shape[0], bool)
    for c in range(3):
        i = np.floor((xyz[c] - lo[c]) / voxel).astype(np.int64)
        inside &= (i >= 0) & (i < shape[c])
        flat *= shape[c]
        flat += i
    return flat[inside], inside


def _reach_task(robot, p):
    size = int(np.prod(p["shape"]))
    flats, outside = [], 0
    for _, xyz in _positions_blocks(robot, p):
        flat, inside = _flat_index(xyz, p["lo"], p["voxel"], p["shape"])
        flats.append(flat)
        outside += int(inside.size - flat.size)
    counts = np.bincount(np.concatenate(flats), minlength=size)
    nz = np.flatnonzero(counts)
    return nz, counts[nz], outside


def _map_setup(robot, n, voxel, frame, chunk_size, seed):
    n = _positive_int(n, "n")
    chunk_size = _positive_int(chunk_size, "chunk_size")
    lo, shape = voxel_grid(robot, voxel, frame)
    _check_memory(
        np.prod(shape, dtype=float) * 16.0,
        f"a voxel grid of {shape} voxels",
        "use a coarser voxel (voxel= in m)",
    )
    voxel = float(voxel)
    n_parts = engine.n_chunks(n, chunk_size)

    def payloads():  # made as they are submitted: n = 10**12 is 10**6 tasks
        for (a, b), s in zip(engine.iter_chunks(n, chunk_size), engine.iter_seeds(seed, n_parts)):
            yield dict(n=b - a, seed=s, frame=frame, lo=lo, voxel=voxel, shape=shape)

    return n, lo, shape, (n_parts, payloads)


def reachability_map(
    robot,
    n: int = 10**6,
    voxel: float = 0.02,
    frame=None,
    *,
    client=None,
    chunk_size: int = MAP_CHUNK,
    seed=0,
    progress: bool = True,
    callback=None,
) -> BatchResult:
    """Monte Carlo reachability map: ``n`` configurations uniform in the joint ranges
    (:meth:`~anthroarm.chain.Chain.random_q`), the position of ``frame`` (default the tool)
    by the batched FK, counted per voxel of side ``voxel`` (m) in the base frame.

    Returns ``counts`` (x, y, z) int64: configurations per voxel (they sum to ``n``: nothing is
    lost or counted twice); coords x, y, z: voxel centres (m); attrs ``volume`` = occupied voxels
    × voxel³ (m³, a lower estimate that converges as n grows)."""
    robot, d = _robot_and_desc(robot, client)
    n, lo, shape, payloads = _map_setup(robot, n, voxel, frame, chunk_size, seed)
    counts = np.zeros(int(np.prod(shape)), np.int64)
    outside = [0]

    def consume(i, part):
        nz, c, out = part
        counts[nz] += c
        outside[0] += out

    _run(
        _tasks(_reach_task, d, payloads), consume, client, robot, progress, "reachability", callback
    )
    counts = counts.reshape(shape)
    return BatchResult(
        "reachability_map",
        {"counts": (("x", "y", "z"), counts)},
        _voxel_coords(lo, shape, voxel),
        _attrs(
            robot,
            frame,
            n=n,
            voxel=float(voxel),
            seed=_seed_attr(seed),
            chunk_size=chunk_size,
            outside=outside[0],
            volume=float(np.count_nonzero(counts)) * float(voxel) ** 3,
            units={"x": "m", "y": "m", "z": "m"},
        ),
    )


def _attrs(robot, frame, **kw):
    return dict(
        robot=robot.name, frame=robot.chain.frame(frame).name, chain_key=robot.chain.key(), **kw
    )


def _seed_attr(seed):
    return seed if isinstance(seed, (int, np.integer)) or seed is None else str(seed)


# ============================================================================ comfort
def discomfort(robot, Q) -> np.ndarray:
    """Distance of configurations ``Q`` (N, nq) from the robot's comfortable posture
    (:func:`anthroarm.ik.qp.tasks.posture.comfortable_posture`: for the human arm the centres of
    RULA's lowest-load bands, McAtamney & Corlett 1993), as the RMS over the independent joints
    of the deviation divided by the joint's range: 0 at the comfortable posture, dimensionless,
    at most 1.  A continuous joint's deviation is wrapped to (−π, π]."""
    chain = robot.chain
    ind = list(chain.independent)
    th_c = chain.angles(comfortable_posture(robot))[ind]
    lo, hi = chain.sampling_box
    th = chain.angles(np.atleast_2d(Q))[:, ind]
    dev = th - th_c
    cont = np.array([chain.joints[i].kind == "continuous" for i in ind])
    if cont.any():
        dev[:, cont] = np.angle(np.exp(1j * dev[:, cont]))
    return np.sqrt(np.mean((dev / (hi - lo)) ** 2, axis=1))


def _comfort_task(robot, p):
    size = int(np.prod(p["shape"]))
    best = np.full(size, np.inf)
    flats = []
    for Q, xyz in _positions_blocks(robot, p):
        flat, inside = _flat_index(xyz, p["lo"], p["voxel"], p["shape"])
        flats.append(flat)
        np.minimum.at(best, flat, discomfort(robot, Q[inside]))
    counts = np.bincount(np.concatenate(flats), minlength=size)
    nz = np.flatnonzero(counts)
    return nz, counts[nz], best[nz]


def comfort_map(
    robot,
    n: int = 10**6,
    voxel: float = 0.02,
    frame=None,
    *,
    client=None,
    chunk_size: int = MAP_CHUNK,
    seed=0,
    progress: bool = True,
    callback=None,
) -> BatchResult:
    """Comfort over the reachable workspace: for each voxel (side ``voxel`` m, base frame) the
    least :func:`discomfort` among the ``n`` sampled configurations that put ``frame`` there.

    Returns ``discomfort`` (x, y, z) float (NaN where no sample landed) and ``counts``
    (x, y, z).  The per-voxel minimum does not depend on the order tasks finish in."""
    robot, d = _robot_and_desc(robot, client)
    n, lo, shape, payloads = _map_setup(robot, n, voxel, frame, chunk_size, seed)
    size = int(np.prod(shape))
    counts = np.zeros(size, np.int64)
    best = np.full(size, np.inf)

    def consume(i, part):
        nz, c, b = part
        counts[nz] += c
        best[nz] = np.minimum(best[nz], b)

    _run(_tasks(_comfort_task, d, payloads), consume, client, robot, progress, "comfort", callback)
    best[counts == 0] = np.nan
    return BatchResult(
        "comfort_map",
        {
            "discomfort": (("x", "y", "z"), best.reshape(shape)),
            "counts": (("x", "y", "z"), counts.reshape(shape)),
        },
        _voxel_coords(lo, shape, voxel),
        _attrs(
            robot,
            frame,
            n=n,
            voxel=float(voxel),
            seed=_seed_attr(seed),
            chunk_size=chunk_size,
            units={"x": "m", "y": "m", "z": "m", "discomfort": "1"},
        ),
    )


# ============================================================================ population
_OFF, _B = 1 << 20, 1 << 21


def _population_task(robot, p):
    codes, rmax = [], 0.0
    pmin, pmax = np.full(3, np.inf), np.full(3, -np.inf)
    for _, xyz in _positions_blocks(robot, p):
        P = np.stack(xyz, 1)
        f = np.floor(P / p["voxel"])
        if not np.all(np.abs(f) < _OFF):  # the codes hold ±2**20 voxels per axis
            raise JobTooLargeError(
                f"population: positions up to {np.max(np.abs(P)):.3g} m are more than {_OFF} "
                f"voxels of {p['voxel']:g} m from the base. Remedy: use a coarser voxel"
            )
        ijk = f.astype(np.int64) + _OFF
        codes.append(np.unique((ijk[:, 0] * _B + ijk[:, 1]) * _B + ijk[:, 2]))
        rmax = max(rmax, float(np.sqrt(np.max(np.einsum("ij,ij->i", P, P)))))
        pmin, pmax = np.minimum(pmin, P.min(0)), np.maximum(pmax, P.max(0))
    return p["person"], np.unique(np.concatenate(codes)), rmax, pmin, pmax


def population_reach(
    model: str = PERSON_ARM,
    heights=(1.55, 1.65, 1.75, 1.85),
    masses=(60.0, 75.0),
    sexes=("female", "male"),
    n: int = 10**5,
    voxel: float = 0.02,
    frame=None,
    *,
    client=None,
    chunk_size: int = MAP_CHUNK,
    seed=0,
    progress: bool = True,
    callback=None,
) -> BatchResult:
    """Workspace of a population: for each (height m, mass kg, sex) of the grid, the catalog
    model ``model`` built with those builder parameters, ``n`` random configurations, and

    ``volume`` (height, mass, sex) m³: occupied voxels (side ``voxel`` m, lattice anchored at the
    base origin) × voxel³; ``max_reach`` m: the largest distance of ``frame`` from the base
    origin; ``envelope`` (height, mass, sex, side, axis) m: the smallest ("min") and largest
    ("max") x, y, z of ``frame`` in the base frame.

    Every person's robot is shipped as (name, parameters) and rebuilt on the worker."""
    n = _positive_int(n, "n")
    chunk_size = _positive_int(chunk_size, "chunk_size")
    voxel = _voxel(voxel)
    heights, masses = np.asarray(heights, float).ravel(), np.asarray(masses, float).ravel()
    sexes = [str(s) for s in np.atleast_1d(sexes)]
    people = [(float(h), float(m), s) for h in heights for m in masses for s in sexes]
    if not people:
        raise BatchParameterError("the population is empty: give at least one height, mass and sex")
    C = engine.n_chunks(n, chunk_size)
    descs = [
        RobotDescription("catalog", model, model, (("height", h), ("mass", m), ("sex", s)))
        for h, m, s in people
    ]

    def make():  # made as they are submitted; seeds in the order of chunk_seeds(seed, P * C)
        seeds = engine.iter_seeds(seed, len(people) * C)
        for k, d in enumerate(descs):
            for a, b in engine.iter_chunks(n, chunk_size):
                p = dict(person=k, n=b - a, seed=next(seeds), frame=frame, voxel=voxel)
                yield _population_task, d, p

    tasks = engine.Tasks(len(people) * C, make)
    first = robot_from(descs[0])  # fail early, here, on a bad model name or parameter
    _voxels_per_side(first.chain.reach(frame), voxel)
    P = len(people)
    volume, rmax = np.zeros(P), np.zeros(P)
    lo, hi = np.full((P, 3), np.inf), np.full((P, 3), -np.inf)
    pending = {k: C for k in range(P)}
    sets: dict = {}

    def consume(i, part):
        k, codes, r, pmin, pmax = part
        # the union so far (order-independent; never more than the occupied voxels)
        sets[k] = np.union1d(sets[k], codes) if k in sets else codes
        rmax[k] = max(rmax[k], r)
        lo[k], hi[k] = np.minimum(lo[k], pmin), np.maximum(hi[k], pmax)
        pending[k] -= 1
        if pending[k] == 0:  # this person is complete: keep the number, drop the voxel set
            volume[k] = sets.pop(k).size * voxel**3

    engine.run(
        tasks, consume, client=client, progress=progress, desc="population", callback=callback
    )
    shp = (heights.size, masses.size, len(sexes))
    env = np.stack([lo, hi], axis=1).reshape(shp + (2, 3))
    return BatchResult(
        "population_reach",
        {
            "volume": (("height", "mass", "sex"), volume.reshape(shp)),
            "max_reach": (("height", "mass", "sex"), rmax.reshape(shp)),
            "envelope": (("height", "mass", "sex", "side", "axis"), env),
        },
        {
            "height": heights,
            "mass": masses,
            "sex": np.array(sexes),
            "side": np.array(["min", "max"]),
            "axis": np.array(["x", "y", "z"]),
        },
        dict(
            model=model,
            frame=frame,
            n=n,
            voxel=voxel,
            seed=_seed_attr(seed),
            chunk_size=chunk_size,
            units={"height": "m", "mass": "kg", "volume": "m^3", "max_reach": "m", "envelope": "m"},
        ),
    )


# ============================================================================ tolerance
def _mc_task(robot, p):
    chain = PerturbedChain(robot, p["frame"], p["params"], p["mode"])
    q = p["q"]
    R0, x0 = chain.pose(q[None])
    rng = np.random.default_rng(p["seed"])
    m = p["n"]
    dq = draw_errors(rng, p["distribution"], p["sigma_q"], m)
    dL = draw_errors(rng, p["distribution"], p["sigma_L"], m)
    R, x = chain.pose(np.broadcast_to(q, (m, q.size)), dL, dq)
    dx = np.empty((m, 6))
    dx[:, :3] = x - x0
    dx[:, 3:] = log3_batch(R @ R0[0].T)
    return np.linalg.norm(dx[:, :3], axis=1), dx.sum(0), dx.T @ dx


def tolerance_monte_carlo(
    robot,
    Q,
    sigma_q=0.0,
    sigma_L=0.0,
    n: int = 10000,
    frame=None,
    params=None,
    mode: str = "length",
    distribution: str = "normal",
    *,
    client=None,
    chunk_size: int = MC_CHUNK,
    seed=0,
    progress: bool = True,
    callback=None,
) -> BatchResult:
    """Monte Carlo tolerance analysis (§6-6) of many configurations ``Q`` (M, nq): per
    configuration ``n`` samples of joint errors (``sigma_q``, rad or m per joint) and link
    errors (``sigma_L``, m per link parameter of
    :func:`~anthroarm.kinematics.error_propagation.link_parameters`), the exact perturbed FK
    (:class:`~anthroarm.kinematics.error_propagation.PerturbedChain`), as
    :func:`~anthroarm.kinematics.error_propagation.monte_carlo` does for one configuration.

    Returns per configuration ``rms_position``, ``p95_position``, ``max_position`` (m) of
    |Δp|, ``mean`` (config, component) and ``cov`` (config, component, component2) of the
    pose error (Δp m; Δφ rad, world axes), and ``linear_cov``: the first-order J Σ Jᵀ of
    Eq. (6-118).  With ``chunk_size >= n`` configuration i draws from
    ``chunk_seeds(seed, M)[i]`` exactly as ``monte_carlo(..., rng=that seed, batch=n)``."""
    robot, d = _robot_and_desc(robot, client)
    Q = np.atleast_2d(robot.check_q(Q))
    n = _positive_int(n, "n")
    chunk_size = _positive_int(chunk_size, "chunk_size")
    if distribution not in ("normal", "uniform"):
        raise BatchParameterError(
            f"distribution must be 'normal' or 'uniform', got {distribution!r}"
        )
    ps = PerturbedChain(robot, frame, params, mode).params
    sq, sL = (
        tolerance_vector(sigma_q, robot.nv, "sigma_q"),
        tolerance_vector(sigma_L, len(ps), "sigma_L"),
    )
    if np.any(sq < 0) or np.any(sL < 0):
        raise BatchParameterError(
            f"tolerances must be non-negative, got sigma_q={sq.tolist()}, sigma_L={sL.tolist()}"
        )
    M = Q.shape[0]
    _check_memory(
        M * n * 8.0,
        f"{M} configurations x {n} samples",
        "fewer samples n or fewer configurations per job",
    )
    C = engine.n_chunks(n, chunk_size)

    def make():  # seeds in the order of chunk_seeds(seed, M * C)
        seeds = engine.iter_seeds(seed, M * C)
        for i in range(M):
            for a, b in engine.iter_chunks(n, chunk_size):
                yield dict(
                    q=Q[i],
                    n=b - a,
                    seed=next(seeds),
                    frame=frame,
                    params=ps,
                    mode=mode,
                    distribution=distribution,
                    sigma_q=sq,
                    sigma_L=sL,
                )

    payloads = (M * C, make)
    store: dict = {}
    _run(
        _tasks(_mc_task, d, payloads),
        store.__setitem__,
        client,
        robot,
        progress,
        "monte carlo",
        callback,
    )
    rms, p95, mx = np.empty(M), np.empty(M), np.empty(M)
    mean, cov, lin = np.empty((M, 6)), np.empty((M, 6, 6)), np.empty((M, 6, 6))
    var_factor = 1.0 if distribution == "normal" else 1.0 / 3.0
    Sigma = np.diag(np.concatenate([sq, sL]) ** 2 * var_factor)
    for i in range(M):  # combine in task order: the same bits whatever order tasks finished in
        got = [store.pop(i * C + j) for j in range(C)]
        dp = np.concatenate([g[0] for g in got])
        s1 = sum((g[1] for g in got[1:]), got[0][1])
        s2 = sum((g[2] for g in got[1:]), got[0][2])
        rms[i], p95[i], mx[i] = np.sqrt(np.mean(dp**2)), np.percentile(dp, 95), dp.max()
        mean[i] = s1 / n
        cov[i] = (s2 - n * np.outer(mean[i], mean[i])) / (n - 1) if n > 1 else 0.0
        J = np.hstack([robot.jacobian(Q[i], frame), length_jacobian(robot, Q[i], frame, ps)])
        lin[i] = J @ Sigma @ J.T
    comp = np.array(["x", "y", "z", "rx", "ry", "rz"])
    return BatchResult(
        "tolerance_monte_carlo",
        {
            "q": (("config", "joint"), Q),
            "rms_position": (("config",), rms),
            "p95_position": (("config",), p95),
            "max_position": (("config",), mx),
            "mean": (("config", "component"), mean),
            "cov": (("config", "component", "component2"), cov),
            "linear_cov": (("config", "component", "component2"), lin),
        },
        {
            "config": np.arange(M),
            "joint": np.array(robot.chain.q_names),
            "component": comp,
            "component2": comp,
        },
        _attrs(
            robot,
            frame,
            n=n,
            seed=_seed_attr(seed),
            chunk_size=chunk_size,
            distribution=distribution,
            sigma_q=sq,
            sigma_L=sL,
            link_parameters=[str(p) for p in ps],
            units={"rms_position": "m", "p95_position": "m", "max_position": "m"},
        ),
    )


# ============================================================================ IK
def _ik_task(robot, p):
    r = solve(robot, p["T"], q0=p["q0"], rng=np.random.default_rng(p["seed"]), **p["kw"])
    return r.q, r.success, r.pos_err, r.rot_err, r.iterations


def ik_dataset(
    robot,
    T,
    q0=None,
    *,
    client=None,
    chunk_size: int = IK_CHUNK,
    seed=0,
    progress: bool = True,
    callback=None,
    **solve_kw,
) -> BatchResult:
    """Inverse kinematics of many targets ``T`` (N, 4, 4) (or positions (N, 3); base frame, m)
    with :func:`anthroarm.ik.solve` (``solve_kw``: frame, tol_pos, max_time, max_restarts,
    posture ...), ``chunk_size`` targets per task, the random restarts of task i seeded by
    ``chunk_seeds(seed, tasks)[i]``.  ``q0`` (N, nq) optional initial guesses.

    Returns ``q`` (target, joint), ``success``, ``pos_err`` (m), ``rot_err`` (rad),
    ``iterations`` (target).  Bitwise reproducible where the time budget ``max_time`` is not what
    stops the search (cap the search with ``max_restarts=`` for strict reproducibility)."""
    robot, d = _robot_and_desc(robot, client)
    T = np.asarray(T, float)
    if (
        T.ndim not in (2, 3)
        or (T.ndim == 3 and T.shape[1:] != (4, 4))
        or (T.ndim == 2 and T.shape[1] != 3)
    ):
        raise BatchParameterError(
            f"T must be (N, 4, 4) poses or (N, 3) positions, got shape {T.shape}"
        )
    N = T.shape[0]
    if q0 is not None:
        q0 = np.asarray(q0, float)
        if q0.shape != (N, robot.nq):
            raise BatchParameterError(f"q0 must have shape ({N}, {robot.nq}), got {q0.shape}")
    chunk_size = _positive_int(chunk_size, "chunk_size")
    _check_memory(
        N * (robot.nq + 4) * 8.0,
        f"IK results of {N} targets",
        "split the targets into several jobs",
    )
    parts = engine.chunks(N, chunk_size)  # N targets are in memory: so may N / 256 pairs be
    seeds = engine.chunk_seeds(seed, len(parts))
    payloads = (
        len(parts),
        lambda: (
            dict(T=T[a:b], q0=None if q0 is None else q0[a:b], seed=s, kw=dict(solve_kw))
            for (a, b), s in zip(parts, seeds)
        ),
    )
    q = np.full((N, robot.nq), np.nan)
    ok, pe, re, it = (
        np.zeros(N, bool),
        np.full(N, np.nan),
        np.full(N, np.nan),
        np.zeros(N, np.int64),
    )

    def consume(i, part):
        a, b = parts[i]
        q[a:b], ok[a:b], pe[a:b], re[a:b], it[a:b] = part

    _run(_tasks(_ik_task, d, payloads), consume, client, robot, progress, "ik", callback)
    return BatchResult(
        "ik_dataset",
        {
            "q": (("target", "joint"), q),
            "success": (("target",), ok),
            "pos_err": (("target",), pe),
            "rot_err": (("target",), re),
            "iterations": (("target",), it),
        },
        {"target": np.arange(N), "joint": np.array(robot.chain.q_names)},
        _attrs(
            robot,
            solve_kw.get("frame"),
            n=N,
            seed=_seed_attr(seed),
            chunk_size=chunk_size,
            solve_kw={
                k: v
                for k, v in solve_kw.items()
                if isinstance(v, (int, float, str, bool, type(None)))
            },
            units={"pos_err": "m", "rot_err": "rad"},
        ),
    )


# ============================================================================ cell table
def _cell_task(robot, p):
    t = CellTable.build(
        robot,
        p["rotation"],
        p["D"],
        p["bounds"],
        q_ref=p["q_ref"],
        branch=p["branch"],
        progress=False,
        swivel=p["swivel"],
    )
    m = p["m"]
    return t.Q[:, :, :m], t.valid[:, :, :m]


def cell_table(
    robot,
    rotation=None,
    D: float = 0.05,
    bounds=None,
    *,
    q_ref=None,
    branch=None,
    swivel: float = 0.0,
    client=None,
    chunk_size: int = CELL_SLICES,
    progress: bool = True,
    callback=None,
) -> BatchResult:
    """The §7-3 cell table (:meth:`anthroarm.ik.cells.CellTable.build`: exact closed-form IK at
    every lattice point of spacing ``D`` m in the box ``bounds = (lo(3), hi(3))`` m, base frame,
    hand orientation ``rotation`` (3, 3), default identity) computed ``chunk_size`` z slices
    per task.  ``bounds`` defaults to the box ±reach.

    Returns ``Q`` (x, y, z, joint) rad (NaN where the point has no solution on the branch) and
    ``valid`` (x, y, z); attrs hold origin, D, rotation, model and params:
    :func:`to_cell_table` makes the :class:`~anthroarm.ik.cells.CellTable`.  Every slice's
    lattice points are computed from the slab's own origin, so a value may differ from one
    single-process ``CellTable.build`` in the last bits (local and Dask runs of this job are
    bitwise identical)."""
    robot, d = _robot_and_desc(robot, client)
    R = np.eye(3) if rotation is None else np.asarray(rotation, float)
    D = float(D)
    if bounds is None:
        r = robot.chain.reach()
        bounds = (np.full(3, -r), np.full(3, r))
    lo, hi = (np.asarray(b, float) for b in bounds)
    if not (
        np.isfinite(D)
        and D > 0
        and lo.shape == hi.shape == (3,)
        and np.all(np.isfinite(lo) & np.isfinite(hi) & (hi > lo))
    ):
        raise BatchParameterError(
            f"need a cell size D > 0 (m) and bounds = (lo(3), hi(3)) with lo < hi; got D={D}, "
            f"bounds={bounds!r}"
        )
    if robot.spec is None:
        raise BatchParameterError(
            f"{robot.name}: the cell table needs a catalog model with a closed form (robot.spec is "
            "None)"
        )
    i0, shape = lattice(lo, hi, D)  # the lattice of CellTable.build
    if np.prod(shape) > MAX_LATTICE:
        raise JobTooLargeError(
            f"lattice of {shape} points is too large. Remedy: increase D or shrink bounds"
        )
    chunk_size = _positive_int(chunk_size, "chunk_size")
    payloads = []  # at most MAX_LATTICE points: a short list
    for k0, k1 in engine.chunks(shape[2], chunk_size):
        m = k1 - k0
        b = (
            np.array([lo[0], lo[1], (i0[2] + k0) * D]),
            np.array([hi[0], hi[1], (i0[2] + k0 + m) * D]),
        )
        payloads.append(
            dict(rotation=R, D=D, bounds=b, q_ref=q_ref, branch=branch, swivel=swivel, m=m)
        )
    Q = np.full(shape + (robot.nq,), np.nan)
    valid = np.zeros(shape, bool)
    slabs = engine.chunks(shape[2], chunk_size)

    def consume(i, part):
        a, b = slabs[i]
        Q[:, :, a:b], valid[:, :, a:b] = part

    tasks = _tasks(_cell_task, d, (len(payloads), lambda: payloads))
    _run(tasks, consume, client, robot, progress, "cell table", callback)
    origin = i0 * D
    coords = {ax: origin[i] + D * np.arange(shape[i]) for i, ax in enumerate("xyz")}
    coords["joint"] = np.array(robot.chain.q_names)
    return BatchResult(
        "cell_table",
        {"Q": (("x", "y", "z", "joint"), Q), "valid": (("x", "y", "z"), valid)},
        coords,
        _attrs(
            robot,
            None,
            model=robot.spec.name,
            params=dict(robot.spec.params),
            rotation=R,
            origin=origin,
            D=D,
            branch=branch,
            swivel=swivel,
            chunk_size=chunk_size,
            units={"x": "m", "y": "m", "z": "m", "Q": "rad"},
        ),
    )


def to_cell_table(result: BatchResult):
    """The :class:`~anthroarm.ik.cells.CellTable` of a :func:`cell_table` result."""
    a = result.attrs
    return CellTable(
        a["model"],
        a["params"],
        np.asarray(a["rotation"], float),
        np.asarray(a["origin"], float),
        a["D"],
        result["Q"],
        result["valid"],
    )
