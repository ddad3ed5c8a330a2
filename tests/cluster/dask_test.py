#!/usr/bin/python3
"""A study on a real Dask cluster equals `plumb sweep` in one process, file for file, byte for byte.

tests/cluster/dask_test.py PLUMB REPO: starts a Dask scheduler and two worker processes (the
dask-scheduler and dask-worker commands of Debian's python3-distributed, one thread each, on
127.0.0.1, in their own working folders so that the workers cannot import the client's code),
then
  1. scripts/sweep-dask STUDY --scheduler ADDRESS --tasks 4: the result's files equal those of
     `plumb sweep STUDY --out DIR --jobs 1`, and both workers ran shards;
  2. run_study(client, ...) imported from scripts/sweep_dask.py, one task per point (6): equal;
  3. a study on a real session's template (mikoff's bundled imu0 calibrated), the template
     shipped to the workers with the study: equal;
  4. bad input: an existing --out (exit 1, left untouched), a study plumb refuses (exit 1, the
     message names the shard, its worker and plumb's error with the study file), usage (exit 2).
The study is fixed (its seed, 6 points of 4 runs: about a second of work). Every process is
started here and killed in a finally block (SIGTERM from a timeout included); every wait has
a timeout. Exit 0 passed, 1 failed, 77 skipped (dask.distributed missing) with the reason.
"""
import filecmp
import json
import os
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

STUDY = {
    "name": "cluster test: the paper's minute by the generalized method", "seed": 11,
    "runs": 4, "design": "grid",
    "base": {"schedule": "paper_static", "still_s": 20, "rate_hz": 100, "sensor": "typical",
             "random_truth": 1, "lat_deg": 6.67, "lon_deg": -1.57, "height_m": 250},
    "factors": [{"name": "still_s", "levels": [10, 20, 40]},
                {"name": "gyro_rw", "levels": [2e-6, 2e-5]}]}
TIMEOUT = 120  # seconds, for any one step


def files_of(folder):
    """Every file under `folder`: relative path -> bytes."""
    out = {}
    for root, _, names in os.walk(folder):
        for name in names:
            path = Path(root) / name
            out[str(path.relative_to(folder))] = path.read_bytes()
    return out


class Checks:
    def __init__(self):
        self.failed = 0

    def expect(self, condition, what, detail=""):
        print(("ok      " if condition else "FAILED  ") + what)
        if not condition:
            self.failed += 1
            if detail:
                print("        " + detail.replace("\n", "\n        "))
        return condition

    def same_files(self, got, want, what):
        a, b = files_of(got), files_of(want)
        differ = sorted(k for k in set(a) | set(b) if a.get(k) != b.get(k))
        return self.expect(bool(a) and not differ, f"{what}: {len(a)} files, each byte-equal",
                           f"missing or different: {differ[:10]}")


def start(command, cwd, log):
    """A process in its own session (its group killed at the end), output to `log`."""
    with open(log, "wb") as f:
        return subprocess.Popen(command, cwd=cwd, stdout=f, stderr=subprocess.STDOUT,
                                start_new_session=True)


def stop(processes):
    """The workers first, then the scheduler (the reverse of their start)."""
    processes = processes[::-1]
    for p in processes:
        if p.poll() is None:
            os.killpg(p.pid, signal.SIGTERM)
    for p in processes:
        try:
            p.wait(timeout=15)
        except subprocess.TimeoutExpired:
            os.killpg(p.pid, signal.SIGKILL)
            p.wait(timeout=15)


def scheduler_address(scheduler_file, scheduler):
    deadline = time.monotonic() + TIMEOUT
    while time.monotonic() < deadline:
        if scheduler.poll() is not None:
            raise RuntimeError(f"dask-scheduler exited {scheduler.returncode}")
        try:
            return json.loads(Path(scheduler_file).read_text())["address"]
        except (OSError, ValueError, KeyError):
            time.sleep(0.2)
    raise RuntimeError(f"dask-scheduler wrote no {scheduler_file} within {TIMEOUT} s")


def run(command, **kwargs):
    return subprocess.run(command, capture_output=True, text=True, timeout=TIMEOUT, **kwargs)


def main(plumb, repo):
    try:
        from distributed import Client
    except ImportError as error:
        print(f"skipped: dask.distributed is not importable by {sys.executable} ({error}); "
              "scripts/setup installs Debian's python3-distributed")
        return 77
    sweep_dask = [sys.executable, str(Path(repo) / "scripts" / "sweep-dask")]
    checks = Checks()
    processes = []
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(1))  # the finally block still runs
    with tempfile.TemporaryDirectory(prefix="plumb-dask-test-") as tmp:
        tmp = Path(tmp)
        study = tmp / "study.json"
        study.write_text(json.dumps(STUDY))
        single = run([plumb, "sweep", str(study), "--out", str(tmp / "single"), "--jobs", "1"])
        if not checks.expect(single.returncode == 0, "plumb sweep in one process", single.stderr):
            return 1
        try:
            for name in ("scheduler", "worker-1", "worker-2"):
                (tmp / name).mkdir()
            processes.append(start(["dask-scheduler", "--host", "127.0.0.1", "--port", "0",
                                    "--no-dashboard", "--scheduler-file", str(tmp / "sched.json")],
                                   tmp / "scheduler", tmp / "scheduler.log"))
            address = scheduler_address(tmp / "sched.json", processes[0])
            for name in ("worker-1", "worker-2"):
                processes.append(start(["dask-worker", address, "--nthreads", "1", "--no-nanny",
                                        "--no-dashboard", "--name", name, "--local-directory",
                                        str(tmp / name)], tmp / name, tmp / f"{name}.log"))
            with Client(address, timeout=TIMEOUT) as client:
                client.wait_for_workers(2, timeout=TIMEOUT)
                checks.expect(len(client.scheduler_info()["workers"]) == 2,
                              f"a scheduler at {address} and two worker processes")
                check_cli(checks, sweep_dask, plumb, address, study, tmp)
                check_function(checks, client, plumb, repo, study, tmp)
                check_template(checks, sweep_dask, plumb, repo, address, tmp)
                check_errors(checks, sweep_dask, plumb, address, study, tmp)
        finally:
            stop(processes)
            for log in ("scheduler.log", "worker-1.log", "worker-2.log"):
                if checks.failed and (tmp / log).is_file():
                    print(f"--- {log}\n" + (tmp / log).read_text(errors="replace")[-3000:])
        checks.expect(all(p.poll() is not None for p in processes), "every process stopped")
    print(f"{'FAILED' if checks.failed else 'passed'}: {checks.failed} checks failed")
    return 1 if checks.failed else 0


