"""`seam batch` (child processes) and seam.batch (in process, and on a Dask LocalCluster of 2 workers) over the same
files: the rows agree with each other and with `seam check --json` of each file; bad files give error rows and the
exit code 2 without stopping the batch."""
import glob
import json
import os
import subprocess
import sys

import pytest

import seam
import seam.batch

ROW_KEYS = ["file", "status", "error", "seams", "gap", "kink", "crease", "G1", "G2", "undetermined", "failed",
            "below_required", "warnings", "worst_gap", "worst_angle_deg", "length_unit", "gap_tolerance", "seconds"]


def small_files(shared_data):
    """The quick files of ../shared/data (the tea set, the fuselage, two IGES parts): the whole directory takes
    about a minute on one core (docs/performance.md), more than the test budget."""
    names = ["bezier/teapot.bpt", "bezier/teacup.bpt", "bezier/teaspoon.bpt"]
    if seam.has_occt:
        names += ["step/bug28366_fuselage.stp", "iges/BUC50025.igs"]
    return [os.path.join(shared_data, n) for n in names]


def comparable(row):
    return {k: v for k, v in row.items() if k != "seconds"}


@pytest.fixture(scope="module")
def batch_dir(tmp_path_factory, shared_data, examples):
    """The small files plus one unreadable file and one valid JSON model, linked into one directory."""
    d = tmp_path_factory.mktemp("batch")
    for f in small_files(shared_data) + [os.path.join(examples, "models", "two_patches.json")]:
        os.symlink(os.path.abspath(f), d / os.path.basename(f))
    (d / "broken.step").write_text("ISO-10303-21;\nthis is not STEP\n")
    (d / "notes.txt").write_text("not a model: ignored")
    return d


def test_cli_batch_rows_match_single_checks(cli, run_cli, batch_dir):
    p = subprocess.run([cli, "batch", str(batch_dir), "--json", "-j", "2"], capture_output=True, text=True,
                       timeout=300)
    assert p.returncode == 2, p.stderr  # broken.step is unreadable
    out = json.loads(p.stdout)
    rows = {os.path.basename(r["file"]): r for r in out["files"]}
    assert "notes.txt" not in rows and len(rows) == len(os.listdir(batch_dir)) - 1
    assert rows["broken.step"]["status"] == "error" and "broken.step" in rows["broken.step"]["error"]
    assert out["summary"]["error"] == 1 and out["summary"]["files"] == len(rows)
    for name, row in rows.items():
        assert list(row.keys()) == ROW_KEYS
        if name == "broken.step":
            continue
        code, single, err = run_cli("check", row["file"], "--json")
        assert code == 0, err
        v = single["summary"]["verdicts"]
        keys = ("gap", "kink", "crease", "G1", "G2", "undetermined")
        assert [row[k] for k in keys] == [v[k] for k in keys]
        assert row["seams"] == single["summary"]["seams"]
        assert row["status"] == ("problem" if v["gap"] + v["kink"] > 0 else "ok")
    # One line per file on stderr, as each finishes.
    assert sum(1 for line in p.stderr.splitlines() if line.startswith("[")) == len(rows)


