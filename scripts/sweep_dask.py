"""A `plumb sweep` study on a dask.distributed cluster (scripts/sweep-dask is its command).

The study is cut into T shards, exactly as `plumb sweep --shard K/T` cuts it (the points whose
index is K-1 modulo T). Each shard is one Dask task: on its worker it runs the native code, the
plumb executable (`plumb sweep STUDY --shard K/T --out <worker temp dir>`), and returns the
shard's files as bytes, so the workers need not share a filesystem with the client. The client
writes them as shard folders and joins them with `plumb sweep merge`, the CLI's own merge, into
a temporary folder beside DIR that is renamed to DIR at the end: DIR is complete or absent, and
an existing DIR (or any input) is never written to. The runs are seeded from the study (its
seed, the point, the run), so the result is the single-process `plumb sweep STUDY --out DIR`'s,
byte for byte, whatever the number of tasks and workers (tests/cluster/dask_test.py checks it).

From Python (the client's Python needs Debian's python3-distributed; the workers too):

    import sys; sys.path.insert(0, "scripts")
    from dask.distributed import Client
    from sweep_dask import run_study
    with Client("tcp://scheduler:8786") as client:
        run_study(client, "examples/studies/poses.json", "out/poses", tasks=16)

The workers need the plumb executable at the path given (`plumb`, default: this checkout's
build/apps/plumb/plumb, else `plumb` on the PATH), and the same build as the client's, whose
plumb does the merge: a shard run by another version is refused.
"""

import argparse
import hashlib
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import uuid
from pathlib import Path

try:
    import cloudpickle
    from distributed import Client, LocalCluster, as_completed, get_worker
except ImportError as error:  # Debian's python3-distributed, for /usr/bin/python3
    Client = None
    _IMPORT_ERROR = error
else:
    _IMPORT_ERROR = None

_REPO = Path(__file__).resolve().parent.parent


class SweepError(Exception):
    """A failed study: the message names the shard, the worker and plumb's own error."""

    def __init__(self, message, exit_code=1):
        super().__init__(message)
        self.exit_code = exit_code  # as the CLI's: 1 bad input or a failed run, 2 usage


def default_plumb():
    """This checkout's build/apps/plumb/plumb when built, else `plumb` on the PATH, else None."""
    built = _REPO / "build" / "apps" / "plumb" / "plumb"
    if built.is_file() and os.access(built, os.X_OK):
        return str(built)
    return shutil.which("plumb")


def study_files(study):
    """The files a worker needs to run `study`: {relative path: bytes}, and the study's path in it.

    The study file itself, under its own name (its extension says JSON or YAML), and a session
    template (`base.template`) given relative to the study file, at the same relative place, so
    that the worker's plumb reads the same study document. An absolute template path is left to
    the workers' filesystem.
    """
    path = Path(study)
    try:
        data = path.read_bytes()
    except OSError as error:
        raise SweepError(f"{study}: cannot be read ({error.strerror})") from None
    files = {path.name: data}
    template = _template_of(path, data)
    if template and not Path(template).is_absolute():
        rel = Path(os.path.normpath(template))
        if rel.parts and rel.parts[0] == "..":
            raise SweepError(f"{study}: base.template '{template}' is outside the study's folder; "
                             "give it an absolute path on the workers' shared filesystem")
        source = path.parent / rel
        try:
            files[str(rel)] = source.read_bytes()
        except OSError as error:
            raise SweepError(f"{source}: the study's base.template cannot be read "
                             f"({error.strerror})") from None
    return files, path.name


def _template_of(path, data):
    """The study's base.template, or None (plumb itself says what is wrong with a bad study)."""
    try:
        if path.suffix in (".yaml", ".yml"):
            import yaml  # python3-yaml, part of scripts/setup
            document = yaml.safe_load(data)
        else:
            document = json.loads(data)
        template = document.get("base", {}).get("template")
    except Exception:  # not valid: left to plumb's message
        return None
    return template if isinstance(template, str) else None


def executable_digest(plumb):
    """(`plumb --version` output, sha256 of the executable) on this machine."""
    version = subprocess.run([plumb, "--version"], capture_output=True, text=True, timeout=60)
    if version.returncode != 0:
        raise SweepError(f"{plumb} --version failed: {version.stderr.strip()}")
    with open(plumb, "rb") as f:
        return version.stdout.strip(), hashlib.sha256(f.read()).hexdigest()