def check_cli(checks, sweep_dask, plumb, address, study, tmp):
    r = run(sweep_dask + [str(study), "--out", str(tmp / "dist"), "--scheduler", address,
                          "--tasks", "4", "--plumb", plumb])
    if checks.expect(r.returncode == 0, "scripts/sweep-dask --tasks 4 exits 0", r.stdout + r.stderr):
        checks.same_files(tmp / "dist", tmp / "single", "its result against plumb sweep's")
        checks.expect("4 shards done on 2 workers" in r.stdout, "both workers ran shards", r.stdout)
        checks.expect(not [p for p in tmp.iterdir() if p.name.startswith(".dist.")],
                      "no staging folder left")


def check_function(checks, client, plumb, repo, study, tmp):
    sys.dont_write_bytecode = True  # no __pycache__ in the source tree
    sys.path.insert(0, str(Path(repo) / "scripts"))
    from sweep_dask import run_study
    lines = []
    said = run_study(client, str(study), str(tmp / "function"), tasks=6, plumb=plumb,
                     log=lines.append)
    checks.expect("merged 6 points from 6 folders" in said, "run_study, one task per point", said)
    checks.same_files(tmp / "function", tmp / "single", "run_study's result against plumb sweep's")


def check_template(checks, sweep_dask, plumb, repo, address, tmp):
    """A study whose base is a real session (a calibrate --json file beside the study): the
    workers, in folders of their own, get the template with the study."""
    folder = tmp / "template"
    folder.mkdir()
    r = run([plumb, "calibrate", str(Path(repo) / "data" / "mikoff" / "imu0.log"), "--columns",
             "ax,ay,az,gx,gy,gz", "--rate", "100", "--json", str(folder / "imu0.json")])
    if not checks.expect(r.returncode == 0, "the bundled session calibrated", r.stderr):
        return
    (folder / "s.json").write_text(json.dumps({
        "seed": 5, "runs": 2, "design": "grid",
        "base": {"schedule": "session", "template": "imu0.json", "rate_hz": 100},
        "factors": [{"name": "gyro_noise", "levels": [7e-5, 2e-4]}]}))
    single = run([plumb, "sweep", str(folder / "s.json"), "--out", str(tmp / "tsingle"),
                  "--jobs", "1"])
    r = run(sweep_dask + [str(folder / "s.json"), "--out", str(tmp / "tdist"), "--scheduler",
                          address, "--tasks", "2", "--plumb", plumb])
    if checks.expect(single.returncode == 0 and r.returncode == 0,
                     "a session-template study, in one process and on Dask",
                     single.stderr + r.stdout + r.stderr):
        checks.same_files(tmp / "tdist", tmp / "tsingle", "its result against plumb sweep's")


def check_errors(checks, sweep_dask, plumb, address, study, tmp):
    (tmp / "taken").mkdir()
    (tmp / "taken" / "mine.txt").write_text("keep")
    r = run(sweep_dask + [str(study), "--out", str(tmp / "taken"), "--scheduler", address,
                          "--plumb", plumb])
    checks.expect(r.returncode == 1 and "exists" in r.stderr and
                  files_of(tmp / "taken") == {"mine.txt": b"keep"},
                  "an existing --out: exit 1, left as it was", r.stderr)
    bad = tmp / "bad.json"
    bad.write_text(json.dumps(dict(STUDY, factors=[{"name": "pose", "levels": [3]}])))
    r = run(sweep_dask + [str(bad), "--out", str(tmp / "bad"), "--scheduler", address,
                          "--tasks", "2", "--plumb", plumb])
    checks.expect(r.returncode == 1 and "/2 on worker tcp://127.0.0.1:" in r.stderr and
                  "plumb exited 1" in r.stderr and "bad.json" in r.stderr and
                  not (tmp / "bad").exists(),
                  "a study plumb refuses: exit 1 naming the shard, its worker and plumb's error",
                  r.stderr)
    r = run(sweep_dask + [str(study), "--out", str(tmp / "x")])
    checks.expect(r.returncode == 2 and "--scheduler" in r.stderr,
                  "neither --scheduler nor --local-workers: usage, exit 2", r.stderr)


if __name__ == "__main__":
    if len(sys.argv) != 3:
        print("usage: dask_test.py PLUMB REPO", file=sys.stderr)
        sys.exit(2)
    sys.exit(main(os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])))
