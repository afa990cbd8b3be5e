"""The batch runner on a LocalCluster of two workers on 127.0.0.1: good and bad jobs reported
exactly, and a worker killed mid-batch does not lose a job."""

import json
import os
import signal
import threading
import time

import pytest

from conftest import MESHES, run_tool

distributed = pytest.importorskip("distributed")
from elastic import batch  # noqa: E402


def map_job(path, particles=600, target="hemisphere.off", **extra):
    job = {
        "command": "map",
        "source": str(MESHES / "grid.off"),
        "source-region": "disk:0.5,0.5,0,0.45",
        "target": str(MESHES / target),
        "target-region": "boundary",
        "particles": particles,
        **extra,
    }
    path.write_text(json.dumps(job))
    return str(path)


@pytest.fixture(scope="module")
def client():
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                       host="127.0.0.1", dashboard_address=None)
    with distributed.Client(cluster) as c:
        yield c
    cluster.close()


def test_six_jobs_with_a_malformed_one_and_a_missing_mesh(client, tmp_path):
    jobs = [map_job(tmp_path / f"good{i}.json", particles=400 + 100 * i) for i in range(3)]
    paste = tmp_path / "paste.json"
    paste.write_text(json.dumps({
        "command": "paste", "source-image": str(MESHES / "pmp_logo_512.png"),
        "source-region": "ellipse", "target": str(MESHES / "hemisphere.off"),
        "particles": 500, "out": str(tmp_path / "ignored"),
    }))
    jobs.append(str(paste))
    malformed = tmp_path / "malformed.json"
    malformed.write_text('{"command": "map", "particles": ')
    jobs.append(str(malformed))
    jobs.append(map_job(tmp_path / "missing.json", target="no-such-mesh.obj"))
    out = tmp_path / "out"
    summary = batch.run_batch(jobs, client, str(out), retries=1)
    by_name = {v["name"]: v for v in summary["jobs"]}
    assert [v["name"] for v in summary["jobs"]] == [os.path.splitext(os.path.basename(j))[0] for j in jobs]
    assert summary["total"] == 6 and summary["ok"] == 4 and summary["failed"] == 2
    for name in ("good0", "good1", "good2", "paste"):
        v = by_name[name]
        assert v["ok"] and v["exit"] == 0, v
        report = json.loads(open(v["report"]).read())
        assert report["folds"] == 0 and report["converged"]
    assert (out / "paste" / "ignored" / "painted.obj").exists()  # the job's out, redirected
    assert not (tmp_path / "ignored").exists()
    assert by_name["malformed"]["exit"] == 65 and "not JSON" in by_name["malformed"]["message"]
    missing = by_name["missing"]
    # The tool's own verdict on the job, as it would print it alone.
    alone = run_tool("map", "--job", jobs[-1], check=False)
    assert missing["exit"] == alone.returncode == 66
    assert missing["message"] == alone.stderr.strip().splitlines()[-1]
    assert "no-such-mesh.obj" in missing["message"]
    json_path, md_path = batch.write_summary(summary, str(out))
    assert json.loads(json_path.read_text())["ok"] == 4
    table = md_path.read_text()
    assert "| missing | map | 66 |" in table and "4 of 6 jobs succeeded" in table


def test_a_worker_killed_mid_batch_loses_no_job(client, tmp_path):
    jobs = [map_job(tmp_path / f"slow{i}.json", particles=25000) for i in range(4)]
    pids = client.run(os.getpid)  # worker address -> pid
    killed = []

    def kill_a_busy_worker():
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline:
            busy = [w for w, tasks in client.processing().items() if tasks]
            if busy:
                time.sleep(0.5)  # let the job start its tool
                os.kill(pids[busy[0]], signal.SIGKILL)
                killed.append(busy[0])
                return
            time.sleep(0.05)

    killer = threading.Thread(target=kill_a_busy_worker)
    killer.start()
    summary = batch.run_batch(jobs, client, str(tmp_path / "out"), retries=2)
    killer.join()
    assert killed, "no worker was busy"
    assert summary["ok"] == 4, summary
    for v in summary["jobs"]:
        report = json.loads(open(v["report"]).read())
        assert report["particles"] > 0 and report["folds"] == 0


def test_command_line_usage_error():
    with pytest.raises(SystemExit) as e:
        batch.main(["--workers", "0", "job.json"])
    assert e.value.code == 2


def test_the_command_line_runs_on_a_scheduler_by_address(tmp_path):
    job = map_job(tmp_path / "one.json", particles=400)
    bad = tmp_path / "bad.json"
    bad.write_text("[]")
    out = tmp_path / "out"
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True,
                                  host="127.0.0.1", dashboard_address=None) as cluster:
        code = batch.main([job, str(bad), "--scheduler", cluster.scheduler_address,
                           "--out", str(out), "-q"])
    assert code == 1  # one job failed
    summary = json.loads((out / "summary.json").read_text())
    assert summary["ok"] == 1 and summary["jobs"][1]["exit"] == 64
    assert summary["scheduler"] == cluster.scheduler_address
