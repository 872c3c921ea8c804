#!/usr/bin/env python3
"""Hold seam's certified seam verdicts on real STEP/IGES files to the OpenCASCADE-only probe (issue 35 §3).

For every file: `seam check FILE --json` and `occt_probe seams FILE --sew --samples N` (the probe reads, sews and
measures with OpenCASCADE alone). Seams are matched by where their edge is, not by
numbers (the two tools may number faces and edges differently after sewing): the probe's seam whose 33 edge points
lie nearest seam's reported points of the seam (its worst G0/G1/G2 points, all on the edge within the gap), among
the probe's seams within MATCH_REL x diagonal (+ the gap); of equally near ones (the two sides of a closed seam, two
edges between the same faces, two edges sewing left side by side) the one of the same edge number (both sides number
the edges of the same, possibly sewn, shape), then the one between the same file face numbers. A seam with no probe seam that near is
unmatched and not compared. For every matched seam that seam calls certified:

  1. its certified gap bound is not below the probe's boundary-to-boundary gap (less the probe's own sampling error);
  2. it is not a "gap" where the probe's boundaries are within the distance tolerance;
  3. it is not a "kink" or "crease" where the probe's largest angle between the faces' normals at their boundaries
     (max_angle_boundary_interior_deg: at the two boundaries, nearest points paired, what seam certifies; the 2 % of
     the edge at each end left out, where a pole or a vertex of three faces makes the probe's normal unreliable) is
     below the G1 tolerance;
  4. its certified angle bound is not below that probe angle;
  (3 and 4 leave out seams where the probe skipped samples or found a pole: it has no normal there.)
  5. no curvature figure above 1e6 / (model diagonal) is printed for a G1/G2 seam (pole noise shown as data).

Prints one line per violation and a summary; exit 1 if any, 0 if none, 2 on a tool failure.
Usage: compare_seams.py SEAM OCCT_PROBE FILE_OR_FOLDER... [--samples N] [--json OUT]
"""
import json
import math
import os
import subprocess
import sys

# The probe's gap is refined on quadratics through its samples: it can exceed the true gap by O(h^3 kappa^2) and
# by round-off; it is compared with this slack relative to the model diagonal.
PROBE_GAP_SLACK_REL = 1e-7
# The probe's angle is acos of the dot product of two unit normals: its round-off floor is sqrt(2 * 2.2e-16) rad =
# 1.2e-6 deg, so it is compared with this slack in degrees.
PROBE_ANGLE_SLACK_DEG = 1e-5
# A "gap" verdict is false when the probe's two-sided gap is below this fraction of the distance tolerance
# (the probe's samples can miss the maximum between them only by its sag, far below this margin).
GAP_VERDICT_MARGIN = 0.5
# A G1/G2 seam's curvature figures are pole noise when above this multiple of 1/diagonal.
CURVATURE_NOISE_FACTOR = 1e6
# More unmatched seams than this fraction of a file's seams is itself a violation: the comparison would pass while
# comparing nothing (until 2026-12-01 seam reported trj3, boxed_sphere, sunglasses and the fuselage in their files'
# units, the probe in mm, and all 719 of their seams went unmatched). 0 of 1 327 are unmatched in mm.
MAX_UNMATCHED_FRACTION = 0.05


# Files whose remaining differences are understood only in part, with the reason; their violations are printed as
# KNOWN and do not fail the run (they are counted and listed, so that a change in them shows).
KNOWN_DIFFERENCES = {
    "bearing.iges": "a sewn IGES model 0.1 mm across whose pcurves drift by up to 1e-5 along their edges (38 "
                    "differences before seam compared normals between closest points, 7 after, issue 35): three "
                    "kinks whose largest angle is at an edge end, inside the 2 % of each end the probe leaves out "
                    "(edges 14, 72, 96: 0.015, 0.020, 0.012 deg there), one bound 0.3 % above the tolerance where "
                    "the probe is 0.1 % below it (edge 47), and three certified gaps of 6e-9 to 1.4e-7 mm on the "
                    "patch-edge route where the probe's boundaries (pcurve images 1e-7 off the patch sides) are "
                    "up to 6.9e-8 mm apart",
}


def expand(paths):
    """Files as given; a folder gives its STEP/IGES files (sorted); a missing folder gives none."""
    out = []
    for p in paths:
        if os.path.isdir(p):
            out += sorted(os.path.join(p, f) for f in os.listdir(p)
                          if f.lower().endswith((".stp", ".step", ".igs", ".iges")))
        elif os.path.exists(p):
            out.append(p)
    return out


def run_json(cmd, timeout):
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    if p.returncode not in (0, 1):
        raise RuntimeError(f"{' '.join(cmd)}: exit {p.returncode}: {p.stderr.strip()[:400]}")
    return json.loads(p.stdout)


def polyline_distance(q, pts):
    best = math.inf
    for a, b in zip(pts, pts[1:]):
        ab = [b[i] - a[i] for i in range(3)]
        aq = [q[i] - a[i] for i in range(3)]
        L = sum(x * x for x in ab)
        t = 0.0 if L == 0 else max(0.0, min(1.0, sum(ab[i] * aq[i] for i in range(3)) / L))
        best = min(best, math.dist(q, [a[i] + t * ab[i] for i in range(3)]))
    return best


