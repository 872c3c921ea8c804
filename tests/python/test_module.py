"""The Python module against the CLI: load, evaluate and check reach the same numbers and dicts by the CLI's route
(`seam eval --json`, `seam check --json`), and bad input raises exceptions that name the problem."""
import json
import math
import os
import subprocess

import numpy as np
import pytest

import seam

RNG = np.random.default_rng(20261125)  # fixed seed: the parameters evaluated below


def test_import_and_version():
    assert isinstance(seam.__version__, str) and seam.__version__.count(".") == 2


def test_load_names_patches(examples):
    m = seam.load(os.path.join(examples, "models", "two_patches.json"))
    assert m.patch_names == ["A", "B", "QuarterCylinder"]
    assert len(m) == 3
    box = m.bounding_box()
    assert box.shape == (2, 3) and np.all(box[0] <= box[1])


def test_evaluate_matches_cli(examples, run_cli):
    path = os.path.join(examples, "models", "two_patches.json")
    m = seam.load(path)
    for patch in m.patch_names:
        (u0, u1), (v0, v1) = m.domain(patch)
        uv = np.column_stack([RNG.uniform(u0, u1, 5), RNG.uniform(v0, v1, 5)])
        points = seam.evaluate(m, patch, uv)
        d = seam.derivatives(m, patch, uv, 2)
        assert points.shape == (5, 3) and d.shape == (5, 3, 3, 3)
        assert np.array_equal(points, d[:, 0, 0, :])
        assert np.all(np.isnan(d[:, 1, 2, :])) and np.all(np.isnan(d[:, 2, 2, :]))  # k + l > 2: not computed
        for i in range(len(uv)):
            code, out, err = run_cli("eval", path, "--patch", patch, "--uv", repr(uv[i, 0]), repr(uv[i, 1]),
                                     "--derivs", "2", "--json")
            assert code == 0, err
            # The same double evaluated by the same code: the CLI prints round-trip precision, so exactly equal.
            assert points[i].tolist() == out["point"]
            for key, value in out["derivatives"].items():
                k, l = (int(x) for x in key.split(","))
                assert d[i, k, l].tolist() == value, (patch, key)


def test_evaluate_single_pair_and_lists(examples):
    m = seam.load(os.path.join(examples, "models", "two_patches.json"))
    one = seam.evaluate(m, "A", [0.25, 0.5])
    many = seam.evaluate(m, "A", [[0.25, 0.5], [0.25, 0.5]])
    assert one.shape == (1, 3) and np.array_equal(many[0], one[0]) and np.array_equal(many[1], one[0])


@pytest.mark.parametrize("model", ["two_patches.json", "network_fan5.json"])
def test_check_dict_equals_cli_json(examples, run_cli, model):
    path = os.path.join(examples, "models", model)
    code, expected, err = run_cli("check", path, "--json")
    assert code == 0, err
    got = seam.check(path)
    assert list(got.keys()) == list(expected.keys())
    assert list(got["summary"].keys()) == list(expected["summary"].keys())
    assert got == expected  # same builder, same numbers (the CLI prints round-trip precision)
    assert seam.check(seam.load(path)) == expected  # a loaded model: the same check


def test_check_options_match_cli(examples, run_cli):
    path = os.path.join(examples, "models", "two_patches.json")
    code, expected, err = run_cli("check", path, "--json", "--sort", "angle", "--top", "1", "--require", "G2",
                                  "--tol-angle", "0.5", "--crease-angle", "30")
    got = seam.check(path, sort="angle", top=1, require="G2", tol_angle=0.5, crease_angle=30)
    assert got == expected
    assert code == (1 if got["summary"]["below_required"] > 0 else 0), err


def test_check_bpt_matches_cli(shared_data, run_cli):
    path = os.path.join(shared_data, "bezier", "teaspoon.bpt")
    code, expected, err = run_cli("check", path, "--json")
    assert code == 0, err
    assert seam.check(path) == expected


@pytest.mark.skipif(not seam.has_occt, reason="built without OpenCASCADE")
def test_check_step_brep_matches_cli(shared_data, run_cli):
    path = os.path.join(shared_data, "step", "bug28366_fuselage.stp")
    code, expected, err = run_cli("check", path, "--json")
    assert code == 0, err
    got = seam.check(path)
    assert got == expected
    assert "non_manifold_edges" in got and got["model"]["faces"] > 0  # the B-rep route, not the patch one
    m = seam.load(path)
    assert len(m) == got["model"]["faces"]


