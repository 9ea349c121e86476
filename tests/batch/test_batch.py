"""anthroarm.batch: every job locally and on a real Dask LocalCluster (2 worker processes).

Oracles: the local reachability map equals a direct robot.fk loop over the same seeded
configurations; the tolerance job equals error_propagation.monte_carlo per configuration; the
cell table equals CellTable.build; the Dask result equals the local one bit for bit."""

from __future__ import annotations

import os
import signal
import socket
import time

import numpy as np
import pytest

import anthroarm as aa
from anthroarm import batch
from anthroarm.batch import engine, jobs

distributed = pytest.importorskip("distributed")


@pytest.fixture(scope="module")
def client():
    from distributed import Client, LocalCluster

    cluster = LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0"
    )
    c = Client(cluster, set_as_default=False)
    try:
        yield c
    finally:
        c.close()
        cluster.close()


@pytest.fixture(scope="module")
def arm():
    return aa.load("human_arm7")


# ----------------------------------------------------------------------------- local oracles
def test_reachability_local_equals_direct_fk_loop(arm):
    n, chunk, voxel = 50_000, 20_000, 0.05  # 3 tasks; 20 000 > BLOCK: blocks inside a task
    res = batch.reachability_map(arm, n=n, voxel=voxel, chunk_size=chunk, seed=7, progress=False)
    lo, shape = batch.voxel_grid(arm, voxel)
    expected = np.zeros(shape, np.int64)
    for (a, b), s in zip(engine.chunks(n, chunk), batch.chunk_seeds(7, 3)):
        Q = arm.chain.random_q(b - a, rng=np.random.default_rng(s))
        P = arm.fk(Q)[:, :3, 3]
        np.add.at(expected, tuple(np.floor((P - lo) / voxel).astype(int).T), 1)
    assert np.array_equal(res["counts"], expected)
    assert res["counts"].sum() == n and res.attrs["outside"] == 0
    assert res.dims("counts") == ("x", "y", "z")
    assert np.allclose(res.coords["x"], lo[0] + voxel * (np.arange(shape[0]) + 0.5))


def test_discomfort_zero_at_the_comfortable_posture(arm):
    from anthroarm.ik.qp.tasks.posture import comfortable_posture

    q = comfortable_posture(arm)
    assert batch.discomfort(arm, q[None])[0] == 0.0
    lo, hi = arm.chain.sampling_box
    q2 = q.copy()
    q2[3] += 0.1 * (hi[3] - lo[3])  # one joint off by 10 % of its range
    assert batch.discomfort(arm, q2[None])[0] == pytest.approx(0.1 / np.sqrt(7), rel=1e-12)


def test_comfort_map_counts_equal_reachability(arm):
    kw = dict(n=30_000, voxel=0.06, chunk_size=10_000, seed=3, progress=False)
    c = batch.comfort_map(arm, **kw)
    r = batch.reachability_map(arm, **kw)
    assert np.array_equal(c["counts"], r["counts"])
    d = c["discomfort"]
    assert np.array_equal(np.isnan(d), c["counts"] == 0)
    assert np.nanmin(d) >= 0 and np.nanmax(d) <= 1


def test_tolerance_equals_monte_carlo_per_configuration(arm):
    from anthroarm.kinematics.error_propagation import monte_carlo

    Q = arm.chain.random_q(2, rng=5)
    res = batch.tolerance_monte_carlo(
        arm, Q, sigma_q=1e-3, sigma_L=2e-4, n=3000, chunk_size=3000, seed=11, progress=False
    )
    for i, s in enumerate(batch.chunk_seeds(11, 2)):
        mc = monte_carlo(
            arm,
            Q[i],
            sigma_q=1e-3,
            sigma_L=2e-4,
            n=3000,
            rng=np.random.default_rng(s),
            batch=3000,
            progress=False,
        )
        assert res["rms_position"][i] == pytest.approx(mc.rms_position, rel=1e-12)
        assert res["p95_position"][i] == pytest.approx(mc.p95_position, rel=1e-12)
        assert res["max_position"][i] == pytest.approx(mc.max_position, rel=1e-12)
        assert np.allclose(res["mean"][i], mc.mean, rtol=1e-9, atol=1e-15)
        assert np.allclose(res["cov"][i], mc.cov, rtol=1e-6, atol=1e-14)
        assert np.allclose(res["linear_cov"][i], mc.linear_cov, rtol=1e-12, atol=1e-18)


