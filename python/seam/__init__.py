"""seam: geometric continuity of spline surfaces (G0/G1/G2 seams with certified bounds).

    import seam
    m = seam.load("examples/models/two_patches.json")   # .json, .bpt, .step/.stp, .iges/.igs
    seam.evaluate(m, "A", [[0.25, 0.5]])                # (n, 3) points
    seam.derivatives(m, "A", uv, 2)                     # (n, 3, 3, 3): [i, k, l] = d^(k+l) S / du^k dv^l
    seam.check("model.step")                            # the dict of `seam check model.step --json`
    seam.check("model.step", timeout=60)                # in a child process, TimeoutError after 60 s
    healed, info = seam.heal(m)                         # (Model, the dict of `seam heal --json`)
    joined, info = seam.join(m, "B", "u0", "A", "u1", continuity="G1")   # (Model, the dict of `seam join --json`)
    filled, info = seam.fill(m, hole=True)              # (Model or None, the dict of `seam fill --json`)
    seam.regularity(m, patch="A")                       # the dict of `seam regularity --json`
    seam.save(healed, "healed.json"); seam.report(m, "report.html")
    seam.batch.check_files(paths, client=None)          # many files, optionally on a Dask cluster

Bad input raises ValueError (invalid data, unknown names, parameters outside the domain), OSError (unreadable
files; TimeoutError past a timeout=) or RuntimeError; messages name the file, the object and the problem. README
"Python".
"""
import os as _os

from . import _isolated, _seam
from ._seam import (Model, __version__, corner, derivatives, dumps, evaluate, evaluate_curve, fill, has_occt, heal,
                    join, loads, regularity, save)

_TIMEOUT_DOC = """

timeout: seconds the call may take (reading the file included), or None (the default) for no limit (math.inf: in
the child process, no limit; zero, negative, NaN or a bool: ValueError). With a number,
the call runs in a separate Python process that is stopped when the time is up, raising TimeoutError (an OSError):
OpenCASCADE can spend minutes on a corrupt STEP/IGES file and cannot be interrupted otherwise. It costs the start of
that process (about 0.3 s). Only for a file path, not for a Model."""


def _isolated_path(what: str, target, timeout):
    """The path of a call that runs in a child process (timeout given), or None to run here."""
    if timeout is None:
        return None
    if isinstance(target, Model):
        raise TypeError(f"{what}: timeout= applies to a file path, not to a Model (a Model is already read)")
    return _os.fspath(target)


def load(path, *, timeout=None):
    if (file := _isolated_path("load", path, timeout)) is None:
        return _seam.load(path)
    return _seam.loads(_isolated.run("load", file, timeout), source=file)


def check(target, *, timeout=None, **options):
    if (file := _isolated_path("check", target, timeout)) is None:
        return _seam.check(target, **options)
    return _isolated.run("check", file, timeout, **options)


def report(target, path, *, timeout=None, **options):
    if (file := _isolated_path("report", target, timeout)) is None:
        return _seam.report(target, path, **options)
    return _isolated.run("report", file, timeout, path=_os.fspath(path), **options)


load.__doc__ = _seam.load.__doc__ + _TIMEOUT_DOC
check.__doc__ = _seam.check.__doc__ + _TIMEOUT_DOC
report.__doc__ = _seam.report.__doc__ + _TIMEOUT_DOC

from . import batch  # noqa: E402 - batch imports check from this module

__all__ = ["Model", "__version__", "batch", "check", "corner", "derivatives", "dumps", "evaluate", "evaluate_curve",
           "fill", "has_occt", "heal", "join", "load", "loads", "regularity", "report", "save"]
