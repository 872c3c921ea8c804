"""join, heal, fill and regularity from Python, each checked by a second route: the tangent planes along a joined or
filled seam measured with the module's own NumPy evaluation (not the certified seam analysis), a healed model
re-checked by the CLI (`seam check --json` in a subprocess), the dicts compared with the CLI's `--json` output, and a
cusp planted in a control polygon built here."""
import json
import os
import warnings

import numpy as np
import pytest

import seam

EDGE_PARAMS = {"u0": (0, "lo"), "u1": (0, "hi"), "v0": (1, "lo"), "v1": (1, "hi")}


def edge_uv(model, patch, edge, t):
    """(n, 2) parameters of the points t (the edge's own parameter) on edge `edge` of `patch`."""
    domain = model.domain(patch)
    fixed_dir, side = EDGE_PARAMS[edge]
    fixed = domain[fixed_dir][0 if side == "lo" else 1]
    t = np.asarray(t, dtype=float)
    return np.column_stack([np.full_like(t, fixed), t] if fixed_dir == 0 else [t, np.full_like(t, fixed)])


def normals(model, patch, uv):
    d = seam.derivatives(model, patch, uv, 1)
    return np.cross(d[:, 1, 0, :], d[:, 0, 1, :])


def seam_angles(model, a, a_edge, b, b_edge, overlap_a, overlap_b, reversed_, n=41):
    """Largest gap and the angles (degrees) between the tangent planes of a and b at n points along their seam,
    with an affine correspondence of the two edges' parameters (the sign of the normals is ignored)."""
    s = np.linspace(0.0, 1.0, n)
    ta = overlap_a[0] + s * (overlap_a[1] - overlap_a[0])
    sb = 1.0 - s if reversed_ else s
    tb = overlap_b[0] + sb * (overlap_b[1] - overlap_b[0])
    uva, uvb = edge_uv(model, a, a_edge, ta), edge_uv(model, b, b_edge, tb)
    gap = np.max(np.linalg.norm(seam.evaluate(model, a, uva) - seam.evaluate(model, b, uvb), axis=1))
    na, nb = normals(model, a, uva), normals(model, b, uvb)
    cross = np.linalg.norm(np.cross(na, nb), axis=1)
    dot = np.abs(np.einsum("ij,ij->i", na, nb))
    return gap, np.degrees(np.arctan2(cross, dot))


def kinked_two_patches(examples):
    """two_patches.json with B's second row of control points lifted: a kink of several degrees at A:u1 / B:u0."""
    with open(os.path.join(examples, "models", "two_patches.json")) as f:
        data = json.load(f)
    data.pop("curves", None)
    data["patches"] = [p for p in data["patches"] if p["name"] in ("A", "B")]
    b = next(p for p in data["patches"] if p["name"] == "B")
    for point in b["points"][1]:
        point[2] += 0.05
    return data


def test_loads_dumps_round_trip(examples, tmp_path):
    path = os.path.join(examples, "models", "two_patches.json")
    m = seam.load(path)
    again = seam.loads(seam.dumps(m), "copy")
    assert again.source == "copy" and again.patch_names == m.patch_names
    seam.save(m, tmp_path / "a.json")
    seam.save(again, tmp_path / "b.json")
    assert (tmp_path / "a.json").read_bytes() == (tmp_path / "b.json").read_bytes()
    assert (tmp_path / "a.json").read_text() == seam.dumps(m)
    points = m.control_points("A")
    assert points.shape == (6, 4, 3) and points[1, 1].tolist() == [0.4, 0.3, 0.2]  # points[i][j] of the file
    with pytest.raises(ValueError, match="mine"):
        seam.loads('{"patches": [{"name": "P"}]}', "mine")