def test_cell_table_equals_single_process_build(arm):
    from anthroarm.ik.cells import CellTable

    bounds = (np.array([-0.3, -0.3, -0.6]), np.array([0.3, 0.3, 0.0]))
    res = batch.cell_table(arm, D=0.1, bounds=bounds, chunk_size=2, progress=False)
    ref = CellTable.build(arm, np.eye(3), 0.1, bounds, progress=False)
    assert np.array_equal(res["valid"], ref.valid) and res["valid"].any()
    assert np.allclose(res["Q"], ref.Q, atol=1e-12, equal_nan=True)
    t = batch.to_cell_table(res)
    assert np.array_equal(t.valid, ref.valid) and np.allclose(t.origin, ref.origin)


def test_ik_dataset_round_trip(arm):
    Q = arm.chain.random_q(12, rng=4, margin=0.05)
    T = arm.fk(Q)
    res = batch.ik_dataset(arm, T, chunk_size=5, max_restarts=20, max_time=1.0, progress=False)
    assert res["success"].all()
    assert np.allclose(arm.fk(res["q"]), T, atol=1e-5)


def test_population_volume_grows_with_height():
    res = batch.population_reach(
        heights=[1.55, 1.85],
        masses=[70.0],
        sexes=["male"],
        n=20_000,
        voxel=0.05,
        chunk_size=10_000,
        progress=False,
    )
    v, r = res["volume"][:, 0, 0], res["max_reach"][:, 0, 0]
    assert v[1] > v[0] > 0 and r[1] > r[0]
    for k, h in enumerate([1.55, 1.85]):  # the largest distance is at most the arm's length
        assert r[k] <= aa.load("human_arm7", height=h, mass=70.0, sex="male").chain.reach() + 1e-12
    env = res["envelope"][:, 0, 0]
    assert np.all(env[:, 0] < env[:, 1])


# ----------------------------------------------------------------------------- Dask = local
SMALL = {
    "reach": lambda arm: (
        batch.reachability_map,
        (arm,),
        dict(n=40_000, voxel=0.05, chunk_size=8_000, seed=1),
    ),
    "comfort": lambda arm: (
        batch.comfort_map,
        ("human_arm7",),
        dict(n=30_000, voxel=0.06, chunk_size=6_000),
    ),
    "population": lambda arm: (
        batch.population_reach,
        (),
        dict(
            heights=[1.6, 1.8],
            masses=[60.0, 80.0],
            sexes=["female"],
            n=8_000,
            voxel=0.05,
            chunk_size=4_000,
        ),
    ),
    "tolerance": lambda arm: (
        batch.tolerance_monte_carlo,
        (arm, arm.chain.random_q(3, rng=2)),
        dict(sigma_q=1e-3, sigma_L=1e-4, n=2_000, chunk_size=700),
    ),
    "ik": lambda arm: (
        batch.ik_dataset,
        (arm, arm.fk(arm.chain.random_q(16, rng=3, margin=0.05))),
        dict(chunk_size=4, max_restarts=20, max_time=1.0),
    ),
    "cells": lambda arm: (batch.cell_table, (arm,), dict(D=0.15, chunk_size=3)),
}


@pytest.mark.parametrize("job", list(SMALL))
def test_dask_result_is_bitwise_the_local_result(job, arm, client):
    fn, args, kw = SMALL[job](arm)
    local = fn(*args, progress=False, **kw)
    remote = fn(*args, client=client, progress=False, **kw)
    assert local.equals(remote), job


def test_worker_killed_mid_job_loses_and_duplicates_nothing(arm, client):
    kw = dict(n=120_000, voxel=0.05, chunk_size=6_000, seed=9, progress=False)  # 20 tasks
    local = batch.reachability_map(arm, **kw)
    pids = client.run(os.getpid)
    victim = sorted(pids.values())[0]
    killed = []

    def kill_after_first(done, total):
        if not killed and done >= 2:
            os.kill(victim, signal.SIGKILL)
            killed.append(done)

    remote = batch.reachability_map(arm, client=client, callback=kill_after_first, **kw)
    assert killed and killed[0] < 20
    assert local.equals(remote)
    assert remote["counts"].sum() == kw["n"]
    client.wait_for_workers(2, timeout=60)  # the nanny restarts the worker for the next tests


@pytest.mark.parametrize("where", ["local", "dask"])
def test_cancelled_job_leaves_no_output_file(arm, client, tmp_path, where):
    out = tmp_path / "reach.npz"

    def interrupt(done, total):
        if done == 2:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        batch.run_job(
            "reach",
            arm,
            out=out,
            client=client if where == "dask" else None,
            n=60_000,
            voxel=0.05,
            chunk_size=5_000,
            progress=False,
            callback=interrupt,
        )
    assert list(tmp_path.iterdir()) == []
    if where == "dask":  # the job's pending tasks were cancelled, none keeps running
        deadline = time.monotonic() + 20
        while any(client.processing().values()) and time.monotonic() < deadline:
            time.sleep(0.1)
        assert not any(client.processing().values())