def run_shard(plumb, files, study_name, shard, tasks, jobs, origin):
    """One Dask task, on the worker: `plumb sweep` on shard `shard` of `tasks` in a temp folder.

    Returns a dict: shard, worker (its address), version and sha256 of its plumb, and either
    files ({path in the shard folder: bytes}) or error (plumb's exit code and stderr, the
    worker's copy of the study's folder written as `origin`, the client's).
    """
    try:
        worker = get_worker().address
    except ValueError:  # called outside a worker
        worker = "this process"
    result = {"shard": shard, "worker": worker, "version": None, "sha256": None}
    if not (os.path.isfile(plumb) and os.access(plumb, os.X_OK)):
        result["error"] = (None, f"no plumb executable at {plumb} on this worker (give the path "
                                 "on the workers with --plumb)")
        return result
    try:
        result["version"], result["sha256"] = executable_digest(plumb)
    except Exception as error:  # SweepError or OSError: said by the client
        result["error"] = (None, str(error))
        return result
    with tempfile.TemporaryDirectory(prefix=f"plumb-shard-{shard}-of-{tasks}-") as tmp:
        for rel, data in files.items():
            target = os.path.join(tmp, "study", rel)
            os.makedirs(os.path.dirname(target), exist_ok=True)
            with open(target, "wb") as f:
                f.write(data)
        out = os.path.join(tmp, "out")
        command = [plumb, "sweep", os.path.join(tmp, "study", study_name), "--out", out,
                   "--shard", f"{shard}/{tasks}", "--jobs", str(jobs)]
        run = subprocess.run(command, capture_output=True, text=True)
        if run.returncode != 0:
            here = os.path.join(tmp, "study") + os.sep
            result["error"] = (run.returncode, run.stderr.strip().replace(here, origin))
            return result
        result["files"] = {}
        for folder, _, names in os.walk(out):
            for name in names:
                path = os.path.join(folder, name)
                with open(path, "rb") as f:
                    result["files"][os.path.relpath(path, out)] = f.read()
    return result


def _write_shard(folder, files, shard, worker):
    """The files returned by a shard's task, under `folder` (relative paths inside it only)."""
    for rel, data in files.items():
        parts = Path(rel).parts
        if Path(rel).is_absolute() or ".." in parts or not parts:
            raise SweepError(f"shard {shard} from worker {worker}: refused file path '{rel}'")
        target = folder.joinpath(*parts)
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_bytes(data)


def run_study(client, study, out, tasks=None, plumb=None, jobs=1, log=print, worker_timeout=60):
    """Run the study file `study` on the Dask `client`'s cluster into the new folder `out`.

    tasks: shards, one Dask task each (default: every thread of the cluster's workers); a shard
    with no point is allowed. plumb: the executable's path on the workers and here (default
    default_plumb()). jobs: `--jobs` of each task's plumb (runs in parallel inside a task).
    log: called with each progress line. worker_timeout: seconds to wait for a first worker.
    Returns the `plumb sweep merge` output. Raises
    SweepError naming the shard, the worker and plumb's error; `out` is then not created.
    """
    plumb = plumb or default_plumb()
    if plumb and os.sep not in plumb:  # a name: this machine's PATH says which
        plumb = shutil.which(plumb)
    if not plumb:
        raise SweepError("no plumb executable: build it (build/apps/plumb/plumb) or give --plumb",
                         exit_code=2)
    plumb = os.path.abspath(plumb)  # the workers run it from other folders
    out = Path(out)
    if os.path.lexists(out):
        raise SweepError(f"{out}: exists; sweep-dask writes a new folder and never overwrites one")
    files, study_name = study_files(study)
    try:
        client.wait_for_workers(1, timeout=worker_timeout)
    except (TimeoutError, OSError):
        raise SweepError(f"no Dask worker joined the scheduler within {worker_timeout} s") from None
    if tasks is None:  # every thread of the workers
        tasks = sum(w["nthreads"] for w in client.scheduler_info()["workers"].values())
    if tasks < 1 or jobs < 1:
        raise SweepError(f"tasks ({tasks}) and jobs ({jobs}) must be at least 1", exit_code=2)
    version, digest = executable_digest(plumb)
    module = sys.modules[run_shard.__module__]
    if module.__name__ != "__main__":  # the workers need not have this file
        cloudpickle.register_pickle_by_value(module)
    token = uuid.uuid4().hex[:8]
    futures = client.map(run_shard, [plumb] * tasks, [files] * tasks, [study_name] * tasks,
                         range(1, tasks + 1), [tasks] * tasks, [jobs] * tasks,
                         [os.path.join(os.path.dirname(study), "")] * tasks,
                         key=[f"plumb-sweep-{token}-shard-{k}-of-{tasks}"
                              for k in range(1, tasks + 1)], pure=False)
    log(f"study {study}: {tasks} shards submitted to {len(client.scheduler_info()['workers'])} "
        f"workers")
    out.parent.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(prefix=f".{out.name}.sweep-dask-", dir=out.parent))
    try:
        _gather(futures, staging, tasks, version, digest, log)
        merged = staging / "merged"
        merge = subprocess.run([plumb, "sweep", "merge"] +
                               [str(staging / f"shard-{k}") for k in range(1, tasks + 1)] +
                               ["--out", str(merged)], capture_output=True, text=True)
        if merge.returncode != 0:
            raise SweepError(f"plumb sweep merge failed (exit {merge.returncode}): "
                             f"{merge.stderr.strip()}")
        if merge.stderr.strip():
            log(merge.stderr.strip())
        if os.path.lexists(out):
            raise SweepError(f"{out}: appeared while the study ran; left as it is")
        os.rename(merged, out)
    except BaseException:
        client.cancel(futures)
        raise
    finally:
        shutil.rmtree(staging, ignore_errors=True)
    return merge.stdout.strip().replace(str(merged), str(out))