def test_join_g1_by_numpy_normals(examples, run_cli, tmp_path):
    data = kinked_two_patches(examples)
    m = seam.loads(json.dumps(data), "kinked")
    seam_args = ("B", "u0", "A", "u1", (0.0, 1.0), (0.0, 1.0), False)
    gap0, angles0 = seam_angles(m, *seam_args)
    assert gap0 < 1e-12 and angles0.max() > 5.0  # the planted kink, measured here

    joined, info = seam.join(m, "B", "u0", "A", "u1", continuity="G1")
    assert info["achieved"] and info["requested"] == "G1" and info["patches_changed"] == ["B"]
    assert info["before"]["g1_max_deg"] >= angles0.max() - 1e-9  # the certified bound is above what we found
    assert info["after"]["geometric"] in ("G1", "G2") and info["after"]["certified"]
    gap1, angles1 = seam_angles(joined, *seam_args, n=201)
    assert gap1 < 1e-9 and angles1.max() < 1e-6, angles1.max()
    assert angles1.max() <= info["after"]["g1_max_deg"] + 1e-9
    # A is untouched, B moved by at most the reported control-point displacement.
    assert np.array_equal(joined.control_points("A"), m.control_points("A"))
    moved = np.linalg.norm(joined.control_points("B") - m.control_points("B"), axis=2).max()
    assert moved == pytest.approx(info["max_displacement"], rel=1e-12, abs=1e-15)

    # The CLI on the same file: the same dict (without "output") and the same model, byte for byte.
    src = tmp_path / "kinked.json"
    seam.save(m, src)
    cli_out = tmp_path / "cli.json"
    code, expected, err = run_cli("join", str(src), "--move", "B:u0", "--to", "A:u1", "-o", str(cli_out), "--json")
    assert code == 0, err
    assert expected.pop("output") == str(cli_out)
    assert info == expected
    seam.save(joined, tmp_path / "py.json")
    assert (tmp_path / "py.json").read_bytes() == cli_out.read_bytes()


def test_join_options_and_errors(examples):
    m = seam.loads(json.dumps(kinked_two_patches(examples)), "kinked")
    g0, info = seam.join(m, "B", "u0", "A", "u1", continuity="G0")
    assert info["requested"] == "G0" and info["achieved"]
    _, crease = seam.join(m, "B", "u0", "A", "u1", crease_angle=1.0)  # the kink counts as a design crease
    assert not crease["achieved"] and crease["patches_changed"] == []
    with pytest.raises(ValueError, match='"S1"'):
        seam.join(m, "S1", "u0", "A", "u1")
    with pytest.raises(ValueError, match="move_edge"):
        seam.join(m, "B", "w0", "A", "u1")
    with pytest.raises(ValueError, match="continuity"):
        seam.join(m, "B", "u0", "A", "u1", continuity="G3")
    with pytest.raises(ValueError, match="method"):
        seam.join(m, "B", "u0", "A", "u1", method="magic")
    with pytest.raises(ValueError, match="crease_angle"):
        seam.join(m, "B", "u0", "A", "u1", crease_angle=0.0)
    with pytest.raises(ValueError):  # edges that do not meet: the C++ message, as a ValueError
        seam.join(m, "B", "u1", "A", "u0")


def test_heal_then_check_matches_cli(examples, run_cli, tmp_path):
    path = os.path.join(examples, "models", "network_fan5.json")
    before = seam.check(path)
    assert before["summary"]["verdicts"].get("kink", 0) > 0  # something to heal
    healed, info = seam.heal(seam.load(path), continuity="G1")
    assert info["achieved"] and info["seams_worse"] == 0
    out = tmp_path / "healed.json"
    seam.save(healed, out)
    code, expected, err = run_cli("check", str(out), "--json")
    assert code == 0, err
    assert seam.check(str(out)) == expected
    got = seam.check(healed)
    assert got["summary"] == expected["summary"] and got["seams"] == expected["seams"]
    assert all(s["geometric"] in ("G1", "G2") for s in expected["seams"])
    # The tangent planes along every healed seam, measured with NumPy.
    for s in expected["seams"]:
        gap, angles = seam_angles(healed, s["a"], s["a_edge"], s["b"], s["b_edge"], s["overlap"], s["overlap_b"],
                                  s["reversed"])
        assert gap <= s["g0_max"] + 1e-12 and angles.max() <= s["g1_max_deg"] + 1e-9