def test_run_job_writes_the_result_atomically(arm, client, tmp_path):
    out, png = tmp_path / "comfort.npz", tmp_path / "comfort.png"
    res = batch.run_job(
        "comfort",
        arm,
        out=out,
        plot=png,
        client=client,
        n=20_000,
        voxel=0.06,
        chunk_size=5_000,
        progress=False,
    )
    back = batch.load(out)
    assert (
        back.equals(res)
        and back.attrs["n"] == 20_000
        and back.dims("discomfort") == ("x", "y", "z")
    )
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["comfort.npz", "comfort.png"]


# ----------------------------------------------------------------------------- bad input
def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_unreachable_scheduler_fails_fast_with_a_typed_error():
    t0 = time.monotonic()
    with pytest.raises(batch.SchedulerUnreachableError, match="--scheduler local"):
        batch.connect(f"tcp://127.0.0.1:{_free_port()}", timeout=2)
    assert time.monotonic() - t0 < 15


def test_robot_without_description_is_refused_for_dask_but_runs_locally(arm, client):
    robot = aa.load(arm.model)  # from an in-memory pin.Model: no URDF text
    with pytest.raises(batch.RobotDescriptionError, match="URDF"):
        batch.reachability_map(robot, n=1000, voxel=0.1, client=client, progress=False)
    assert batch.reachability_map(robot, n=1000, voxel=0.1, progress=False)["counts"].sum() == 1000


def test_worker_that_rebuilds_another_robot_raises_rebuild_error(arm, client):
    d = batch.describe(arm)
    bad = batch.RobotDescription(
        d.kind, d.source, d.name, (("height", 1.5),), d.tool, d.locked, d.key
    )
    lo, shape = batch.voxel_grid(arm, 0.1)
    payload = dict(n=100, seed=np.random.SeedSequence(0), frame=None, lo=lo, voxel=0.1, shape=shape)
    with pytest.raises(batch.RobotRebuildError, match="Remedy"):
        engine.run(
            [(jobs._reach_task, bad, payload)], lambda i, p: None, client=client, progress=False
        )


def test_urdf_robot_is_shipped_as_text_and_rebuilt(tmp_path, client):
    path = tmp_path / "arm.urdf"
    path.write_text(aa.models.urdf_text("human_arm7", height=1.6))
    robot = aa.load(path)
    d = batch.describe(robot)
    assert d.kind == "urdf" and d.key == robot.chain.key()
    kw = dict(n=10_000, voxel=0.08, chunk_size=5_000, progress=False)
    assert batch.reachability_map(robot, **kw).equals(
        batch.reachability_map(robot, client=client, **kw)
    )


def test_output_too_large_is_refused_before_allocating(arm):
    with pytest.raises(batch.JobTooLargeError, match="coarser voxel"):
        batch.reachability_map(arm, n=10, voxel=1e-4, progress=False)


def test_tasks_are_chunked_never_one_giant_array(arm, monkeypatch):
    seen = []
    orig = jobs._positions_blocks

    def spy(robot, p):
        for Q, xyz in orig(robot, p):
            seen.append(Q.shape[0])
            yield Q, xyz

    monkeypatch.setattr(jobs, "_positions_blocks", spy)
    batch.reachability_map(arm, n=3 * jobs.BLOCK + 5, voxel=0.1, progress=False)
    assert max(seen) == jobs.BLOCK and sum(seen) == 3 * jobs.BLOCK + 5


# ----------------------------------------------------------------------------- command line
def test_cli_batch_on_the_cluster_equals_in_process(client, tmp_path, capsys):
    from anthroarm.cli import main

    common = [
        "batch",
        "reach",
        "--param",
        "height=1.62",
        "--n",
        "20000",
        "--voxel",
        "0.06",
        "--chunk-size",
        "5000",
        "--no-progress",
    ]
    assert main(common + ["--out", str(tmp_path / "a.npz")]) == 0
    assert (
        main(common + ["--scheduler", client.scheduler.address, "--out", str(tmp_path / "b.npz")])
        == 0
    )
    assert '"n": 20000' in capsys.readouterr().out
    assert batch.load(tmp_path / "a.npz").equals(batch.load(tmp_path / "b.npz"))


def test_cli_batch_unreachable_scheduler_is_one_line_exit_2(capsys):
    from anthroarm.cli import main

    t0 = time.monotonic()
    rc = main(
        [
            "batch",
            "reach",
            "--n",
            "100",
            "--scheduler",
            f"tcp://127.0.0.1:{_free_port()}",
            "--timeout",
            "2",
        ]
    )
    err = capsys.readouterr().err
    assert rc == 2 and "no Dask scheduler answered" in err and err.count("\n") == 1
    assert time.monotonic() - t0 < 15