def test_cli_batch_exit_codes(cli, tmp_path, examples):
    good = os.path.join(examples, "models", "two_patches.json")
    p = subprocess.run([cli, "batch", good], capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, p.stderr
    assert "two_patches.json" in p.stdout and "1 files: 1 ok" in p.stdout
    p = subprocess.run([cli, "batch", str(tmp_path / "nothing*.step")], capture_output=True, text=True, timeout=60)
    assert p.returncode == 2 and "no .json/.bpt" in p.stderr
    p = subprocess.run([cli, "batch", good, "--timeout", "-1"], capture_output=True, text=True, timeout=60)
    assert p.returncode == 2 and "--timeout" in p.stderr


@pytest.mark.parametrize("units", [None, "in"])
def test_cli_batch_table_names_each_gap_tolerance(cli, run_cli, shared_data, examples, units):
    """The combined table has a "gap tolerance" column: each file's distance tolerance with its unit, as the
    file's own `seam check --json` resolves it (tolerances.distance, units.length; the number alone when unit-less);
    the --json rows carry the same in gap_tolerance and length_unit."""
    files = [os.path.join(examples, "models", "two_patches.json")]
    if seam.has_occt:
        files.append(os.path.join(shared_data, "step", "bug28366_fuselage.stp"))
    flags = ["--units", units] if units else []
    p = subprocess.run([cli, "batch", *files, "-j", "1", *flags], capture_output=True, text=True, timeout=300)
    assert p.returncode in (0, 1), p.stderr
    lines = p.stdout.splitlines()
    header = next(line for line in lines if line.startswith("file "))
    column_end = header.index("gap tolerance") + len("gap tolerance")  # the column is right-aligned
    rows = json.loads(subprocess.run([cli, "batch", *files, "-j", "1", "--json", *flags], capture_output=True,
                                     text=True, timeout=300).stdout)["files"]
    for f in files:
        code, single, err = run_cli("check", f, "--json", *flags)
        assert code in (0, 1), err
        distance, unit = single["tolerances"]["distance"], single["units"]["length"]
        cell = "%.4g" % distance + (" " + unit if unit else "")  # the CLI's text: 4 significant digits (--digits)
        line = next(line for line in lines if line.startswith(f + " "))
        assert line[:column_end].endswith(" " + cell), (cell, header, line)
        row = next(r for r in rows if r["file"] == f)
        assert row["gap_tolerance"] == distance and row["length_unit"] == unit
    if units == "in":  # the absolute default 0.001 mm in inches for the JSON model (rows are listed by path, so
        # the JSON model's row is found by its name: a checkout under a path after "/work/shared" lists it second)
        row = next(r for r in rows if r["file"] == files[0])
        assert row["gap_tolerance"] == pytest.approx(0.001 / 25.4, rel=1e-15)


def test_python_batch_matches_cli_batch(cli, batch_dir):
    p = subprocess.run([cli, "batch", str(batch_dir), "--json", "-j", "2"], capture_output=True, text=True,
                       timeout=300)
    expected = sorted((comparable(r) for r in json.loads(p.stdout)["files"]), key=lambda r: r["file"])
    files = seam.batch.find_files(str(batch_dir))
    local = [comparable(r) for r in seam.batch.check_files(files)]
    for got, want in zip(local, expected):
        if want["status"] == "error":  # the messages name the same file; the CLI's carries no "seam: error:" prefix
            assert got["status"] == "error" and os.path.basename(want["file"]) in got["error"]
            got["error"] = want["error"]
        assert got == want
    assert seam.batch.exit_code(local) == p.returncode == 2


def test_exit_code_rule_is_the_clis(cli, shared_data):
    """One rule for check, batch and seam.batch.exit_code (docs/check-output.md, "Exit codes"): the teaspoon has
    gaps and kinks, a "problem" row, but exit 1 only when a class is required."""
    spoon = os.path.join(shared_data, "bezier", "teaspoon.bpt")
    for require, code in ((None, 0), ("G1", 1)):
        flags = ["--require", require] if require else []
        check = subprocess.run([cli, "check", spoon, *flags], capture_output=True, text=True, timeout=120)
        batch = subprocess.run([cli, "batch", spoon, "--json", *flags], capture_output=True, text=True, timeout=120)
        rows = seam.batch.check_files([spoon], **({"require": require} if require else {}))
        assert check.returncode == batch.returncode == seam.batch.exit_code(rows) == code, (require, batch.stderr)
        assert rows[0]["status"] == json.loads(batch.stdout)["files"][0]["status"] == "problem"
        assert rows[0]["below_required"] == json.loads(batch.stdout)["files"][0]["below_required"]


def test_dask_snippet_of_the_docs_runs_as_a_script(tmp_path, shared_data):
    """docs/python.md's Dask block, pasted into a script and run as users do (issue 38 goal 10)."""
    pytest.importorskip("distributed")
    page = open(os.path.join(os.path.dirname(__file__), "..", "..", "docs", "python.md"), encoding="utf-8").read()
    block = next(b for b in page.split("```python")[1:] if "LocalCluster" in b).split("```")[0]
    assert 'if __name__ == "__main__":' in block
    script = tmp_path / "batch.py"
    script.write_text(block.replace('"../shared/data"', repr(os.path.join(shared_data, "bezier"))))
    env = dict(os.environ, PYTHONPATH=os.path.dirname(seam.__path__[0]))
    p = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=300, cwd=tmp_path,
                       env=env)
    assert p.returncode == 0, p.stderr[-2000:]  # the teapot, teacup and teaspoon are read; no --require: exit 0
    assert "bootstrapping phase" not in p.stderr


def test_dask_local_cluster_matches_local(batch_dir):
    distributed = pytest.importorskip("distributed")
    files = seam.batch.find_files(str(batch_dir))
    local = [comparable(r) for r in seam.batch.check_files(files)]
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                                  silence_logs=40) as cluster, distributed.Client(cluster) as client:
        rows = seam.batch.check_files(files, client=client)
        workers = client.run(os.getpid)
    assert len(set(workers.values())) == 2 and os.getpid() not in workers.values()  # really on two other processes
    assert [comparable(r) for r in rows] == local


