"""Many CAD files checked at once: in this process, or mapped over a Dask distributed cluster.

    import seam.batch
    files = seam.batch.find_files("../shared/data")          # a directory (recursive) or a glob
    rows = seam.batch.check_files(files)                      # here, one file after another
    from distributed import Client, LocalCluster
    with LocalCluster(n_workers=2, threads_per_worker=1) as cluster, Client(cluster) as client:
        rows = seam.batch.check_files(files, client=client)   # the same rows, computed on the workers

Each row is the per-file summary of `seam batch --json` (same keys): file, status ("ok", "problem": some seam is a
gap or a kink, or failed to be analysed (a degenerate edge), or below `require`; "error": unreadable or invalid, with
the message in "error"), seams, the verdict counts, "failed" (seams whose analysis failed), "warnings" (the reader's:
entities lost, roots not transferred; a partly read file is never "ok" without them), the worst gap and angle,
seconds. A bad file gives an "error" row; it never stops the batch.

On a cluster, every worker must import the same seam module (build/python on its path) and see the files under the
same path. OpenCASCADE's readers keep global state, so a worker reads one STEP/IGES file at a time (the module
serialises them); use threads_per_worker=1 and one worker process per core.
"""
from __future__ import annotations

import glob
import os
import time
import warnings

#: The extensions `seam batch` and find_files pick up (any case).
EXTENSIONS = (".json", ".bpt", ".step", ".stp", ".iges", ".igs")

#: The verdicts that make a file a "problem" (docs/check-output.md): gaps and kinks; creases are by design.
PROBLEM_VERDICTS = ("gap", "kink")


def find_files(where: str) -> list[str]:
    """The model files of a directory (recursively) or of a glob pattern, sorted. Raises ValueError when nothing
    matches (a typo should not look like an empty, successful batch)."""
    if os.path.isdir(where):
        found = [os.path.join(root, name) for root, _, names in os.walk(where) for name in names]
    else:
        found = glob.glob(where, recursive=True)
    named = [f for f in found if os.path.splitext(f)[1].lower() in EXTENSIONS]
    for f in named:
        if not os.path.isfile(f) and not os.path.isdir(f):  # a FIFO, a device, a dangling link: said, not checked
            warnings.warn(f"{f}: skipped: not a regular file (a FIFO, a device or a dangling symbolic link)",
                          stacklevel=2)
    files = sorted(f for f in named if os.path.isfile(f))
    if not files:
        raise ValueError(f"{where}: no .json/.bpt/.step/.stp/.iges/.igs files")
    return files


def summarize(path: str, result: dict, seconds: float, require: str | None = None) -> dict:
    """The per-file row of a check dict (seam.check's result)."""
    summary = result.get("summary", {})
    verdicts = summary.get("verdicts", {})
    worst_gap = summary.get("worst_gap") or {}
    worst_kink = summary.get("worst_kink") or {}
    below = summary.get("below_required", 0) if require else 0
    failed = summary.get("failed", 0)  # seams whose analysis failed (a degenerate edge): a problem
    problem = any(verdicts.get(v, 0) > 0 for v in PROBLEM_VERDICTS) or bool(below) or failed > 0
    row = {"file": path, "status": "problem" if problem else "ok", "error": None,
           "seams": summary.get("seams", 0)}
    for v in ("gap", "kink", "crease", "G1", "G2", "undetermined"):
        row[v] = verdicts.get(v, 0)
    row["failed"] = failed
    row["below_required"] = below
    row["warnings"] = list(result.get("warnings") or [])  # the reader's: a partly read file is never a bare "ok"
    row["worst_gap"] = worst_gap.get("gap")
    row["worst_angle_deg"] = worst_kink.get("angle_deg")
    row["length_unit"] = (result.get("units") or {}).get("length")
    row["gap_tolerance"] = (result.get("tolerances") or {}).get("distance")
    row["seconds"] = seconds
    return row


def error_row(path: str, message: str, seconds: float = 0.0) -> dict:
    """The row of a file that could not be checked."""
    return {"file": path, "status": "error", "error": message, "seams": 0, "gap": 0, "kink": 0, "crease": 0, "G1": 0,
            "G2": 0, "undetermined": 0, "failed": 0, "below_required": 0, "warnings": [], "worst_gap": None,
            "worst_angle_deg": None, "length_unit": None, "gap_tolerance": None, "seconds": seconds}


def check_file(path: str, **options) -> dict:
    """One file's row; never raises for a bad file (status "error" and the message instead)."""
    from . import check  # imported here so that a Dask worker unpickling this function imports the module itself

    start = time.perf_counter()
    try:
        result = check(path, **options)  # options may hold timeout= (a child process per file)
    except (ValueError, OSError, RuntimeError) as e:
        return error_row(path, str(e), time.perf_counter() - start)
    return summarize(path, result, time.perf_counter() - start, options.get("require"))


def check_files(paths, client=None, function=None, **options) -> list[dict]:
    """Rows of check_file for every path, in the order given. With a distributed.Client the files are mapped over
    its workers (one task per file); without one they are checked here, one after another. `options` are
    seam.check's keyword options (tol_distance, require, timeout, ...): with timeout=SECONDS each file is checked
    in a process of its own and a file past the limit gets an error row (a corrupt file cannot hold up a worker
    for minutes inside OpenCASCADE). `function` replaces check_file (same arguments, same
    row), e.g. to add columns. A task that fails on a worker (a worker killed by a crash in a reader gives
    distributed's KilledWorker) becomes that file's error row: the batch goes on."""
    paths = [os.fspath(p) for p in paths]
    function = function or check_file
    if client is None:
        return [function(p, **options) for p in paths]
    futures = client.map(function, paths, pure=False, **options)
    rows = []
    for path, future in zip(paths, futures):
        try:
            rows.append(future.result())
        except Exception as e:  # noqa: BLE001 - any failure of one task is that file's error, never the batch's
            rows.append(error_row(path, f"{type(e).__name__}: {e}"))
    return rows


def exit_code(rows) -> int:
    """The CLI's rule (seam check and seam batch): 2 when some file could not be read, else 1 when some file has a
    seam below the required class (rows made with require=...), else 0. Gaps and kinks alone do not make it 1."""
    if any(r["status"] == "error" for r in rows):
        return 2
    return 1 if any(r.get("below_required", 0) > 0 for r in rows) else 0