def _gather(futures, staging, tasks, version, digest, log):
    """Each shard's files into staging/shard-K as its task ends; the first failure raises."""
    workers = set()
    for future in as_completed(futures):
        try:
            r = future.result()
        except Exception as error:  # the task could not run (a worker lost, ...)
            raise SweepError(f"a shard's task failed on the cluster ({future.key}): "
                             f"{type(error).__name__}: {error}") from None
        where = f"shard {r['shard']}/{tasks} on worker {r['worker']}"
        if "error" in r:
            code, stderr = r["error"]
            said = f"plumb exited {code}" if code is not None else "not run"
            raise SweepError(f"{where}: {said}: {stderr}", exit_code=1)
        if r["version"] != version:
            raise SweepError(f"{where}: its plumb is '{r['version']}', this machine's "
                             f"'{version}': shards must come from the same build")
        if r["sha256"] != digest:
            log(f"warning: {where}: its plumb executable differs from this machine's (sha256); "
                "the result equals a single run's only for the same build")
        workers.add(r["worker"])
        _write_shard(staging / f"shard-{r['shard']}", r["files"], r["shard"], r["worker"])
        points = sum(1 for rel in r["files"] if rel.startswith("points"))
        log(f"{where}: {points} point{'' if points == 1 else 's'}")
    log(f"{tasks} shards done on {len(workers)} workers")


def parse_args(argv):
    parser = argparse.ArgumentParser(
        prog="sweep-dask",
        description="Run a plumb sweep study on a dask.distributed cluster: one task per shard "
                    "(plumb sweep --shard K/T on a worker), joined by plumb sweep merge into a "
                    "new folder, the same files byte for byte as one plumb sweep.",
        epilog="Example: scripts/sweep-dask examples/studies/poses.json --out out/poses "
               "--local-workers 2")
    parser.add_argument("study", metavar="STUDY", help="the study file (JSON or YAML)")
    parser.add_argument("--out", required=True, metavar="DIR",
                        help="folder for the result (must not exist; written at the end, whole)")
    where = parser.add_mutually_exclusive_group(required=True)
    where.add_argument("--scheduler", metavar="ADDRESS",
                       help="a running Dask scheduler, e.g. tcp://head:8786")
    where.add_argument("--local-workers", type=int, metavar="N",
                       help="start a local cluster of N worker processes (one thread each)")
    parser.add_argument("--tasks", type=int, metavar="T",
                        help="shards, one task each (default: the workers' threads)")
    parser.add_argument("--plumb", metavar="PATH",
                        help="the plumb executable, the same path on the workers (default: "
                             "build/apps/plumb/plumb of this checkout, else plumb on the PATH)")
    parser.add_argument("--jobs-per-task", type=int, default=1, metavar="J",
                        help="runs in parallel inside each task (plumb sweep --jobs; default 1)")
    args = parser.parse_args(argv)
    for name in ("local_workers", "tasks", "jobs_per_task"):
        value = getattr(args, name)
        if value is not None and value < 1:
            parser.error(f"--{name.replace('_', '-')} must be at least 1, got {value}")
    return args


def main(argv=None):
    args = parse_args(sys.argv[1:] if argv is None else argv)
    if _IMPORT_ERROR is not None:
        print(f"sweep-dask: error: needs dask.distributed ({_IMPORT_ERROR}): install Debian's "
              "python3-distributed (scripts/setup) and run with /usr/bin/python3",
              file=sys.stderr)
        return 1
    log = lambda line: print(line, flush=True)
    # SIGTERM (timeout, kill) as an exit: the staging folder is removed, the cluster closed.
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(143))
    try:
        if args.local_workers:
            with LocalCluster(n_workers=args.local_workers, threads_per_worker=1,
                              processes=True, dashboard_address=None) as cluster, \
                    Client(cluster) as client:
                client.wait_for_workers(args.local_workers, timeout=120)
                said = run_study(client, args.study, args.out, args.tasks, args.plumb,
                                 args.jobs_per_task, log)
        else:
            with Client(args.scheduler, timeout=60) as client:
                said = run_study(client, args.study, args.out, args.tasks, args.plumb,
                                 args.jobs_per_task, log)
    except SweepError as error:
        print(f"sweep-dask: error: {error}", file=sys.stderr)
        return error.exit_code
    except OSError as error:  # e.g. no scheduler at the address
        print(f"sweep-dask: error: {error}", file=sys.stderr)
        return 1
    print(said.strip())
    return 0


if __name__ == "__main__":
    sys.exit(main())
