#!/usr/bin/env python3
"""Validates `seam check --json` against docs/check.schema.json (issue 17 §3: one JSON shape for patch models and
B-rep files, tied to the file).

Usage: check_schema.py SCHEMA SEAM_BINARY MODEL...

Each MODEL is checked with `seam check MODEL --json` (exit 0 or 1 accepted); its output must validate against the
schema, name the file, and say its format. Beyond the schema, every seam must carry `geometric` and `verdict`, and a
seam whose analysis failed must say so (`verdict` error, `geometric` null). Run with Debian's /usr/bin/python3, which
sees python3-jsonschema.
"""
import json
import os
import subprocess
import sys

import jsonschema

FORMATS = {".json": "json", ".bpt": "bpt", ".step": "step", ".stp": "step", ".iges": "iges", ".igs": "iges"}


def check(schema, binary, model, extra=()):
    r = subprocess.run([binary, "check", model, "--json", *extra], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                       text=True, timeout=900)
    if r.returncode not in (0, 1):
        return [f"exit {r.returncode}: {r.stderr.strip()[-500:]}"]
    out = json.loads(r.stdout)
    problems = [f"{'/'.join(str(p) for p in e.absolute_path)}: {e.message}"
                for e in jsonschema.Draft202012Validator(schema).iter_errors(out)]
    if out.get("file") != model:
        problems.append(f"file is {out.get('file')!r}, not the input {model!r}")
    expected = FORMATS[os.path.splitext(model)[1].lower()]
    if out.get("format") != expected:
        problems.append(f"format is {out.get('format')!r}, expected {expected!r}")
    for s in out.get("seams", []):
        if "error" in s and (s.get("verdict") != "error" or s.get("geometric") is not None):
            problems.append(f"seam {s.get('index')}: failed analysis without verdict error / geometric null")
    if out["summary"]["seams"] < len(out["seams"]):
        problems.append("summary counts fewer seams than listed")
    units = out.get("units") or {}
    # Issue 38 §1: a STEP/IGES file is shown in the unit its header names (FOOT: ft, IN/INCH: in, MM: mm).
    header_unit = {"MM": "mm", "MILLIMETRE": "mm", "CM": "cm", "M": "m", "METRE": "m", "IN": "in", "INCH": "in",
                   "FT": "ft", "FOOT": "ft"}.get((units.get("file_unit") or "").upper(), "mm")
    if expected in ("step", "iges") and (units.get("length") != header_unit or units.get("source") != "file header"):
        problems.append(f"STEP/IGES units {units!r}: not the header's unit ({header_unit}) from the file header")
    if expected in ("json", "bpt") and not extra and units.get("length") is not None:
        problems.append(f"a JSON/.bpt model without --units has units {units!r}")
    return problems


def check_units(schema, binary, model):
    """A unit-less model with `--units m --preset catia`: units from --units, CATIA's 0.001 mm = 1e-6 m."""
    problems = check(schema, binary, model, ["--units", "m", "--preset", "catia"])
    r = subprocess.run([binary, "check", model, "--json", "--units", "m", "--preset", "catia"],
                       stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, timeout=900)
    out = json.loads(r.stdout)
    if out["units"] != {"length": "m", "file_unit": None, "source": "--units", "declared_resolution": None}:
        problems.append(f"--units m: units {out['units']!r}")
    if abs(out["tolerances"]["distance"] - 1e-6) > 1e-18 or out["tolerances"]["distance_source"] != "preset":
        problems.append(f"--units m --preset catia: tolerances {out['tolerances']!r}, expected 1e-6 from the preset")
    return problems


def main():
    schema_file, binary = sys.argv[1:3]
    models = sys.argv[3:]
    with open(schema_file, encoding="utf-8") as f:
        schema = json.load(f)
    jsonschema.Draft202012Validator.check_schema(schema)
    failures = 0
    for model in models:
        problems = check(schema, binary, model)
        if os.path.splitext(model)[1].lower() == ".json":
            problems += check_units(schema, binary, model)
        print(f"{'ok' if not problems else 'FAILED'}: {model}")
        for p in problems[:20]:
            print(f"  {p}")
        failures += bool(problems)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