@pytest.mark.parametrize("units, preset", [("mm", None), ("in", "catia"), ("m", "nx"), ("ft", "rhino"),
                                           (None, "rhino"), ("cm", None)])
def test_check_units_preset_match_cli(examples, run_cli, units, preset):
    """units= and preset= mean the CLI's --units and --preset: the same dict as `seam check --json` with those flags."""
    path = os.path.join(examples, "models", "two_patches.json")
    flags = (["--units", units] if units else []) + (["--preset", preset] if preset else [])
    code, expected, err = run_cli("check", path, "--json", *flags)
    assert expected is not None, err
    got = seam.check(path, units=units, preset=preset)
    assert got == expected
    assert seam.check(seam.load(path), units=units, preset=preset) == expected  # a loaded model: the same
    assert got["units"]["length"] == units  # None: unit-less
    assert got["units"]["source"] == ("--units" if units else "none (unit-less model)")
    # The preset's millimetres (docs/tolerances.md) converted to the model's unit.
    scale = {"mm": 1.0, "cm": 10.0, "m": 1000.0, "in": 25.4, "ft": 304.8}
    if preset and units:
        mm = {"catia": 0.001, "rhino": 0.001, "nx": 0.0254}[preset]
        assert got["tolerances"]["distance"] == pytest.approx(mm / scale[units], rel=1e-15)


@pytest.mark.skipif(not seam.has_occt, reason="built without OpenCASCADE")
def test_check_units_preset_cad_match_cli(shared_data, run_cli):
    """A STEP file (mm in its header): units= rescales it as --units does, a preset's mm stay mm."""
    path = os.path.join(shared_data, "step", "bug28366_fuselage.stp")
    for flags, kwargs in ((["--units", "in", "--preset", "catia"], dict(units="in", preset="catia")),
                          (["--preset", "nx"], dict(preset="nx"))):
        code, expected, err = run_cli("check", path, "--json", *flags)
        assert expected is not None, err
        assert seam.check(path, **kwargs) == expected
    assert expected["tolerances"]["distance_source"] == "preset"


@pytest.mark.skipif(not seam.has_occt, reason="built without OpenCASCADE")
def test_check_display_units_match_cli(shared_data, examples, run_cli):
    """display_units= is --display-units (issue 38 §1): the fuselage (FOOT) shown in feet by default, in mm on
    request, the same dict as the CLI's; every gap in mm is the gap in feet times 304.8."""
    path = os.path.join(shared_data, "step", "bug28366_fuselage.stp")
    feet = seam.check(path)
    assert feet["units"]["length"] == "ft" and feet["units"]["source"] == "file header"
    code, expected, err = run_cli("check", path, "--json", "--display-units", "mm")
    assert code in (0, 1), err
    mm = seam.check(path, display_units="mm")
    assert mm == expected
    assert mm["units"]["length"] == "mm" and mm["units"]["source"] == "--display-units"
    for a, b in zip(feet["seams"], mm["seams"]):
        assert b["g0_max"] == pytest.approx(a["g0_max"] * 304.8, rel=1e-9, abs=1e-12)
        assert b["verdict"] == a["verdict"]
    with pytest.raises(ValueError, match="display_units"):
        seam.check(path, display_units="furlong")
    unitless = os.path.join(examples, "models", "two_patches.json")
    with pytest.raises(ValueError, match="--display-units needs a model with a length unit"):
        seam.check(unitless, display_units="cm")
    assert seam.check(unitless, units="mm", display_units="cm")["units"]["length"] == "cm"


def test_check_bad_units_preset_raise(examples, run_cli):
    path = os.path.join(examples, "models", "two_patches.json")
    with pytest.raises(ValueError, match=r'units: "furlong" is not a length unit \(use mm, cm, m, in, ft\)'):
        seam.check(path, units="furlong")
    with pytest.raises(ValueError, match=r'preset: "solidworks" is not a preset \(use catia, rhino, nx\)'):
        seam.check(seam.load(path), preset="solidworks")
    code, _, err = run_cli("check", path, "--units", "furlong")  # the CLI refuses the same values: exit 2
    assert code == 2 and "furlong" in err
    code, _, err = run_cli("check", path, "--preset", "solidworks")
    assert code == 2 and "solidworks" in err


