"""Batches of ElasticPaint jobs on a Dask cluster.

    python3 -m elastic.batch JOBS... [--scheduler ADDRESS] [--workers N] [--out DIR]

Every job file is an ordinary job of the ``elastic`` tool (``--job FILE``; a report's
``job`` works too): its ``command`` key says which subcommand runs it. Without
``--scheduler`` a ``distributed.LocalCluster`` of ``--workers`` processes is started on
127.0.0.1; with an address the jobs go to that scheduler (its workers need the
``elastic`` tool and the job's input files at the same paths).

Each job runs ``elastic COMMAND --job FILE -q`` on a worker. With ``--out DIR`` its files
go to ``DIR/NAME/`` (NAME: the job file's stem): the report always, and the job's own
``out``/``heatmap`` folders under the same names. One bad job never stops the batch: its
verdict (exit code, the tool's one-line message, report path, seconds) goes into
``DIR/summary.json`` and ``DIR/summary.md``. A worker that dies mid-job has the job run
again elsewhere (Dask reschedules it; at most ``--retries`` times); the tool writes its
outputs atomically, so a job run twice never leaves a half file. The tool of a dead worker
dies with it (PR_SET_PDEATHSIG).

Exit status: 0 when every job succeeded, 1 when one failed, 2 for a usage error.
"""

from __future__ import annotations

import argparse
import ctypes
import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path
from typing import Any, Callable, Optional

# Folder flags of the tool's subcommands that a batch redirects into the job's own folder.
_FOLDER_FLAGS = ("out", "heatmap")
# Subcommands that take --threads.
_THREADED = ("map", "paste", "compare", "render", "region")


def find_tool() -> str:
    """The ``elastic`` executable: $ELASTIC_TOOL, the one this package was built or installed
    with, or the first on PATH."""
    candidates = [os.environ.get("ELASTIC_TOOL", "")]
    try:
        from ._tool import TOOL  # written by CMake

        candidates.append(TOOL)
    except ImportError:
        pass
    candidates.append(shutil.which("elastic") or "")
    for candidate in candidates:
        if candidate and os.access(candidate, os.X_OK):
            return candidate
    raise FileNotFoundError("elastic.batch: no elastic tool found (set ELASTIC_TOOL)")


class JobFileError(ValueError):
    """A job file the batch cannot run; `exit` is the tool's exit code for the same mistake
    (docs/cli.md): 66 unreadable, 65 not JSON, 64 no command."""

    def __init__(self, message: str, exit_code: int):
        super().__init__(message)
        self.exit = exit_code


def read_job(path: str) -> dict:
    """The job object of a job file or of a report (its ``job``). Raises JobFileError naming the
    file when it cannot be read or is not a JSON object with a ``command``."""
    try:
        with open(path, encoding="utf-8") as f:
            data = json.load(f)
    except OSError as e:
        raise JobFileError(f"{path}: cannot read the job file ({e.strerror})", 66) from None
    except (json.JSONDecodeError, UnicodeDecodeError) as e:
        raise JobFileError(f"{path}: the job file is not JSON ({e})", 65) from None
    if isinstance(data, dict) and isinstance(data.get("job"), dict):
        data = data["job"]
    if not isinstance(data, dict) or not isinstance(data.get("command"), str):
        raise JobFileError(f"{path}: a job file is a JSON object with a \"command\"", 64)
    return data


def _die_with_parent() -> None:
    # Linux: the tool gets SIGKILL when the worker that started it dies.
    try:
        libc = ctypes.CDLL("libc.so.6", use_errno=True)
        libc.prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG
    except OSError:
        pass


def run_job(path: str, out: Optional[str], tool: str, threads: int = 1) -> dict:
    """Runs one job with the tool and returns its verdict (runs on a Dask worker)."""
    start = time.monotonic()
    name = Path(path).stem
    verdict: dict[str, Any] = {
        "job": path,
        "name": name,
        "command": None,
        "exit": None,
        "ok": False,
        "message": "",
        "report": None,
        "seconds": 0.0,
        "host": socket.gethostname(),
    }
    try:
        job = read_job(path)
    except JobFileError as e:
        verdict.update(exit=e.exit, message=str(e), seconds=time.monotonic() - start)
        return verdict
    command = job["command"]
    verdict["command"] = command
    argv = [tool, command, "--job", path, "-q"]
    if command in _THREADED:
        argv += ["--threads", str(threads)]
    report = job.get("report") or None
    if out is not None:
        folder = Path(out) / name
        folder.mkdir(parents=True, exist_ok=True)
        report = str(folder / "report.json")
        for flag in _FOLDER_FLAGS:
            if job.get(flag):
                argv += [f"--{flag}", str(folder / Path(str(job[flag])).name)]
    if report is not None and command != "version":
        argv += ["--report", report]
    # Dask's nanny gives its workers MALLOC_TRIM_THRESHOLD_=65536 (for Python's heap); inherited,
    # it makes the tool give memory back and fault it in again all the time (a paste took 6 s
    # instead of 3.9 s). The tool runs with the malloc defaults.
    env = {k: v for k, v in os.environ.items() if k != "MALLOC_TRIM_THRESHOLD_"}
    process = subprocess.run(argv, capture_output=True, text=True, env=env,
                             preexec_fn=_die_with_parent)
    lines = [line for line in process.stderr.splitlines() if line.strip()]
    verdict.update(
        exit=process.returncode,
        ok=process.returncode == 0,
        message=lines[-1] if lines else "",
        report=report if report and os.path.exists(report) else None,
        seconds=time.monotonic() - start,
    )
    return verdict