def test_dask_worker_crash_is_an_error_row(batch_dir):
    """A file that kills its worker (as a crash inside OpenCASCADE would) gives an error row; the other files are
    checked and the batch returns."""
    distributed = pytest.importorskip("distributed")
    import dask

    files = seam.batch.find_files(str(batch_dir))
    victim = [f for f in files if f.endswith("teapot.bpt")][0]

    def crash_on_teapot(path, **options):  # pickled by value (a local function), run on the workers
        if path.endswith("teapot.bpt"):
            os._exit(3)
        return seam.batch.check_file(path, **options)

    with dask.config.set({"distributed.scheduler.allowed-failures": 0}):
        with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                                      silence_logs=50) as cluster, distributed.Client(cluster) as client:
            rows = seam.batch.check_files(files, client=client, function=crash_on_teapot)
    by_file = {r["file"]: r for r in rows}
    assert by_file[victim]["status"] == "error" and "KilledWorker" in by_file[victim]["error"]
    assert len(rows) == len(files)
    # With allowed-failures 0, a task queued on the dying worker fails with it (by default Dask retries such tasks
    # 3 times); every other file is checked.
    others = [r for r in rows if r["file"] != victim and not r["file"].endswith("broken.step")]
    assert all(r["status"] in ("ok", "problem") or "KilledWorker" in r["error"] for r in others)
    assert any(r["status"] in ("ok", "problem") for r in others)
    assert seam.batch.exit_code(rows) == 2


def test_cli_batch_timeout_is_an_error_row(cli, shared_data):
    slow = os.path.join(shared_data, "bezier", "teapot.bpt")  # ~0.5 s: far above a 1 ms limit
    p = subprocess.run([cli, "batch", slow, "--json", "--timeout", "0.001"], capture_output=True, text=True,
                       timeout=120)
    assert p.returncode == 2, p.stderr
    row = json.loads(p.stdout)["files"][0]
    assert row["status"] == "error" and "timed out" in row["error"] and row["seconds"] < 60


HOSTILE_CAD = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "data", "hostile_cad")


@pytest.mark.skipif(not seam.has_occt, reason="STEP/IGES need a build with OpenCASCADE")
def test_a_partly_read_file_is_never_ok_without_its_warning(cli):
    """iges_truncated_3_of_7.igs lost 4 of its 7 root entities (issue 39 goal 3): the check dict, the in-process row
    and the CLI's row all carry the reader's warning."""
    path = os.path.join(HOSTILE_CAD, "iges_truncated_3_of_7.igs")
    with pytest.warns(UserWarning, match="only 3 of 7 root entities"):
        result = seam.check(path)
    assert len(result["warnings"]) == 2 and "only 3 of 7 root entities" in result["warnings"][1]
    with pytest.warns(UserWarning):
        row = seam.batch.check_files([path])[0]
    assert row["warnings"] == result["warnings"]
    cli_row = json.loads(subprocess.run([cli, "batch", path, "--json"], capture_output=True, text=True,
                                        timeout=300).stdout)["files"][0]
    assert cli_row["warnings"] == row["warnings"] and cli_row["status"] == row["status"]


def test_failed_seams_are_a_problem():
    """A seam whose analysis failed (summary.failed > 0) makes the row a problem, with the count."""
    result = {"summary": {"seams": 1, "failed": 1, "verdicts": {}}, "warnings": []}
    row = seam.batch.summarize("m.json", result, 0.0)
    assert row["status"] == "problem" and row["failed"] == 1
    assert seam.batch.summarize("m.json", {"summary": {"seams": 1, "failed": 0}}, 0.0)["status"] == "ok"


def test_find_files_warns_about_what_it_skips(tmp_path, examples):
    os.symlink(os.path.join(examples, "models", "two_patches.json"), tmp_path / "good.json")
    os.mkfifo(tmp_path / "pipe.json")
    os.symlink(tmp_path / "absent.json", tmp_path / "dangling.json")
    os.symlink("/dev/zero", tmp_path / "zero.json")
    with pytest.warns(UserWarning) as caught:
        files = seam.batch.find_files(str(tmp_path))
    assert files == [str(tmp_path / "good.json")]
    said = " ".join(str(w.message) for w in caught)
    for name in ("pipe.json", "dangling.json", "zero.json"):
        assert name in said
