"""seam: geometric continuity of spline surfaces (G0/G1/G2 seams with certified bounds).

    import seam
    m = seam.load("examples/models/two_patches.json")   # .json, .bpt, .step/.stp, .iges/.igs
    seam.evaluate(m, "A", [[0.25, 0.5]])                # (n, 3) points
    seam.derivatives(m, "A", uv, 2)                     # (n, 3, 3, 3): [i, k, l] = d^(k+l) S / du^k dv^l
    seam.check("model.step")                            # the dict of `seam check model.step --json`
    healed, info = seam.heal(m)                         # (Model, the dict of `seam heal --json`)
    joined, info = seam.join(m, "B", "u0", "A", "u1", continuity="G1")   # (Model, the dict of `seam join --json`)
    filled, info = seam.fill(m, hole=True)              # (Model or None, the dict of `seam fill --json`)
    seam.regularity(m, patch="A")                       # the dict of `seam regularity --json`
    seam.save(healed, "healed.json"); seam.report(m, "report.html")
    seam.batch.check_files(paths, client=None)          # many files, optionally on a Dask cluster

Bad input raises ValueError (invalid data, unknown names, parameters outside the domain), OSError (unreadable
files) or RuntimeError; messages name the file, the object and the problem. README "Python".
"""
from ._seam import (Model, __version__, check, corner, derivatives, dumps, evaluate, evaluate_curve, fill, has_occt,
                    heal, join, load, loads, regularity, report, save)
from . import batch

__all__ = ["Model", "__version__", "batch", "check", "corner", "derivatives", "dumps", "evaluate", "evaluate_curve",
           "fill", "has_occt", "heal", "join", "load", "loads", "regularity", "report", "save"]