@pytest.mark.parametrize("mode,args,cli_args", [
    ("quad", {"quad": ("r1", "r2", "r4")}, ["--quad", "r1", "r2", "r4"]),
    ("hole", {"hole": True}, ["--hole"]),
    ("fillet", {"fillet": (["a0", "a1", "a2"], ["b0", "b1", "b2"])}, ["--fillet", "a0,a1,a2", "b0,b1,b2"]),
])
def test_fill_matches_cli_and_is_g1(examples, run_cli, tmp_path, mode, args, cli_args):
    path = os.path.join(examples, "models", f"fill_{mode}.json")
    m = seam.load(path)
    filled, info = seam.fill(m, **args)
    cli_out = tmp_path / "cli.json"
    code, expected, err = run_cli("fill", path, *cli_args, "-o", str(cli_out), "--json")
    assert code == 0, err
    assert expected["output"] == str(cli_out) and info["output"] is None
    info["output"] = expected["output"]
    assert info == expected
    seam.save(filled, tmp_path / "py.json")
    assert (tmp_path / "py.json").read_bytes() == cli_out.read_bytes()
    assert info["g1"] and info["mode"] == mode
    new = [p["name"] for p in info["new_patches"]]
    assert filled.patch_names == m.patch_names + new
    for name in m.patch_names:  # the input patches are copied unchanged
        assert np.array_equal(filled.control_points(name), m.control_points(name))
    for s in info["seams"]:  # every new seam, measured with NumPy
        gap, angles = seam_angles(filled, s["a"], s["a_edge"], s["b"], s["b_edge"], s["overlap_a"], s["overlap_b"],
                                  s["reversed"])
        assert gap < 1e-9 and angles.max() < 1e-6, (s["a"], s["b"], angles.max())


def test_fill_hole_not_g1_builds_nothing(examples):
    m = seam.load(os.path.join(examples, "models", "fill_hole_not_g1.json"))
    filled, info = seam.fill(m, hole=True)
    assert filled is None and not info["g1"] and not info["surrounding_g1"] and info["new_patches"] == []


def test_fill_errors(examples):
    m = seam.load(os.path.join(examples, "models", "fill_hole.json"))
    with pytest.raises(ValueError, match="exactly one"):
        seam.fill(m)
    with pytest.raises(ValueError, match="exactly one"):
        seam.fill(m, hole=True, quad=("a", "b", "c"))
    with pytest.raises(ValueError, match="degree"):
        seam.fill(m, hole=True, degree=7)
    with pytest.raises(ValueError, match="around"):
        seam.fill(m, around=["x"], quad=("a", "b", "c"))
    with pytest.raises(ValueError, match="nope"):
        seam.fill(m, quad=("nope", "b", "c"))


def test_regularity_matches_cli(examples, run_cli):
    path = os.path.join(examples, "models", "two_patches.json")
    code, expected, err = run_cli("regularity", path, "--json")
    got = seam.regularity(seam.load(path))
    assert got == expected
    assert list(got.keys()) == ["file", "curves", "patches"]
    assert [p["name"] for p in got["patches"]] == ["A", "B", "QuarterCylinder"]
    assert seam.regularity(path) == expected  # a path: loaded, as the CLI does
    code, expected, err = run_cli("regularity", path, "--patch", "A", "--ell", "1", "--json")
    assert seam.regularity(seam.load(path), patch="A", ell=1) == expected


# A planar cubic with a cusp at t = 1/2: C'(1/2) = 3 (P0 - P1 - P2 + P3) / 4 = 0, C(1/2) = (P0 + 3 P1 + 3 P2 + P3) / 8.
CUSP_POLYGON = [[0.0, 0.0], [1.0, 1.0], [0.0, 1.0], [1.0, 0.0]]
CUSP_POINT = [0.5, 0.75]


def cusp_model():
    curve = {"name": "cusp", "type": "bezier", "points": CUSP_POLYGON}
    smooth = {"name": "smooth", "type": "bezier", "points": [[0.0, 0.0], [1.0, 1.0], [2.0, 1.0], [3.0, 0.0]]}
    # A bicubic patch whose normal vanishes at one point: S(u, v) = (C_x(u), C_x(v), (u - 1/2)(v - 1/2)) with the
    # cusp's x polynomial (C_x'(1/2) = 0); S_u x S_v = (-(v - 1/2) C_x'(v), -(u - 1/2) C_x'(u), C_x'(u) C_x'(v)) is
    # zero only at (1/2, 1/2), where S = (1/2, 1/2, 0). The Bernstein coefficients of u - 1/2 are i/3 - 1/2.
    x = [p[0] for p in CUSP_POLYGON]
    patch = {"name": "pinch", "type": "bezier",
             "points": [[[x[i], x[j], (i / 3 - 0.5) * (j / 3 - 0.5)] for j in range(4)] for i in range(4)]}
    return seam.loads(json.dumps({"patches": [patch], "curves": [curve, smooth]}), "cusp")