def test_bad_input_raises(tmp_path, examples):
    missing = tmp_path / "missing.json"
    with pytest.raises(OSError, match="missing.json"):
        seam.load(missing)
    with pytest.raises(OSError, match="missing.json"):
        seam.check(str(missing))
    bad = tmp_path / "bad.json"
    bad.write_text('{"patches": [{"name": "P", "degree": [3, 3]')
    with pytest.raises(ValueError, match="bad.json"):
        seam.load(bad)
    unknown = tmp_path / "model.xyz"
    unknown.write_text("x")
    with pytest.raises((ValueError, OSError), match="model.xyz"):
        seam.load(unknown)
    m = seam.load(os.path.join(examples, "models", "two_patches.json"))
    with pytest.raises(ValueError, match='no patch named "S1"'):
        seam.evaluate(m, "S1", [0.5, 0.5])
    with pytest.raises(ValueError, match=r'patch "A": u = 2 is outside the parameter domain'):
        seam.evaluate(m, "A", [[0.5, 0.5], [2.0, 0.5]])
    with pytest.raises(ValueError, match="not a finite number"):
        seam.evaluate(m, "A", [math.nan, 0.5])
    with pytest.raises(ValueError, match="shape"):
        seam.evaluate(m, "A", np.zeros((3, 3)))
    with pytest.raises(ValueError, match="derivative order"):
        seam.derivatives(m, "A", [0.5, 0.5], -1)
    with pytest.raises(ValueError, match="require"):
        seam.check(m, require="G3")
    with pytest.raises(ValueError, match="tol_distance"):
        seam.check(m, tol_distance=-1.0)
    with pytest.raises(ValueError, match="crease_angle"):
        seam.check(m, crease_angle=200.0)


def test_heal_matches_cli(examples, run_cli, tmp_path):
    path = os.path.join(examples, "models", "network_fan5.json")
    cli_out = tmp_path / "cli.json"
    code, expected, err = run_cli("heal", path, "-o", str(cli_out), "--json")
    assert code == 0, err
    healed, info = seam.heal(seam.load(path))
    expected.pop("output")
    assert info == expected
    py_out = tmp_path / "py.json"
    seam.save(healed, py_out)
    assert py_out.read_bytes() == cli_out.read_bytes()  # the same healed model, written by the same writer
    with pytest.raises(ValueError, match="continuity"):
        seam.heal(healed, continuity="G3")
    g2, info_g2 = seam.heal(seam.load(path), continuity="G2")  # the G2 network solve (issue 14)
    assert info_g2["achieved"] and info_g2["requested"] == "G2"
    with pytest.raises(ValueError, match="fairness"):
        seam.heal(seam.load(path), continuity="G2", fairness=-1.0)


@pytest.mark.skipif(not seam.has_occt, reason="built without OpenCASCADE")
@pytest.mark.parametrize("name, kwargs", [("iges/BUC50025.igs", {}),
                                          ("step/bug28366_fuselage.stp", dict(units="in", preset="catia"))])