def run_batch(
    jobs: list[str],
    client: Any,
    out: Optional[str] = None,
    retries: int = 2,
    threads: int = 1,
    on_done: Optional[Callable[[dict], None]] = None,
) -> dict:
    """Runs every job on the Dask `client`'s workers; returns the summary (see write_summary).
    A job whose task fails for good (its workers died more than `retries` times) gets exit
    None and the scheduler's message."""
    from distributed import as_completed

    tool = find_tool()
    start = time.monotonic()
    jobs = [os.path.abspath(j) for j in jobs]
    futures = {}
    for i, job in enumerate(jobs):
        future = client.submit(
            run_job,
            job,
            os.path.abspath(out) if out else None,
            tool,
            threads,
            key=f"elastic-job-{i}-{Path(job).stem}",
            retries=retries,
            pure=False,
        )
        futures[future] = job
    verdicts = {}
    for future in as_completed(list(futures)):
        job = futures[future]
        try:
            verdict = future.result()
        except Exception as e:  # noqa: BLE001: a task that failed for good (KilledWorker, ...)
            verdict = {
                "job": job,
                "name": Path(job).stem,
                "command": None,
                "exit": None,
                "ok": False,
                "message": f"{type(e).__name__}: {e}",
                "report": None,
                "seconds": 0.0,
            }
        verdicts[job] = verdict
        if on_done is not None:
            on_done(verdict)
    ordered = [verdicts[j] for j in jobs]
    info = client.scheduler_info()
    return {
        "jobs": ordered,
        "total": len(ordered),
        "ok": sum(1 for v in ordered if v["ok"]),
        "failed": sum(1 for v in ordered if not v["ok"]),
        "seconds": time.monotonic() - start,
        "scheduler": info.get("address"),
        "workers": len(info.get("workers", {})),
    }


def summary_markdown(summary: dict) -> str:
    """The summary as a Markdown table, one row per job."""
    lines = [
        f"{summary['ok']} of {summary['total']} jobs succeeded in {summary['seconds']:.1f} s "
        f"on {summary['workers']} workers.",
        "",
        "| job | command | exit | seconds | message | report |",
        "|---|---|---:|---:|---|---|",
    ]
    for v in summary["jobs"]:
        message = (v["message"] or "").replace("|", "\\|")
        exit_code = "" if v["exit"] is None else str(v["exit"])
        lines.append(
            f"| {v['name']} | {v['command'] or ''} | {exit_code} | {v['seconds']:.2f} "
            f"| {message} | {v['report'] or ''} |"
        )
    return "\n".join(lines) + "\n"


def _write_atomically(path: Path, text: str) -> None:
    tmp = path.with_name(f".{path.name}.tmp.{os.getpid()}")
    tmp.write_text(text, encoding="utf-8")
    os.replace(tmp, path)


def write_summary(summary: dict, folder: str) -> tuple[Path, Path]:
    """Writes summary.json and summary.md into `folder` (atomically)."""
    root = Path(folder)
    root.mkdir(parents=True, exist_ok=True)
    json_path, md_path = root / "summary.json", root / "summary.md"
    _write_atomically(json_path, json.dumps(summary, indent=2) + "\n")
    _write_atomically(md_path, summary_markdown(summary))
    return json_path, md_path


def main(argv: Optional[list[str]] = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python3 -m elastic.batch",
        description="Run many elastic jobs on a Dask cluster (a local one by default).",
    )
    parser.add_argument("jobs", nargs="+", help="job files (or reports) of the elastic tool")
    parser.add_argument("--scheduler", help="address of a Dask scheduler (default: a LocalCluster)")
    parser.add_argument("--workers", type=int, default=os.cpu_count() or 1,
                        help="worker processes of the local cluster (default: the cores)")
    parser.add_argument("--out", default="elastic-batch",
                        help="folder for each job's files and the summary (default: elastic-batch)")
    parser.add_argument("--retries", type=int, default=2,
                        help="times a job is run again after its worker died (default 2)")
    parser.add_argument("--threads", type=int, default=1, help="threads per job (default 1)")
    parser.add_argument("-q", "--quiet", action="store_true", help="no line per finished job")
    args = parser.parse_args(argv)
    if args.workers < 1 or args.retries < 0 or args.threads < 1:
        parser.error("--workers and --threads must be at least 1, --retries at least 0")

    import dask
    from distributed import Client, LocalCluster

    # A worker that dies mid-job: the scheduler runs its task elsewhere, at most `retries` times.
    dask.config.set({"distributed.scheduler.allowed-failures": args.retries})
    cluster = None
    if args.scheduler:
        client = Client(args.scheduler)
    else:
        cluster = LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True,
                               host="127.0.0.1", dashboard_address=None)
        client = Client(cluster)

    def report(verdict: dict) -> None:
        if not args.quiet:
            state = "ok" if verdict["ok"] else f"FAILED (exit {verdict['exit']})"
            print(f"{verdict['name']}: {state} in {verdict['seconds']:.1f} s"
                  + (f": {verdict['message']}" if not verdict["ok"] else ""), flush=True)

    try:
        summary = run_batch(args.jobs, client, args.out, args.retries, args.threads, report)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    json_path, md_path = write_summary(summary, args.out)
    print(f"{summary['ok']} of {summary['total']} jobs succeeded; summary: {json_path}, {md_path}")
    return 0 if summary["failed"] == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