# A probe seam matches when seam's reported points lie within this x diagonal (+ the seam's gap) of its edge
# polyline (33 points: a chord's sag on a quarter circle of radius r is 7e-4 r).
MATCH_REL = 2e-3


def match(r, probe_seams, diag):
    """The probe seam nearest seam's reported points of seam row r, or None."""
    pts = [w["point"] for w in (r.get("worst") or {}).values() if w and w.get("point")]
    if not pts:
        return None
    faces = frozenset((int(r["a"].lstrip("F")), int(r["b"].lstrip("F"))))
    limit = MATCH_REL * diag + (r.get("g0_max") or 0.0)
    scored = []
    for q in probe_seams:
        d = max(polyline_distance(x, q["points"]) for x in pts)
        if d <= limit:
            scored.append((d, q["edge"] != r.get("edge"), frozenset((q["face_a"], q["face_b"])) != faces, q))
    if not scored:
        return None
    best = min(scored, key=lambda e: e[0])[0]
    ties = [e for e in scored if e[0] <= best + 1e-3 * limit]
    return min(ties, key=lambda e: (e[1], e[2], e[0]))[3]


def compare(seam_bin, probe_bin, path, samples):
    s = run_json([seam_bin, "check", path, "--json", "--display-units", "mm"], 900)  # the probe measures in mm
    p = run_json([probe_bin, "seams", path, "--sew", "--samples", str(samples)], 900)
    tol = s["tolerances"]
    diag = p["bbox_diagonal"]
    rows, unmatched, compared = [], 0, 0
    for r in s["seams"]:
        q = match(r, p["seams"], diag)
        if q is None:
            unmatched += 1
            continue
        compared += 1
        if not r.get("certified"):
            continue
        where = f"{path}: edge {r['edge']} ({r['a']}|{r['b']}; probe edge {q['edge']})"
        gap, gap_bound = q["gap"], r["g0_max"]
        if gap_bound < gap - PROBE_GAP_SLACK_REL * diag:
            rows.append(f"{where}: certified gap {gap_bound:.3g} below the probe's {gap:.3g}")
        if r["verdict"] == "gap" and gap < GAP_VERDICT_MARGIN * tol["distance"]:
            rows.append(f"{where}: 'gap' ({gap_bound:.3g}) where the probe's boundaries are {gap:.3g} apart")
        angle = q.get("max_angle_boundary_interior_deg")
        if angle is not None and q["skipped"] == 0 and not q["pole"]:
            if r["verdict"] in ("kink", "crease") and angle < tol["angle_deg"]:
                rows.append(f"{where}: '{r['verdict']}' ({r['g1_max_deg']:.4g} deg) where the probe's angle is "
                            f"{angle:.3g} deg")
            if r["g1_max_deg"] < angle - PROBE_ANGLE_SLACK_DEG:
                rows.append(f"{where}: certified angle {r['g1_max_deg']:.4g} deg below the probe's {angle:.4g}")
        if r["verdict"] in ("G1", "G2"):
            g2 = r.get("g2_max")
            if g2 is not None and math.isfinite(g2) and g2 > CURVATURE_NOISE_FACTOR / diag:
                rows.append(f"{where}: {r['verdict']} seam prints a curvature jump of {g2:.3g} 1/mm")
    return rows, {"file": path, "seams": len(s["seams"]), "probe_seams": len(p["seams"]), "compared": compared,
                  "unmatched": unmatched, "violations": len(rows)}


def main(argv):
    samples, out, args = 500, None, []
    it = iter(argv[1:])
    for a in it:
        if a == "--samples":
            samples = int(next(it))
        elif a == "--json":
            out = next(it)
        else:
            args.append(a)
    if len(args) < 3:
        print(__doc__, file=sys.stderr)
        return 2
    seam_bin, probe_bin, files = args[0], args[1], expand(args[2:])
    all_rows, known, stats = [], [], []
    for f in files:
        try:
            rows, st = compare(seam_bin, probe_bin, f, samples)
        except (RuntimeError, subprocess.TimeoutExpired, json.JSONDecodeError) as e:
            print(f"{f}: {e}", file=sys.stderr)
            return 2
        if os.path.basename(f) in KNOWN_DIFFERENCES:
            known += rows
            st["known_difference"] = KNOWN_DIFFERENCES[os.path.basename(f)]
        else:
            all_rows += rows
        if st["unmatched"] > MAX_UNMATCHED_FRACTION * st["seams"]:
            all_rows.append(f"{f}: {st['unmatched']} of {st['seams']} seams match no probe seam (units? matching?)")
        stats.append(st)
        print(f"{f}: {st['compared']} of {st['seams']} seams compared ({st['unmatched']} unmatched), "
              f"{len(rows)} violations")
    for r in known:
        print("KNOWN " + r)
    for r in all_rows:
        print("VIOLATION " + r)
    if out:
        with open(out, "w") as fh:
            json.dump({"files": stats, "violations": all_rows, "known": known}, fh, indent=1)
    print(f"{len(all_rows)} violations in {len(files)} files ({len(known)} known differences, not counted)")
    if not files:
        print("no files", file=sys.stderr)
        return 2
    return 1 if all_rows else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
