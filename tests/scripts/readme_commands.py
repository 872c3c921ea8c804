#!/usr/bin/env python3
"""Runs every `build/bin/seam` command of the README's sh code blocks (issue 17 §6: the README never drifts).

Usage: readme_commands.py README SEAM_BINARY SOURCE_DIR [--no-cad]

Each command runs with build/bin/seam replaced by SEAM_BINARY, in a fresh temporary working directory (so its
outputs land there), with the repository-relative inputs (examples/..., ../shared/...) made absolute. A command must
exit 0, or the code its trailing comment documents when the comment starts with it ("# exit 1: ...",
"# exits 1"). A block line that is not a seam
command is refused, except the set-up block (bash scripts/setup.sh, ctest). Exits 77 (skipped) when a command needs
../shared/data and that folder is missing, or (with --no-cad, a build without OpenCASCADE) reads or writes STEP/IGES.
"""
import os
import re
import shlex
import subprocess
import sys
import tempfile

SETUP_COMMANDS = ("bash scripts/setup.sh", "ctest ")


def sh_blocks(text):
    return re.findall(r"^```sh\n(.*?)^```", text, flags=re.S | re.M)


def commands(readme):
    """(line, expected exit code) of every seam command in the README's sh blocks; a comment-only line continues
    the comment of the command above it."""
    with open(readme, encoding="utf-8") as f:
        text = f.read()
    found = []
    for block in sh_blocks(text):
        for line in block.splitlines():
            stripped = line.strip()
            if not stripped or stripped.startswith("#") or stripped.startswith(SETUP_COMMANDS):
                continue
            if not stripped.startswith("build/bin/seam"):
                raise SystemExit(f"{readme}: a sh block line that is not a seam command: {stripped!r}")
            code, _, comment = stripped.partition("#")
            m = re.match(r"\s*exits? (\d)\b", comment)
            found.append((code.strip(), int(m.group(1)) if m else 0))
    return found


def argv_of(command, binary, source_dir):
    args = shlex.split(command)
    assert args[0] == "build/bin/seam"
    out = [binary]
    for a in args[1:]:
        if a.startswith("examples/") or a.startswith("../shared/"):
            a = os.path.normpath(os.path.join(source_dir, a))
        out.append(a)
    return out


def main():
    readme, binary, source_dir = sys.argv[1:4]
    binary, source_dir = os.path.abspath(binary), os.path.abspath(source_dir)
    no_cad = "--no-cad" in sys.argv[4:]
    cmds = commands(readme)
    if len(cmds) < 5:
        raise SystemExit(f"{readme}: found only {len(cmds)} seam commands; the Quick start block was not parsed")
    shared = os.path.normpath(os.path.join(source_dir, "../shared/data"))
    failures = 0
    skipped = 0
    for command, expected in cmds:
        argv = argv_of(command, binary, source_dir)
        if any(a.startswith(shared) for a in argv) and not os.path.isdir(shared):
            print(f"skipped (no {shared}): {command}")
            skipped += 1
            continue
        if no_cad and any(re.search(r"\.(step|stp|iges|igs)$", a, flags=re.I) for a in argv):
            print(f"skipped (a build without OpenCASCADE): {command}")
            skipped += 1
            continue
        with tempfile.TemporaryDirectory(prefix="seam_readme_") as work:
            r = subprocess.run(argv, cwd=work, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                               timeout=600)
        status = "ok" if r.returncode == expected else "FAILED"
        print(f"{status}: exit {r.returncode} (expected {expected}): {command}")
        if r.returncode != expected:
            failures += 1
            sys.stdout.write(r.stderr[-2000:])
    print(f"{len(cmds)} README commands, {failures} failed, {skipped} skipped")
    if failures:
        return 1
    return 77 if skipped else 0


if __name__ == "__main__":
    sys.exit(main())
