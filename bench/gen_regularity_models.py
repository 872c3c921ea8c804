#!/usr/bin/env python3
"""Large inputs for `seam regularity` timings (docs/performance.md, issues 15 and 16). Written to a file, never
committed (they are tens of megabytes).

  bench/gen_regularity_models.py curve N OUT.json      one cubic B-spline curve of N segments (uniform knots, a helix
                                                        whose turns lie close: many overlapping boxes, no defect)
  bench/gen_regularity_models.py net N OUT.json        one bicubic B-spline patch of N x N Bezier sub-nets (a wavy
                                                        height field)
  bench/gen_regularity_models.py bezier N OUT.json     one Bezier patch of N x N control points (degree N-1)
  bench/gen_regularity_models.py bezier-curve N OUT.json   one Bezier curve of N control points (degree N-1)
"""
import math
import sys


def num(x):
    return repr(round(x, 12))


def write_curve(n_segments, out):
    n = n_segments + 3
    pts = []
    for i in range(n):
        a = 0.3 * i
        pts.append("[%s,%s,%s]" % (num(math.cos(a)), num(math.sin(a)), num(0.002 * i)))
    knots = ",".join(str(i) for i in range(n + 4))
    out.write('{"curves":[{"name":"C","type":"bspline","degree":3,"knots":[%s],"points":[%s]}]}\n'
              % (knots, ",".join(pts)))


def net_rows(n, f):
    return ",".join("[" + ",".join("[%s,%s,%s]" % tuple(num(c) for c in f(i, j)) for j in range(n)) + "]"
                    for i in range(n))


def write_net(n_sub, out):
    n = n_sub + 3
    knots = ",".join(str(i) for i in range(n + 4))
    rows = net_rows(n, lambda i, j: (i, j, math.sin(0.2 * i) * math.cos(0.2 * j)))
    out.write('{"patches":[{"name":"S","type":"bspline","degree":[3,3],"knots":[[%s],[%s]],"points":[%s]}]}\n'
              % (knots, knots, rows))


def write_bezier(n, out):
    rows = net_rows(n, lambda i, j: (i / (n - 1), j / (n - 1), 0.1 * math.sin(3 * i / n) * math.cos(3 * j / n)))
    out.write('{"patches":[{"name":"B","type":"bezier","points":[%s]}]}\n' % rows)


def write_bezier_curve(n, out):
    pts = ",".join("[%s,%s,%s]" % (num(i / (n - 1)), num(math.sin(3 * i / n)), "0") for i in range(n))
    out.write('{"curves":[{"name":"B","type":"bezier","points":[%s]}]}\n' % pts)


def main():
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    kind, n, path = sys.argv[1], int(sys.argv[2]), sys.argv[3]
    writers = {"curve": write_curve, "net": write_net, "bezier": write_bezier, "bezier-curve": write_bezier_curve}
    if kind not in writers:
        sys.exit(__doc__)
    with open(path, "w") as out:
        writers[kind](n, out)


if __name__ == "__main__":
    main()
