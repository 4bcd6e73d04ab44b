"""The aero stage's CFD cases on a Dask cluster (``--scheduler``, bridge.cluster): the same numbers as local
cases, a bad address refused before any work, and an interrupted run that leaves no case computing on the
cluster's workers."""

from __future__ import annotations

import socket
import sys

import numpy as np
import pytest

from bridge import scenario, sweep
from bridge.aero.forced_motion import ForcedCase, StaticCase, run_cases
from bridge.aero.presets import QUALITY, preset, section_polygons
from bridge.cfd.sections import FlatPlate, Rectangle


def _unused_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture
def short_timeout(monkeypatch):
    import bridge.cluster

    monkeypatch.setattr(bridge.cluster, "CONNECT_TIMEOUT_S", 1)


@pytest.mark.parametrize("command", ["scenario", "sweep"])
def test_a_scheduler_that_does_not_answer_is_refused_before_any_work(tmp_path, capsys, short_timeout, command):
    out = tmp_path / "out"
    main = scenario.main if command == "scenario" else sweep.main
    for address, says in ((f"tcp://127.0.0.1:{_unused_port()}", "no Dask scheduler answers there within 1 s"),
                          ("nonsense", "not a scheduler's address")):
        assert main(["great_belt", "--scheduler", address, "--out", str(out)]) == 2
        err = capsys.readouterr().err
        assert f"--scheduler = {address!r}" in err and says in err
        assert not out.exists()   # nothing written
    if command == "scenario":   # a run without CFD never asks the scheduler
        assert main(["thin_plate_section", "--scheduler", "nonsense", "--out", str(out)]) == 0


def test_the_scheduler_without_dask_installed_and_with_workers_is_refused(tmp_path, capsys, monkeypatch):
    out = tmp_path / "out"
    assert scenario.main(["great_belt", "--scheduler", "tcp://h:8786", "--workers", "2", "--out", str(out)]) == 2
    assert "--workers = 2: not with --scheduler" in capsys.readouterr().err
    monkeypatch.setitem(sys.modules, "distributed", None)   # import distributed now fails
    assert scenario.main(["great_belt", "--scheduler", "tcp://h:8786", "--out", str(out)]) == 2
    assert 'needs Dask: pip install -e ".[dask]"' in capsys.readouterr().err
    assert not out.exists()


@pytest.fixture
def cluster(request):
    """A local Dask cluster of ``request.param`` worker processes, one thread each."""
    from distributed import LocalCluster

    with LocalCluster(n_workers=request.param, threads_per_worker=1, processes=True, dashboard_address=None) as c:
        yield c


@pytest.mark.slow
@pytest.mark.parametrize("cluster", [2], indirect=True)
def test_cases_on_a_cluster_give_the_numbers_of_local_cases_and_their_checkpoints(cluster, tmp_path):
    poly = section_polygons(Rectangle(10.0, 2.0))[0]
    q = QUALITY["tiny"].with_(static_duration=1.0)
    jobs = [(StaticCase(a), tmp_path / "runs" / f"{a:g}.h5", f"angle {a:g}") for a in (2.0, -1.0, 0.0)]
    lines = []
    there = run_cases(poly, jobs, q, progress=lines.append, scheduler=cluster.scheduler_address)
    here = run_cases(poly, [(c, None, label) for c, _, label in jobs], q, workers=1)
    for a, b in zip(there, here, strict=True):
        np.testing.assert_array_equal(a.lift, b.lift)
        np.testing.assert_array_equal(a.moment, b.moment)
    assert there[0].lift.mean() != there[1].lift.mean()   # in the jobs' order (different angles)
    assert {line.split(":")[0] for line in lines} >= {"angle 2", "angle -1", "angle 0"}   # progress came back
    assert all(path.is_file() for _, path, _ in jobs)   # the workers wrote the checkpoints


@pytest.mark.slow
@pytest.mark.parametrize("cluster", [1], indirect=True)
def test_an_interrupted_cluster_run_leaves_no_case_running_on_the_workers(cluster):
    """Dask cannot kill a running task: the case itself must stop once the caller is interrupted (Ctrl-C
    here, at the case's first progress line).  The cluster has one worker thread, so a task submitted after
    the interrupt runs only once the case has let that thread go; the case alone would run nine times as
    long again as it took to its first line."""
    from distributed import Client

    shape = [FlatPlate(1.0, 0.05).polygon()]
    q = preset("tiny", "single").with_(periods=20)   # its first progress line comes a tenth of the way in

    def ctrl_c(line: str) -> None:
        if "t = " in line:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        run_cases(shape, [(ForcedCase.thesis("heave", 0.2), None, "heave")], q, progress=ctrl_c,
                  scheduler=cluster.scheduler_address)
    with Client(cluster.scheduler_address) as client:
        assert client.submit(lambda: 42, pure=False).result(timeout=20) == 42
