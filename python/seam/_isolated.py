"""The timeout= of seam.load, seam.check and seam.report: the call runs in a separate Python process that is killed
when the time is up.

OpenCASCADE's shape healing can spend minutes on a corrupt STEP/IGES file in code that never looks at a clock, and a
thread cannot be stopped from outside: only a process can. The child gets the request as JSON on its standard input
and answers with JSON on its standard output (a model comes back as seam's JSON text, which round-trips every double
exactly). Errors come back with their Python type (ValueError, OSError, RuntimeError, TypeError) and message, and the
warnings the call issued are issued again here. A process (not multiprocessing) so that it also works inside Dask
workers, which are daemonic processes and may not have multiprocessing children. docs/reliability.md, "Time limit".
"""
import json
import math
import os
import signal
import subprocess
import sys
import warnings

# Exceptions passed back by name; anything else becomes RuntimeError.
_ERRORS = {"ValueError": ValueError, "OSError": OSError, "RuntimeError": RuntimeError, "TypeError": TypeError,
           "FileNotFoundError": FileNotFoundError, "PermissionError": PermissionError}


def _number(seconds: float) -> str:
    return f"{seconds:g}"


def run(function: str, path, timeout: float, /, **kwargs):
    """The result of seam's `function` ("load", "check", "report") on `path` with `kwargs`, computed in a child
    process given `timeout` seconds. Raises TimeoutError (an OSError) when the time is up."""
    path = os.fspath(path)
    if isinstance(timeout, bool) or not (isinstance(timeout, (int, float)) and timeout > 0 and timeout == timeout):
        raise ValueError(f"timeout must be a positive number of seconds, not {timeout!r}")
    try:
        limit = None if math.isinf(timeout) else float(timeout)  # inf: the child process, with no limit
    except OverflowError:  # an int beyond a float (10**400): no limit either
        limit = None
    request = json.dumps({"function": function, "path": path, "kwargs": kwargs})
    package_parent = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    env = dict(os.environ)
    env["PYTHONPATH"] = package_parent + (os.pathsep + env["PYTHONPATH"] if env.get("PYTHONPATH") else "")
    try:
        done = subprocess.run([sys.executable, "-m", "seam._isolated"], input=request, capture_output=True, text=True,
                              timeout=limit, env=env, check=False)
    except subprocess.TimeoutExpired:
        raise TimeoutError(f"{path}: {function} took longer than the time limit of {_number(timeout)} s and was "
                           "stopped (a corrupt STEP/IGES file can keep OpenCASCADE's shape healing busy for "
                           "minutes); allow more time with timeout=, or None for no limit") from None
    if done.returncode != 0 or not done.stdout:
        how = (f"signal {-done.returncode} ({signal.Signals(-done.returncode).name})" if done.returncode < 0
               else f"exit code {done.returncode}")
        detail = done.stderr.strip().splitlines()[-1] if done.stderr.strip() else "no message"
        raise RuntimeError(f"{path}: the process running {function} on the file ended with {how}: {detail}")
    reply = json.loads(done.stdout)
    for message in reply.get("warnings", []):
        warnings.warn(message, stacklevel=3)
    if "error" in reply:
        raise _ERRORS.get(reply["error"], RuntimeError)(reply["message"])
    return reply["result"]


def _serve() -> None:
    """The child's side: one request from stdin, one reply on stdout."""
    from . import _seam

    request = json.load(sys.stdin)
    function, path, kwargs = request["function"], request["path"], request["kwargs"]
    reply = {}
    with warnings.catch_warnings(record=True) as issued:
        warnings.simplefilter("always")
        try:
            if function == "load":
                reply["result"] = _seam.dumps(_seam.load(path))
            elif function == "check":
                reply["result"] = _seam.check(path, **kwargs)
            elif function == "report":
                reply["result"] = os.fspath(_seam.report(path, **kwargs))
            else:
                raise ValueError(f"unknown function {function!r}")
        except Exception as e:  # noqa: BLE001 - every failure goes back to the caller with its type
            reply = {"error": type(e).__name__, "message": str(e)}
    reply["warnings"] = [str(w.message) for w in issued]
    json.dump(reply, sys.stdout)


if __name__ == "__main__":
    _serve()
