"""timeout= of seam.load / seam.check / seam.report (issue 15 §2): the call runs in a child process that is stopped
when the time is up. With a generous limit the results equal the in-process calls exactly; past a limit far below
the file's reading time the call raises TimeoutError; errors keep their type and message; a Dask worker (a daemonic
process) can use it. No corrupt file stalls OpenCASCADE deterministically (docs/reliability.md, "Time limit"), so a
valid file with a limit of 10 ms stands in for one."""
import os
import time

import pytest

import seam
import seam.batch

pytestmark = pytest.mark.skipif(not seam.has_occt, reason="STEP/IGES need a build with OpenCASCADE")


@pytest.fixture(scope="module")
def step_file(shared_data):
    return os.path.join(shared_data, "step", "bug28366_fuselage.stp")


def test_results_with_a_timeout_equal_the_in_process_calls(step_file, tmp_path):
    assert seam.check(step_file, timeout=120) == seam.check(step_file)
    options = dict(tol_angle=0.5, sort="angle", top=3, preset="catia")
    assert seam.check(step_file, timeout=120, **options) == seam.check(step_file, **options)
    here, there = seam.load(step_file), seam.load(step_file, timeout=120)
    assert there.source == here.source == step_file
    assert seam.dumps(there) == seam.dumps(here)  # every control point, weight and knot bit for bit
    out = tmp_path / "r.html"
    assert seam.report(step_file, out, timeout=120) == os.fspath(out)
    assert out.stat().st_size > 10_000


def test_past_the_limit_is_a_timeout_error_naming_the_file(step_file, tmp_path):
    out = tmp_path / "never.html"
    for call in (lambda: seam.check(step_file, timeout=0.01), lambda: seam.load(step_file, timeout=0.01),
                 lambda: seam.report(step_file, out, timeout=0.01)):
        start = time.perf_counter()
        with pytest.raises(TimeoutError, match="took longer than the time limit of 0.01 s") as e:
            call()
        assert step_file in str(e.value)
        assert time.perf_counter() - start < 30  # stopped, not waited for
    assert not out.exists()


def test_errors_keep_their_type_and_message(tmp_path):
    missing = tmp_path / "missing.step"
    with pytest.raises(OSError, match="missing.step"):
        seam.check(missing, timeout=60)
    broken = tmp_path / "broken.step"
    broken.write_text("ISO-10303-21;\nthis is not STEP\n")
    with pytest.raises(ValueError) as here:
        seam.check(broken)
    with pytest.raises(ValueError) as there:
        seam.check(broken, timeout=60)
    assert str(there.value) == str(here.value)
    with pytest.raises(ValueError, match="positive number of seconds"):
        seam.check(broken, timeout=-1)


def test_a_model_takes_no_timeout(step_file):
    with pytest.raises(TypeError, match="file path"):
        seam.check(seam.load(step_file), timeout=10)


def test_batch_rows_with_a_timeout(step_file, shared_data):
    teapot = os.path.join(shared_data, "bezier", "teapot.bpt")
    rows = seam.batch.check_files([step_file, teapot], timeout=120)
    plain = seam.batch.check_files([step_file, teapot])
    strip = [{k: v for k, v in r.items() if k != "seconds"} for r in rows]
    assert strip == [{k: v for k, v in r.items() if k != "seconds"} for r in plain]
    late = seam.batch.check_files([step_file], timeout=0.01)[0]
    assert late["status"] == "error" and "time limit" in late["error"]


def test_timeout_works_inside_a_dask_worker(step_file):
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None,
                                  silence_logs=40) as cluster, distributed.Client(cluster) as client:
        rows = seam.batch.check_files([step_file, step_file], client=client, timeout=120)
        late = seam.batch.check_files([step_file], client=client, timeout=0.01)
    assert all(r["status"] in ("ok", "problem") for r in rows), rows
    assert late[0]["status"] == "error" and "time limit" in late[0]["error"]


def test_an_infinite_timeout_is_no_limit_and_bad_ones_are_value_errors(step_file):
    """timeout=inf (issue 39 §5) used to raise OverflowError; it runs the call in the child process without a limit."""
    import math
    assert seam.check(step_file, timeout=math.inf) == seam.check(step_file)
    for bad in (0, -1, float("nan"), True, "60"):
        with pytest.raises(ValueError, match="timeout"):
            seam.check(step_file, timeout=bad)