def test_regularity_finds_planted_cusp(run_cli, tmp_path):
    m = cusp_model()
    d = seam.evaluate_curve(m, "cusp", [0.5], 1)
    assert np.allclose(d[0, 0], CUSP_POINT) and np.allclose(d[0, 1], 0.0)  # the construction, checked
    n = normals(m, "pinch", [[0.5, 0.5], [0.4, 0.5], [0.5, 0.6], [0.25, 0.75]])
    assert np.allclose(n[0], 0.0) and np.all(np.linalg.norm(n[1:], axis=1) > 1e-3)

    r = seam.regularity(m)
    curves = {c["name"]: c for c in r["curves"]}
    cusp, smooth = curves["cusp"], curves["smooth"]
    assert cusp["critical_points"], cusp
    assert any(abs(c["t"] - 0.5) < 1e-3 and np.allclose(c["point"], CUSP_POINT, atol=1e-3)
               for c in cusp["critical_points"])
    assert all(s["verdict"] != "certified" for s in cusp["segments"])
    assert not smooth["critical_points"] and all(s["verdict"] == "certified" for s in smooth["segments"])
    pinch = r["patches"][0]
    assert pinch["name"] == "pinch" and pinch["critical_points"]
    for c in pinch["critical_points"]:
        assert abs(c["u"] - 0.5) < 1e-3 and abs(c["v"] - 0.5) < 1e-3 and np.allclose(c["point"], [0.5, 0.5, 0.0],
                                                                                       atol=1e-3)
    assert all(s["verdict"] != "certified" for s in pinch["subnets"])

    # The CLI on the same model: the same dict (the file named as given).
    path = tmp_path / "cusp.json"
    seam.save(m, path)
    code, expected, err = run_cli("regularity", str(path), "--json")
    assert code == 1, err  # a cusp is a problem
    again = seam.regularity(seam.load(str(path)))
    assert again == expected
    only = seam.regularity(m, curve="smooth")
    assert only["patches"] == [] and [c["name"] for c in only["curves"]] == ["smooth"]
    with pytest.raises(ValueError, match="not both"):
        seam.regularity(m, patch="pinch", curve="cusp")
    with pytest.raises(ValueError, match='no curve named "x"'):
        seam.regularity(m, curve="x")
    with pytest.raises(ValueError, match="ell"):
        seam.regularity(m, ell=-1)


def test_corner_errors(examples):
    m = seam.load(os.path.join(examples, "models", "two_patches.json"))
    with pytest.raises(ValueError, match="exactly one"):
        seam.corner(m)
    with pytest.raises(ValueError, match="three"):
        seam.corner(m, three=[("A", "u1", "v0"), ("B", "u0", "v0")])
    with pytest.raises(ValueError, match="four"):
        seam.corner(m, four=[("A", "u1"), ("B", "u0", "v0"), ("A", "u1", "v0"), ("B", "u0", "v0")])


def four_patch_vertex():
    """Four bicubic Bezier patches around the vertex (0, 0, 0) in cyclic order P1 (x, y >= 0), P2 (x <= 0 <= y),
    P3 (x, y <= 0), P4 (y <= 0 <= x), u along x and v along y; patch k is z = c_k x y (bilinear: its Bezier
    coefficients are its values at the grid points), zero on the axes: G0 everywhere, kinked across every seam."""
    def patch(name, x0, y0, c):
        return {"name": name, "type": "bezier",
                "points": [[[x0 + i / 3, y0 + j / 3, c * (x0 + i / 3) * (y0 + j / 3)] for j in range(4)]
                           for i in range(4)]}
    return {"patches": [patch("P1", 0, 0, 0.1), patch("P2", -1, 0, -0.05), patch("P3", -1, -1, 0.08),
                        patch("P4", 0, -1, -0.03)]}


FOUR = [("P1", "u0", "v0"), ("P2", "v0", "u1"), ("P3", "u1", "v1"), ("P4", "v1", "u0")]
FOUR_SEAMS = [("P1", "u0", "P2", "u1"), ("P2", "v0", "P3", "v1"), ("P3", "u1", "P4", "u0"), ("P4", "v1", "P1", "v0")]