def test_brep_report_matches_cli(cli, shared_data, run_cli, tmp_path, name, kwargs):
    """seam.report on a STEP/IGES path is the B-rep report of `seam report FILE` (same builder): the same page, byte
    for byte, as the CLI process writes with the same flags; the CLI names as many B-rep seams as `seam check
    --json` finds."""
    path = os.path.join(shared_data, name)
    flags = [x for k, v in kwargs.items() for x in (f"--{k}", v)]
    cli_out, py_out = tmp_path / "cli.html", tmp_path / "py.html"
    p = subprocess.run([cli, "report", path, "-o", str(cli_out), *flags], capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    assert seam.report(path, py_out, **kwargs) == str(py_out)
    page = py_out.read_text()
    assert page == cli_out.read_text()
    code, checked, err = run_cli("check", path, "--json", *flags)
    assert code in (0, 1), err
    assert f"({checked['summary']['seams']} B-rep seams" in p.stdout
    assert "OpenCASCADE" in page  # the B-rep route's extra column, not the patch route
    if kwargs.get("units"):
        assert "--units" in page
    with pytest.raises(ValueError, match="furlong"):
        seam.report(path, tmp_path / "bad.html", units="furlong")
    with pytest.raises(OSError, match="missing.step"):
        seam.report(tmp_path / "missing.step", tmp_path / "bad.html")


@pytest.mark.skipif(not seam.has_occt, reason="built without OpenCASCADE")
def test_report_of_a_json_with_its_brep_is_the_brep_report(cli, shared_data, run_cli, tmp_path):
    """A JSON with trimmed faces and their topology ("brep") is reported as a B-rep, as `seam check` of it: its
    faces' real edges (linkrods: 108), not the patches of their parameter boxes (35); the same page from Python as
    from the CLI."""
    json_path = tmp_path / "linkrods.json"
    code, _, err = run_cli("convert", os.path.join(shared_data, "step", "linkrods.step"), str(json_path))
    assert code == 0, err
    cli_out, py_out = tmp_path / "cli.html", tmp_path / "py.html"
    p = subprocess.run([cli, "report", str(json_path), "-o", str(cli_out)], capture_output=True, text=True,
                       timeout=300)
    assert p.returncode == 0, p.stderr
    code, checked, err = run_cli("check", str(json_path), "--json")
    assert code in (0, 1), err
    assert checked["summary"]["seams"] == 108
    assert f"({checked['summary']['seams']} B-rep seams" in p.stdout
    assert seam.report(str(json_path), py_out) == str(py_out)
    assert py_out.read_text() == cli_out.read_text()
    assert "OpenCASCADE" in py_out.read_text()


def test_report_writes_html(examples, tmp_path):
    m = seam.load(os.path.join(examples, "models", "two_patches.json"))
    out = tmp_path / "r.html"
    assert seam.report(m, out, title="two patches") == str(out)
    text = out.read_text()
    assert text.lstrip().lower().startswith("<!doctype html") and "two patches" in text
    assert not [p for p in tmp_path.iterdir() if p.name != "r.html"]  # atomic: no temporary file left
    with pytest.raises(OSError):
        seam.report(m, tmp_path)  # a directory is not an output file
    with pytest.raises(ValueError, match=r"save writes .json, .step/.stp and .iges/.igs"):
        seam.save(m, tmp_path / "m.obj")
    if seam.has_occt:  # STEP by the extension, as `seam convert x.json y.step`: the patches sewn
        seam.save(m, tmp_path / "m.step")
        assert seam.check(str(tmp_path / "m.step"))["summary"]["seams"] == seam.check(m)["summary"]["seams"]


def test_curve_parameters_are_a_number_or_a_list_of_reals(examples):
    """evaluate_curve (issue 39 §5): (2, 2) used to be flattened into 4 parameters and complex input lost its
    imaginary part; both are a ValueError now. A number and an (n,) list still work."""
    m = seam.loads(json.dumps({"curves": [{"name": "line", "type": "bezier", "points": [[0, 0, 0], [2, 4, 6]]}]}),
                   "line")
    assert np.allclose(seam.evaluate_curve(m, "line", 0.5)[0, 0], [1, 2, 3])  # the straight line, by hand
    assert seam.evaluate_curve(m, "line", [0.25, 0.5]).shape == (2, 1, 3)
    with pytest.raises(ValueError, match=r"shape \(n,\), not of shape \(2, 2\)"):
        seam.evaluate_curve(m, "line", np.full((2, 2), 0.5))
    with pytest.raises(ValueError, match="complex"):
        seam.evaluate_curve(m, "line", np.array([0.5 + 0.25j]))
    with pytest.raises(ValueError, match="complex"):
        seam.evaluate(seam.load(os.path.join(examples, "models", "two_patches.json")), "A", [[0.5 + 1j, 0.5]])
    with pytest.raises(ValueError, match="real numbers"):
        seam.evaluate_curve(m, "line", ["a"])


def test_step_to_json_keeps_the_trims(shared_data, cli, tmp_path):
    """Issue 34 §1: STEP -> seam.load -> seam.save(.json) keeps the trimmed faces (the JSON's "brep"), and the JSON
    converts back to a STEP file with the same faces, trimmed faces and solids (counted by `seam convert` on the
    STEP -> STEP route, which is OpenCASCADE's own B-rep, not the JSON's)."""
    import json
    import re
    path = os.path.join(shared_data, "step", "linkrods.step")
    m = seam.load(path)
    out = tmp_path / "linkrods.json"
    seam.save(m, str(out))
    doc = json.loads(out.read_text())
    assert "brep" in doc and len(doc["brep"]["faces"]) == len(m)
    import subprocess
    back = subprocess.run([cli, "convert", str(out), str(tmp_path / "back.step")], capture_output=True, text=True)
    assert back.returncode == 0, back.stderr
    direct = subprocess.run([cli, "convert", path, str(tmp_path / "direct.step")], capture_output=True, text=True)
    assert direct.returncode == 0, direct.stderr
    text, direct = back.stdout, direct.stdout
    counts = lambda s: re.search(r"(\d+) faces, (\d+) of them trimmed, \d+ edges, \d+ shells, (\d+) solids", s).groups()
    assert counts(text) == counts(direct)