def test_corner_four_matches_cli_and_is_g1(run_cli, tmp_path):
    m = seam.loads(json.dumps(four_patch_vertex()), "vertex")
    angles0 = [seam_angles(m, a, ae, b, be, (0, 1), (0, 1), False)[1].max() for a, ae, b, be in FOUR_SEAMS]
    assert max(angles0) > 5.0
    cornered, info = seam.corner(m, four=FOUR)
    src = tmp_path / "vertex.json"
    seam.save(m, src)
    cli_out = tmp_path / "cli.json"
    code, expected, err = run_cli("corner", str(src), "--four", *[":".join(x) for x in FOUR], "-o", str(cli_out),
                                  "--json")
    assert expected is not None, err
    expected.pop("output")
    assert info == expected
    seam.save(cornered, tmp_path / "py.json")
    assert (tmp_path / "py.json").read_bytes() == cli_out.read_bytes()
    assert info["achieved"] and code == 0, err
    for a, ae, b, be in FOUR_SEAMS:  # G1 at the vertex: every seam's tangent planes, measured with NumPy
        gap, angles = seam_angles(cornered, a, ae, b, be, cornered.domain(a)[0 if ae[0] == "v" else 1],
                                  cornered.domain(b)[0 if be[0] == "v" else 1], False, n=101)
        assert gap < 1e-9 and angles.max() < 1e-6, (a, b, angles.max())


def test_report_of_a_file(examples, tmp_path):
    path = os.path.join(examples, "models", "two_patches.json")
    out = tmp_path / "r.html"
    assert seam.report(path, out, title="from a file") == str(out)
    assert "from a file" in out.read_text()
    # A STEP/IGES path is the B-rep report (test_module.py compares it with the CLI's); a missing one names itself.
    with pytest.raises(OSError, match="part.step"):
        seam.report(os.path.join(examples, "part.step"), tmp_path / "s.html")
    with pytest.raises(ValueError, match="units= and preset= apply to the B-rep report"):
        seam.report(path, tmp_path / "u.html", units="mm")
    with pytest.raises(OSError, match="missing.json"):
        seam.report(tmp_path / "missing.json", tmp_path / "m.html")


@pytest.mark.parametrize("units,preset", [("in", None), (None, "rhino"), ("mm", "catia")])
def test_repairs_take_units_and_preset_as_the_cli(examples, run_cli, tmp_path, units, preset):
    """units= and preset= on heal, join and fill mean the CLI's --units and --preset: the same "units" and
    "tolerances" (and the same rest of the dict) as `seam heal/join/fill --json` with those flags."""
    flags, kwargs = [], {}
    if units:
        flags += ["--units", units]
        kwargs["units"] = units
    if preset:
        flags += ["--preset", preset]
        kwargs["preset"] = preset

    kinked = tmp_path / "kinked.json"
    seam.save(seam.loads(json.dumps(kinked_two_patches(examples)), "kinked"), kinked)
    _, info = seam.join(seam.load(kinked), "B", "u0", "A", "u1", **kwargs)
    code, expected, err = run_cli("join", str(kinked), "--move", "B:u0", "--to", "A:u1", "-o",
                                  str(tmp_path / "j.json"), "--json", *flags)
    assert code in (0, 1), err
    expected.pop("output")
    assert info == expected
    assert info["units"] == expected["units"] and info["tolerances"] == expected["tolerances"]
    if units:
        assert info["units"]["length"] == units
        assert info["tolerances"]["distance_source"] != "relative default"

    fan = os.path.join(examples, "models", "network_fan5.json")
    _, info = seam.heal(seam.load(fan), **kwargs)
    code, expected, err = run_cli("heal", fan, "-o", str(tmp_path / "h.json"), "--json", *flags)
    assert code in (0, 1), err
    expected.pop("output")
    assert info == expected

    quad = os.path.join(examples, "models", "fill_quad.json")
    _, info = seam.fill(seam.load(quad), quad=("r1", "r2", "r4"), **kwargs)
    code, expected, err = run_cli("fill", quad, "--quad", "r1", "r2", "r4", "-o", str(tmp_path / "f.json"), "--json",
                                  *flags)
    assert code in (0, 1), err
    info["output"] = expected["output"]
    assert info == expected


def test_repairs_refuse_bad_units_and_preset(examples):
    m = seam.loads(json.dumps(kinked_two_patches(examples)), "kinked")
    with pytest.raises(ValueError, match="units"):
        seam.join(m, "B", "u0", "A", "u1", units="furlong")
    with pytest.raises(ValueError, match="preset"):
        seam.heal(m, preset="solidworks")


@pytest.mark.skipif(not seam.has_occt, reason="STEP needs the OpenCASCADE build")
def test_a_step_model_keeps_its_unit_and_says_it_is_trimmed(shared_data, run_cli):
    """seam.load of a STEP file (issue 38 goal 10): the trimmed-face note of `seam check` as a Python warning, and
    the CLI's unit (mm from the header) and absolute default tolerance (0.001 mm, docs/tolerances.md) on every call
    on the loaded model, not the unit-less relative default."""
    path = os.path.join(shared_data, "step", "linkrods.step")
    with pytest.warns(UserWarning, match="faces are trimmed"):
        m = seam.load(path)
    code, cli, err = run_cli("check", path, "--json", "--patches")
    assert code == 0, err
    checked = seam.check(m)
    assert checked["units"]["length"] == cli["units"]["length"] == "mm"
    assert checked["tolerances"]["distance"] == cli["tolerances"]["distance"] == 0.001
    # heal of this trimmed model is the B-rep heal of its file (below), with the same tolerance.


@pytest.mark.skipif(not seam.has_occt, reason="STEP needs the OpenCASCADE build")
def test_heal_of_a_trimmed_step_model_is_the_brep_heal_of_the_cli(shared_data, run_cli, tmp_path):
    """Issue 34 §2: seam.heal of a model loaded from STEP with trimmed faces heals the B-rep (every face, trim and
    solid kept), returns the dict of `seam heal FILE -o OUT.step --json` (without "output") and a model that
    seam.save writes as STEP with its trims; a JSON model with trimmed faces, or one healed before, is healed as its
    B-rep too."""
    path = os.path.join(shared_data, "step", "trj3_s1-al-214.stp")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m = seam.load(path)
    healed, info = seam.heal(m)
    cli_out = tmp_path / "cli.step"
    code, expected, err = run_cli("heal", path, "-o", str(cli_out), "--json")
    assert code in (0, 1), err
    assert expected.pop("output") == str(cli_out)
    assert info == expected
    assert info["route"] == "brep" and info["seams_worse"] == 0 and info["seams_healed"] > 0
    assert info["tolerances"]["distance_mm"] == 0.001
    assert info["counts"]["faces"] == [94, 94] and info["counts"]["trimmed_faces"] == [76, 76]
    assert info["counts"]["solids"] == [5, 5]
    out = tmp_path / "py.step"
    seam.save(healed, out)
    code, saved, err = run_cli("check", str(out), "--json")
    code, cli_saved, err = run_cli("check", str(cli_out), "--json")
    for key in ("seams", "free_edges", "non_manifold_edges"):
        assert saved["summary"][key] == cli_saved["summary"][key], key
    # A JSON model with trimmed faces (its "brep") is healed as that B-rep, as `seam heal IN.json` heals it: the same
    # dict (the temporary STEP file of the B-rep is never named); and so is a model healed before.
    json_path = tmp_path / "trj3.json"
    seam.save(m, json_path)  # the trims as plain data (faces open as read included)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        healed_json, info_json = seam.heal(seam.load(str(json_path)))
        again, info_again = seam.heal(healed)
    code, expected_json, err = run_cli("heal", str(json_path), "-o", str(tmp_path / "cli.json"), "--json")
    assert code in (0, 1), err
    expected_json.pop("output")
    assert info_json == expected_json
    assert ".seam-" not in str(info_json)
    assert info_json["route"] == "brep" and info_json["seams_worse"] == 0
    assert info_json["seams_to_heal"] == info["seams_to_heal"]
    assert info_json["seams_healed"] == info["seams_healed"]
    assert info_again["counts"]["faces"] == [94, 94] and info_again["counts"]["trimmed_faces"] == [76, 76]
    assert info_again["seams_worse"] == 0
    assert healed_json.patch_names == m.patch_names
